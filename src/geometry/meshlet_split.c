/* Level-0 meshlets split where their triangles lie far apart (meshlet_split.h).
 *
 * meshoptimizer 0.18 grows a meshlet through triangles next to it; once none is free it takes the
 * free triangle nearest to the meshlet's centre, however far. The meshlet then holds two places
 * and its sphere covers the space between them, and so does the sphere of every LOD group above it
 * (a group's sphere encloses its children's). Here a meshlet's triangles are put in parts: triangles
 * sharing a vertex are in one part, and parts whose bounding boxes come closer than the chunk's
 * median meshlet size (half its box diagonal) are joined. A meshlet with more than one part is
 * replaced by one meshlet per part. Nearby unconnected pieces (a UV seam's two sides, small parts
 * side by side) stay together; only a jump farther than a typical meshlet is cut. */
#include "geometry/meshlet_split.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* meshoptimizer's own limits on a meshlet: local indices are bytes. */
#define MAX_LOCAL 256u
#define MAX_TRIANGLES 512u

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

/* The parts of meshlet m: part[t] for each of its triangles, numbered in the order of their first
 * triangle; returns the number of parts. Parts closer than `link` are one. */
static uint32_t meshlet_parts(const struct meshopt_Meshlet *m, const uint32_t *vertices, const uint8_t *triangles,
                              const float *positions, double link, uint8_t *part)
{
    uint8_t parent[MAX_LOCAL], component[MAX_LOCAL];
    for (uint32_t v = 0; v < m->vertex_count; v++)
        parent[v] = (uint8_t)v, component[v] = UINT8_MAX;
    const uint8_t *tri = triangles + m->triangle_offset;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        unite(parent, tri[3 * t], tri[3 * t + 1]);
        unite(parent, tri[3 * t], tri[3 * t + 2]);
    }
    /* Components of shared vertices, numbered by first triangle, with their boxes. */
    box boxes[MAX_TRIANGLES];
    uint32_t count = 0;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        uint32_t root = find(parent, tri[3 * t]);
        if (component[root] == UINT8_MAX)
            box_empty(&boxes[count]), component[root] = (uint8_t)count++;
        part[t] = component[root];
        for (int k = 0; k < 3; k++)
            box_add(&boxes[part[t]], positions + 3 * (size_t)vertices[m->vertex_offset + tri[3 * t + k]]);
    }
    if (count == 1)
        return 1;
    /* Single linkage: components whose boxes come within `link` are one part. A meshlet has at most
     * one component per triangle (its vertex limit keeps that near 21), so pairs are cheap. */
    uint8_t joined[MAX_LOCAL], number[MAX_LOCAL];
    for (uint32_t i = 0; i < count; i++)
        joined[i] = (uint8_t)i, number[i] = UINT8_MAX;
    for (uint32_t i = 0; i < count; i++)
        for (uint32_t j = i + 1; j < count; j++)
            if (find(joined, i) != find(joined, j) && box_gap(&boxes[i], &boxes[j]) <= link)
                unite(joined, i, j);
    uint32_t parts = 0;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        uint32_t root = find(joined, part[t]);
        if (number[root] == UINT8_MAX)
            number[root] = (uint8_t)parts++;
        part[t] = number[root];
    }
    return parts;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The median of the meshlets' half box diagonals: the distance beyond which parts are cut. */
static double median_size(const meshlet_arrays *a, const float *positions, double *sizes)
{
    for (size_t i = 0; i < a->count; i++) {
        const struct meshopt_Meshlet *m = &a->meshlets[i];
        box b;
        box_empty(&b);
        for (uint32_t v = 0; v < m->vertex_count; v++)
            box_add(&b, positions + 3 * (size_t)a->vertices[m->vertex_offset + v]);
        sizes[i] = half_diagonal(&b);
    }
    qsort(sizes, a->count, sizeof *sizes, by_value);
    return sizes[a->count / 2];
}

/* Writes part p of meshlet m (its triangles in order, its vertices in first-use order) at the
 * ends of the output arrays; returns the new meshlet. */
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

/* The split arrays into out (allocated here); parts[i] is meshlet i's part count, part its
 * triangles' parts in meshlet order. */
static int emit(const meshlet_arrays *a, const uint32_t *parts, const uint8_t *part, size_t total_parts,
                meshlet_arrays *out)
{
    const struct meshopt_Meshlet *last = &a->meshlets[a->count - 1];
    size_t vertices = (size_t)last->vertex_offset + last->vertex_count;
    size_t bytes = (size_t)last->triangle_offset + ((last->triangle_count * 3 + 3) & ~3u) + 4 * total_parts;
    out->meshlets = malloc(total_parts * sizeof *out->meshlets);
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

int gdr_meshlets_split_far_parts(meshlet_arrays *a, const float *positions)
{
    if (a->count < 2)
        return 0; /* nothing to measure a jump against */
    size_t triangles = 0;
    for (size_t i = 0; i < a->count; i++)
        triangles += a->meshlets[i].triangle_count;
    double *sizes = malloc(a->count * sizeof *sizes);
    uint32_t *parts = malloc(a->count * sizeof *parts);
    uint8_t *part = malloc(triangles);
    if (!sizes || !parts || !part) {
        free(sizes);
        free(parts);
        free(part);
        return -1;
    }
    double link = median_size(a, positions, sizes);
    size_t total = 0, first = 0;
    for (size_t i = 0; i < a->count; i++) {
        parts[i] = meshlet_parts(&a->meshlets[i], a->vertices, a->triangles, positions, link, part + first);
        first += a->meshlets[i].triangle_count;
        total += parts[i];
    }
    int status = 0;
    meshlet_arrays out = {0};
    if (total > a->count && (status = emit(a, parts, part, total, &out)) == 0) {
        free(a->meshlets);
        free(a->vertices);
        free(a->triangles);
        *a = out;
    }
    free(sizes);
    free(parts);
    free(part);
    return status;
}
