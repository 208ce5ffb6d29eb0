/* Checks of the level-0 cluster contract (include/gdr/geometry.h) shared by the geometry tests:
 * each returns 1 when the property holds and prints what broke it otherwise. */
#ifndef GDR_TEST_CLUSTER_CHECKS_H
#define GDR_TEST_CLUSTER_CHECKS_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "gdr/scene.h"

static inline int same_bytes(const void *a, const void *b, size_t n)
{
    return n == 0 || (a && b && memcmp(a, b, n) == 0);
}

/* Bit for bit, every field and array (the DAG's groups and the LOD hierarchy included). */
static inline int same_clusters(const gdr_mesh_clusters *x, const gdr_mesh_clusters *y)
{
    return x->cluster_count == y->cluster_count && x->level0_cluster_count == y->level0_cluster_count &&
           x->vertex_count == y->vertex_count && x->triangle_byte_count == y->triangle_byte_count &&
           x->group_count == y->group_count && x->dag_depth == y->dag_depth &&
           same_bytes(x->clusters, y->clusters, sizeof(gdr_cluster) * x->cluster_count) &&
           same_bytes(x->vertices, y->vertices, sizeof(uint32_t) * x->vertex_count) &&
           same_bytes(x->triangles, y->triangles, x->triangle_byte_count) &&
           same_bytes(x->groups, y->groups, sizeof(gdr_cluster_group) * x->group_count) &&
           x->lod_node_count == y->lod_node_count && x->lod_node_levels == y->lod_node_levels &&
           same_bytes(x->lod_nodes, y->lod_nodes, sizeof(gdr_lod_node) * x->lod_node_count);
}

/* Global corner k of triangle t of cluster c. */
static inline uint32_t cluster_corner(const gdr_mesh_clusters *mc, const gdr_cluster *c, uint32_t t, uint32_t k)
{
    return mc->vertices[c->vertex_offset + mc->triangles[c->triangle_offset + 3 * t + k]];
}

/* Sizes, offsets and index ranges; arrays sized exactly; DAG fields empty. */
static inline int check_cluster_layout(const gdr_mesh *mesh, const gdr_mesh_clusters *mc, uint32_t max_vertices,
                                       uint32_t max_triangles)
{
    if (mc->cluster_count == 0 || mc->level0_cluster_count != mc->cluster_count || mc->groups ||
        mc->group_count || mc->dag_depth) {
        fprintf(stderr, "mesh '%s': %u clusters, level 0 %u, %u groups, depth %u\n", mesh->name, mc->cluster_count,
                mc->level0_cluster_count, mc->group_count, mc->dag_depth);
        return 0;
    }
    uint64_t vertex_end = 0, triangle_end = 0;
    for (uint32_t i = 0; i < mc->cluster_count; i++) {
        const gdr_cluster *c = &mc->clusters[i];
        int bad = c->vertex_count < 1 || c->vertex_count > max_vertices || c->triangle_count < 1 ||
                  c->triangle_count > max_triangles || c->triangle_offset % 4 != 0 ||
                  c->vertex_offset != vertex_end || c->triangle_offset != triangle_end ||
                  (uint64_t)c->vertex_offset + c->vertex_count > mc->vertex_count ||
                  (uint64_t)c->triangle_offset + 3ull * c->triangle_count > mc->triangle_byte_count ||
                  c->group != GDR_NO_INDEX || c->refined_group != GDR_NO_INDEX || c->reserved != 0;
        if (bad) {
            fprintf(stderr, "mesh '%s' cluster %u: offsets %u/%u counts %u/%u group %u/%u\n", mesh->name, i,
                    c->vertex_offset, c->triangle_offset, c->vertex_count, c->triangle_count, c->group,
                    c->refined_group);
            return 0;
        }
        for (uint32_t k = 0; k < 3 * c->triangle_count; k++)
            if (mc->triangles[c->triangle_offset + k] >= c->vertex_count) {
                fprintf(stderr, "mesh '%s' cluster %u: local index %u >= %u\n", mesh->name, i,
                        mc->triangles[c->triangle_offset + k], c->vertex_count);
                return 0;
            }
        /* Every listed vertex is used, and none twice: the list is exactly the cluster's vertices. */
        uint8_t used[256] = {0};
        for (uint32_t k = 0; k < 3 * c->triangle_count; k++)
            used[mc->triangles[c->triangle_offset + k]] = 1;
        for (uint32_t v = 0; v < c->vertex_count; v++) {
            if (!used[v] || mc->vertices[c->vertex_offset + v] >= mesh->vertex_count) {
                fprintf(stderr, "mesh '%s' cluster %u: vertex %u unused or out of range\n", mesh->name, i, v);
                return 0;
            }
            for (uint32_t w = 0; w < v; w++)
                if (mc->vertices[c->vertex_offset + w] == mc->vertices[c->vertex_offset + v]) {
                    fprintf(stderr, "mesh '%s' cluster %u: vertex listed twice\n", mesh->name, i);
                    return 0;
                }
        }
        /* The padding up to the next 4-byte boundary is zero. */
        for (uint64_t b = c->triangle_offset + 3ull * c->triangle_count; b % 4; b++)
            if (b >= mc->triangle_byte_count || mc->triangles[b] != 0) {
                fprintf(stderr, "mesh '%s' cluster %u: padding byte %llu\n", mesh->name, i, (unsigned long long)b);
                return 0;
            }
        vertex_end = (uint64_t)c->vertex_offset + c->vertex_count;
        triangle_end = ((uint64_t)c->triangle_offset + 3ull * c->triangle_count + 3) / 4 * 4;
    }
    if (vertex_end != mc->vertex_count || triangle_end != mc->triangle_byte_count) {
        fprintf(stderr, "mesh '%s': arrays hold %u vertices / %u bytes, clusters use %llu / %llu\n", mesh->name,
                mc->vertex_count, mc->triangle_byte_count, (unsigned long long)vertex_end,
                (unsigned long long)triangle_end);
        return 0;
    }
    return 1;
}

typedef struct test_triangle {
    uint32_t v[3];
} test_triangle;

/* The rotation of (a, b, c) that starts at its smallest index: equal for equal windings. */
static inline test_triangle canonical_triangle(uint32_t a, uint32_t b, uint32_t c)
{
    if (b < a && b <= c)
        return (test_triangle){{b, c, a}};
    if (c < a && c < b)
        return (test_triangle){{c, a, b}};
    return (test_triangle){{a, b, c}};
}

static inline int compare_triangle_values(const void *x, const void *y)
{
    const test_triangle *a = x, *b = y;
    for (int k = 0; k < 3; k++)
        if (a->v[k] != b->v[k])
            return a->v[k] < b->v[k] ? -1 : 1;
    return 0;
}

/* Level 0 holds the mesh's triangles exactly: the same multiset, each with its winding. */
static inline int check_cluster_coverage(const gdr_mesh *mesh, const gdr_mesh_clusters *mc)
{
    size_t n = mesh->index_count / 3, m = 0;
    for (uint32_t i = 0; i < mc->level0_cluster_count; i++)
        m += mc->clusters[i].triangle_count;
    if (m != n) {
        fprintf(stderr, "mesh '%s': %zu triangles in clusters, %zu in the mesh\n", mesh->name, m, n);
        return 0;
    }
    test_triangle *input = malloc(n * sizeof *input), *output = malloc(n * sizeof *output);
    for (size_t t = 0; t < n; t++)
        input[t] = canonical_triangle(mesh->indices[3 * t], mesh->indices[3 * t + 1], mesh->indices[3 * t + 2]);
    size_t at = 0;
    for (uint32_t i = 0; i < mc->level0_cluster_count; i++) {
        const gdr_cluster *c = &mc->clusters[i];
        for (uint32_t t = 0; t < c->triangle_count; t++)
            output[at++] = canonical_triangle(cluster_corner(mc, c, t, 0), cluster_corner(mc, c, t, 1),
                                              cluster_corner(mc, c, t, 2));
    }
    qsort(input, n, sizeof *input, compare_triangle_values);
    qsort(output, n, sizeof *output, compare_triangle_values);
    int same = memcmp(input, output, n * sizeof *input) == 0;
    if (!same)
        fprintf(stderr, "mesh '%s': the clusters' triangles differ from the mesh's\n", mesh->name);
    free(input);
    free(output);
    return same;
}

/* Every vertex of every cluster lies in its sphere (exactly: the builder rounds the radius up). */
static inline int check_cluster_spheres(const gdr_mesh *mesh, const gdr_mesh_clusters *mc)
{
    for (uint32_t i = 0; i < mc->cluster_count; i++) {
        const gdr_cluster *c = &mc->clusters[i];
        if (!(c->sphere.w >= 0.0f) || !isfinite(c->sphere.x) || !isfinite(c->sphere.y) || !isfinite(c->sphere.z) ||
            !isfinite(c->sphere.w))
            return 0;
        for (uint32_t v = 0; v < c->vertex_count; v++) {
            gdr_vec3 p = mesh->positions[mc->vertices[c->vertex_offset + v]];
            double dx = (double)p.x - c->sphere.x, dy = (double)p.y - c->sphere.y, dz = (double)p.z - c->sphere.z;
            double d = sqrt(dx * dx + dy * dy + dz * dz);
            if (d > c->sphere.w) {
                fprintf(stderr, "mesh '%s' cluster %u: vertex %u at %.9g from the centre, radius %.9g\n", mesh->name,
                        i, v, d, (double)c->sphere.w);
                return 0;
            }
        }
    }
    return 1;
}

/* The cone test as a shader runs it, in float: 1 when the cluster is cone-culled from p. */
static inline int cone_culls(const gdr_cluster *c, gdr_vec3 p)
{
    float dx = c->cone_apex.x - p.x, dy = c->cone_apex.y - p.y, dz = c->cone_apex.z - p.z;
    float length = sqrtf(dx * dx + dy * dy + dz * dz);
    if (!(length > 0.0f))
        return 0;
    float d = (dx * c->cone_axis.x + dy * c->cone_axis.y + dz * c->cone_axis.z) / length;
    return d >= c->cone_cutoff;
}

/* Cosine of the angle between triangle t's normal and the direction from its centroid to p, in
 * double: > 0 means front-facing from p. Returns -2 for a triangle of zero area. */
static inline double facing_cosine(const gdr_mesh *mesh, const gdr_mesh_clusters *mc, const gdr_cluster *c,
                                   uint32_t t, gdr_vec3 p)
{
    double v[3][3];
    for (int k = 0; k < 3; k++) {
        gdr_vec3 q = mesh->positions[cluster_corner(mc, c, t, (uint32_t)k)];
        v[k][0] = q.x, v[k][1] = q.y, v[k][2] = q.z;
    }
    double e1[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
    double e2[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    double to[3];
    for (int k = 0; k < 3; k++)
        to[k] = (double)(&p.x)[k] - (v[0][k] + v[1][k] + v[2][k]) / 3.0;
    double tl = sqrt(to[0] * to[0] + to[1] * to[1] + to[2] * to[2]);
    if (nl == 0.0)
        return -2.0;
    if (tl == 0.0)
        return 0.0;
    return (n[0] * to[0] + n[1] * to[1] + n[2] * to[2]) / (nl * tl);
}

#endif
