/* Culling from another camera (gdr_frame_desc.cull_camera, the viewer's "freeze culling"): every
 * pipeline draws exactly the instances the culling camera sees, whatever camera draws the image;
 * a culling camera equal to the camera changes nothing; a different projection is refused. */
#include <stdlib.h>
#include <string.h>

#include "gdr/gdr.h"
#include "test_util.h"

#define WIDTH 96
#define HEIGHT 64

static int compare_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* The sorted visible instances of one frame; returns their count. */
static uint32_t visible_set(gdr_renderer *r, const gdr_frame_desc *frame, uint32_t *out, uint32_t capacity)
{
    gdr_error err = {0};
    uint32_t count = 0;
    if (gdr_renderer_render(r, frame, 1, NULL, &err) != GDR_OK ||
        gdr_renderer_read_visible(r, out, capacity, &count, &err) != GDR_OK) {
        fprintf(stderr, "render: %s\n", err.message);
        test_failure_count++;
        return 0;
    }
    qsort(out, count, sizeof *out, compare_u32);
    return count;
}

static void check_pipeline(gdr_renderer *r, const gdr_scene *scene, gdr_pipeline pipeline, uint32_t *a, uint32_t *b)
{
    uint32_t n = scene->instance_count;
    gdr_camera seen = scene->cameras[0], away = seen;
    /* The drawing camera turned half around and moved: it sees other instances. */
    away.rotation = gdr_quat_normalize(gdr_quat_mul(gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, 3.14159f),
                                                    seen.rotation));
    away.position = gdr_vec3_add(seen.position, (gdr_vec3){3.0f, 0.0f, 2.0f});
    gdr_frame_desc frame = {.camera = seen, .pipeline = pipeline, .occlusion = GDR_CULL_OFF};
    uint32_t from_seen = visible_set(r, &frame, a, n);
    frame.camera = away;
    uint32_t from_away = visible_set(r, &frame, b, n);
    CHECK(from_seen > 0 && from_away > 0);
    CHECK(from_seen != from_away || memcmp(a, b, sizeof *a * from_seen) != 0); /* the test means something */
    frame.cull_camera = &seen; /* drawn from `away`, culled for `seen` */
    uint32_t frozen = visible_set(r, &frame, b, n);
    CHECK(frozen == from_seen && memcmp(a, b, sizeof *a * frozen) == 0);
    frame.occlusion = GDR_CULL_DEFAULT; /* occlusion culling is off while culling is frozen */
    frozen = visible_set(r, &frame, b, n);
    CHECK(frozen == from_seen && memcmp(a, b, sizeof *a * frozen) == 0);
    gdr_camera wider = seen;
    wider.yfov *= 1.5f;
    frame.cull_camera = &wider;
    gdr_error err = {0};
    CHECK(gdr_renderer_render(r, &frame, 1, NULL, &err) == GDR_ERROR_INVALID_ARGUMENT);
}

int main(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_renderer *r = NULL;
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true};
    if (gdr_scene_create_demo(&(gdr_demo_desc){.instances = 400}, &scene, &err) != GDR_OK ||
        gdr_renderer_create(&desc, &r, &err) != GDR_OK || gdr_renderer_set_scene(r, scene, &err) != GDR_OK) {
        fprintf(stderr, "setup: %s\n", err.message);
        return 1;
    }
    uint32_t *a = malloc(sizeof *a * scene->instance_count), *b = malloc(sizeof *b * scene->instance_count);
    check_pipeline(r, scene, GDR_PIPELINE_INDIRECT, a, b);
    check_pipeline(r, scene, GDR_PIPELINE_CPU, a, b);
    if (gdr_renderer_has_mesh_pipeline(r, NULL))
        check_pipeline(r, scene, GDR_PIPELINE_MESH, a, b);
    gdr_frame_stats stats;
    CHECK(gdr_renderer_render(r, &(gdr_frame_desc){.camera = scene->cameras[0]}, 1, &stats, &err) == GDR_OK);
    CHECK(stats.validation_messages == 0);
    free(a);
    free(b);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_cull_camera");
}
