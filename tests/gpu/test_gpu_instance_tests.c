/* Seed 002's GPU instance tests besides the frustum: invalid or empty bounds, screen-size culling
 * (each instance's range and the frame's minimum) and the global clip plane, in the indirect and
 * mesh pipelines (lavapipe, validation on). The instances drawn are those a CPU reference of the
 * same definitions finds (cases within rounding of a limit are skipped), every culled instance is
 * counted by the test that culled it, and where the tests cull nothing the image is the one without
 * them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gpu_test_util.h"

#define WIDTH 160
#define HEIGHT 96
#define ROWS 12
#define COLUMNS 10

typedef struct expectation {
    uint8_t *visible; /* per instance: 1 drawn, 0 culled, 2 too close to a limit to call */
    uint32_t invalid, screen_size, clip_plane;
} expectation;

static uint32_t add_box(gdr_scene *scene)
{
    gdr_error err = {0};
    gdr_vec3 corners[8];
    for (uint32_t v = 0; v < 8; v++)
        corners[v] = (gdr_vec3){v & 1 ? 0.5f : -0.5f, v & 2 ? 0.5f : -0.5f, v & 4 ? 0.5f : -0.5f};
    const uint32_t faces[36] = {4, 5, 7, 4, 7, 6, 0, 2, 3, 0, 3, 1, 1, 3, 7, 1, 7, 5,
                                0, 4, 6, 0, 6, 2, 2, 6, 7, 2, 7, 3, 0, 1, 5, 0, 5, 4};
    uint32_t mesh = 0;
    CHECK(gdr_scene_add_mesh(scene, "box", corners, NULL, NULL, 8, faces, 36, &mesh, &err) == GDR_OK);
    return mesh;
}

/* Boxes in rows going away from the camera at the origin (looking down -Z), of random sizes, some
 * with a screen-size range of their own; one of zero scale (empty bounds). */
static gdr_scene *make_scene(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    CHECK(gdr_scene_create(&scene, &err) == GDR_OK);
    if (!scene)
        return NULL;
    uint32_t box = add_box(scene);
    unsigned rng = 7;
    for (uint32_t row = 0; row < ROWS; row++) {
        for (uint32_t column = 0; column < COLUMNS; column++) {
            float scale = test_random_range(&rng, 0.2f, 1.5f);
            gdr_vec3 at = {((float)column - 4.5f) * 1.6f, test_random_range(&rng, -1.5f, 1.5f), -3.0f - 2.5f * (float)row};
            gdr_instance instance = {.transform = gdr_mat4_from_trs(at, gdr_quat_identity(), (gdr_vec3){scale, scale, scale}),
                                     .mesh = box, .material = GDR_NO_INDEX, .color = {0.8f, 0.6f, 0.3f, 1.0f}};
            unsigned kind = (row * COLUMNS + column) % 5;
            if (kind == 1)
                instance.min_screen_size = 0.12f;
            else if (kind == 2)
                instance.max_screen_size = 0.2f;
            else if (kind == 3)
                instance.transform = gdr_mat4_from_trs(at, gdr_quat_identity(), (gdr_vec3){0.0f, 0.0f, 0.0f});
            CHECK(gdr_scene_add_instance(scene, &instance, &err) == GDR_OK);
        }
    }
    /* The renderer never builds clusters: a scene comes with them. */
    CHECK(gdr_scene_build_clusters(scene, NULL, &err) == GDR_OK);
    return scene;
}

/* The CPU reference of the tests, in the GPU's order (invalid, frustum, screen size, clip plane),
 * with the bounding sphere of drawcull.comp. */
static expectation expect(const gdr_scene *scene, const gdr_frame_desc *frame)
{
    expectation e = {.visible = calloc(scene->instance_count, 1)};
    gdr_mat4 projection = gdr_perspective_reverse_z_infinite(frame->camera.yfov, (float)WIDTH / HEIGHT, frame->camera.znear);
    float screen_scale = fmaxf(fabsf(projection.m[0]), fabsf(projection.m[5]));
    for (uint32_t i = 0; e.visible && i < scene->instance_count; i++) {
        const gdr_instance *inst = &scene->instances[i];
        gdr_vec4 b = scene->meshes[inst->mesh].bounds;
        gdr_vec3 center = gdr_mat4_transform_point(inst->transform, (gdr_vec3){b.x, b.y, b.z});
        float radius = b.w * gdr_mat4_max_axis_scale(inst->transform);
        if (!(radius > 0.0f)) {
            e.invalid++;
            continue;
        }
        int frustum = cpu_instance_visibility(scene, i, &frame->camera, (float)WIDTH / HEIGHT);
        if (frustum <= 0) {
            e.visible[i] = frustum == 0 ? 2 : 0;
            continue;
        }
        float distance = gdr_vec3_length(gdr_vec3_sub(center, frame->camera.position));
        float size = screen_scale * radius / distance;
        float limits[3] = {inst->min_screen_size, frame->min_screen_size, inst->max_screen_size};
        bool near_limit = false;
        for (int l = 0; l < 3; l++)
            near_limit |= limits[l] > 0.0f && fabsf(size - limits[l]) < 1e-3f * limits[l];
        bool sized = !(inst->min_screen_size > 0.0f && size < inst->min_screen_size) &&
                     !(frame->min_screen_size > 0.0f && size < frame->min_screen_size) &&
                     !(inst->max_screen_size > 0.0f && size >= inst->max_screen_size);
        gdr_vec4 p = frame->clip_plane;
        float side = p.x * center.x + p.y * center.y + p.z * center.z + p.w;
        float reach = radius * sqrtf(p.x * p.x + p.y * p.y + p.z * p.z);
        bool has_plane = p.x != 0.0f || p.y != 0.0f || p.z != 0.0f;
        near_limit |= has_plane && fabsf(side + reach) < 1e-3f * (1.0f + reach);
        bool clipped = has_plane && side < -reach;
        e.screen_size += !sized;
        e.clip_plane += sized && clipped;
        e.visible[i] = near_limit ? 2 : (sized && !clipped);
    }
    return e;
}

static bool render(gdr_renderer *r, const gdr_frame_desc *frame, uint8_t *image, uint8_t *drawn, gdr_frame_stats *stats,
                   uint32_t instance_count)
{
    gdr_error err = {0};
    uint32_t *list = malloc(sizeof *list * instance_count), count = 0;
    bool ok = list && gdr_renderer_render(r, frame, 1, stats, &err) == GDR_OK &&
              gdr_renderer_read_color(r, image, &err) == GDR_OK &&
              gdr_renderer_read_visible(r, list, instance_count, &count, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "render: %s\n", err.message);
    memset(drawn, 0, instance_count);
    for (uint32_t i = 0; ok && i < count; i++)
        drawn[list[i]] = 1;
    free(list);
    return ok && stats->validation_messages == 0;
}

static void check_pipeline(gdr_renderer *r, const gdr_scene *scene, gdr_pipeline pipeline)
{
    uint32_t n = scene->instance_count;
    uint8_t *with = malloc(WIDTH * HEIGHT * 4), *without = malloc(WIDTH * HEIGHT * 4), *drawn = malloc(n);
    gdr_frame_desc frame = {.camera = test_look((gdr_vec3){0, 0, 0}, 0.0f, 0.0f, 1.0f, 0.1f), .read_back = true,
                            .pipeline = pipeline, .lod_error_px = 1.0f, .occlusion = GDR_CULL_OFF};
    gdr_frame_stats stats;
    /* Nothing culled by the new tests: a tiny minimum and a plane behind everything change nothing. */
    CHECK(render(r, &frame, without, drawn, &stats, n));
    frame.min_screen_size = 1e-6f;
    frame.clip_plane = (gdr_vec4){0.0f, 0.0f, -1.0f, 100.0f}; /* drawn where z < 100 */
    CHECK(render(r, &frame, with, drawn, &stats, n));
    expectation e = expect(scene, &frame);
    CHECK(memcmp(with, without, WIDTH * HEIGHT * 4) == 0);
    CHECK(stats.instances_invalid == e.invalid && e.invalid == n / 5);
    /* The tests culling: the frame's minimum, each instance's range, a plane through the field. */
    frame.min_screen_size = 0.05f;
    frame.clip_plane = (gdr_vec4){0.3f, 0.0f, 1.0f, 16.0f}; /* drawn where z > -16 - 0.3 x */
    CHECK(render(r, &frame, with, drawn, &stats, n));
    free(e.visible);
    e = expect(scene, &frame);
    uint32_t wrong = 0, called = 0;
    for (uint32_t i = 0; e.visible && i < n; i++) {
        called += e.visible[i] != 2;
        wrong += e.visible[i] != 2 && e.visible[i] != drawn[i];
    }
    printf("%s: %u of %u instances as the CPU reference says (%u too close to call); culled: %u invalid, %u by "
           "screen size, %u by the clip plane\n", gdr_pipeline_name(pipeline), called - wrong, called, n - called,
           stats.instances_invalid, stats.instances_screen_size_culled, stats.instances_clip_plane_culled);
    CHECK(wrong == 0 && called > n * 3 / 4);
    CHECK(stats.instances_invalid == e.invalid && stats.instances_screen_size_culled == e.screen_size &&
          stats.instances_clip_plane_culled == e.clip_plane);
    CHECK(e.screen_size > 10 && e.clip_plane > 5);
    CHECK(memcmp(with, without, WIDTH * HEIGHT * 4) != 0);
    free(e.visible);
    free(with);
    free(without);
    free(drawn);
}

int main(void)
{
    gdr_scene *scene = make_scene();
    CHECK(scene && gdr_scene_build_clusters(scene, NULL, &(gdr_error){0}) == GDR_OK); /* the renderer never builds them */
    gdr_renderer *r = scene ? gpu_test_renderer(WIDTH, HEIGHT, scene) : NULL;
    CHECK(r != NULL);
    if (r) {
        check_pipeline(r, scene, GDR_PIPELINE_INDIRECT);
        check_pipeline(r, scene, GDR_PIPELINE_MESH);
        /* Bad frame values are refused, naming the field. */
        gdr_error err = {0};
        gdr_frame_desc bad = {.camera = test_look((gdr_vec3){0, 0, 0}, 0, 0, 1, 0.1f), .min_screen_size = NAN};
        CHECK_FAILS(gdr_renderer_render(r, &bad, 1, NULL, &err), err, GDR_ERROR_INVALID_ARGUMENT);
        CHECK_NAMES(err, "min_screen_size");
        bad = (gdr_frame_desc){.camera = bad.camera, .clip_plane = {0, INFINITY, 0, 0}};
        CHECK_FAILS(gdr_renderer_render(r, &bad, 1, NULL, &err), err, GDR_ERROR_INVALID_ARGUMENT);
        CHECK_NAMES(err, "clip_plane");
    }
    /* Bad instance values are refused. */
    gdr_error err = {0};
    gdr_instance bad = {.transform = gdr_mat4_identity(), .mesh = 0, .material = GDR_NO_INDEX, .min_screen_size = -1.0f};
    CHECK(scene != NULL);
    if (scene)
        CHECK_FAILS(gdr_scene_add_instance(scene, &bad, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_instance_tests");
}
