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
#include "group_distance.h"
#include "test_util.h"

#define MAX_RATIO 2.5

typedef struct bound_check {
    lod_triangle_grid full; /* level 0, every triangle of a cell looked at: exact */
    double worst_ratio;     /* the largest deviation / max(D1, measured distance) */
    uint32_t groups, under; /* groups checked; of them, stating less than the measured distance */
} bound_check;

static void observe_step(void *user, const lod_build *b, const lod_step_view *v)
{
    bound_check *k = user;
    for (uint32_t g = 0; g < v->groups; g++) {
        const group_result *r = &v->results[g];
        if (!r->formed)
            continue;
        double measured = group_level0_distance(&k->full, b, r), error = r->error, deviation = r->deviation;
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
    static gdr_vec3 positions[CRUMPLED_VERTICES];
    static uint32_t indices[CRUMPLED_INDICES];
    crumpled_sheet(positions, NULL, indices);
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
           CRUMPLED_QUADS * CRUMPLED_QUADS * 2, k.groups, k.worst_ratio, k.under);
    CHECK_MSG(k.groups > 10, "only %u groups formed", k.groups);
    CHECK_MSG(k.under == 0, "%u groups state less than their measured distance to full detail", k.under);
    CHECK_MSG(k.worst_ratio <= MAX_RATIO, "a group states %.3fx the larger of D1 and its measured distance",
          k.worst_ratio);
    lod_triangle_grid_free(&k.full);
    gdr_scene_destroy(s);
    return test_finish("test_lod_probe_bound");
}
