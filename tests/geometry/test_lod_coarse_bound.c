/* The coarse end of a UV-mapped mesh states its distance to full detail tightly where that distance
 * decides its error, white-box (the build's observer, geometry/lod_internal.h).
 *
 * A probe's walk bound up to twice the largest distance checked (D1 at first) is taken as it is
 * (lod_error.c, probe_d2): cheap, and loose by up to 2x. At the coarse end of a textured model that
 * 2x decides the cut: DamagedHelmet's group that a 16 x 9 pixel view must take stated 0.43 units of
 * D2, twice its D1, where a pixel allows 0.38. Where D2's bound is above everything else the group's
 * error holds (D1, the texture slide, the members' errors) and the group holds at least a quarter of
 * the mesh's samples, D2 is measured again with every bound that would raise it past the largest
 * checked measured exactly over the level-0 triangles around the simplified corners (tight_d2).
 *
 * The check, on a charted torus (every chart border a uv seam, so the coarse groups cross charts
 * and state slides) and on a crumpled sheet mapped by its plane (test_lod_probe_bound's, where walks
 * stop in folds; its slides are small, so D2 decides): every group holding at least a third of the
 * samples and stating at least a quarter of the mesh's radius states a deviation no
 * larger than the largest of D1, its slide, its members' errors and 1.6 times the exact distance from
 * its simplified triangles to level 0 at a barycentric grid of 8 steps (1.45x: the corners' triangles
 * are not all of level 0, and the probes' points are not the grid's); and every
 * group's deviation and error are at least that distance (they stay bounds). Before, the sheet's
 * coarse groups stated up to 1.9x. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "gdr/geometry.h"
#include "gdr/scene.h"
#include "charted_torus.h"
#include "group_distance.h"
#include "test_util.h"

#define MAX_RATIO 1.6
/* The groups checked: those holding at least a third of the samples and stating at least this share
 * of the mesh's radius (lod_error.c measures D2 where its bound decides such a group's error: a
 * quarter of the samples, a quarter of the radius). */
#define COARSE_SHARE 0.25

typedef struct coarse_check {
    lod_triangle_grid full; /* level 0, every triangle of a cell looked at: exact */
    double worst_ratio;     /* the largest deviation / max(other parts, measured distance) of a coarse group */
    uint32_t coarse, under; /* groups holding a third of the samples; groups stating less than the measured distance */
    uint32_t checked;       /* coarse groups stating at least COARSE_SHARE of the radius: their ratio checked */
    uint32_t decided;       /* checked groups whose measured distance is above their other parts */
} coarse_check;

/* The largest error of the groups g's members came from (0 for level-0 members). */
static double members_error(const lod_build *b, const lod_step_view *v, uint32_t g)
{
    double e = 0;
    for (uint32_t i = v->member_start[g]; i < v->member_start[g + 1]; i++) {
        uint32_t from = b->clusters[v->members[i]].refined_group;
        if (from != GDR_NO_INDEX)
            e = fmax(e, b->groups[from].error);
    }
    return e;
}

static void observe_step(void *user, const lod_build *b, const lod_step_view *v)
{
    coarse_check *k = user;
    for (uint32_t g = 0; g < v->groups; g++) {
        const group_result *r = &v->results[g];
        if (!r->formed)
            continue;
        double measured = group_level0_distance(&k->full, b, r), deviation = r->deviation;
        k->under += b->groups[r->group].error < measured * (1.0 - 1e-5) || deviation < measured * (1.0 - 1e-5);
        uint32_t samples = r->cluster_sample_first[r->cluster_count];
        if ((size_t)samples * 3 < b->position_count)
            continue;
        k->coarse++;
        if (deviation < COARSE_SHARE * b->mesh->bounds.w)
            continue;
        k->checked++;
        double others = fmax(fmax((double)r->d1, (double)r->slide), members_error(b, v, g));
        double ratio = deviation / fmax(fmax(others, measured), 1e-9);
        k->decided += measured > others;
        if (ratio > k->worst_ratio)
            k->worst_ratio = ratio;
        printf("  depth %u group %u (%u of %u samples): deviation %.5f, D1 %.5f, slide %.5f, members %.5f, "
               "measured %.5f (%.3fx)\n",
               v->depth, g, samples, b->position_count, deviation, (double)r->d1, (double)r->slide,
               members_error(b, v, g), measured, ratio);
    }
}

/* The crumpled sheet mapped by its plane (one chart: its slides are small). */
static uint32_t add_crumpled_sheet(gdr_scene *s)
{
    static gdr_vec3 p[CRUMPLED_VERTICES];
    static gdr_vec2 uv[CRUMPLED_VERTICES];
    static uint32_t idx[CRUMPLED_INDICES];
    crumpled_sheet(p, uv, idx);
    uint32_t mesh = 0;
    gdr_error err = {0};
    charted_torus_check(gdr_scene_add_mesh(s, "crumpled", p, NULL, uv, (uint32_t)(sizeof p / sizeof *p), idx,
                                           (uint32_t)(sizeof idx / sizeof *idx), &mesh, &err),
                        &err, "crumpled sheet");
    return mesh;
}

/* Builds the DAG of mesh `which` (0: a charted torus of segments x sides quads, 1: the crumpled
 * sheet) and checks its groups. */
static void check_mesh(int which, uint32_t segments, uint32_t sides)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    charted_torus_check(gdr_scene_create(&s, &err), &err, "scene");
    uint32_t mi = which == 0 ? add_charted_torus(s, segments, sides) : add_crumpled_sheet(s);
    gdr_mesh *m = &s->meshes[mi];
    coarse_check k = {.worst_ratio = 0};
    CHECK_MSG(lod_triangle_grid_build(&k.full, &m->positions[0].x, m->indices, m->index_count / 3),
              "out of memory");
    k.full.cell_limit = UINT32_MAX;
    lod_observer obs = {observe_step, &k};
    gdr_lod_options o = {.thread_count = 2, .no_progress = 1};
    charted_torus_check(gdr_meshlets_build(m, NULL, &m->clusters, &err), &err, "meshlets");
    charted_torus_check(gdr_lod_build_observed(m, &o, &obs, NULL, &err), &err, "DAG");
    printf("test_lod_coarse_bound: %s %u x %u: %u coarse groups, %u checked (%u where the distance is above the rest), "
           "deviation at most %.3fx the larger of the rest and the distance measured; %u groups below it\n",
           which == 0 ? "charted torus" : "crumpled sheet", segments, sides, k.coarse, k.checked, k.decided, k.worst_ratio, k.under);
    CHECK_MSG(k.coarse >= 3 && k.checked >= 1, "only %u coarse groups, %u checked: the mesh does not test the coarse end",
              k.coarse, k.checked);
    CHECK_MSG(k.under == 0, "%u groups state less than their measured distance", k.under);
    CHECK_MSG(k.worst_ratio <= MAX_RATIO, "a coarse group states %.3fx the larger of its other parts and its "
              "measured distance (at most %.2f)", k.worst_ratio, MAX_RATIO);
    lod_triangle_grid_free(&k.full);
    gdr_scene_destroy(s);
}

int main(void)
{
    check_mesh(0, 96, 32);
    check_mesh(1, CRUMPLED_QUADS, CRUMPLED_QUADS);
    return test_finish("test_lod_coarse_bound");
}
