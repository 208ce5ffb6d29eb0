/* A group's error, measured against the full-detail surface (docs/GEOMETRY.md, "The error").
 *
 * Every distinct level-0 position is a *sample* of the full-detail surface S0, owned by exactly one
 * cluster of the frontier (at first the first level-0 cluster that uses it). When a group is
 * simplified into new clusters, each of its members' samples passes to the new cluster whose
 * triangle is nearest to it. The group's deviation is the larger of
 *  - the largest distance from one of its samples to the simplified triangles (exact), and
 *  - an upper bound of the largest distance from probe points of the simplified triangles (grids
 *    of 3 steps an edge, 8 where the deviation is largest) to S0: the distance to the level-0 triangles around the position a
 *    walk ends at, or where that looks far off, to all level-0 triangles around the group's
 *    samples or around its simplified corners (a distance to some triangles of S0 is never below
 *    the distance to S0).
 * The group's error is the larger of its deviation and the errors of the groups its members came
 * from. Every level-0 position stays a sample at every step (that is what the proof needs). The
 * group's farthest samples (above its floor: members' errors and D2) are listed for lod_redirect.c,
 * which may pass them to a neighbouring group's cluster. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geometry/lod_internal.h"
#include "geometry/lod_sort.h"

#define NO_SOURCE UINT32_MAX

static gdr_vec3 sub3(gdr_vec3 x, gdr_vec3 y) { return (gdr_vec3){x.x - y.x, x.y - y.y, x.z - y.z}; }
static float dot3(gdr_vec3 x, gdr_vec3 y) { return x.x * y.x + x.y * y.y + x.z * y.z; }
/* o + t * d */
static gdr_vec3 along(gdr_vec3 o, float t, gdr_vec3 d) { return (gdr_vec3){o.x + t * d.x, o.y + t * d.y, o.z + t * d.z}; }

/* Squared distance from p to triangle (a, b, c), by the region of the closest point q. Any corner
 * bounds the distance too (d(p, a), the smaller is returned): that guards the degenerate cases. In
 * scalars, not arrays, so that the compiler keeps them in registers. *where: FOOT_INSIDE where q
 * lies inside the triangle (p's foot on its plane), the edge k (joining corners k and k + 1 mod 3)
 * where q lies on it, FOOT_CORNER at a corner. */
#define FOOT_INSIDE 3
#define FOOT_CORNER 4
static float point_triangle_foot_d2(gdr_vec3 p, gdr_vec3 a, gdr_vec3 b, gdr_vec3 c, int *where)
{
    *where = FOOT_CORNER;
    gdr_vec3 ab = sub3(b, a), ac = sub3(c, a), ap = sub3(p, a);
    float d1 = dot3(ab, ap), d2 = dot3(ac, ap), da = dot3(ap, ap);
    if (d1 <= 0.0f && d2 <= 0.0f)
        return da; /* q = a */
    gdr_vec3 bp = sub3(p, b), cp = sub3(p, c);
    float d3 = dot3(ab, bp), d4 = dot3(ac, bp), d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    float va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
    gdr_vec3 q;
    if (d3 >= 0.0f && d4 <= d3) {
        q = b;
    } else if (d6 >= 0.0f && d5 <= d6) {
        q = c;
    } else if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) {
        q = along(a, d1 / (d1 - d3), ab);
        *where = 0;
    } else if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) {
        q = along(a, d2 / (d2 - d6), ac);
        *where = 2;
    } else if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) {
        q = along(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), sub3(c, b));
        *where = 1;
    } else {
        float denom = va + vb + vc;
        float v = vb / denom, w = vc / denom;
        *where = denom > 0.0f ? FOOT_INSIDE : FOOT_CORNER;
        if (!(denom > 0.0f)) /* degenerate: nearest corner */
            v = w = 0.0f;
        q = (gdr_vec3){a.x + ab.x * v + ac.x * w, a.y + ab.y * v + ac.y * w, a.z + ab.z * v + ac.z * w};
    }
    gdr_vec3 pq = sub3(p, q);
    float d = dot3(pq, pq);
    return d < da ? d : da;
}

static float point_triangle_d2(gdr_vec3 p, gdr_vec3 a, gdr_vec3 b, gdr_vec3 c)
{
    int where;
    return point_triangle_foot_d2(p, a, b, c, &where);
}

static gdr_vec3 load3(const float *f) { return (gdr_vec3){f[0], f[1], f[2]}; }

/* --- setup ------------------------------------------------------------------------------------- */

static int reserve_cluster_samples(lod_build *b, size_t need)
{
    if (need <= b->cluster_sample_cap)
        return 1;
    size_t n = b->cluster_sample_cap ? b->cluster_sample_cap : 64;
    while (n < need)
        n *= 2;
    uint32_t *first = realloc(b->cluster_sample_first, n * sizeof *first);
    if (!first)
        return 0;
    b->cluster_sample_first = first;
    uint32_t *count = realloc(b->cluster_sample_count, n * sizeof *count);
    if (!count)
        return 0;
    b->cluster_sample_count = count;
    uint32_t *source = realloc(b->cluster_sample_source, n * sizeof *source);
    if (!source)
        return 0;
    b->cluster_sample_source = source;
    b->cluster_sample_cap = n;
    return 1;
}

/* Level-0 triangles around each position (by position id), as cluster << 9 | triangle << 2 | the
 * corner that is the position (a walk looks only at the other two). */
static int build_adjacency(lod_build *b, uint32_t level0)
{
    size_t corners = 0;
    for (uint32_t c = 0; c < level0; c++)
        corners += (size_t)b->clusters[c].triangle_count * 3;
    b->adjacency_start = calloc((size_t)b->position_count + 1, sizeof *b->adjacency_start);
    b->adjacency = malloc((corners ? corners : 1) * sizeof *b->adjacency);
    if (!b->adjacency_start || !b->adjacency || corners > UINT32_MAX)
        return 0;
    for (uint32_t c = 0; c < level0; c++) {
        const gdr_cluster *k = &b->clusters[c];
        const uint8_t *t = gdr_lod_cluster_triangles(b, k);
        const uint32_t *v = gdr_lod_cluster_vertices(b, k);
        for (uint32_t i = 0; i < k->triangle_count * 3; i++)
            b->adjacency_start[b->position_id[v[t[i]]] + 1]++;
    }
    for (uint32_t p = 0; p < b->position_count; p++)
        b->adjacency_start[p + 1] += b->adjacency_start[p];
    for (uint32_t c = 0; c < level0; c++) {
        const gdr_cluster *k = &b->clusters[c];
        const uint8_t *t = gdr_lod_cluster_triangles(b, k);
        const uint32_t *v = gdr_lod_cluster_vertices(b, k);
        for (uint32_t i = 0; i < k->triangle_count * 3; i++)
            b->adjacency[b->adjacency_start[b->position_id[v[t[i]]]]++] = c << 9 | (i / 3) << 2 | (i % 3);
    }
    for (uint32_t p = b->position_count; p > 0; p--) /* start[p] now holds the end of p: shift back */
        b->adjacency_start[p] = b->adjacency_start[p - 1];
    b->adjacency_start[0] = 0;
    return 1;
}

/* An adjacency entry's triangle (its three corners as bytes into its cluster's vertices), and its
 * cluster's vertices: from the compact table of the level-0 clusters' offsets, which stays in the
 * nearest cache where the clusters (72 bytes each) do not. */
static const uint8_t *ring_triangle(const lod_build *b, uint32_t entry)
{
    return b->triangles + b->level0_offsets[(size_t)(entry >> 9) * 2 + 1] + (size_t)(entry >> 2 & 127) * 3;
}
static const uint32_t *ring_vertices(const lod_build *b, uint32_t entry)
{
    return b->vertices + b->level0_offsets[(size_t)(entry >> 9) * 2];
}

/* The compact table of the level-0 clusters' offsets (ring_triangle). */
static int build_level0_offsets(lod_build *b, uint32_t level0)
{
    b->level0_offsets = malloc(((size_t)level0 + 1) * 2 * sizeof *b->level0_offsets);
    if (!b->level0_offsets)
        return 0;
    for (uint32_t c = 0; c < level0; c++) {
        b->level0_offsets[(size_t)c * 2] = b->clusters[c].vertex_offset;
        b->level0_offsets[(size_t)c * 2 + 1] = b->clusters[c].triangle_offset;
    }
    return 1;
}

/* Each position used by level 0 is owned by the first level-0 cluster that uses it. */
static int assign_level0_samples(lod_build *b, uint32_t level0)
{
    uint32_t *owner = b->owner; /* free until the first step: borrowed, then reset */
    b->samples = malloc(((size_t)b->position_count + 1) * sizeof *b->samples);
    if (!b->samples || !reserve_cluster_samples(b, level0))
        return 0;
    for (uint32_t c = 0; c < level0; c++) {
        const gdr_cluster *k = &b->clusters[c];
        const uint32_t *v = gdr_lod_cluster_vertices(b, k);
        b->cluster_sample_first[c] = b->sample_count;
        for (uint32_t j = 0; j < k->vertex_count; j++) {
            uint32_t p = b->position_id[v[j]];
            if (owner[p] != OWNER_NONE)
                continue;
            owner[p] = c;
            b->sample_vertex[p] = v[j];
            b->samples[b->sample_count++] = p;
        }
        b->cluster_sample_count[c] = b->sample_count - b->cluster_sample_first[c];
        b->cluster_sample_source[c] = NO_SOURCE;
    }
    memset(owner, 0xff, (size_t)b->position_count * sizeof *owner);
    return 1;
}

int gdr_lod_error_setup(lod_build *b)
{
    uint32_t level0 = b->mesh->clusters.level0_cluster_count;
    b->sample_vertex = malloc(((size_t)b->position_count + 1) * sizeof *b->sample_vertex);
    if (!b->sample_vertex || level0 >= (1u << 23)) /* adjacency entries hold the cluster in 23 bits */
        return 0;
    return build_adjacency(b, level0) && build_level0_offsets(b, level0) && assign_level0_samples(b, level0);
}

void gdr_lod_error_free(lod_build *b)
{
    free(b->sample_vertex);
    free(b->adjacency_start);
    free(b->adjacency);
    free(b->level0_offsets);
    free(b->samples);
    free(b->cluster_sample_first);
    free(b->cluster_sample_count);
    free(b->cluster_sample_source);
}

/* --- following the frontier -------------------------------------------------------------------- */

int gdr_lod_error_inherit(lod_build *b, uint32_t cluster, uint32_t from)
{
    if (!reserve_cluster_samples(b, (size_t)cluster + 1))
        return 0;
    b->cluster_sample_first[cluster] = b->cluster_sample_first[from];
    b->cluster_sample_count[cluster] = b->cluster_sample_count[from];
    b->cluster_sample_source[cluster] = b->cluster_sample_source[from];
    return 1;
}

int gdr_lod_error_adopt(lod_build *b, uint32_t cluster, uint32_t group, const group_result *r, uint32_t index)
{
    if (!reserve_cluster_samples(b, (size_t)cluster + 1))
        return 0;
    b->cluster_sample_first[cluster] = r->cluster_sample_first[index];
    b->cluster_sample_count[cluster] = r->cluster_sample_first[index + 1] - r->cluster_sample_first[index];
    b->cluster_sample_source[cluster] = group;
    return 1;
}

int gdr_lod_error_gather(lod_build *b, const uint32_t *frontier, uint32_t count)
{
    uint32_t *next = malloc(((size_t)b->position_count + 1) * sizeof *next);
    if (!next)
        return 0;
    uint32_t n = 0;
    for (uint32_t f = 0; f < count; f++) {
        uint32_t c = frontier[f], src = b->cluster_sample_source[c];
        const uint32_t *from = src == NO_SOURCE ? b->samples : b->results[src].samples;
        memcpy(next + n, from + b->cluster_sample_first[c], b->cluster_sample_count[c] * sizeof *next);
        b->cluster_sample_first[c] = n;
        b->cluster_sample_source[c] = NO_SOURCE;
        n += b->cluster_sample_count[c];
    }
    free(b->samples);
    b->samples = next;
    b->sample_count = n;
    return 1;
}

/* --- one group ----------------------------------------------------------------------------------- */

/* The simplified triangles (group-local vertex ids) in cluster order, the cluster of each, and the
 * triangles around each local vertex. */
static int output_triangles(lod_scratch *s, const group_result *r, uint32_t local_count)
{
    uint32_t t = 0;
    for (uint32_t i = 0; i < r->cluster_count; i++)
        t += s->meshlets[i].triangle_count;
    if (!LOD_RESERVE(s, out_corners, (size_t)t * 3) || !LOD_RESERVE(s, out_cluster, t) ||
        !LOD_RESERVE(s, ring_start, (size_t)local_count + 1) || !LOD_RESERVE(s, ring, (size_t)t * 3))
        return 0;
    t = 0;
    for (uint32_t i = 0; i < r->cluster_count; i++) {
        const struct meshopt_Meshlet *m = &s->meshlets[i];
        for (uint32_t j = 0; j < m->triangle_count * 3; j++)
            s->out_corners[(size_t)t * 3 + j] = s->meshlet_vertices[m->vertex_offset +
                                                                     s->meshlet_triangles[m->triangle_offset + j]];
        for (uint32_t j = 0; j < m->triangle_count; j++)
            s->out_cluster[t + j] = i;
        t += m->triangle_count;
    }
    s->out_triangle_count = t;
    memset(s->ring_start, 0, ((size_t)local_count + 1) * sizeof *s->ring_start);
    for (size_t i = 0; i < (size_t)t * 3; i++)
        s->ring_start[s->out_corners[i] + 1]++;
    for (uint32_t l = 0; l < local_count; l++)
        s->ring_start[l + 1] += s->ring_start[l];
    for (size_t i = 0; i < (size_t)t * 3; i++)
        s->ring[s->ring_start[s->out_corners[i]]++] = (uint32_t)(i / 3);
    for (uint32_t l = local_count; l > 0; l--)
        s->ring_start[l] = s->ring_start[l - 1];
    s->ring_start[0] = 0;
    return 1;
}

/* The members' samples, gathered in member order, with their coordinates. */
static int gather_samples(lod_build *b, lod_scratch *s, const uint32_t *members, uint32_t count)
{
    size_t n = 0;
    for (uint32_t i = 0; i < count; i++)
        n += b->cluster_sample_count[members[i]];
    if (!LOD_RESERVE(s, sample_ids, n + 1) || !LOD_RESERVE(s, sample_points, n + 1) ||
        !LOD_RESERVE(s, sample_cluster, n + 1))
        return 0;
    n = 0;
    for (uint32_t i = 0; i < count; i++) {
        uint32_t c = members[i];
        const uint32_t *ids = b->samples + b->cluster_sample_first[c];
        for (uint32_t j = 0; j < b->cluster_sample_count[c]; j++) {
            s->sample_ids[n] = ids[j];
            s->sample_points[n++] = b->mesh->positions[b->sample_vertex[ids[j]]];
        }
    }
    s->gathered = (uint32_t)n;
    return 1;
}

/* Distance (squared) from p to the triangles around local vertex l, and the nearest of them; the
 * search stops at distance 0 (p is a corner) and at the first triangle that holds p's foot and
 * brings it to at most `enough` (the nearest there, on a surface). */
static float ring_d2(const lod_scratch *s, uint32_t l, gdr_vec3 p, uint32_t *nearest, float enough)
{
    float best = INFINITY;
    *nearest = s->ring[s->ring_start[l]];
    for (uint32_t k = s->ring_start[l]; k < s->ring_start[l + 1]; k++) {
        const uint32_t *t = s->out_corners + (size_t)s->ring[k] * 3;
        int where;
        float d = point_triangle_foot_d2(p, load3(s->positions + (size_t)t[0] * 3),
                                         load3(s->positions + (size_t)t[1] * 3), load3(s->positions + (size_t)t[2] * 3),
                                         &where);
        if (d < best) {
            best = d;
            *nearest = s->ring[k];
            if (best == 0.0f || (where == FOOT_INSIDE && best <= enough))
                break;
        }
    }
    return best;
}

/* Keeps the k->limit largest sample distance bounds seen (squared, ascending, with their sample):
 * all other samples lie within the smallest of them of their cluster. The place is found by binary
 * search and the tail moved at once: with the 1,025 bounds a group may keep (keep_more) a scan that
 * moves one entry at a time cost 2.5% of a build. A new bound goes after those equal to it while
 * the list fills, and before them once it is full (the smallest is dropped), as the scans did; the
 * list is sorted because no distance is NaN (point_triangle_foot_d2 returns at most the squared
 * distance to a corner, a sum of squares). */
static void keep_largest(lod_kept *k, float d, uint32_t sample)
{
    uint32_t at, lo, hi;
    if (k->count < k->limit) { /* not full: after the last bound at most d */
        for (lo = 0, hi = k->count; lo < hi;) {
            uint32_t mid = lo + (hi - lo) / 2;
            if (k->d2[mid] > d)
                hi = mid;
            else
                lo = mid + 1;
        }
        at = lo;
        memmove(&k->d2[at + 1], &k->d2[at], (k->count - at) * sizeof k->d2[0]);
        memmove(&k->sample[at + 1], &k->sample[at], (k->count - at) * sizeof k->sample[0]);
        k->count++;
    } else if (d > k->d2[0]) { /* full: drop the smallest, before the first bound at least d */
        for (lo = 1, hi = k->count; lo < hi;) {
            uint32_t mid = lo + (hi - lo) / 2;
            if (k->d2[mid] < d)
                lo = mid + 1;
            else
                hi = mid;
        }
        at = lo - 1;
        memmove(&k->d2[0], &k->d2[1], at * sizeof k->d2[0]);
        memmove(&k->sample[0], &k->sample[1], at * sizeof k->sample[0]);
    } else {
        return;
    }
    k->d2[at] = d;
    k->sample[at] = sample;
}

/* The smallest kept bound once k->limit are kept (what every other sample lies within of its
 * cluster); -1 before. */
static float kept_bound(const lod_kept *k) { return k->count == k->limit ? k->d2[0] : -1.0f; }

/* The step's only group measures its samples in this many ranges (fewer where a range would hold
 * fewer than LOD_SAMPLE_RANGE_MIN): a fixed count, so that the result does not depend on the
 * thread count. A range settles samples within its own smallest kept bound, the 65th largest of
 * its samples': the larger the range, the more it settles. */
#define LOD_SAMPLE_RANGES 8u
#define LOD_SAMPLE_RANGE_MIN 2048u

/* Distance (squared) from sample i to the simplified triangles around its nearest simplified
 * vertex (an upper bound), and the nearest of them (the first at most `enough`: ring_d2). */
static float sample_ring_d2(const lod_scratch *s, uint32_t i, uint32_t *nearest, float enough)
{
    float d2;
    uint32_t l = s->vertex_local[lod_grid_nearest(&s->grid, s->sample_points[i], &d2)];
    return ring_d2(s, l, s->sample_points[i], nearest, enough);
}

/* Squared distance from sample i to simplified triangle t; *where: where its foot is (FOOT_INSIDE,
 * an edge or FOOT_CORNER). */
static float sample_triangle_d2(const lod_scratch *s, uint32_t i, uint32_t t, int *where)
{
    const uint32_t *c = s->out_corners + (size_t)t * 3;
    return point_triangle_foot_d2(s->sample_points[i], load3(s->positions + (size_t)c[0] * 3),
                                  load3(s->positions + (size_t)c[1] * 3), load3(s->positions + (size_t)c[2] * 3),
                                  where);
}

/* The simplified triangle other than t that shares t's edge k (corners k and k + 1 mod 3), the
 * first in output order; UINT32_MAX when none. */
static uint32_t across_edge(const lod_scratch *s, uint32_t t, int k)
{
    uint32_t a = s->out_corners[(size_t)t * 3 + k], b = s->out_corners[(size_t)t * 3 + (k == 2 ? 0 : k + 1)];
    for (uint32_t i = s->ring_start[a]; i < s->ring_start[a + 1]; i++) {
        const uint32_t *u = s->out_corners + (size_t)s->ring[i] * 3;
        if (s->ring[i] != t && (u[0] == b || u[1] == b || u[2] == b))
            return s->ring[i];
    }
    return UINT32_MAX;
}

/* The triangle that settles sample i, UINT32_MAX when none: `last` (the one the last measured
 * sample passed to, or UINT32_MAX) or, where i's foot lies beyond one of its edges, the triangle
 * across that edge, if the sample lies within `bound`, the smallest kept bound (kept_bound), of it
 * and its foot is inside it. Such a sample cannot raise the largest distance (its exact distance is at
 * most that bound) and lies within the smallest kept bound of the triangle's cluster, all that a
 * sample not kept is promised: it passes there unmeasured (docs/GEOMETRY.md, "Measuring the
 * samples cheaply"). The foot inside keeps it with its nearest triangle on a surface: a sample
 * handed to a farther cluster is measured against that cluster's group at the next step (on the
 * 1 M-triangle torus without it, the groups' mean error rose 14%). Consecutive samples are
 * neighbours on S0: mostly over the same triangle or the next. (Moving `last` to the settling
 * triangle settles more, but on that torus raised the mean error 9%: not done.) */
static uint32_t settling_triangle(const lod_scratch *s, uint32_t i, uint32_t last, float bound)
{
    if (last == UINT32_MAX || bound < 0.0f)
        return UINT32_MAX;
    int where;
    float d = sample_triangle_d2(s, i, last, &where);
    if (where == FOOT_INSIDE)
        return d <= bound ? last : UINT32_MAX;
    uint32_t next = where < FOOT_INSIDE ? across_edge(s, last, where) : UINT32_MAX;
    if (next == UINT32_MAX)
        return UINT32_MAX;
    d = sample_triangle_d2(s, i, next, &where);
    return where == FOOT_INSIDE && d <= bound ? next : UINT32_MAX;
}

/* Samples [first, end) in order, into `kept` (empty at first): a sample settled by the last
 * measured one's triangle or the next (settling_triangle) is not measured; of the others, the
 * ring's search stops at the first triangle that holds the sample's foot within the smallest kept
 * bound (the sample is then settled by that triangle, the same rule), and only a sample whose ring
 * bound exceeds the largest distance so far is measured exactly (grid of the triangles).
 * kept->worst: the largest distance, squared. */
static void measure_samples(lod_scratch *s, uint32_t first, uint32_t end, lod_kept *kept)
{
    uint32_t last = UINT32_MAX;
    kept->count = 0;
    kept->worst = 0.0f;
    for (uint32_t i = first; i < end; i++) {
        float bound = kept_bound(kept);
        uint32_t settled = settling_triangle(s, i, last, bound);
        if (settled != UINT32_MAX) {
            s->sample_cluster[i] = s->out_cluster[settled];
            continue;
        }
        uint32_t nearest;
        float d = sample_ring_d2(s, i, &nearest, bound > 0.0f ? bound : 0.0f);
        if (d > kept->worst)
            nearest = lod_triangle_grid_nearest(&s->triangle_grid, s->sample_points[i], point_triangle_d2, &d);
        s->sample_cluster[i] = s->out_cluster[nearest];
        last = nearest;
        keep_largest(kept, d, i);
        kept->worst = d > kept->worst ? d : kept->worst;
    }
}

/* One range of the step's only group's samples, measured as measure_samples measures a group. */
static void sample_range_task(void *user, uint32_t range, uint32_t worker)
{
    lod_scratch *s = user;
    (void)worker;
    uint32_t first = range * s->range_size, end = first + s->range_size;
    s->range_kept[range].limit = s->top.limit;
    measure_samples(s, first, end < s->gathered ? end : s->gathered, &s->range_kept[range]);
}

/* The step's only group (its task runs on the calling thread, outside any job) measures its samples
 * in ranges (LOD_SAMPLE_RANGES), each with its own kept bounds, on the pool's workers where there
 * are several: the same result for any thread count. The group keeps the largest of all ranges'
 * kept bounds. A sample a range settled lies within that range's smallest kept bound, which is at
 * most the group's (the range's own kept bounds are among those the group's are chosen from), and
 * a bound a range kept but the group did not is at most the group's smallest: every promise holds.
 * The largest distance is the largest of the ranges'. Returns 0 when out of memory. */
static int measure_in_ranges(const lod_build *b, lod_scratch *s)
{
    uint32_t size = (s->gathered + LOD_SAMPLE_RANGES - 1) / LOD_SAMPLE_RANGES;
    s->range_size = size > LOD_SAMPLE_RANGE_MIN ? size : LOD_SAMPLE_RANGE_MIN;
    uint32_t ranges = (s->gathered + s->range_size - 1) / s->range_size;
    if (!LOD_RESERVE(s, range_kept, ranges))
        return 0;
    if (gdr_thread_pool_thread_count(b->pool) > 1 && ranges > 1)
        gdr_thread_pool_run(b->pool, ranges, sample_range_task, s);
    else
        for (uint32_t r = 0; r < ranges; r++)
            sample_range_task(s, r, 0);
    s->top.count = 0;
    s->top.worst = 0.0f;
    for (uint32_t r = 0; r < ranges; r++) {
        const lod_kept *k = &s->range_kept[r];
        for (uint32_t j = 0; j < k->count; j++)
            keep_largest(&s->top, k->d2[j], k->sample[j]);
        s->top.worst = k->worst > s->top.worst ? k->worst : s->top.worst;
    }
    return 1;
}

/* Every sample of the group measured (the grids built), keeping `limit` largest bounds in s->top:
 * the largest distance, or -1 when out of memory. */
static float measure_all_samples(const lod_build *b, lod_scratch *s, uint32_t limit)
{
    s->top.limit = limit;
    if (!b->lone_group)
        measure_samples(s, 0, s->gathered, &s->top);
    else if (!measure_in_ranges(b, s))
        return -1.0f;
    return sqrtf(s->top.worst);
}

/* The point grid over the simplified vertices that have triangles (s->grid; the probes may rebuild
 * it over the samples later: nearest_sample). Returns 0 when out of memory. */
static int build_vertex_grid(lod_scratch *s, uint32_t local_count)
{
    uint32_t used = 0;
    if (!LOD_RESERVE(s, vertex_points, local_count) || !LOD_RESERVE(s, vertex_local, local_count))
        return 0;
    for (uint32_t l = 0; l < local_count; l++)
        if (s->ring_start[l + 1] > s->ring_start[l]) {
            memcpy(&s->vertex_points[used], s->positions + (size_t)l * 3, sizeof(gdr_vec3));
            s->vertex_local[used++] = l;
        }
    s->grid_holds_samples = 0;
    return lod_grid_build(&s->grid, s->vertex_points, used, 4.0);
}

/* Largest distance from a sample to the simplified triangles; each sample's nearest cluster, and
 * the samples of the largest distance bounds (keep_largest). The triangles around the nearest
 * simplified vertex give an upper bound quickly; only a sample whose bound exceeds the largest
 * distance so far is measured exactly (grid of the triangles), so the result is the exact maximum
 * and every sample lies within it of the cluster it passes to. */
static float samples_to_simplified(const lod_build *b, lod_scratch *s, uint32_t local_count)
{
    if (!build_vertex_grid(s, local_count) ||
        !lod_triangle_grid_build(&s->triangle_grid, s->positions, s->out_corners, s->out_triangle_count))
        return -1.0f;
    return measure_all_samples(b, s, LOD_KEPT_FIRST);
}

/* Distance (squared) from p to the level-0 triangles around position `position`: an upper bound of
 * the distance from p to S0. */
/* A position's triangles are looked at up to this many: around a position of thousands (the centre
 * of a fan) every probe would otherwise cost the whole fan. Fewer triangles only make a distance to
 * them larger than the distance to the full-detail surface, so the bound stays a bound. */
#define LOD_RING_LIMIT 64u
#define LOD_WALK_LIMIT 32u

static uint32_t ring_end(const lod_build *b, uint32_t position)
{
    uint32_t start = b->adjacency_start[position], end = b->adjacency_start[position + 1];
    return end - start > LOD_RING_LIMIT ? start + LOD_RING_LIMIT : end;
}

static float ring_entry_d2(const lod_build *b, uint32_t entry, gdr_vec3 p)
{
    const gdr_vec3 *x = b->mesh->positions;
    const uint8_t *t = ring_triangle(b, entry);
    const uint32_t *v = ring_vertices(b, entry);
    return point_triangle_d2(p, x[v[t[0]]], x[v[t[1]]], x[v[t[2]]]);
}

/* Stops at the first triangle that brings the distance to at most `at_most` or below `below`
 * (squared): the caller has no use for a smaller bound (probe_state). Adjacency entry `first` (of
 * this position's, or UINT32_MAX), the triangle a walk ending here guessed nearest, is looked at
 * first: the smallest distance is the same in any order. *triangle receives the level-0 triangle
 * (its adjacency entry without the corner) the bound is the distance to. */
static float to_full_detail_d2(const lod_build *b, uint32_t position, gdr_vec3 p, uint32_t first, float at_most,
                               float below, uint32_t *triangle)
{
    float best = first == UINT32_MAX ? INFINITY : ring_entry_d2(b, b->adjacency[first], p);
    uint32_t best_entry = first == UINT32_MAX ? b->adjacency[b->adjacency_start[position]] : b->adjacency[first];
    for (uint32_t k = b->adjacency_start[position], end = ring_end(b, position);
         k < end && !(best <= at_most) && !(best < below); k++) {
        float d = k == first ? best : ring_entry_d2(b, b->adjacency[k], p);
        if (d < best) {
            best = d;
            best_entry = b->adjacency[k];
        }
    }
    *triangle = best_entry >> 2;
    return best;
}

static float distance2(gdr_vec3 q, gdr_vec3 p)
{
    float dx = q.x - p.x, dy = q.y - p.y, dz = q.z - p.z;
    return dx * dx + dy * dy + dz * dz;
}

/* Walks over level-0 positions from `start`, to a neighbour nearer to p while there is one: the
 * walk ends at a position nearest to p among its neighbours (on a surface, next to p's foot).
 * *stopped_short is set when the walk was cut off by the step limit while still moving. A
 * neighbour is compared by its mesh vertex (all vertices of a position have its coordinates); the
 * position id is looked up only for the one the walk moves to. *nearest receives the adjacency
 * entry of the end's triangle whose other two corners are nearest to p (summed), the likeliest
 * to hold p's foot (UINT32_MAX when stopped short). */
static uint32_t walk_towards(const lod_build *b, uint32_t start, gdr_vec3 p, int *stopped_short, uint32_t *nearest)
{
    const gdr_vec3 *x = b->mesh->positions;
    uint32_t at = start, to = UINT32_MAX;
    float best = distance2(x[b->sample_vertex[at]], p);
    *stopped_short = 0;
    /* At most LOD_WALK_LIMIT steps: on a strip or a fan's rim a walk would cross the whole mesh one
     * neighbour at a time. Where it stops short, the distance from there is only larger (a bound
     * still), and probe_d2 starts it again nearer to p. */
    static const uint8_t other_corners[4][2] = {{1, 2}, {0, 2}, {0, 1}, {0, 1}}; /* in order, for ties */
    for (uint32_t steps = 0; steps < LOD_WALK_LIMIT; steps++) {
        float nearest_sum = INFINITY;
        uint32_t nearest_entry = UINT32_MAX;
        for (uint32_t k = b->adjacency_start[at], end = ring_end(b, at); k < end; k++) {
            uint32_t entry = b->adjacency[k];
            const uint8_t *t = ring_triangle(b, entry);
            const uint32_t *v = ring_vertices(b, entry);
            const uint8_t *o = other_corners[entry & 3]; /* not the corner at `at`: no nearer than `best` */
            const uint32_t other[2] = {v[t[o[0]]], v[t[o[1]]]};
            float sum = 0.0f;
            for (int j = 0; j < 2; j++) {
                float d = distance2(x[other[j]], p);
                sum += d;
                if (d < best) { /* strictly nearer: the walk ends */
                    best = d;
                    to = other[j];
                }
            }
            if (sum < nearest_sum) {
                nearest_sum = sum;
                nearest_entry = k;
            }
        }
        if (to == UINT32_MAX) {
            *nearest = nearest_entry;
            return at;
        }
        at = b->position_id[to];
        to = UINT32_MAX;
    }
    *stopped_short = 1;
    *nearest = UINT32_MAX;
    return at;
}

static int compare_u32(const void *x, const void *y)
{
    uint32_t a = *(const uint32_t *)x, b = *(const uint32_t *)y;
    return a < b ? -1 : a > b;
}

/* The level-0 triangles around `count` positions (position(b, s, i) for i < count), at most `limit`
 * of each position's, each once, into refs (adjacency entries without their corner), their corners
 * as mesh vertex indices into corners, and a grid over them. Returns 0 when out of memory. */
typedef uint32_t region_position_fn(const lod_build *b, const lod_scratch *s, size_t i);
static int build_triangle_region(const lod_build *b, lod_scratch *s, region_position_fn *position, size_t count,
                                 uint32_t limit, uint32_t **refs, size_t *refs_cap, uint32_t **corners,
                                 size_t *corners_cap, lod_triangle_grid *grid)
{
    size_t n = 0;
    for (size_t i = 0; i < count; i++) {
        uint32_t p = position(b, s, i), around = b->adjacency_start[p + 1] - b->adjacency_start[p];
        n += around < limit ? around : limit;
    }
    if (!gdr_lod_reserve(refs, refs_cap, n + 1, sizeof **refs))
        return 0;
    n = 0;
    for (size_t i = 0; i < count; i++) {
        uint32_t p = position(b, s, i), around = b->adjacency_start[p + 1] - b->adjacency_start[p];
        for (uint32_t k = b->adjacency_start[p]; k < b->adjacency_start[p] + (around < limit ? around : limit); k++)
            (*refs)[n++] = b->adjacency[k] >> 2; /* the triangle, whichever corner */
    }
    /* The corners' array sorts the list first: each listing is a distinct corner of its triangle, so
     * n is at most 3 x the distinct triangles, which the corners need anyway (no memory more). */
    if (!gdr_lod_reserve(corners, corners_cap, n + 1, sizeof **corners))
        return 0;
    size_t unique = lod_sort_unique_u32(*refs, n, *corners);
    /* The triangles' corners as mesh vertex indices, over the mesh's own positions: a group near the
     * DAG's root gathers most of the mesh, and a copy of its corners' positions would cost each
     * worker 36 bytes per level-0 triangle. */
    if (!gdr_lod_reserve(corners, corners_cap, unique * 3 + 1, sizeof **corners))
        return 0;
    for (size_t i = 0; i < unique; i++) {
        const uint8_t *t = ring_triangle(b, (*refs)[i] << 2);
        const uint32_t *v = ring_vertices(b, (*refs)[i] << 2);
        for (int k = 0; k < 3; k++)
            (*corners)[i * 3 + (size_t)k] = v[t[k]];
    }
    return lod_triangle_grid_build(grid, &b->mesh->positions[0].x, *corners, (uint32_t)unique);
}

static uint32_t sample_position(const lod_build *b, const lod_scratch *s, size_t i)
{
    (void)b;
    return s->sample_ids[i];
}

/* The i-th distinct position of the simplified triangles' corners (span_positions). */
static uint32_t corner_position(const lod_build *b, const lod_scratch *s, size_t i)
{
    (void)b;
    return s->span_positions[i];
}

/* The level-0 triangles around the group's samples. */
static int build_region(const lod_build *b, lod_scratch *s)
{
    s->region_built = 1;
    return build_triangle_region(b, s, sample_position, s->gathered, UINT32_MAX, &s->region_refs, &s->region_refs_cap,
                                 &s->region_corners, &s->region_corners_cap, &s->region_grid);
}

/* The level-0 triangles around the simplified triangles' corners (up to LOD_RING_LIMIT of each: a
 * fan's hub is a corner of every group around it): a corner's sample may belong to
 * a neighbouring group while the level-0 surface a simplified triangle spans lies around its
 * corners (a rail of level-0 strips from end to end, whose corners' samples went to the groups at
 * its ends, was bounded 1.03 units off where it lies within 0.003). A grid of its own: one grid
 * over both would crowd the cells where a group's triangles lie over another part (a fan on a
 * plate), whose triangles a cell lists only up to a limit (lod_grid.c). */
static int build_span(const lod_build *b, lod_scratch *s)
{
    s->span_built = 1;
    size_t corners = (size_t)s->out_triangle_count * 3, unique = 0;
    if (!LOD_RESERVE(s, span_positions, corners + 1))
        return 0;
    for (size_t i = 0; i < corners; i++)
        s->span_positions[i] = b->position_id[s->local_to_mesh[s->out_corners[i]]];
    if (!LOD_RESERVE(s, span_refs, corners + 1)) /* free until build_triangle_region: the sort's scratch */
        return 0;
    unique = lod_sort_unique_u32(s->span_positions, corners, s->span_refs); /* a hub's fan is listed once */
    return build_triangle_region(b, s, corner_position, unique, LOD_RING_LIMIT, &s->span_refs, &s->span_refs_cap, &s->span_corners,
                                 &s->span_corners_cap, &s->span_grid);
}

/* A walk bound up to twice the largest distance checked is taken without the exact measure
 * (probe_d2): squared. */
#define LOD_LOOSE 4.0f

/* What probing a group's simplified triangles needs. */
typedef struct probe_state {
    const lod_build *b;
    lod_scratch *s;
    float worst;  /* squared: the largest distance so far (at least the samples' largest) */
    float checked; /* squared: the largest of the floor (D1) and the bounds the group's own surface settled
                      (probe_d2) */
    float at_most, below; /* squared: a probe bound at most / below these changes nothing (per probe) */
    int failed;   /* out of memory */
    float loose;  /* a walk bound up to this times the largest checked (squared) is taken as it is: 4
                     (twice), or 1 in tight_d2's pass, which measures over the corners' triangles only
                     (no grid of the group's own surface is built for it: at the DAG's top that grid
                     covers most of the mesh, and the blob's peak heap rose from 79 to 129 B per
                     triangle) */
} probe_state;

/* The group's sample nearest to p; UINT32_MAX when out of memory. The point grid, which indexed the
 * simplified vertices for samples_to_simplified (done by now), is rebuilt over the samples on first
 * use: one grid's arrays per worker rather than two. A group near the root holds most of the mesh's
 * positions and few queries come here, so its cells are fewer (one per sample, not four). */
static uint32_t nearest_sample(lod_scratch *s, gdr_vec3 p)
{
    if (!s->grid_holds_samples) {
        if (!lod_grid_build(&s->grid, s->sample_points, s->gathered, 1.0))
            return UINT32_MAX;
        s->grid_holds_samples = 1;
    }
    float d2;
    return s->sample_ids[lod_grid_nearest(&s->grid, p, &d2)];
}

/* Where the last walk of a triangle's probes ended: the position, and the adjacency entry of its
 * triangle guessed nearest to the next probe (UINT32_MAX: none). */
typedef struct walk_end {
    uint32_t position, entry;
} walk_end;

/* Where a walk towards p ends: from *at, and again from the group's sample nearest to p where the
 * first walk's bound could raise the largest distance and was cut off by the step limit, or would
 * send p to the exact measure. On a coarse group a simplified triangle spans more level-0 edges
 * than the limit, and the bound from where a cut-off walk stops is several times the distance (on
 * the 1 M-triangle torus up to 13x); a walk can also end at a nearest position of one side of a
 * thin part while p is nearer the other. Returns the bound (squared) from where it ended.
 *
 * No walk is taken where the level-0 triangle the last walk guessed nearest to its probe already
 * brings p's bound within what changes nothing (probe_state): most probes lie close to the last,
 * and their bound matters only where it is large. *at then stays, and the next walk starts there
 * (so later walks may end elsewhere than they would have: still a bound, not the same DAG). */
static float walk_bound_d2(probe_state *ps, walk_end *at, gdr_vec3 p, uint32_t *triangle)
{
    if (at->entry != UINT32_MAX) {
        float d = ring_entry_d2(ps->b, ps->b->adjacency[at->entry], p);
        *triangle = ps->b->adjacency[at->entry] >> 2;
        if (d <= ps->at_most || d < ps->below)
            return d;
    }
    int stopped_short;
    at->position = walk_towards(ps->b, at->position, p, &stopped_short, &at->entry);
    float d = to_full_detail_d2(ps->b, at->position, p, at->entry, ps->at_most, ps->below, triangle);
    int suspect = (stopped_short && d > ps->worst) || d > 4.0f * ps->worst;
    if (!suspect || ps->s->gathered == 0)
        return d;
    uint32_t start = nearest_sample(ps->s, p);
    if (start == UINT32_MAX) {
        ps->failed = 1;
        return d;
    }
    walk_end again;
    uint32_t triangle_again;
    again.position = walk_towards(ps->b, start, p, &stopped_short, &again.entry);
    float d_again = to_full_detail_d2(ps->b, again.position, p, again.entry, ps->at_most, ps->below, &triangle_again);
    if (d_again >= d)
        return d;
    *at = again;
    *triangle = triangle_again;
    return d_again;
}

/* Upper bound (squared) of the distance from p to S0: to the level-0 triangles around the position
 * a walk ends at (the position nearest to p among its neighbours; on a regular surface the triangle
 * nearest to p is among these). Where that bound would raise the largest so far and is more than
 * twice the largest distance checked (D1, or a bound the group's own surface settled), the exact
 * distance to the level-0 triangles around the simplified triangles' corners is taken, and where
 * that is still more than twice the largest checked, the smaller of it and the exact distance to
 * the level-0 triangles around the group's samples, which becomes a distance checked (the walk can
 * stop far away on meshes of long thin triangles or on a crumpled surface). Only that measure
 * raises the reference: with the largest bound so far as the reference, each loose bound accepted
 * raised what the next was compared with, and a chain of them climbed (DamagedHelmet's first-step
 * groups stated 0.08-0.25 of the radius for a distance of 0.004-0.011: docs/GEOMETRY.md), and the
 * corners' triangles alone can be as loose. So every bound stated is at most twice a distance
 * checked. *at receives where the walk ended (the next probe of the triangle starts there). */
static float probe_d2(probe_state *ps, walk_end *at, gdr_vec3 p, uint32_t *triangle)
{
    float d = walk_bound_d2(ps, at, p, triangle);
    if (d <= ps->worst || d <= ps->loose * ps->checked || ps->failed) /* squared: raises nothing, or within twice */
        return d;
    if (!ps->s->span_built && !build_span(ps->b, ps->s)) {
        ps->failed = 1;
        return d;
    }
    float exact = INFINITY, spanned;
    uint32_t nearest = 0;
    uint32_t nearest_spanned = lod_triangle_grid_nearest(&ps->s->span_grid, p, point_triangle_d2, &spanned);
    int own_surface = ps->s->region_built || ps->loose == LOD_LOOSE; /* not built for tight_d2 */
    if (!(spanned <= ps->loose * ps->checked) && own_surface) {
        if (!ps->s->region_built && !build_region(ps->b, ps->s)) {
            ps->failed = 1;
            return d;
        }
        nearest = lod_triangle_grid_nearest(&ps->s->region_grid, p, point_triangle_d2, &exact);
    }
    if (exact < d || spanned < d) {
        *triangle = spanned < exact ? ps->s->span_refs[nearest_spanned] : ps->s->region_refs[nearest];
        d = spanned < exact ? spanned : exact;
    }
    if (exact < INFINITY) /* the group's own surface measured */
        ps->checked = d > ps->checked ? d : ps->checked;
    return d;
}

/* A triangle's coarse probes decide whether it is refined: refined unless its largest is below this
 * share of the largest coarse probe of the group (squared: 70%). */
static float refine_share(float coarse_worst) { return 0.49f * coarse_worst; }

/* Which edge of triangle v's barycentric grid point (i, j) of n steps lies on: edge k joins corners
 * k and k + 1 (mod 3); 3 inside. */
static int grid_edge(int i, int j, int n)
{
    if (j == 0)
        return 0;
    if (i + j == n)
        return 1;
    return i == 0 ? 2 : 3;
}

/* The finest probe grid's steps an edge. */
#define LOD_FINE_STEPS 8

/* A simplified triangle's probe grid: each point, its bound (squared) and the level-0 triangle
 * that bound is the distance to (UINT32_MAX where the point was not probed here). */
typedef struct probe_lattice {
    gdr_vec3 point[LOD_FINE_STEPS + 1][LOD_FINE_STEPS + 1];
    float d2[LOD_FINE_STEPS + 1][LOD_FINE_STEPS + 1];
    uint32_t triangle[LOD_FINE_STEPS + 1][LOD_FINE_STEPS + 1];
} probe_lattice;

/* The plane of level-0 triangle `triangle` (an adjacency entry without its corner); w NaN when it
 * has no area. */
static gdr_vec4 level0_plane(const lod_build *b, uint32_t triangle)
{
    const gdr_vec3 *x = b->mesh->positions;
    const uint8_t *t = ring_triangle(b, triangle << 2);
    const uint32_t *v = ring_vertices(b, triangle << 2);
    gdr_vec3 a = x[v[t[0]]], e1 = sub3(x[v[t[1]]], a), e2 = sub3(x[v[t[2]]], a);
    gdr_vec3 n = {e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
    float length = sqrtf(dot3(n, n));
    if (!(length > 0.0f))
        return (gdr_vec4){0.0f, 0.0f, 0.0f, NAN};
    n = (gdr_vec3){n.x / length, n.y / length, n.z / length};
    return (gdr_vec4){n.x, n.y, n.z, dot3(n, a)};
}

static float plane_distance(gdr_vec4 plane, gdr_vec3 p)
{
    return plane.x * p.x + plane.y * p.y + plane.z * p.z - plane.w;
}

/* Probes p (probe_triangle's rules for what a bound must settle), raising *largest and the group's
 * largest; returns the bound (squared) and the level-0 triangle it is the distance to. On the
 * refining grid a bound is looked for until it is below 70% of the group's largest (not only below
 * the largest): a point that may border a ridge then has its nearest level-0 triangle, whose plane
 * probe_ridges needs. */
static float probe_at(probe_state *ps, walk_end *at, gdr_vec3 p, int refine, float *largest, uint32_t *triangle)
{
    ps->at_most = refine ? refine_share(ps->worst) : *largest;
    ps->below = refine ? 0.0f : refine_share(ps->worst);
    float d = probe_d2(ps, at, p, triangle);
    *largest = d > *largest ? d : *largest;
    ps->worst = d > ps->worst ? d : ps->worst;
    return d;
}

/* Where, between grid points a and b, the distances to the planes of their level-0 triangles meet
 * while one rises from a and the other falls towards b: the top of a ridge of the distance to S0
 * (the larger of two plane distances' minimum) that neither point sees. Returns its fraction of the
 * way from a, and the predicted distance there in *top; -1 when there is none. */
static float ridge_between(gdr_vec3 a, gdr_vec4 plane_a, gdr_vec3 b, gdr_vec4 plane_b, float *top)
{
    float fa0 = plane_distance(plane_a, a), fa1 = plane_distance(plane_a, b);
    float fb0 = plane_distance(plane_b, a), fb1 = plane_distance(plane_b, b);
    if (fa0 < 0.0f) /* distances on a's side of its plane (b's of its) count as positive */
        fa0 = -fa0, fa1 = -fa1;
    if (fb1 < 0.0f)
        fb0 = -fb0, fb1 = -fb1;
    float rise = fa1 - fa0, fall = fb0 - fb1;
    if (!(rise > 0.0f && fall > 0.0f && fa1 >= 0.0f && fb0 >= 0.0f))
        return -1.0f;
    float t = (fb0 - fa0) / (rise + fall);
    if (!(t > 0.0f && t < 1.0f))
        return -1.0f;
    *top = fa0 + t * rise;
    return t;
}

/* The grid's neighbouring point pairs: (i, j) with (i + 1, j), (i, j + 1) and (i + 1, j) with
 * (i, j + 1). */
static const int8_t lattice_steps[3][4] = {{0, 0, 1, 0}, {0, 0, 0, 1}, {1, 0, 0, 1}};

/* On the refining grid, probes the ridge tops between neighbouring grid points (one of them at
 * least 70% of the group's largest) whose level-0 planes predict one above 90% of the group's
 * largest. The distance from a simplified triangle to S0 peaks on such ridges (where two facets of
 * S0 are seen from inside a fold, the nearer of the two planes changes), between the grid's points:
 * on the knot a grid of 8 steps missed one by 7.8% of the bound. A distance to a plane bounds
 * nothing (the plane extends past its triangle), so the prediction only says where to probe; the
 * probe's bound is a distance to a level-0 triangle like every other. Returns the triangle's
 * largest. */
static float probe_ridges(probe_state *ps, walk_end *at, const probe_lattice *l, int n, float largest,
                          float edge_d2[3])
{
    for (int i = 0; i < n; i++)
        for (int j = 0; i + j < n; j++)
            for (int k = 0; k < 3; k++) {
                int ai = i + lattice_steps[k][0], aj = j + lattice_steps[k][1];
                int bi = i + lattice_steps[k][2], bj = j + lattice_steps[k][3];
                uint32_t ta = l->triangle[ai][aj], tb = l->triangle[bi][bj];
                if (ta == UINT32_MAX || tb == UINT32_MAX || ta == tb ||
                    !(fmaxf(l->d2[ai][aj], l->d2[bi][bj]) >= refine_share(ps->worst)))
                    continue;
                float wanted = 0.81f * ps->worst;
                float top, t = ridge_between(l->point[ai][aj], level0_plane(ps->b, ta), l->point[bi][bj],
                                             level0_plane(ps->b, tb), &top);
                if (t < 0.0f || !(top * top > wanted))
                    continue;
                gdr_vec3 a = l->point[ai][aj], p = along(a, t, sub3(l->point[bi][bj], a));
                uint32_t triangle;
                float d = probe_at(ps, at, p, 1, &largest, &triangle);
                int edge = grid_edge(ai, aj, n);
                if (edge < 3 && edge == grid_edge(bi, bj, n))
                    edge_d2[edge] = d > edge_d2[edge] ? d : edge_d2[edge];
            }
    return largest;
}

/* The largest probe distance over the points of a barycentric grid of n steps on triangle v, corners
 * left out (they are level-0 vertices: distance 0), and of each edge k's points into edge_d2[k];
 * the points of an edge whose bit is set in `skip` are left out (a neighbour probed them). Walks
 * start at *at. `largest` starts at `floor` (what the skipped edges gave). A probe's bound is the
 * smallest over some level-0 triangles, and how small it is matters only while it could raise
 * something: once a triangle brings it to at most `at_most` or below `below` the rest are skipped,
 * which leaves every decision as if all were measured (docs/GEOMETRY.md, "The error"). Both are at
 * most the largest so far, so the walks' checks against that come out the same; on the refining
 * grid (`refine`) the search goes on to refine_share of the largest so far (probe_at), and its
 * ridges are probed (probe_ridges); on the coarse grid, this triangle's largest and whether it stays
 * below refine_share of the largest, which can only grow. */
static float probe_triangle(probe_state *ps, walk_end *at, const gdr_vec3 v[3], int n, int refine, unsigned skip,
                            float floor, float edge_d2[3])
{
    probe_lattice lattice;
    float largest = floor;
    for (int i = 0; i <= n; i++)
        for (int j = 0; i + j <= n; j++) {
            int edge = grid_edge(i, j, n);
            lattice.triangle[i][j] = UINT32_MAX; /* not probed here: never read */
            if (i == n || j == n || i + j == 0 || (edge < 3 && (skip >> edge & 1)))
                continue;
            float u = (float)i / (float)n, w = (float)j / (float)n, z = 1.0f - u - w;
            gdr_vec3 p = {z * v[0].x + u * v[1].x + w * v[2].x, z * v[0].y + u * v[1].y + w * v[2].y,
                          z * v[0].z + u * v[1].z + w * v[2].z};
            lattice.point[i][j] = p;
            float d = probe_at(ps, at, p, refine, &largest, &lattice.triangle[i][j]);
            lattice.d2[i][j] = d;
            if (edge < 3)
                edge_d2[edge] = d > edge_d2[edge] ? d : edge_d2[edge];
        }
    return refine ? probe_ridges(ps, at, &lattice, n, largest, edge_d2) : largest;
}

static void triangle_corners(const lod_scratch *s, uint32_t t, gdr_vec3 v[3])
{
    for (int k = 0; k < 3; k++)
        v[k] = load3(s->positions + (size_t)s->out_corners[(size_t)t * 3 + k] * 3);
}

/* The edge (3u + j: corners j and j + 1 of triangle u) of a triangle u before t that joins the same
 * two group vertices as t's edge k; UINT32_MAX when none. */
static uint32_t earlier_edge(const lod_scratch *s, uint32_t t, int k)
{
    uint32_t a = s->out_corners[(size_t)t * 3 + k], b = s->out_corners[(size_t)t * 3 + (k == 2 ? 0 : k + 1)];
    for (uint32_t i = s->ring_start[a]; i < s->ring_start[a + 1] && s->ring[i] < t; i++) {
        const uint32_t *u = s->out_corners + (size_t)s->ring[i] * 3;
        for (int j = 0; j < 3; j++)
            if ((u[j] == a && u[(j + 1) % 3] == b) || (u[j] == b && u[(j + 1) % 3] == a))
                return s->ring[i] * 3 + (uint32_t)j;
    }
    return UINT32_MAX;
}

/* Probes triangle t on a grid of n steps, leaving out the edges an earlier triangle probed on the
 * same grid (edge_d2 >= 0: the coarse grid, whose largest counts towards t's; refined: -1 once
 * probed); records its own edges'. Returns its largest (coarse). */
static float probe_shared(probe_state *ps, lod_scratch *s, uint32_t t, int n, int refine)
{
    unsigned skip = 0;
    float floor = 0.0f, edge_d2[3] = {0.0f, 0.0f, 0.0f};
    for (int k = 0; k < 3; k++) {
        uint32_t e = earlier_edge(s, t, k);
        if (e == UINT32_MAX || (refine ? s->edge_d2[e] >= 0.0f : s->edge_d2[e] < 0.0f))
            continue;
        skip |= 1u << k;
        floor = s->edge_d2[e] > floor ? s->edge_d2[e] : floor;
    }
    gdr_vec3 v[3];
    triangle_corners(s, t, v);
    walk_end at = {ps->b->position_id[s->local_to_mesh[s->out_corners[(size_t)t * 3]]], UINT32_MAX};
    float largest = probe_triangle(ps, &at, v, n, refine, skip, refine ? 0.0f : floor, edge_d2);
    for (int k = 0; k < 3; k++)
        s->edge_d2[(size_t)t * 3 + k] = refine ? -1.0f : edge_d2[k];
    return largest;
}

/* Largest distance from the simplified triangles to S0, or `floor` when that is larger (the
 * samples' largest distance: probes below it cannot change the group's deviation). Every triangle
 * is probed on a barycentric grid of 3 steps an edge (6 points on the edges, the centroid); those
 * whose probes come within 70% of the largest then, on a grid of 8 steps (the deviation of a
 * simplified triangle peaks inside it or on an edge, between the coarse points). An edge two
 * triangles share is probed once on each grid (by the first; the second counts its probes as its
 * own). Returns INFINITY as soon as the largest exceeds `cap` (no bound then), -1 when out of
 * memory. */
static float simplified_to_full(const lod_build *b, lod_scratch *s, float floor, float cap, float loose)
{
    probe_state ps = {b, s, floor * floor, floor * floor, 0.0f, 0.0f, 0, loose};
    float cap2 = cap * cap;
    if (!LOD_RESERVE(s, coarse_d2, (size_t)s->out_triangle_count + 1) ||
        !LOD_RESERVE(s, edge_d2, (size_t)s->out_triangle_count * 3 + 1))
        return -1.0f;
    for (uint32_t t = 0; t < s->out_triangle_count && !(ps.worst > cap2); t++)
        s->coarse_d2[t] = probe_shared(&ps, s, t, 3, 0);
    float coarse_worst = ps.worst;
    for (uint32_t t = 0; t < s->out_triangle_count && !(ps.worst > cap2); t++)
        if (!(s->coarse_d2[t] < refine_share(coarse_worst)))
            probe_shared(&ps, s, t, LOD_FINE_STEPS, 1);
    return ps.failed ? -1.0f : ps.worst > cap2 ? INFINITY : sqrtf(ps.worst);
}

/* D2's bound is measured again only where it is at least this share of the mesh's bounding radius
 * (tight_d2): a tenth took watch.glb at 64 x 36 pixels from 41.1 to 37.9 dB, white-claw-can.glb at
 * 256 x 144 to 39.96 dB with no share at all. */
#define LOD_TIGHT_D2_SHARE 0.25f

/* D2 measured again where its bound decides the error of a group at the coarse end: above D1, the
 * texture slide and the members' errors, of a group holding at least a quarter of the mesh's samples,
 * and at least LOD_TIGHT_D2_SHARE of the mesh's radius. A bound taken within twice the largest
 * checked may be twice the distance, and there nothing else covers it; so the probes are measured
 * again from that level up, each bound that would raise D2 past the largest checked measured exactly
 * over the level-0 triangles around the simplified triangles' corners, and over the group's own
 * surface where its grid is built already (distances to some level-0 triangles: never below the
 * distance to S0, so still bounds). Both measures bound D2: the smaller is returned. Such groups are drawn at 1 px
 * where the whole model spans some tens of pixels or fewer (a pixel of a 16 x 9 view of a framed
 * model is about 0.3 of its radius, of 64 x 36 about 0.08). Finer, the loose bound is kept, which
 * guards shading and silhouettes that the distance does not weigh (docs/GEOMETRY.md, "The coarse
 * end of a textured mesh"). The quarter of the samples bounds the cost: at most four such groups a
 * step, at the DAG's top. */
static float tight_d2(const lod_build *b, lod_scratch *s, const group_result *r, float to_simplified, float to_full)
{
    float level = to_simplified > r->slide ? to_simplified : r->slide;
    level = level > r->error ? level : r->error;
    if (!(to_full > level) || (size_t)s->gathered * 4 < b->position_count ||
        to_full < LOD_TIGHT_D2_SHARE * b->mesh->bounds.w)
        return to_full;
    float again = simplified_to_full(b, s, level, to_full, 1.0f);
    return again >= 0.0f && again < to_full ? again : to_full;
}

/* The samples in order of the new cluster they pass to, into r. */
static int hand_samples_to_clusters(lod_scratch *s, group_result *r)
{
    r->samples = malloc(((size_t)s->gathered + 1) * sizeof *r->samples);
    r->cluster_sample_first = calloc((size_t)r->cluster_count + 1, sizeof *r->cluster_sample_first);
    uint32_t *start = r->cluster_sample_first;
    if (!r->samples || !start)
        return 0;
    for (uint32_t i = 0; i < s->gathered; i++)
        start[s->sample_cluster[i] + 1]++;
    for (uint32_t c = 0; c < r->cluster_count; c++)
        start[c + 1] += start[c];
    for (uint32_t i = 0; i < s->gathered; i++)
        r->samples[start[s->sample_cluster[i]]++] = s->sample_ids[i];
    for (uint32_t c = r->cluster_count; c > 0; c--) /* start[c] now holds the end of c: shift back */
        start[c] = start[c - 1];
    start[0] = 0;
    return 1;
}

/* The samples farther from the simplified triangles than `floor` (the group's error without D1, at
 * least the smallest kept bound), with their exact distance, into r->excess (docs/GEOMETRY.md,
 * "Samples that pass to a neighbour"); the exact query also hands such a sample to its nearest
 * cluster. Only kept samples can be farther than the floor. */
static int collect_excess(lod_scratch *s, group_result *r, float floor)
{
    float floor2 = floor * floor;
    uint32_t over[LOD_EXCESS_LIMIT + 1], n = 0;
    for (uint32_t k = 0; k < s->top.count; k++)
        if (s->top.d2[k] > floor2)
            over[n++] = s->top.sample[k];
    r->floor = floor;
    r->excess_count = 0;
    if (n == 0 || n > LOD_EXCESS_LIMIT)
        return 1;
    qsort(over, n, sizeof *over, compare_u32); /* in sample order */
    r->excess = malloc(n * sizeof *r->excess);
    r->excess_distance = malloc(n * sizeof *r->excess_distance);
    if (!r->excess || !r->excess_distance)
        return 0;
    for (uint32_t k = 0; k < n; k++) {
        uint32_t i = over[k];
        float d;
        uint32_t nearest = lod_triangle_grid_nearest(&s->triangle_grid, s->sample_points[i], point_triangle_d2, &d);
        s->sample_cluster[i] = s->out_cluster[nearest];
        if (!(d > floor2))
            continue;
        r->excess[r->excess_count] = s->sample_ids[i];
        r->excess_distance[r->excess_count++] = sqrtf(d);
    }
    return 1;
}

/* The group's floor (docs/GEOMETRY.md, "Samples that pass to a neighbour"): its members' errors,
 * D2, and the smallest kept bound once the kept bounds are full. Where D1 is set by the few samples
 * farther than all others and the members' errors, D2 is measured again down to that level: the
 * part of its error that no redirection of samples can lower. Both measures bound D2: the smaller
 * is left in *to_full, but not below the group's texture slide, which *to_full holds already. Not
 * where that level is above LOD_REDIRECT_GAIN of the error, and no further once D2 is: no
 * redirection would pay. */
static float group_floor(const lod_build *b, lod_scratch *s, const group_result *r, float to_simplified,
                         float *to_full)
{
    float kept = kept_bound(&s->top), rest = kept > 0.0f ? sqrtf(kept) : 0.0f;
    float floor = r->error > rest ? r->error : rest;
    if (to_simplified > floor && *to_full >= 0.0f && floor <= LOD_REDIRECT_GAIN * *to_full) {
        float again = simplified_to_full(b, s, floor, LOD_REDIRECT_GAIN * *to_full, LOD_LOOSE);
        if (again >= 0.0f && again < r->slide)
            again = r->slide; /* the texture slides that far on the simplified surface, as measured first */
        *to_full = again < *to_full ? again : *to_full;
    }
    return *to_full > floor ? *to_full : floor;
}

/* Whether the floor from LOD_EXCESS_LIMIT + 1 kept bounds could differ from the one from the bounds
 * kept: the smallest kept bound is above the members' errors, and D2 (`to_full`, measured down to
 * D1) is not above D1, where it would set the floor, and those errors leave room for measuring D2
 * below D1 (group_floor). Then the samples are measured again keeping LOD_EXCESS_LIMIT + 1 bounds,
 * so that a band of samples a neighbour's triangles keep may pass there as a few farthest samples
 * do; elsewhere the floor is the same either way. */
static int keep_more(const lod_scratch *s, const group_result *r, float to_simplified, float to_full)
{
    float kept = kept_bound(&s->top);
    return s->top.limit < LOD_EXCESS_LIMIT + 1 && kept >= 0.0f && sqrtf(kept) > r->error &&
           r->error <= LOD_REDIRECT_GAIN * to_full && to_full <= to_simplified;
}

/* D1 and the smallest kept bound into r, and for an observer (a test) the kept samples. Returns 0
 * when out of memory. */
static int record_kept(const lod_build *b, const lod_scratch *s, group_result *r, float to_simplified)
{
    float kept = kept_bound(&s->top);
    r->d1 = to_simplified;
    r->kept_bound = kept >= 0.0f ? sqrtf(kept) : -1.0f;
    if (!b->observer)
        return 1;
    r->kept = malloc(((size_t)s->top.count + 1) * sizeof *r->kept);
    if (!r->kept)
        return 0;
    for (uint32_t k = 0; k < s->top.count; k++)
        r->kept[k] = s->sample_ids[s->top.sample[k]];
    r->kept_count = s->top.count;
    return 1;
}

int gdr_lod_group_deviation(lod_build *b, lod_scratch *s, const uint32_t *members, uint32_t count,
                            uint32_t local_count, group_result *r)
{
    if (!output_triangles(s, r, local_count) || !gather_samples(b, s, members, count))
        return 0;
    /* The grids of the level-0 triangles around the samples and the corners, and of the samples, are
     * built when the probes first need them and kept for the group: group_floor probes again over
     * the same triangles and samples. */
    s->region_built = 0;
    s->span_built = 0;
    s->grid_holds_samples = 0;
    s->top.count = 0; /* a group without samples keeps none */
    s->top.limit = LOD_KEPT_FIRST;
    float to_simplified = s->gathered ? samples_to_simplified(b, s, local_count) : 0.0f;
    float to_full = to_simplified < 0.0f ? 0.0f : simplified_to_full(b, s, to_simplified, INFINITY, LOD_LOOSE);
    if (to_simplified >= 0.0f && to_full >= 0.0f)
        to_full = tight_d2(b, s, r, to_simplified, to_full);
    if (to_full >= 0.0f && r->slide > to_full)
        to_full = r->slide; /* the texture slides that far on the simplified surface */
    /* Measured again (the same largest distance), over the vertex grid the probes may have taken.
     * Not for the step's only group (the steps below one cluster measure the whole mesh each): no
     * neighbour can take its samples, and its error does not change: a lower floor only lets
     * group_floor refine D2 further below the floor, and the floor is at most D1. */
    if (!b->lone_group && to_simplified >= 0.0f && to_full >= 0.0f && keep_more(s, r, to_simplified, to_full) &&
        (!build_vertex_grid(s, local_count) || measure_all_samples(b, s, LOD_EXCESS_LIMIT + 1) < 0.0f))
        return 0;
    float floor = to_simplified < 0.0f ? 0.0f : group_floor(b, s, r, to_simplified, &to_full);
    if (to_simplified < 0.0f || to_full < 0.0f || !collect_excess(s, r, floor) || !hand_samples_to_clusters(s, r) ||
        !record_kept(b, s, r, to_simplified))
        return 0;
    r->deviation = to_simplified > to_full ? to_simplified : to_full;
    return 1;
}

float gdr_lod_point_triangle_d2(gdr_vec3 p, gdr_vec3 a, gdr_vec3 b, gdr_vec3 c)
{
    return point_triangle_d2(p, a, b, c);
}
