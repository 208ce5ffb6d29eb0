/* meshopt_buildMeshlets with its worst case bounded (meshlet_chunks.h).
 *
 * meshoptimizer 0.18 finds the triangle that starts each meshlet in a kd-tree of triangle
 * centroids, split at the mean of the widest axis; a range it cannot split into two parts of more
 * than 4 becomes one leaf, scanned whole at every search. A triangle soup plus one triangle far
 * away (a legal file) makes that a single leaf of every triangle: quadratic. The same build is
 * simulated here first (linear work for sound meshes, capped otherwise); when it ends in a large
 * leaf, or is cut short, the triangles are given to meshoptimizer in chunks, so that no leaf and no
 * adjacency list holds more than a chunk. Sound meshes are built exactly as before. */
#include "geometry/meshlet_chunks.h"

#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>

/* Leaves up to this size are what sound meshes make (meshoptimizer's leaves hold 8). */
#define LARGEST_SOUND_LEAF 256u
/* Triangles per chunk when chunking. */
#define CHUNK_TRIANGLES 4096u

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
        if (n <= 8)
            continue;
        if ((work += n) > work_limit)
            return 1;
        double mean[3] = {0, 0, 0}, m2[3] = {0, 0, 0};
        for (uint32_t i = 0; i < n; i++) {
            const float *p = centroids + 3 * (size_t)order[r.begin + i];
            for (int k = 0; k < 3; k++) {
                double delta = p[k] - mean[k];
                mean[k] += delta / (i + 1);
                m2[k] += delta * (p[k] - mean[k]);
            }
        }
        int axis = m2[0] >= m2[1] && m2[0] >= m2[2] ? 0 : m2[1] >= m2[2] ? 1 : 2;
        float split = (float)mean[axis];
        uint32_t middle = r.begin;
        for (uint32_t i = r.begin; i < r.end; i++)
            if (centroids[3 * (size_t)order[i] + axis] < split) {
                uint32_t t = order[middle];
                order[middle++] = order[i];
                order[i] = t;
            }
        uint32_t left = middle - r.begin;
        if (left <= 4 || left >= n - 4) {
            if (n > LARGEST_SOUND_LEAF)
                return 1;
            continue;
        }
        stack[top++] = (kd_range){r.begin, middle};
        stack[top++] = (kd_range){middle, r.end};
    }
    return 0;
}

size_t gdr_meshlet_chunks_bound(const gdr_mesh *mesh, uint32_t max_vertices, uint32_t max_triangles)
{
    size_t bound = 0;
    for (uint32_t first = 0; first < mesh->index_count; first += 3 * CHUNK_TRIANGLES) {
        uint32_t n = mesh->index_count - first < 3 * CHUNK_TRIANGLES ? mesh->index_count - first : 3 * CHUNK_TRIANGLES;
        bound += meshopt_buildMeshletsBound(n, max_vertices, max_triangles);
    }
    return bound;
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

size_t gdr_meshlet_build_chunks(const gdr_mesh *mesh, uint32_t max_vertices, uint32_t max_triangles,
                                float cone_weight, struct meshopt_Meshlet *meshlets, unsigned int *vertices,
                                unsigned char *triangles)
{
    uint32_t *local_of = malloc(sizeof(uint32_t) * (size_t)mesh->vertex_count);
    uint32_t *global_of = malloc(sizeof(uint32_t) * 3 * CHUNK_TRIANGLES);
    uint32_t *indices = malloc(sizeof(uint32_t) * 3 * CHUNK_TRIANGLES);
    gdr_vec3 *positions = malloc(sizeof(gdr_vec3) * 3 * CHUNK_TRIANGLES);
    size_t count = 0, vertex_end = 0, triangle_end = 0;
    if (!local_of || !global_of || !indices || !positions)
        goto done;
    memset(local_of, 0xff, sizeof(uint32_t) * (size_t)mesh->vertex_count);
    for (uint32_t first = 0; first < mesh->index_count; first += 3 * CHUNK_TRIANGLES) {
        uint32_t n = mesh->index_count - first < 3 * CHUNK_TRIANGLES ? mesh->index_count - first : 3 * CHUNK_TRIANGLES;
        uint32_t local_count = 0;
        for (uint32_t i = 0; i < n; i++) {
            uint32_t v = mesh->indices[first + i];
            if (local_of[v] == UINT32_MAX) {
                local_of[v] = local_count;
                global_of[local_count] = v;
                positions[local_count++] = mesh->positions[v];
            }
            indices[i] = local_of[v];
        }
        size_t made = meshopt_buildMeshlets(meshlets + count, vertices + vertex_end, triangles + triangle_end, indices,
                                            n, &positions[0].x, local_count, sizeof(gdr_vec3), max_vertices,
                                            max_triangles, cone_weight);
        for (size_t m = count; m < count + made; m++) {
            for (uint32_t k = 0; k < meshlets[m].vertex_count; k++)
                vertices[vertex_end + meshlets[m].vertex_offset + k] =
                    global_of[vertices[vertex_end + meshlets[m].vertex_offset + k]];
            meshlets[m].vertex_offset += (unsigned)vertex_end;
            meshlets[m].triangle_offset += (unsigned)triangle_end;
        }
        for (uint32_t k = 0; k < local_count; k++)
            local_of[global_of[k]] = UINT32_MAX;
        if (made == 0) {
            count = 0;
            goto done;
        }
        count += made;
        const struct meshopt_Meshlet *last = &meshlets[count - 1];
        vertex_end = (size_t)last->vertex_offset + last->vertex_count;
        triangle_end = (size_t)last->triangle_offset + ((size_t)last->triangle_count * 3 + 3) / 4 * 4;
    }
done:
    free(local_of);
    free(global_of);
    free(indices);
    free(positions);
    return count;
}
