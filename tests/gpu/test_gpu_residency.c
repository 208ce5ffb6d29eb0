/* The cut over resident groups on the GPU (docs/STREAMING.md, "Never a hole, never a crack"), on
 * the default device (lavapipe in CI), validation on: with the finer groups of every mesh marked
 * absent in the page table (down to all but the root and the group below it) (a residency closed upwards, as the streaming residency keeps it), the
 * clusters the traversal and the cluster tests draw are exactly the CPU reference
 * gdr_lod_cut_select_hierarchical_resident for several cameras and thresholds, through the LOD
 * hierarchy and the flat cluster test alike; they differ from the fully resident cut (the test
 * would see the page table ignored), and with every group resident again the image is the one
 * before. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/io.h"
#include "geometry/lod_cut.h"
#include "gpu_test_util.h"
#include "render/renderer_debug.h"

#define WIDTH 192
#define HEIGHT 128

/* Resident: every group of DAG depth >= min_depth (and the root). Parents are deeper than the groups
 * they are made from, so this is closed upwards; the test checks it on every cluster. */
static uint8_t *residency_from_depth(const gdr_mesh_clusters *c, uint32_t min_depth, uint32_t **absent)
{
    uint8_t *resident = malloc(c->group_count ? c->group_count : 1);
    *absent = malloc(sizeof **absent * (c->lod_node_count ? c->lod_node_count : 1));
    if (!resident || !*absent) {
        free(resident);
        free(*absent);
        *absent = NULL;
        return NULL;
    }
    for (uint32_t g = 0; g < c->group_count; g++)
        resident[g] = c->groups[g].depth >= min_depth || g + 1 == c->group_count;
    for (uint32_t k = 0; k < c->cluster_count; k++) {
        uint32_t group = c->clusters[k].group, refined = c->clusters[k].refined_group;
        if (group != GDR_NO_INDEX && refined != GDR_NO_INDEX)
            CHECK(!resident[refined] || resident[group]);
    }
    gdr_lod_nodes_count_absent_refined(c, resident, *absent);
    return resident;
}

static bool set_residency(gdr_renderer *r, const gdr_scene *scene, uint32_t min_depth, uint32_t *absent_groups)
{
    gdr_error err = {0};
    bool ok = true;
    for (uint32_t m = 0; m < scene->mesh_count && ok; m++) {
        const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
        uint32_t *absent = NULL;
        uint8_t *resident = residency_from_depth(c, min_depth, &absent);
        ok = resident && gdr_renderer_debug_set_residency(r, m, resident, absent, &err) == GDR_OK;
        for (uint32_t g = 0; resident && g < c->group_count; g++)
            *absent_groups += !resident[g];
        if (!ok)
            fprintf(stderr, "residency: %s\n", err.message);
        free(resident);
        free(absent);
    }
    return ok;
}

/* Within float rounding of the threshold: the GPU may decide either way. */
static bool near_threshold(const gdr_mesh_clusters *c, uint32_t group, const gdr_lod_view *view)
{
    if (group == GDR_NO_INDEX || isinf(c->groups[group].error))
        return false;
    const float *m = view->transform.m;
    float e = gdr_lod_group_projected_error(c->groups[group].sphere, c->groups[group].error,
                                            (gdr_vec3){m[0], m[1], m[2]}, (gdr_vec3){m[4], m[5], m[6]},
                                            (gdr_vec3){m[8], m[9], m[10]}, (gdr_vec3){m[12], m[13], m[14]},
                                            view->camera_position, view->znear, gdr_lod_projection_scale(view));
    return fabsf(e - view->threshold) <= 1e-4f * view->threshold;
}

/* Marks asked[group] = 1 for each request of instance `instance`, and checks each: its mesh, a
 * group of it that does not pass, the priority its projected error. */
static void check_requests(const gdr_mesh_clusters *c, const gdr_lod_view *view, uint32_t instance, uint32_t mesh,
                           const gdr_group_request *requests, uint32_t count, uint8_t *asked, uint32_t *wrong)
{
    for (uint32_t q = 0; q < count; q++) {
        const gdr_group_request *rq = &requests[q];
        if (rq->instance != instance)
            continue;
        bool ok = rq->mesh == mesh && rq->group < c->group_count && rq->priority > view->threshold;
        if (ok) {
            const float *m = view->transform.m;
            float e = gdr_lod_group_projected_error(c->groups[rq->group].sphere, c->groups[rq->group].error,
                                                    (gdr_vec3){m[0], m[1], m[2]}, (gdr_vec3){m[4], m[5], m[6]},
                                                    (gdr_vec3){m[8], m[9], m[10]}, (gdr_vec3){m[12], m[13], m[14]},
                                                    view->camera_position, view->znear, gdr_lod_projection_scale(view));
            ok = fabsf(e - rq->priority) <= 1e-3f * e;
            asked[rq->group] = 1;
        }
        if (!ok && ++*wrong <= 3)
            fprintf(stderr, "request %u: mesh %u group %u priority %g: not a valid request of instance %u\n", q,
                    rq->mesh, rq->group, (double)rq->priority, instance);
    }
}

/* The clusters the GPU drew for `frame` against the CPU's resident cut (min_depth's residency) of
 * every instance; counts clusters that differ beyond rounding in *wrong and those that differ from
 * the fully resident cut in *changed. */
static void compare_cut(gdr_renderer *r, const gdr_scene *scene, const gdr_frame_desc *frame, uint32_t min_depth,
                        uint32_t *wrong, uint32_t *changed, uint32_t *requested)
{
    gdr_error err = {0};
    gdr_frame_stats stats;
    uint64_t capacity = 1;
    for (uint32_t i = 0; i < scene->instance_count; i++)
        capacity += scene->meshes[scene->instances[i].mesh].clusters.cluster_count;
    gdr_visible_meshlet *drawn = malloc(sizeof *drawn * capacity);
    uint32_t count = 0;
    gdr_frame_desc f = *frame;
    f.record_visible_meshlets = true;
    bool ok = drawn && gdr_renderer_render(r, &f, 1, &stats, &err) == GDR_OK &&
              gdr_renderer_read_visible_meshlets(r, drawn, (uint32_t)capacity, &count, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "render: %s\n", err.message);
    CHECK(ok && stats.validation_messages == 0 && stats.task_overflow == 0 && stats.traversal.overflow == 0);
    if (!ok) {
        free(drawn);
        return;
    }
    qsort(drawn, count, sizeof *drawn, compare_visible_meshlets);
    gdr_group_request *requests = malloc(sizeof *requests * 4096);
    uint32_t request_count = 0, dropped = 0;
    CHECK(requests && gdr_renderer_read_group_requests(r, requests, 4096, &request_count, &dropped, &err) == GDR_OK &&
          dropped == 0);
    *requested += request_count;
    CHECK(stats.streaming.requests == request_count && stats.streaming.requests_dropped == dropped &&
          stats.streaming.absent_groups > 0);
    CHECK(stats.traversal.applied == (frame->lod_hierarchy != GDR_CULL_OFF));
    gdr_mat4 projection = gdr_perspective_reverse_z_infinite(frame->camera.yfov, (float)WIDTH / HEIGHT,
                                                             frame->camera.znear);
    uint32_t cursor = 0;
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        const gdr_mesh_clusters *c = &scene->meshes[scene->instances[i].mesh].clusters;
        gdr_lod_view view = {.transform = scene->instances[i].transform, .camera_position = frame->camera.position,
                             .projection_y = fabsf(projection.m[5]), .viewport_height = HEIGHT,
                             .znear = frame->camera.znear, .threshold = frame->lod_error_px};
        uint32_t *absent = NULL;
        uint8_t *resident = residency_from_depth(c, min_depth, &absent);
        uint8_t *selected = malloc(c->cluster_count ? c->cluster_count : 1);
        uint8_t *full = malloc(c->cluster_count ? c->cluster_count : 1);
        uint8_t *asked = calloc(c->group_count ? c->group_count : 1, 1);
        if (resident && selected && full && asked && requests) {
            check_requests(c, &view, i, scene->instances[i].mesh, requests, request_count, asked, wrong);
            gdr_lod_cut_select_hierarchical_resident(c, &view, resident, absent, selected, NULL);
            gdr_lod_cut_select(c, &view, full);
            for (uint32_t k = 0; k < c->cluster_count; k++) {
                bool gpu = cursor < count && drawn[cursor].instance == i && drawn[cursor].meshlet == k;
                cursor += gpu;
                *changed += selected[k] != full[k];
                bool unsure = near_threshold(c, c->clusters[k].group, &view) ||
                              near_threshold(c, c->clusters[k].refined_group, &view);
                if (gpu != (selected[k] != 0) && !unsure && ++*wrong <= 3)
                    fprintf(stderr, "instance %u cluster %u: GPU %s, CPU resident cut %s\n", i, k,
                            gpu ? "drawn" : "not drawn", selected[k] ? "drawn" : "not drawn");
                /* The CPU's request: drawn in the place of an absent refined group that does not pass. */
                uint32_t refined = c->clusters[k].refined_group;
                bool wanted = selected[k] && refined != GDR_NO_INDEX && !resident[refined] &&
                              !gdr_lod_group_passes(c, refined, &view);
                if (refined != GDR_NO_INDEX && wanted != (asked[refined] != 0) && !unsure && ++*wrong <= 3)
                    fprintf(stderr, "instance %u group %u: GPU %s, CPU %s\n", i, refined,
                            wanted ? "not requested" : "requested", wanted ? "requested" : "not requested");
                if (wanted)
                    asked[refined] = 2; /* a group the CPU wants */
            }
            for (uint32_t q = 0; q < c->group_count; q++)
                if (asked[q] == 1 && ++*wrong <= 3) /* requested, and no drawn cluster wants it */
                    fprintf(stderr, "instance %u group %u: requested, not wanted\n", i, q);
        } else {
            CHECK(false);
        }
        free(resident);
        free(absent);
        free(selected);
        free(full);
        free(asked);
    }
    free(requests);
    CHECK(cursor == count); /* nothing drawn outside the instances' clusters */
    free(drawn);
}

static bool render_image(gdr_renderer *r, const gdr_frame_desc *frame, uint8_t *image)
{
    gdr_error err = {0};
    gdr_frame_stats stats;
    gdr_frame_desc f = *frame;
    f.read_back = true;
    bool ok = gdr_renderer_render(r, &f, 1, &stats, &err) == GDR_OK && gdr_renderer_read_color(r, image, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "render: %s\n", err.message);
    return ok && stats.validation_messages == 0;
}

int main(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    CHECK(gdr_scene_load("lod-field:instances=24,triangles=30000,seed=3", NULL, &scene, &err) == GDR_OK);
    gdr_renderer *r = scene ? gpu_test_renderer(WIDTH, HEIGHT, scene) : NULL;
    uint8_t *before = malloc(WIDTH * HEIGHT * 4), *after = malloc(WIDTH * HEIGHT * 4);
    CHECK(r && before && after);
    if (r && before && after) {
        static const float thresholds[3] = {0.5f, 2.0f, 8.0f};
        gdr_frame_desc frame = {.camera = test_look((gdr_vec3){0, 3, 2}, 0, -0.3f, 1.0f, 0.1f),
                                .pipeline = GDR_PIPELINE_MESH, .cull = GDR_CULL_OFF, .occlusion = GDR_CULL_OFF,
                                .lod_error_px = 1.0f};
        CHECK(render_image(r, &frame, before));
        /* Groups below depth 2, then below depth 4, absent (dropping the node test's relaxation
         * shows only with the second), then all but the root and the lone cluster it was made from
         * (the root chain of the instance cull must leave the rest to the cluster test, which draws
         * in an absent group's place and asks for it). */
        const uint32_t min_depths[3] = {2, 4, scene ? scene->meshes[0].clusters.dag_depth - 1 : 0};
        for (int d = 0; d < 3; d++) {
            uint32_t min_depth = min_depths[d];
            uint32_t absent_groups = 0, wrong = 0, changed = 0, requested = 0;
            CHECK(set_residency(r, scene, min_depth, &absent_groups));
            for (int n = 0; n < 6; n++) {
                frame.lod_error_px = thresholds[n % 3];
                frame.lod_hierarchy = n < 3 ? GDR_CULL_DEFAULT : GDR_CULL_OFF;
                frame.camera = test_look((gdr_vec3){0.5f * (float)n - 1.0f, 2.0f + 0.5f * (float)n, 2.0f - (float)n},
                                         0.1f, -0.3f, 1.0f, 0.1f);
                compare_cut(r, scene, &frame, min_depth, &wrong, &changed, &requested);
            }
            printf("depth < %u absent (%u groups): %u clusters or requests differ from the CPU resident cut, %u cut "
                   "choices changed by residency, %u requests\n", min_depth, absent_groups, wrong, changed, requested);
            CHECK(absent_groups > 0 && wrong == 0 && changed > 0 && requested > 0);
        }
        /* Every group resident again: the image of before. */
        uint32_t none = 0;
        CHECK(set_residency(r, scene, 0, &none) && none == 0);
        frame.camera = test_look((gdr_vec3){0, 3, 2}, 0, -0.3f, 1.0f, 0.1f);
        frame.lod_error_px = 1.0f;
        frame.lod_hierarchy = GDR_CULL_DEFAULT;
        CHECK(render_image(r, &frame, after) && memcmp(before, after, WIDTH * HEIGHT * 4) == 0);
        gdr_group_request request;
        uint32_t requests = 1, dropped = 1;
        CHECK(gdr_renderer_read_group_requests(r, &request, 1, &requests, &dropped, &err) == GDR_OK && requests == 0 &&
              dropped == 0);
    }
    free(before);
    free(after);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_residency");
}
