/* Samples that pass to a neighbouring group (docs/GEOMETRY.md, "Samples that pass to a neighbour").
 *
 * A group's D1 is measured against its own new clusters only. Where a sample lies on a border
 * that this group's simplification moved away from but a neighbouring group of the same step kept
 * (a sliver dropped on one side, an open seam that slid), the sample sets the group's error far
 * above the rest of it. After all groups of a step are measured, such a sample s of group g may
 * pass to the new cluster c' of another group h nearest to it when d(s, c') <= floor(h) (the part
 * of h's error no redirection lowers) and h's error, once settled, is below d(s, C(g)). Then g's
 * error need only cover h's error instead of that distance; for the cut, "g passes" must imply
 * "h passes", so g's error stays at least h's and g's sphere encloses h's (equal spheres where
 * errors tie, since ties may form cycles). A redirection that would grow a sphere past
 * LOD_SPHERE_GROWTH times the largest of its own and its targets' is not made. Runs on the
 * building thread, in group order: the result does not depend on the thread count. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geometry/lod_internal.h"

/* A sphere grows by at most half for redirections (measured against 2x: docs/PERFORMANCE.md). */
#define LOD_SPHERE_GROWTH 1.5f
#define NONE UINT32_MAX

_Static_assert(sizeof(gdr_vec3) == 3 * sizeof(float), "positions are read as a float array");

typedef struct group_key {
    float error;
    uint32_t root, group;
} group_key;

static int compare_keys(const void *pa, const void *pb)
{
    const group_key *a = pa, *b = pb;
    if (a->error != b->error)
        return a->error < b->error ? -1 : 1;
    if (a->root != b->root)
        return a->root < b->root ? -1 : 1;
    return a->group < b->group ? -1 : a->group > b->group;
}

/* The step's redirection state; excess samples flattened over the groups. */
typedef struct redirect {
    lod_build *b;
    uint32_t groups;
    uint32_t *first;    /* group g: excess samples [first[g], first[g + 1]) */
    uint32_t *target;   /* per excess sample: the group it may pass to, or NONE */
    uint32_t *cluster;  /* ... and that group's new cluster */
    float *distance;    /* ... its distance to its own group's new clusters */
    uint32_t count;
    float *error;       /* per group: its error once settled */
    uint8_t *forbidden; /* per group: keeps its samples (a sphere would grow too much) */
    gdr_vec4 *sphere;   /* per group: its sphere once settled */
    uint32_t *parent;   /* union-find over redirections between groups of equal error */
    group_key *order;
} redirect;

static void redirect_free(redirect *rd)
{
    free(rd->first);
    free(rd->target);
    free(rd->cluster);
    free(rd->distance);
    free(rd->error);
    free(rd->forbidden);
    free(rd->sphere);
    free(rd->parent);
    free(rd->order);
}

/* The new triangles of the step's formed groups near an excess sample, as mesh vertex corners,
 * with their group and cluster; a grid over them answers "the nearest new triangle" for every
 * excess sample. Only clusters whose sphere comes within the largest floor of an excess sample are
 * listed: a triangle farther than that from a sample can be no target of it. */
typedef struct step_triangles {
    uint32_t *corners, *group, *cluster;
    uint32_t count;
    lod_triangle_grid grid;
    gdr_vec3 *points; /* the excess samples */
    lod_grid point_grid;
    uint8_t *near; /* per new cluster of the step, in group order: listed */
} step_triangles;

/* Marks the clusters near an excess sample; returns how many triangles they hold, or SIZE_MAX when
 * out of memory. */
static size_t mark_near_clusters(const redirect *rd, step_triangles *t)
{
    const lod_build *b = rd->b;
    size_t clusters = 0, n = 0;
    float reach = 0.0f;
    for (uint32_t g = 0; g < rd->groups; g++)
        if (b->results[g].formed) {
            clusters += b->results[g].cluster_count;
            reach = b->results[g].floor > reach ? b->results[g].floor : reach;
        }
    t->points = malloc(((size_t)rd->count + 1) * sizeof *t->points);
    t->near = malloc(clusters + 1);
    if (!t->points || !t->near)
        return SIZE_MAX;
    for (uint32_t g = 0; g < rd->groups; g++)
        for (uint32_t k = rd->first[g]; k < rd->first[g + 1]; k++)
            t->points[k] = b->mesh->positions[b->sample_vertex[b->results[g].excess[k - rd->first[g]]]];
    if (!lod_grid_build(&t->point_grid, t->points, rd->count, 1.0))
        return SIZE_MAX;
    clusters = 0;
    for (uint32_t g = 0; g < rd->groups; g++)
        for (uint32_t i = 0; b->results[g].formed && i < b->results[g].cluster_count; i++) {
            const gdr_cluster *c = &b->clusters[b->results[g].first_cluster + i];
            float d2, within = c->sphere.w + reach;
            lod_grid_nearest(&t->point_grid, (gdr_vec3){c->sphere.x, c->sphere.y, c->sphere.z}, &d2);
            t->near[clusters] = d2 <= within * within;
            n += t->near[clusters++] ? c->triangle_count : 0;
        }
    return n;
}

static int collect_triangles(const redirect *rd, step_triangles *t)
{
    const lod_build *b = rd->b;
    size_t n = mark_near_clusters(rd, t), clusters = 0;
    if (n == SIZE_MAX || n > UINT32_MAX / 3)
        return 0;
    t->corners = malloc((n * 3 + 1) * sizeof *t->corners);
    t->group = malloc((n + 1) * sizeof *t->group);
    t->cluster = malloc((n + 1) * sizeof *t->cluster);
    if (!t->corners || !t->group || !t->cluster)
        return 0;
    t->count = 0;
    for (uint32_t g = 0; g < rd->groups; g++) {
        const group_result *r = &b->results[g];
        for (uint32_t i = 0; r->formed && i < r->cluster_count; i++) {
            const gdr_cluster *c = &b->clusters[r->first_cluster + i];
            if (!t->near[clusters++])
                continue;
            const uint8_t *corner = gdr_lod_cluster_triangles(b, c);
            const uint32_t *vertex = gdr_lod_cluster_vertices(b, c);
            for (uint32_t j = 0; j < c->triangle_count * 3; j++)
                t->corners[(size_t)t->count * 3 + j] = vertex[corner[j]];
            for (uint32_t j = 0; j < c->triangle_count; j++) {
                t->group[t->count + j] = g;
                t->cluster[t->count + j] = i;
            }
            t->count += c->triangle_count;
        }
    }
    if (t->count > 0 && !lod_triangle_grid_build(&t->grid, (const float *)b->mesh->positions, t->corners, t->count))
        return 0;
    /* Up to 4,096 triangles of a cell are looked at, not 64: the listed clusters lie around excess
     * samples anywhere on the mesh, so the grid's box is the mesh's and its cells are coarse for the
     * triangles (on the 1 M-triangle torus up to 109 a cell); a cut-off cell can hide the
     * neighbour's triangle a sample lies on. The queries are few (the excess samples); the limit
     * keeps a hostile mesh (every triangle in one cell) from making each cost the whole step. A
     * cell cut off only misses a target: the sample stays, its error a bound as before. */
    t->grid.cell_limit = 4096u;
    return 1;
}

static void step_triangles_free(step_triangles *t)
{
    free(t->corners);
    free(t->group);
    free(t->cluster);
    free(t->points);
    free(t->near);
    lod_triangle_grid_free(&t->grid);
    lod_grid_free(&t->point_grid);
}

/* For every excess sample, the nearest new triangle of the step; a target when it belongs to
 * another group and lies within that group's floor. */
static void find_targets(redirect *rd, const step_triangles *t)
{
    const lod_build *b = rd->b;
    for (uint32_t g = 0; g < rd->groups; g++) {
        const group_result *r = &b->results[g];
        for (uint32_t k = 0; k < r->excess_count; k++) {
            uint32_t e = rd->first[g] + k;
            rd->distance[e] = r->excess_distance[k];
            rd->target[e] = NONE;
            if (t->count == 0)
                continue;
            float d2;
            uint32_t q = lod_triangle_grid_nearest(&t->grid, t->points[e], gdr_lod_point_triangle_d2, &d2);
            uint32_t h = t->group[q];
            float floor = b->results[h].floor;
            if (h != g && d2 <= floor * floor) {
                rd->target[e] = h;
                rd->cluster[e] = t->cluster[q];
            }
        }
    }
}

/* The least errors with: error(g) >= floor(g); for each excess sample of g, error(g) >= its
 * distance, or error(g) >= error(target) when it passes (it passes when that is smaller). From
 * the floors upwards: every update only raises an error, to one of finitely many values. */
static void settle_errors(redirect *rd)
{
    const group_result *results = rd->b->results;
    for (uint32_t g = 0; g < rd->groups; g++)
        rd->error[g] = rd->first[g + 1] > rd->first[g] && !rd->forbidden[g] ? results[g].floor : results[g].error;
    for (int changed = 1; changed;) {
        changed = 0;
        for (uint32_t g = 0; g < rd->groups; g++) {
            if (rd->first[g + 1] == rd->first[g] || rd->forbidden[g])
                continue;
            float e = results[g].floor;
            for (uint32_t k = rd->first[g]; k < rd->first[g + 1]; k++) {
                float need = rd->distance[k];
                if (rd->target[k] != NONE && rd->error[rd->target[k]] < need)
                    need = rd->error[rd->target[k]];
                e = need > e ? need : e;
            }
            if (e != rd->error[g]) {
                rd->error[g] = e;
                changed = 1;
            }
        }
    }
}

/* Forbids groups whose settled error is not at most LOD_REDIRECT_GAIN of their own to pass
 * samples: a small gain is not worth a larger sphere. Errors count from the smallest error a group
 * is given (flat parts gain nothing). Returns whether any was forbidden (their errors go back up:
 * settle again). */
static int forbid_small_gains(redirect *rd)
{
    int any = 0;
    float least = rd->b->min_error;
    for (uint32_t g = 0; g < rd->groups; g++)
        if (rd->first[g + 1] > rd->first[g] && !rd->forbidden[g] &&
            !(fmaxf(rd->error[g], least) <= LOD_REDIRECT_GAIN * fmaxf(rd->b->results[g].error, least))) {
            rd->forbidden[g] = 1;
            any = 1;
        }
    return any;
}

/* Whether excess sample k of group g passes to its target. */
static int passes(const redirect *rd, uint32_t g, uint32_t k)
{
    return !rd->forbidden[g] && rd->target[k] != NONE && rd->error[rd->target[k]] < rd->distance[k];
}

/* The spheres once settled: a group encloses the settled spheres of the groups its samples pass
 * to; groups of equal error joined by redirections share one sphere. Groups are visited by error
 * (their targets first). The limit is LOD_SPHERE_GROWTH times the largest own sphere of the set
 * and of the groups it passes samples to: enclosing a neighbour larger than itself makes a group
 * about as large as that neighbour, which the cut already tests (where a level-0 cluster's
 * triangles lie far apart, every group above it is large). Returns 1 when no sphere grew past the
 * limit, else forbids the groups of the offending set to pass samples and returns 0; -1 when out
 * of memory. */
static int settle_spheres(redirect *rd)
{
    const group_result *results = rd->b->results;
    uint32_t n = rd->groups;
    for (uint32_t g = 0; g < n; g++) {
        rd->parent[g] = g;
        rd->sphere[g] = results[g].sphere;
    }
    for (uint32_t g = 0; g < n; g++)
        for (uint32_t k = rd->first[g]; k < rd->first[g + 1]; k++)
            if (passes(rd, g, k) && rd->error[rd->target[k]] == rd->error[g])
                rd->parent[gdr_lod_find_root(rd->parent, g)] = gdr_lod_find_root(rd->parent, rd->target[k]);
    for (uint32_t g = 0; g < n; g++)
        rd->order[g] = (group_key){rd->error[g], gdr_lod_find_root(rd->parent, g), g};
    qsort(rd->order, n, sizeof *rd->order, compare_keys);
    int ok = 1;
    gdr_vec4 *list = NULL;
    size_t list_cap = 0;
    for (uint32_t i = 0, j; i < n; i = j) {
        uint32_t root = rd->order[i].root;
        size_t m = 0;
        float largest = 0.0f;
        for (j = i; j < n && rd->order[j].root == root; j++) {
            uint32_t g = rd->order[j].group;
            if (!gdr_lod_reserve(&list, &list_cap, m + 1 + rd->first[g + 1] - rd->first[g], sizeof *list)) {
                free(list);
                return -1;
            }
            list[m++] = results[g].sphere;
            largest = results[g].sphere.w > largest ? results[g].sphere.w : largest;
            for (uint32_t k = rd->first[g]; k < rd->first[g + 1]; k++)
                if (passes(rd, g, k)) {
                    uint32_t h = rd->target[k];
                    list[m++] = rd->sphere[h];
                    largest = results[h].sphere.w > largest ? results[h].sphere.w : largest;
                }
        }
        if (m == 1)
            continue;
        gdr_vec4 s = gdr_lod_enclosing_sphere(list, m);
        if (s.w > LOD_SPHERE_GROWTH * largest) {
            for (uint32_t x = i; x < j; x++)
                rd->forbidden[rd->order[x].group] = 1;
            ok = 0;
        }
        for (uint32_t x = i; x < j; x++)
            rd->sphere[rd->order[x].group] = s;
    }
    free(list);
    return ok;
}

/* Group g's samples again, by new cluster: without those that pass to another group (marked in
 * `moved`), with those that pass to g (records in[0 .. count), in order). */
static int rebuild_samples(group_result *r, const uint8_t *moved, const uint32_t *in_sample,
                           const uint32_t *in_cluster, uint32_t in_count)
{
    uint32_t *first = calloc((size_t)r->cluster_count + 1, sizeof *first);
    uint32_t *samples = malloc(((size_t)r->cluster_sample_first[r->cluster_count] + in_count + 1) * sizeof *samples);
    if (!first || !samples) {
        free(first);
        free(samples);
        return 0;
    }
    uint32_t n = 0;
    for (uint32_t c = 0; c < r->cluster_count; c++) {
        first[c] = n;
        for (uint32_t i = r->cluster_sample_first[c]; i < r->cluster_sample_first[c + 1]; i++)
            if (!moved[r->samples[i]])
                samples[n++] = r->samples[i];
        for (uint32_t i = 0; i < in_count; i++)
            if (in_cluster[i] == c)
                samples[n++] = in_sample[i];
    }
    first[r->cluster_count] = n;
    free(r->samples);
    free(r->cluster_sample_first);
    r->samples = samples;
    r->cluster_sample_first = first;
    return 1;
}

/* Moves the samples that pass, and gives every group its settled error and sphere. */
static int apply(redirect *rd)
{
    lod_build *b = rd->b;
    uint32_t n = rd->groups, moves = 0;
    for (uint32_t g = 0; g < n; g++)
        for (uint32_t k = rd->first[g]; k < rd->first[g + 1]; k++)
            moves += passes(rd, g, k);
    if (moves == 0)
        return 1;
    uint8_t *moved = calloc((size_t)b->position_count + 1, 1);
    uint32_t *in_start = calloc((size_t)n + 1, sizeof *in_start);
    uint32_t *in_sample = malloc((size_t)moves * sizeof *in_sample);
    uint32_t *in_cluster = malloc((size_t)moves * sizeof *in_cluster);
    int ok = moved && in_start && in_sample && in_cluster;
    for (uint32_t g = 0; ok && g < n; g++)
        for (uint32_t k = rd->first[g]; k < rd->first[g + 1]; k++)
            if (passes(rd, g, k)) {
                in_start[rd->target[k] + 1]++;
                moved[b->results[g].excess[k - rd->first[g]]] = 1;
            }
    for (uint32_t g = 0; ok && g < n; g++)
        in_start[g + 1] += in_start[g];
    for (uint32_t g = 0; ok && g < n; g++) /* records by target group, in source order */
        for (uint32_t k = rd->first[g]; k < rd->first[g + 1]; k++)
            if (passes(rd, g, k)) {
                uint32_t at = in_start[rd->target[k]]++;
                in_sample[at] = b->results[g].excess[k - rd->first[g]];
                in_cluster[at] = rd->cluster[k];
            }
    for (uint32_t g = n; ok && g > 0; g--) /* in_start[g] now holds the end of g: shift back */
        in_start[g] = in_start[g - 1];
    if (ok)
        in_start[0] = 0;
    for (uint32_t g = 0; ok && g < n; g++) {
        group_result *r = &b->results[g];
        int out = 0;
        for (uint32_t k = rd->first[g]; k < rd->first[g + 1]; k++)
            out |= passes(rd, g, k);
        uint32_t in = in_start[g + 1] - in_start[g];
        if (out || in)
            ok = rebuild_samples(r, moved, in_sample + in_start[g], in_cluster + in_start[g], in);
        if (r->formed && rd->error[g] < r->error)
            r->error = rd->error[g];
        r->sphere = rd->sphere[g];
    }
    free(moved);
    free(in_start);
    free(in_sample);
    free(in_cluster);
    return ok;
}

static int redirect_alloc(redirect *rd, uint32_t count)
{
    uint32_t n = rd->groups;
    rd->target = malloc(((size_t)count + 1) * sizeof *rd->target);
    rd->cluster = malloc(((size_t)count + 1) * sizeof *rd->cluster);
    rd->distance = malloc(((size_t)count + 1) * sizeof *rd->distance);
    rd->error = malloc(((size_t)n + 1) * sizeof *rd->error);
    rd->forbidden = calloc((size_t)n + 1, 1);
    rd->sphere = malloc(((size_t)n + 1) * sizeof *rd->sphere);
    rd->parent = malloc(((size_t)n + 1) * sizeof *rd->parent);
    rd->order = malloc(((size_t)n + 1) * sizeof *rd->order);
    return rd->target && rd->cluster && rd->distance && rd->error && rd->forbidden && rd->sphere && rd->parent &&
           rd->order;
}

int gdr_lod_redirect_samples(lod_build *b, uint32_t groups)
{
    redirect rd = {.b = b, .groups = groups};
    rd.first = malloc(((size_t)groups + 1) * sizeof *rd.first);
    if (!rd.first)
        return 0;
    rd.first[0] = 0;
    for (uint32_t g = 0; g < groups; g++)
        rd.first[g + 1] = rd.first[g] + (b->results[g].formed ? b->results[g].excess_count : 0);
    rd.count = rd.first[groups];
    if (rd.count == 0) {
        free(rd.first);
        return 1;
    }
    step_triangles t = {0};
    int ok = redirect_alloc(&rd, rd.count) && collect_triangles(&rd, &t);
    if (ok) {
        find_targets(&rd, &t);
        int settled = 0;
        while (!settled) {
            do
                settle_errors(&rd);
            while (forbid_small_gains(&rd));
            settled = settle_spheres(&rd);
            ok = settled >= 0;
            settled = settled != 0;
        }
    }
    ok = ok && apply(&rd);
    step_triangles_free(&t);
    redirect_free(&rd);
    return ok;
}
