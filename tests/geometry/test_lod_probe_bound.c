/* The bound a group states for the distance from its simplified triangles to the full-detail surface
 * (D2) stays close to that distance on a crumpled sheet, white-box (the build's observer,
 * geometry/lod_internal.h).
 *
 * A probe's bound is the distance to the level-0 triangles where a walk over level-0 positions ends;
 * on a crumpled surface walks stop in folds far from the probe's foot. A bound up to twice a
 * reference is accepted as it is, a larger one is measured exactly against the group's own surface.
 * With the largest bound so far as the reference, each loose bound accepted raised the reference
 * for the next, and the groups of this sheet stated up to 4.4x the larger of D1 and the distance
 * measured here (DamagedHelmet's first-step groups: 10-20x); with the largest distance checked (D1,
 * or a bound the exact measure settled) as the reference, at most 2x. The check: every group's
 * deviation (the larger of D1 and D2) and error are at least the exact distance at a barycentric grid
 * of 8 steps on each of its triangles (they stay bounds), and the deviation is at most 2.5x the
 * larger of that distance and D1 (the error also carries the errors of the groups its members came
 * from). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "gdr/geometry.h"
#include "gdr/scene.h"
#include "geometry/lod_grid.h"
#include "geometry/lod_internal.h"
#include "point_distance.h"
#include "test_util.h"

#define QUADS 120
#define MAX_RATIO 2.5

/* A unit square of QUADS x QUADS quads, jittered in the plane and folded by a wave whose crests
 * wander: folds a few quads apart, which a group's simplified triangles span. */
static void crumpled_sheet(gdr_vec3 *p, uint32_t *idx)
{
    for (uint32_t y = 0; y <= QUADS; y++)
        for (uint32_t x = 0; x <= QUADS; x++) {
            uint32_t i = y * (QUADS + 1) + x;
            float u = (float)x / QUADS, v = (float)y / QUADS;
            float du = 2.0f * test_hash_unit(2 * i) - 1.0f, dv = 2.0f * test_hash_unit(2 * i + 1) - 1.0f;
            p[i] = (gdr_vec3){u + 0.004f * du, v + 0.004f * dv, 0.05f * sinf(40.0f * u + 7.0f * sinf(9.0f * v))};
        }
    uint32_t k = 0;
    for (uint32_t y = 0; y < QUADS; y++)
        for (uint32_t x = 0; x < QUADS; x++) {
            uint32_t a = y * (QUADS + 1) + x, b = a + 1, c = a + QUADS + 1, d = c + 1;
            uint32_t t[6] = {a, b, d, a, d, c};
            for (int j = 0; j < 6; j++)
                idx[k++] = t[j];
        }
}

static float point_triangle_d2_float(gdr_vec3 p, gdr_vec3 a, gdr_vec3 b, gdr_vec3 c)
{
    double d = point_triangle(d3(p), d3(a), d3(b), d3(c));
    return (float)(d * d);
}

typedef struct bound_check {
    lod_triangle_grid full; /* level 0, every triangle of a cell looked at: exact */
    double worst_ratio;     /* the largest deviation / max(D1, measured distance) */
    uint32_t groups, under; /* groups checked; of them, stating less than the measured distance */
} bound_check;

/* The exact distance to level 0, largest over a barycentric grid of 8 steps on each triangle of the
 * clusters r made. */
static double measured_distance(const bound_check *k, const lod_build *b, const group_result *r)
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
                    lod_triangle_grid_nearest(&k->full, q, point_triangle_d2_float, &d2);
                    worst = fmax(worst, sqrt(d2));
                }
        }
    }
    return worst;
}

static void observe_step(void *user, const lod_build *b, const lod_step_view *v)
{
    bound_check *k = user;
    for (uint32_t g = 0; g < v->groups; g++) {
        const group_result *r = &v->results[g];
        if (!r->formed)
            continue;
        double measured = measured_distance(k, b, r), error = r->error, deviation = r->deviation;
        double ratio = deviation / fmax(fmax(measured, r->d1), 1e-9);
        k->groups++;
        k->under += error < measured * (1.0 - 1e-5) || deviation < measured * (1.0 - 1e-5);
        if (ratio > k->worst_ratio)
            k->worst_ratio = ratio;
        if (ratio > MAX_RATIO)
            printf("  depth %u group %u: deviation %.5f, D1 %.5f, measured %.5f (%.2fx)\n", v->depth, g,
                   deviation, (double)r->d1, measured, ratio);
    }
}

int main(void)
{
    static gdr_vec3 positions[(QUADS + 1) * (QUADS + 1)];
    static uint32_t indices[QUADS * QUADS * 6];
    crumpled_sheet(positions, indices);
    gdr_scene *s = NULL;
    gdr_error err = {0};
    uint32_t mesh = 0;
    if (gdr_scene_create(&s, &err) != GDR_OK ||
        gdr_scene_add_mesh(s, "crumpled", positions, NULL, NULL, (uint32_t)(sizeof positions / sizeof *positions),
                           indices, (uint32_t)(sizeof indices / sizeof *indices), &mesh, &err) != GDR_OK) {
        fprintf(stderr, "test_lod_probe_bound: %s\n", err.message);
        return 1;
    }
    gdr_mesh *m = &s->meshes[mesh];
    bound_check k = {.worst_ratio = 0};
    if (!lod_triangle_grid_build(&k.full, &m->positions[0].x, m->indices, m->index_count / 3)) {
        fprintf(stderr, "test_lod_probe_bound: out of memory\n");
        return 1;
    }
    k.full.cell_limit = UINT32_MAX;
    lod_observer obs = {observe_step, &k};
    gdr_lod_options o = {.thread_count = 1, .no_progress = 1};
    if (gdr_meshlets_build(m, NULL, &m->clusters, &err) != GDR_OK ||
        gdr_lod_build_observed(m, &o, &obs, NULL, &err) != GDR_OK) {
        fprintf(stderr, "test_lod_probe_bound: %s: %s\n", m->name, err.message);
        return 1;
    }
    printf("crumpled sheet of %u triangles: %u groups, deviation at most %.3fx the larger of D1 and the distance "
           "measured, %u below it\n",
           QUADS * QUADS * 2, k.groups, k.worst_ratio, k.under);
    CHECK_MSG(k.groups > 10, "only %u groups formed", k.groups);
    CHECK_MSG(k.under == 0, "%u groups state less than their measured distance to full detail", k.under);
    CHECK_MSG(k.worst_ratio <= MAX_RATIO, "a group states %.3fx the larger of D1 and its measured distance",
          k.worst_ratio);
    lod_triangle_grid_free(&k.full);
    gdr_scene_destroy(s);
    return test_finish("test_lod_probe_bound");
}
