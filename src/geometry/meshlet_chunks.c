/* Whether meshopt_buildMeshlets would be quadratic on a mesh (meshlet_chunks.h).
 *
 * meshoptimizer 0.18 finds the triangle that starts each meshlet in a kd-tree of triangle
 * centroids, split at the mean of the widest axis; a range it cannot split into two parts of more
 * than 4 becomes one leaf, scanned whole at every search. A triangle soup plus one triangle far
 * away (a legal file) makes that a single leaf of every triangle: quadratic. The same build is
 * simulated here first (linear work for sound meshes, capped otherwise); when it ends in a large
 * leaf, or is cut short, meshlets.c gives the triangles to meshoptimizer in small chunks, so that
 * no leaf holds more than a chunk. Sound meshes are built exactly as before. */
#include "geometry/meshlet_chunks.h"

#include <stdlib.h>
#include <string.h>

/* Leaves up to this size are what sound meshes make (meshoptimizer's leaves hold 8). */
#define LARGEST_SOUND_LEAF 256u

typedef struct kd_range {
    uint32_t begin, end;
} kd_range;

/* Simulates the kd-tree build over triangle centroids: true when it ends with a leaf larger than
 * LARGEST_SOUND_LEAF or needs more than 64 passes over the triangles. */
static int kdtree_degenerates(const float *centroids, uint32_t count, uint32_t *order, kd_range *stack)
{
    for (uint32_t i = 0; i < count; i++)
        order[i] = i;
    uint64_t work = 0, work_limit = 64ull * count + 4096;
    uint32_t top = 0;
    stack[top++] = (kd_range){0, count};
    while (top > 0) {
        kd_range r = stack[--top];
        uint32_t n = r.end - r.begin;
        if (n <= LARGEST_SOUND_LEAF) /* nothing below can make a larger leaf */
            continue;
        if ((work += n) > work_limit)
            return 1;
        /* Sums about the range's first point (no division per point; the spread decides the axis). */
        const float *origin = centroids + 3 * (size_t)order[r.begin];
        double sum[3] = {0, 0, 0}, squares[3] = {0, 0, 0};
        for (uint32_t i = r.begin; i < r.end; i++) {
            const float *p = centroids + 3 * (size_t)order[i];
            for (int k = 0; k < 3; k++) {
                double d = (double)p[k] - origin[k];
                sum[k] += d;
                squares[k] += d * d;
            }
        }
        double spread[3];
        for (int k = 0; k < 3; k++)
            spread[k] = squares[k] - sum[k] * sum[k] / n;
        int axis = spread[0] >= spread[1] && spread[0] >= spread[2] ? 0 : spread[1] >= spread[2] ? 1 : 2;
        float split = (float)(origin[axis] + sum[axis] / n);
        uint32_t middle = r.begin;
        for (uint32_t i = r.begin; i < r.end; i++)
            if (centroids[3 * (size_t)order[i] + axis] < split) {
                uint32_t t = order[middle];
                order[middle++] = order[i];
                order[i] = t;
            }
        uint32_t left = middle - r.begin;
        if (left <= 4 || left >= n - 4)
            return 1; /* a leaf of n > LARGEST_SOUND_LEAF triangles */
        stack[top++] = (kd_range){r.begin, middle};
        stack[top++] = (kd_range){middle, r.end};
    }
    return 0;
}

int gdr_meshlet_needs_chunks(const gdr_mesh *mesh)
{
    uint32_t count = mesh->index_count / 3;
    if (count <= LARGEST_SOUND_LEAF)
        return 0;
    float *centroids = malloc(sizeof(float) * 3 * (size_t)count);
    uint32_t *order = malloc(sizeof(uint32_t) * (size_t)count);
    kd_range *stack = malloc(sizeof(kd_range) * ((size_t)count + 1));
    int degenerate = 1; /* out of memory: chunks need little */
    if (centroids && order && stack) {
        for (uint32_t t = 0; t < count; t++) {
            const gdr_vec3 *a = &mesh->positions[mesh->indices[3 * t]], *b = &mesh->positions[mesh->indices[3 * t + 1]],
                           *c = &mesh->positions[mesh->indices[3 * t + 2]];
            centroids[3 * t] = (a->x + b->x + c->x) / 3.0f;
            centroids[3 * t + 1] = (a->y + b->y + c->y) / 3.0f;
            centroids[3 * t + 2] = (a->z + b->z + c->z) / 3.0f;
        }
        degenerate = kdtree_degenerates(centroids, count, order, stack);
    }
    free(centroids);
    free(order);
    free(stack);
    return degenerate;
}
