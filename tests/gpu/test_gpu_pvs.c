/* Precomputed visibility in the frame, on every pipeline (lavapipe, validation on), on the rooms
 * scene with a PVS baked here over the eye-height layer of cells:
 * - from sample points of baked cells (where the bake's guarantee holds) in four directions, the
 *   image with the PVS is byte for byte the image without it;
 * - the instances drawn with it are exactly those drawn without it that the cell lists, and the
 *   statistics count the others;
 * - from the scene's first camera the PVS removes props of the room behind the north wall that the
 *   frustum keeps;
 * - an instance moved after the bake is never culled by it;
 * - the switch (frame pvs off, culling off, pvs on without a PVS) and set_pvs's checks. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/cull.h"
#include "gdr/io.h"
#include "gpu_test_util.h"

#define WIDTH 160
#define HEIGHT 96
#define OBJECTS 8 /* props per room */

typedef struct pvs_case {
    gdr_renderer *r;
    const gdr_scene *scene;
    gdr_pvs *pvs;
    gdr_pvs_cache *lookup; /* the test's own */
    uint8_t *image_on, *image_off, *drawn_on, *drawn_off;
    uint8_t *moved; /* per instance: moved with gdr_renderer_update_instance */
} pvs_case;

static bool render(pvs_case *c, const gdr_frame_desc *frame, uint8_t *image, uint8_t *drawn, gdr_frame_stats *stats)
{
    gdr_error err = {0};
    uint32_t n = c->scene->instance_count, count = 0;
    uint32_t *list = malloc(sizeof *list * n);
    bool ok = list && gdr_renderer_render(c->r, frame, 1, stats, &err) == GDR_OK &&
              gdr_renderer_read_color(c->r, image, &err) == GDR_OK &&
              gdr_renderer_read_visible(c->r, list, n, &count, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "render: %s\n", err.message);
    memset(drawn, 0, n);
    for (uint32_t i = 0; ok && i < count; i++)
        drawn[list[i]] = 1;
    free(list);
    return ok && stats->validation_messages == 0;
}

/* One view with the PVS on and off: the same image; drawn with it = drawn without it and listed by
 * the camera's cell (or moved); the count of the others in the statistics. Returns that count. */
static uint32_t check_view(pvs_case *c, gdr_pipeline pipeline, gdr_camera camera, const uint8_t *moved)
{
    gdr_frame_desc frame = {.camera = camera, .read_back = true, .pipeline = pipeline, .lod_error_px = 1.0f,
                            .occlusion = GDR_CULL_OFF, .pvs = GDR_CULL_OFF};
    gdr_frame_stats off, on;
    CHECK(render(c, &frame, c->image_off, c->drawn_off, &off));
    frame.pvs = GDR_CULL_DEFAULT; /* on: the renderer holds a PVS */
    CHECK(render(c, &frame, c->image_on, c->drawn_on, &on));
    const uint32_t *cell = gdr_pvs_lookup(c->lookup, camera.position);
    CHECK(cell != NULL);
    if (!cell)
        return 0;
    CHECK(memcmp(c->image_on, c->image_off, WIDTH * HEIGHT * 4) == 0);
    uint32_t removed = 0, wrong = 0;
    for (uint32_t i = 0; i < c->scene->instance_count; i++) {
        bool listed = gdr_cull_bit(cell, i) || (moved && moved[i]);
        removed += c->drawn_off[i] && !listed;
        wrong += c->drawn_on[i] != (c->drawn_off[i] && listed);
    }
    CHECK(wrong == 0);
    CHECK(!off.pvs.enabled && off.pvs.instances_culled == 0 && off.pvs.cells == gdr_pvs_cell_count(c->pvs));
    CHECK(on.pvs.enabled && on.pvs.cell_found && on.pvs.instances_culled == removed);
    CHECK(on.instances_visible + removed == off.instances_visible);
    return removed;
}

/* Sample points of baked cells with nothing nearer than the near plane can reach (the bake proves
 * what rays from the point hit; a wall cut by the near plane would let the camera see past it). */
static uint32_t pick_points(const pvs_case *c, const gdr_bvh *bvh, gdr_vec3 *points, uint32_t capacity)
{
    uint32_t count = 0, cells = gdr_pvs_cell_count(c->pvs);
    for (uint32_t cell = 0; cell < cells && count < capacity; cell += 11) {
        uint32_t n = 0;
        const gdr_vec3 *samples = gdr_pvs_samples(c->pvs, cell, &n);
        if (n > 0 && !gdr_bvh_overlaps_box(bvh, samples[0], (gdr_vec3){0.3f, 0.3f, 0.3f}))
            points[count++] = samples[0];
    }
    return count;
}

static void check_sample_points(pvs_case *c, gdr_pipeline pipeline, const gdr_vec3 *points, uint32_t count)
{
    uint32_t removed = 0;
    for (uint32_t p = 0; p < count; p++)
        for (int d = 0; d < 4; d++)
            removed += check_view(c, pipeline, test_look(points[p], (float)d * 1.5707963f, -0.1f, 1.0f, 0.1f), NULL);
    printf("%s: %u views from sample points, the same image with and without the PVS; %u instances removed by it\n",
           gdr_pipeline_name(pipeline), 4 * count, removed);
    CHECK(removed > 4 * count); /* more than one per view on average */
}

/* The rooms scene's instance order: the ground, walls, corridor walls, then OBJECTS props per room. */
static uint32_t first_prop_of_room(const gdr_scene *scene, uint32_t room)
{
    return scene->instance_count - 4 * OBJECTS + room * OBJECTS;
}

/* From the first camera (room 0, looking north), props of room 2 (behind room 0's north wall) in the
 * frustum are culled by the PVS alone (the ones not moved). With `move`, one of them is then moved
 * into view and drawn, and moved back behind the wall, where the PVS still never culls it. */
static void check_behind_wall(pvs_case *c, gdr_pipeline pipeline, bool move)
{
    gdr_camera camera = c->scene->cameras[0];
    uint32_t first = first_prop_of_room(c->scene, 2), behind = 0, culled = 0, chosen = UINT32_MAX;
    check_view(c, pipeline, camera, c->moved);
    for (uint32_t i = first; i < first + OBJECTS; i++) {
        bool kept = c->drawn_off[i] && !c->moved[i];
        behind += kept;
        culled += kept && !c->drawn_on[i];
        if (kept && !c->drawn_on[i])
            chosen = i;
    }
    printf("%s: room 2's props: %u of %u in the frustum behind the wall (not moved), %u of them culled by the PVS\n",
           gdr_pipeline_name(pipeline), behind, OBJECTS, culled);
    CHECK(culled > 0); /* the others are seen through a doorway */
    for (uint32_t i = first; i < first + OBJECTS; i++)
        if (c->moved[i]) /* in the frustum behind the wall: only the PVS could cull it, and does not */
            CHECK(c->drawn_on[i]);
    if (!move || chosen == UINT32_MAX)
        return;
    /* Moved into room 0, in front of the camera: the PVS does not know it there. */
    gdr_error err = {0};
    gdr_mat4 transform = c->scene->instances[chosen].transform;
    transform.m[12] = camera.position.x;
    transform.m[14] = camera.position.z - 2.5f;
    CHECK(gdr_renderer_update_instance(c->r, chosen, &transform, NULL, &err) == GDR_OK);
    c->moved[chosen] = 1;
    check_view(c, pipeline, camera, c->moved);
    CHECK(c->drawn_on[chosen] && c->drawn_off[chosen]);
    /* Back where it was baked, behind the wall. */
    CHECK(gdr_renderer_update_instance(c->r, chosen, &c->scene->instances[chosen].transform, NULL, &err) == GDR_OK);
    check_view(c, pipeline, camera, c->moved);
    CHECK(c->drawn_on[chosen]);
}

/* The switch: off, culling off, and on without a PVS; set_pvs's checks. */
static void check_switch(pvs_case *c, const gdr_pvs *other)
{
    gdr_error err = {0};
    gdr_frame_desc frame = {.camera = c->scene->cameras[0], .pipeline = GDR_PIPELINE_INDIRECT, .cull = GDR_CULL_OFF};
    gdr_frame_stats stats;
    CHECK(gdr_renderer_render(c->r, &frame, 1, &stats, &err) == GDR_OK && !stats.pvs.enabled &&
          stats.pvs.instances_culled == 0);
    frame.cull = GDR_CULL_ON;
    frame.pvs = (gdr_cull_mode)7;
    CHECK(gdr_renderer_render(c->r, &frame, 1, &stats, &err) == GDR_ERROR_INVALID_ARGUMENT);
    CHECK(gdr_renderer_set_pvs(c->r, other, &err) == GDR_ERROR_INVALID_ARGUMENT);
    printf("set_pvs of another scene's PVS: %s\n", err.message);
    frame.pvs = GDR_CULL_ON; /* the renderer kept its PVS */
    CHECK(gdr_renderer_render(c->r, &frame, 1, &stats, &err) == GDR_OK && stats.pvs.enabled &&
          stats.pvs.instances_culled > 0);
    CHECK(gdr_renderer_set_pvs(c->r, NULL, &err) == GDR_OK);
    CHECK(gdr_renderer_render(c->r, &frame, 1, &stats, &err) == GDR_ERROR_INVALID_ARGUMENT);
    frame.pvs = GDR_CULL_DEFAULT;
    CHECK(gdr_renderer_render(c->r, &frame, 1, &stats, &err) == GDR_OK && !stats.pvs.enabled &&
          stats.pvs.cells == 0);
}

static gdr_pvs *bake(const gdr_scene *scene, gdr_vec3 lo, gdr_vec3 hi, float cell, bool keep_samples)
{
    gdr_error err = {0};
    gdr_pvs *pvs = NULL;
    gdr_pvs_bake_report report;
    gdr_pvs_bake_desc desc = {.scene = scene, .region_min = lo, .region_max = hi, .cell_size = cell,
                              .samples_per_cell = 2, .keep_samples = keep_samples};
    CHECK(gdr_pvs_bake(&desc, &pvs, &report, &err) == GDR_OK);
    if (pvs)
        printf("pvs: %u cells baked of %u, %llu visible pairs of %llu\n", report.cells_baked, report.cells_total,
               (unsigned long long)report.visible_pairs, (unsigned long long)report.cells_baked * scene->instance_count);
    return pvs;
}

int main(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL, *other_scene = NULL;
    CHECK(gdr_scene_load("rooms:rooms=4,objects=8", NULL, &scene, &err) == GDR_OK);
    CHECK(gdr_scene_load("rooms:rooms=1,objects=1", NULL, &other_scene, &err) == GDR_OK);
    if (!scene || !other_scene)
        return test_finish("test_gpu_pvs");
    /* The eye-height layer of 1 m cells over the 2 x 2 rooms (12.6 m apart, 4.3 m to their outsides). */
    pvs_case c = {.scene = scene};
    c.pvs = bake(scene, (gdr_vec3){-4.5f, 1.0f, -17.0f}, (gdr_vec3){17.0f, 2.0f, 4.5f}, 1.0f, true);
    gdr_pvs *other = bake(other_scene, (gdr_vec3){-4.5f, 1.0f, -4.5f}, (gdr_vec3){4.5f, 2.0f, 4.5f}, 3.0f, false);
    c.r = gpu_test_renderer(WIDTH, HEIGHT, scene);
    gdr_bvh *bvh = NULL;
    CHECK(gdr_bvh_create_from_scene(scene, &bvh, &err) == GDR_OK);
    CHECK(c.r && c.pvs && other && bvh);
    if (c.r && c.pvs && other && bvh && gdr_pvs_cache_create(c.pvs, &c.lookup, &err) == GDR_OK &&
        gdr_renderer_set_pvs(c.r, c.pvs, &err) == GDR_OK) {
        size_t bytes = WIDTH * HEIGHT * 4;
        c.image_on = malloc(bytes);
        c.image_off = malloc(bytes);
        c.drawn_on = malloc(scene->instance_count);
        c.drawn_off = malloc(scene->instance_count);
        c.moved = calloc(scene->instance_count, 1);
        gdr_vec3 points[12];
        uint32_t count = pick_points(&c, bvh, points, 12);
        CHECK(count >= 6);
        const char *why = NULL;
        gdr_pipeline pipelines[3] = {GDR_PIPELINE_INDIRECT, GDR_PIPELINE_CPU, GDR_PIPELINE_MESH};
        int pipeline_count = gdr_renderer_has_mesh_pipeline(c.r, &why) ? 3 : 2;
        if (pipeline_count == 2)
            printf("mesh pipeline skipped: %s\n", why);
        for (int p = 0; p < pipeline_count; p++)
            check_sample_points(&c, pipelines[p], points, count);
        check_switch(&c, other);
        CHECK(gdr_renderer_set_pvs(c.r, c.pvs, &err) == GDR_OK);
        for (int p = 0; p < pipeline_count; p++)
            check_behind_wall(&c, pipelines[p], true);
        for (int p = 0; p < pipeline_count; p++) /* every pipeline with every instance moved so far */
            check_behind_wall(&c, pipelines[p], false);
        free(c.image_on);
        free(c.image_off);
        free(c.drawn_on);
        free(c.drawn_off);
        free(c.moved);
    }
    gdr_renderer_destroy(c.r);
    gdr_pvs_cache_destroy(c.lookup);
    gdr_bvh_destroy(bvh);
    gdr_pvs_destroy(c.pvs);
    gdr_pvs_destroy(other);
    gdr_scene_destroy(scene);
    gdr_scene_destroy(other_scene);
    return test_finish("test_gpu_pvs");
}
