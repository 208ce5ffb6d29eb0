/* Level-0 meshlets split where meshoptimizer jumped far (meshlet_split.h).
 *
 * meshoptimizer 0.18 grows a meshlet through the triangles next to it; once none is free it takes
 * the free triangle nearest to the meshlet's centre, however far, and grows on there. Such a
 * meshlet holds two places and its sphere covers the space between them, and so does the sphere of
 * every LOD group above it (a group's sphere encloses its children's).
 *
 * A meshlet's *parts*: triangles sharing a vertex are one part, and parts whose bounding boxes come
 * within LINK_EDGES of the meshlet's mean edge length are joined (a seam's two sides, a crack, a
 * narrow hole). A meshlet is replaced by one meshlet per part when
 *  - it has 2 to MAX_PARTS parts (more: scattered pieces, such as a triangle soup, that no cut makes
 *    compact; cutting them would only empty the clusters),
 *  - it is more than SIZE_RATIO times as large as its largest part (half box diagonals): a jump,
 *    not a bay or a hole of one surface, and
 *  - it is more than OUTLIER times the chunk's typical size, the median over its meshlets of their
 *    largest part (a jump does not move that median, however many meshlets jump).
 * Every cut costs fill: both pieces are partly filled clusters, and meshoptimizer's meshlets around
 * them are full (the vertex limit binds), so nothing takes them in. The last condition keeps the
 * cut to the far jumps that inflate the spheres above them most (docs/GEOMETRY.md, "Compact level-0
 * clusters", has the measurements). */
#include "geometry/meshlet_split.h"

#include "gdr/geometry.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Local vertex indices are bytes; components and parts are numbered in bytes too. */
#define MAX_LOCAL 256u
#define MAX_TRIANGLES GDR_CLUSTER_MAX_TRIANGLES
_Static_assert(GDR_CLUSTER_MAX_TRIANGLES < 256, "components are numbered in bytes");

#define LINK_EDGES 2.0
#define MAX_PARTS 8u
#define SIZE_RATIO 2.0
#define OUTLIER 8.0

typedef struct box {
    float lo[3], hi[3];
} box;

static void box_empty(box *b)
{
    for (int k = 0; k < 3; k++) {
        b->lo[k] = FLT_MAX;
        b->hi[k] = -FLT_MAX;
    }
}

static void box_add(box *b, const float *p)
{
    for (int k = 0; k < 3; k++) {
        b->lo[k] = p[k] < b->lo[k] ? p[k] : b->lo[k];
        b->hi[k] = p[k] > b->hi[k] ? p[k] : b->hi[k];
    }
}

static box box_union(const box *x, const box *y)
{
    box b = *x;
    box_add(&b, y->lo);
    box_add(&b, y->hi);
    return b;
}

/* The distance between two boxes (0 where they overlap). */
static double box_gap(const box *a, const box *b)
{
    double sum = 0.0;
    for (int k = 0; k < 3; k++) {
        double d = (double)a->lo[k] - b->hi[k];
        double e = (double)b->lo[k] - a->hi[k];
        d = d > e ? d : e;
        sum += d > 0.0 ? d * d : 0.0;
    }
    return sqrt(sum);
}

static double half_diagonal(const box *b)
{
    double sum = 0.0;
    for (int k = 0; k < 3; k++) {
        double d = (double)b->hi[k] - b->lo[k];
        sum += d * d;
    }
    return 0.5 * sqrt(sum);
}

static double distance(const float *x, const float *y)
{
    double dx = (double)x[0] - y[0], dy = (double)x[1] - y[1], dz = (double)x[2] - y[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* Union-find over at most 256 elements (the lower root wins: deterministic). */
static uint32_t find(uint8_t *parent, uint32_t x)
{
    while (parent[x] != x)
        x = parent[x] = parent[parent[x]];
    return x;
}

static void unite(uint8_t *parent, uint32_t a, uint32_t b)
{
    a = find(parent, a);
    b = find(parent, b);
    if (a != b)
        parent[a > b ? a : b] = (uint8_t)(a < b ? a : b);
}

/* The components of meshlet m (triangles sharing a vertex): component[t] for each triangle, in the
 * order of their first triangle; returns their count. */
static uint32_t components(const struct meshopt_Meshlet *m, const uint8_t *tri, uint8_t *component)
{
    uint8_t parent[MAX_LOCAL], number[MAX_LOCAL];
    for (uint32_t v = 0; v < m->vertex_count; v++)
        parent[v] = (uint8_t)v, number[v] = UINT8_MAX;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        unite(parent, tri[3 * t], tri[3 * t + 1]);
        unite(parent, tri[3 * t], tri[3 * t + 2]);
    }
    uint32_t count = 0;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        uint32_t root = find(parent, tri[3 * t]);
        if (number[root] == UINT8_MAX)
            number[root] = (uint8_t)count++;
        component[t] = number[root];
    }
    return count;
}

/* The components' boxes; returns the meshlet's mean edge length. */
static double component_boxes(const struct meshopt_Meshlet *m, const uint32_t *vertices, const uint8_t *tri,
                              const float *positions, const uint8_t *component, uint32_t count, box *boxes)
{
    for (uint32_t i = 0; i < count; i++)
        box_empty(&boxes[i]);
    double edges = 0.0;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const float *corner[3];
        for (int k = 0; k < 3; k++) {
            corner[k] = positions + 3 * (size_t)vertices[m->vertex_offset + tri[3 * t + k]];
            box_add(&boxes[component[t]], corner[k]);
        }
        edges += distance(corner[0], corner[1]) + distance(corner[1], corner[2]) + distance(corner[2], corner[0]);
    }
    return edges / (3.0 * m->triangle_count);
}

/* The parts of meshlet m: part[t] for each of its triangles, numbered by first triangle; returns
 * their count, 0 where there are more than MAX_PARTS. `whole` and `largest` get the half box
 * diagonals of the meshlet and of its largest part (with too many parts, of the meshlet: such a
 * meshlet counts as one piece in the typical size). */
static uint32_t meshlet_parts(const struct meshopt_Meshlet *m, const uint32_t *vertices, const uint8_t *triangles,
                              const float *positions, uint8_t *part, double *whole, double *largest)
{
    const uint8_t *tri = triangles + m->triangle_offset;
    uint32_t count = components(m, tri, part);
    if (count == 1) { /* most meshlets: one box over its vertices */
        box b;
        box_empty(&b);
        for (uint32_t v = 0; v < m->vertex_count; v++)
            box_add(&b, positions + 3 * (size_t)vertices[m->vertex_offset + v]);
        *whole = *largest = half_diagonal(&b);
        return 1;
    }
    box boxes[MAX_TRIANGLES];
    double link = LINK_EDGES * component_boxes(m, vertices, tri, positions, part, count, boxes);
    /* Single linkage: components whose boxes come within `link` are one part. A meshlet has at most
     * one component per triangle (its vertex limit keeps that near 21), so pairs are cheap. */
    uint8_t joined[MAX_TRIANGLES], number[MAX_TRIANGLES];
    for (uint32_t i = 0; i < count; i++)
        joined[i] = (uint8_t)i, number[i] = UINT8_MAX;
    for (uint32_t i = 0; i < count; i++)
        for (uint32_t j = i + 1; j < count; j++)
            if (find(joined, i) != find(joined, j) && box_gap(&boxes[i], &boxes[j]) <= link)
                unite(joined, i, j);
    box parts[MAX_PARTS], all;
    box_empty(&all);
    for (uint32_t i = 0; i < count; i++)
        all = box_union(&all, &boxes[i]);
    *whole = *largest = half_diagonal(&all);
    uint32_t n = 0;
    for (uint32_t i = 0; i < count; i++) {
        uint32_t root = find(joined, i);
        if (number[root] == UINT8_MAX) {
            if (n == MAX_PARTS)
                return 0;
            box_empty(&parts[n]);
            number[root] = (uint8_t)n++;
        }
        parts[number[root]] = box_union(&parts[number[root]], &boxes[i]);
    }
    *largest = 0.0;
    for (uint32_t i = 0; i < n; i++)
        *largest = half_diagonal(&parts[i]) > *largest ? half_diagonal(&parts[i]) : *largest;
    for (uint32_t t = 0; t < m->triangle_count; t++)
        part[t] = number[find(joined, part[t])];
    return n;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Writes part p of meshlet m (its triangles in order, its vertices in first-use order) at the ends
 * of the output arrays; returns the new meshlet. */
static struct meshopt_Meshlet emit_part(const meshlet_arrays *a, const struct meshopt_Meshlet *m,
                                        const uint8_t *part, uint32_t p, meshlet_arrays *out, uint32_t *vo,
                                        uint32_t *to)
{
    uint8_t local[MAX_LOCAL];
    memset(local, UINT8_MAX, sizeof local);
    struct meshopt_Meshlet r = {.vertex_offset = *vo, .triangle_offset = *to};
    const uint8_t *tri = a->triangles + m->triangle_offset;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        if (part[t] != p)
            continue;
        for (int k = 0; k < 3; k++) {
            uint8_t v = tri[3 * t + k];
            if (local[v] == UINT8_MAX) {
                local[v] = (uint8_t)r.vertex_count++;
                out->vertices[r.vertex_offset + local[v]] = a->vertices[m->vertex_offset + v];
            }
            out->triangles[r.triangle_offset + 3 * r.triangle_count + (uint32_t)k] = local[v];
        }
        r.triangle_count++;
    }
    *vo += r.vertex_count;
    *to += (r.triangle_count * 3 + 3) & ~3u;
    return r;
}

/* The split arrays into out (allocated here): parts[i] is meshlet i's part count (1: as it is),
 * part its triangles' parts in meshlet order. A part's vertices are its own (parts share none),
 * so the vertex total stays; each new meshlet pads its triangles to 4 bytes. */
static int emit(const meshlet_arrays *a, const uint32_t *parts, const uint8_t *part, size_t total,
                meshlet_arrays *out)
{
    const struct meshopt_Meshlet *last = &a->meshlets[a->count - 1];
    size_t vertices = (size_t)last->vertex_offset + last->vertex_count;
    size_t bytes = (size_t)last->triangle_offset + ((last->triangle_count * 3 + 3) & ~3u) + 4 * total;
    out->meshlets = malloc(total * sizeof *out->meshlets);
    out->vertices = malloc(vertices * sizeof *out->vertices);
    out->triangles = calloc(bytes, 1); /* the padding between meshlets stays zero */
    if (!out->meshlets || !out->vertices || !out->triangles) {
        free(out->meshlets);
        free(out->vertices);
        free(out->triangles);
        return -1;
    }
    uint32_t vo = 0, to = 0;
    size_t k = 0, first = 0;
    for (size_t i = 0; i < a->count; i++) {
        const struct meshopt_Meshlet *m = &a->meshlets[i];
        for (uint32_t p = 0; p < parts[i]; p++)
            out->meshlets[k++] = emit_part(a, m, part + first, p, out, &vo, &to);
        first += m->triangle_count;
    }
    out->count = k;
    return 0;
}

/* Which meshlets are cut (parts[i] > 1), from their parts and sizes; returns the meshlets after. */
static size_t choose_cuts(const meshlet_arrays *a, uint32_t *parts, uint8_t *part, const double *whole,
                          const double *largest, double *scratch)
{
    memcpy(scratch, largest, a->count * sizeof *scratch);
    qsort(scratch, a->count, sizeof *scratch, by_value);
    double typical = scratch[a->count / 2];
    size_t total = 0, first = 0;
    for (size_t i = 0; i < a->count; i++) {
        if (parts[i] != 1 && !(parts[i] > 1 && whole[i] > SIZE_RATIO * largest[i] && whole[i] > OUTLIER * typical)) {
            parts[i] = 1;
            memset(part + first, 0, a->meshlets[i].triangle_count);
        }
        first += a->meshlets[i].triangle_count;
        total += parts[i];
    }
    return total;
}

int gdr_meshlets_split_far_parts(meshlet_arrays *a, const float *positions)
{
    if (a->count < 2)
        return 0; /* nothing to measure a jump against */
    size_t triangles = 0;
    for (size_t i = 0; i < a->count; i++)
        triangles += a->meshlets[i].triangle_count;
    uint32_t *parts = malloc(a->count * sizeof *parts);
    double *sizes = malloc(3 * a->count * sizeof *sizes);
    uint8_t *part = malloc(triangles);
    int status = parts && sizes && part ? 0 : -1;
    double *whole = status == 0 ? sizes + a->count : NULL, *largest = status == 0 ? sizes + 2 * a->count : NULL;
    for (size_t i = 0, first = 0; status == 0 && i < a->count; i++) {
        parts[i] = meshlet_parts(&a->meshlets[i], a->vertices, a->triangles, positions, part + first, &whole[i],
                                 &largest[i]);
        first += a->meshlets[i].triangle_count;
    }
    size_t total = status == 0 ? choose_cuts(a, parts, part, whole, largest, sizes) : 0;
    meshlet_arrays out = {0};
    if (status == 0 && total > a->count && (status = emit(a, parts, part, total, &out)) == 0) {
        free(a->meshlets);
        free(a->vertices);
        free(a->triangles);
        *a = out;
    }
    free(parts);
    free(sizes);
    free(part);
    return status;
}
