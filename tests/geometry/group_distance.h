/* The crumpled sheet and the exact distance from a group's simplified triangles to level 0, shared
 * by the white-box tests of the groups' D2 bounds (test_lod_probe_bound, test_lod_coarse_bound). */
#ifndef GDR_TEST_GROUP_DISTANCE_H
#define GDR_TEST_GROUP_DISTANCE_H

#include <math.h>
#include <stdint.h>

#include "gdr/geometry.h"
#include "geometry/lod_grid.h"
#include "geometry/lod_internal.h"
#include "point_distance.h"
#include "test_util.h"

#define CRUMPLED_QUADS 120u
#define CRUMPLED_VERTICES ((CRUMPLED_QUADS + 1) * (CRUMPLED_QUADS + 1))
#define CRUMPLED_INDICES (CRUMPLED_QUADS * CRUMPLED_QUADS * 6)

/* A unit square of CRUMPLED_QUADS x CRUMPLED_QUADS quads, jittered in the plane and folded by a wave
 * whose crests wander: folds a few quads apart, which a group's simplified triangles span and where
 * probes' walks stop far from their foot. uv (NULL: none) maps it by its plane: one chart. */
static inline void crumpled_sheet(gdr_vec3 *p, gdr_vec2 *uv, uint32_t *idx)
{
    const uint32_t n = CRUMPLED_QUADS;
    for (uint32_t y = 0; y <= n; y++)
        for (uint32_t x = 0; x <= n; x++) {
            uint32_t i = y * (n + 1) + x;
            float u = (float)x / (float)n, v = (float)y / (float)n;
            float du = 2.0f * test_hash_unit(2 * i) - 1.0f, dv = 2.0f * test_hash_unit(2 * i + 1) - 1.0f;
            p[i] = (gdr_vec3){u + 0.004f * du, v + 0.004f * dv, 0.05f * sinf(40.0f * u + 7.0f * sinf(9.0f * v))};
            if (uv)
                uv[i] = (gdr_vec2){p[i].x, p[i].y};
        }
    uint32_t k = 0;
    for (uint32_t y = 0; y < n; y++)
        for (uint32_t x = 0; x < n; x++) {
            uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
            uint32_t t[6] = {a, b, d, a, d, c};
            for (int j = 0; j < 6; j++)
                idx[k++] = t[j];
        }
}

static inline float point_triangle_d2_float(gdr_vec3 p, gdr_vec3 a, gdr_vec3 b, gdr_vec3 c)
{
    double d = point_triangle(d3(p), d3(a), d3(b), d3(c));
    return (float)(d * d);
}

/* The exact distance to level 0 (`full`: its triangles, every triangle of a cell looked at), largest
 * over a barycentric grid of 8 steps on each triangle of the clusters r made. */
static inline double group_level0_distance(const lod_triangle_grid *full, const lod_build *b, const group_result *r)
{
    const gdr_vec3 *pos = b->mesh->positions;
    double worst = 0;
    for (uint32_t i = 0; i < r->cluster_count; i++) {
        const gdr_cluster *c = &b->clusters[r->first_cluster + i];
        const uint32_t *v = gdr_lod_cluster_vertices(b, c);
        const uint8_t *t = gdr_lod_cluster_triangles(b, c);
        for (uint32_t j = 0; j < c->triangle_count; j++) {
            gdr_vec3 a = pos[v[t[3 * j]]], e = pos[v[t[3 * j + 1]]], f = pos[v[t[3 * j + 2]]];
            for (int s = 0; s <= 8; s++)
                for (int w = 0; s + w <= 8; w++) {
                    float fs = (float)s / 8.0f, fw = (float)w / 8.0f, fz = 1.0f - fs - fw;
                    gdr_vec3 q = {fz * a.x + fs * e.x + fw * f.x, fz * a.y + fs * e.y + fw * f.y,
                                  fz * a.z + fs * e.z + fw * f.z};
                    float d2;
                    lod_triangle_grid_nearest(full, q, point_triangle_d2_float, &d2);
                    worst = fmax(worst, sqrt(d2));
                }
        }
    }
    return worst;
}

#endif
