/* The texture slide stays in a group's error (white-box, the build's observer): for every group of
 * every step of a UV-mapped mesh's DAG, the error the group states is at least the slide its
 * simplification charged (lod_simplify.c). The slide enters the group's measured distance to full
 * detail as D2 does; where the samples' distance is set by a few far samples, D2 is measured again
 * down to the floor (lod_error.c, group_floor), and that second measurement of the distance alone
 * used to replace the raised value: on DamagedHelmet 5 of 45 groups stated less than their slide
 * (0.13 for a slide of 0.38 of a model of radius 1.27), and so did groups of the charted torus here. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "gdr/geometry.h"
#include "gdr/scene.h"
#include "geometry/lod_internal.h"
#include "charted_torus.h"
#include "test_util.h"

typedef struct slide_check {
    uint32_t groups, with_slide, below;
    float worst; /* the smallest error / slide met */
} slide_check;

static void observe_step(void *user, const lod_build *b, const lod_step_view *v)
{
    slide_check *k = user;
    for (uint32_t g = 0; g < v->groups; g++) {
        const group_result *r = &v->results[g];
        if (!r->formed)
            continue;
        float error = b->groups[r->group].error;
        k->groups++;
        if (r->slide <= 0.0f)
            continue;
        k->with_slide++;
        float ratio = error / r->slide;
        k->worst = ratio < k->worst ? ratio : k->worst;
        if (error < r->slide) {
            if (k->below < 5)
                fprintf(stderr, "  depth %u group %u: error %g below its slide %g\n", v->depth, r->group,
                        (double)error, (double)r->slide);
            k->below++;
        }
    }
}

/* Builds the DAG of a charted torus of segments x sides quads; checks every group's error against its
 * slide. */
static void check_torus(uint32_t segments, uint32_t sides)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    charted_torus_check(gdr_scene_create(&s, &err), &err, "scene");
    uint32_t mi = add_charted_torus(s, segments, sides);
    gdr_mesh *m = &s->meshes[mi];
    slide_check k = {.worst = INFINITY};
    lod_observer obs = {observe_step, &k};
    gdr_lod_options o = {.thread_count = 2, .no_progress = 1};
    charted_torus_check(gdr_meshlets_build(m, NULL, &m->clusters, &err), &err, "meshlets");
    charted_torus_check(gdr_lod_build_observed(m, &o, &obs, NULL, &err), &err, "DAG");
    printf("test_lod_slide_error: torus %u x %u: %u groups, %u with a slide, %u stating less than it (smallest "
           "error / slide %.3f)\n",
           segments, sides, k.groups, k.with_slide, k.below, (double)k.worst);
    CHECK_MSG(k.with_slide > 0, "no group charged a slide: the test mesh does not test it");
    CHECK_MSG(k.below == 0, "%u groups state an error below their texture slide", k.below);
    gdr_scene_destroy(s);
}

int main(void)
{
    check_torus(96, 32);   /* before: a depth-3 group stated 0.155 for a slide of 0.462 */
    check_torus(300, 100); /* before: a depth-4 group stated 0.046 for 0.113 */
    return test_finish("test_lod_slide_error");
}
