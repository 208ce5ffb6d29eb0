/* GPU instance culling against the CPU reference, and culling never changing the picture. */
#include <math.h>

#include "gdr/io.h"
#include "gpu_test_util.h"

#define WIDTH 192
#define HEIGHT 108
#define PI_F 3.14159265f

static gdr_scene *scene;
static gdr_renderer *renderer;
static uint32_t *visible;
static uint8_t *image_culled, *image_all;

static bool render(const gdr_camera *camera, gdr_cull_mode cull, uint8_t *pixels, gdr_frame_stats *stats)
{
    gdr_error err = {0};
    gdr_frame_desc frame = {.camera = *camera, .cull = cull, .read_back = true, .pipeline = GDR_PIPELINE_INDIRECT};
    if (gdr_renderer_render(renderer, &frame, 1, stats, &err) != GDR_OK ||
        gdr_renderer_read_color(renderer, pixels, &err) != GDR_OK) {
        fprintf(stderr, "render: %s\n", err.message);
        return false;
    }
    return true;
}

/* Checks one camera: the GPU's visible set equals the CPU reference, and the culled image equals
 * the image of everything. */
static void check_camera(const gdr_camera *camera, int index)
{
    gdr_frame_stats stats;
    gdr_error err = {0};
    if (!render(camera, GDR_CULL_ON, image_culled, &stats)) {
        CHECK(false);
        return;
    }
    uint32_t count = 0;
    CHECK(gdr_renderer_read_visible(renderer, visible, scene->instance_count, &count, &err) == GDR_OK);
    qsort(visible, count, sizeof *visible, compare_u32);
    uint64_t triangles = 0;
    uint32_t cursor = 0, undecided = 0;
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        bool gpu = cursor < count && visible[cursor] == i;
        if (gpu) {
            cursor++;
            triangles += scene->meshes[scene->instances[i].mesh].index_count / 3;
        }
        int cpu = cpu_instance_visibility(scene, i, camera, (float)WIDTH / HEIGHT);
        if (cpu == 0)
            undecided++;
        else if ((cpu > 0) != gpu) {
            fprintf(stderr, "camera %d: instance %u: GPU says %s, CPU reference says %s\n", index, i,
                    gpu ? "visible" : "culled", cpu > 0 ? "visible" : "culled");
            CHECK(false);
        }
    }
    CHECK(cursor == count); /* no duplicates, no out-of-range indices */
    CHECK(undecided <= 2);
    CHECK(stats.instances_visible == count);
    CHECK(stats.triangles == triangles);
    CHECK(count < scene->instance_count); /* the cameras always leave something out */

    gdr_frame_stats all;
    if (!render(camera, GDR_CULL_OFF, image_all, &all)) {
        CHECK(false);
        return;
    }
    CHECK(all.instances_visible == scene->instance_count);
    uint32_t differing = 0;
    for (size_t p = 0; p < (size_t)WIDTH * HEIGHT * 4; p++)
        differing += image_culled[p] != image_all[p];
    if (differing) {
        fprintf(stderr, "camera %d: %u bytes differ between the culled and the unculled image\n", index, differing);
        CHECK(false);
    }
}

/* Frames whose commands are submitted again (the default) draw exactly what frames recorded anew
 * draw, through camera moves, instance updates and a change of pipeline. */
static void check_resubmission(void)
{
    gdr_error err = {0};
    gdr_renderer *fresh = NULL;
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true, .record_every_frame = true};
    if (gdr_renderer_create(&desc, &fresh, &err) != GDR_OK || gdr_renderer_set_scene(fresh, scene, &err) != GDR_OK) {
        fprintf(stderr, "renderer: %s\n", err.message);
        CHECK(false);
        gdr_renderer_destroy(fresh);
        return;
    }
    gdr_renderer *renderers[2] = {renderer, fresh};
    uint8_t *images[2] = {image_culled, image_all};
    const gdr_pipeline pipelines[2] = {GDR_PIPELINE_MESH, GDR_PIPELINE_INDIRECT};
    uint32_t recorded = 0, frames = 0;
    for (int step = 0; step < 12; step++) {
        gdr_camera camera = scene->cameras[0];
        camera.position.x += 0.7f * (float)step;
        gdr_frame_desc frame = {.camera = camera, .read_back = true, .pipeline = pipelines[step / 6 % 2],
                                .lod_error_px = 1.0f};
        gdr_frame_stats stats[2];
        for (int k = 0; k < 2; k++) {
            if (step % 4 == 1) { /* an instance moves */
                gdr_mat4 moved = gdr_mat4_from_trs((gdr_vec3){0.5f * (float)step, 0.0f, 0.0f}, (gdr_quat){0, 0, 0, 1},
                                                   (gdr_vec3){1, 1, 1});
                CHECK(gdr_renderer_update_instance(renderers[k], (uint32_t)step, &moved, NULL, &err) == GDR_OK);
            }
            CHECK(gdr_renderer_render(renderers[k], &frame, 3, &stats[k], &err) == GDR_OK);
            CHECK(gdr_renderer_read_color(renderers[k], images[k], &err) == GDR_OK);
        }
        CHECK(memcmp(images[0], images[1], WIDTH * HEIGHT * 4) == 0);
        CHECK(stats[0].instances_visible == stats[1].instances_visible && stats[0].triangles == stats[1].triangles);
        CHECK(stats[1].frames_recorded == 3);
        recorded += stats[0].frames_recorded;
        frames += 3;
    }
    printf("resubmission: %u of %u frames recorded, the images equal those of frames recorded every time\n", recorded,
           frames);
    CHECK(recorded < frames / 2); /* the other frames were submitted again */
    gdr_renderer_destroy(fresh);
}

int main(void)
{
    gdr_error err = {0};
    CHECK(gdr_scene_load("demo:instances=256,seed=11", NULL, &scene, &err) == GDR_OK);
    if (!scene)
        return test_finish("test_gpu_culling");
    renderer = gpu_test_renderer(WIDTH, HEIGHT, scene);
    visible = malloc(sizeof *visible * scene->instance_count);
    image_culled = malloc(WIDTH * HEIGHT * 4);
    image_all = malloc(WIDTH * HEIGHT * 4);
    if (!renderer) {
        CHECK(false);
        return test_finish("test_gpu_culling");
    }
    unsigned rng = 777;
    for (int n = 0; n < 40; n++) {
        /* Random cameras over and inside the grid (about 64 m wide), looking in every direction,
         * some close to the ground, some from above, with narrow and wide fields of view. */
        gdr_quat yaw = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, test_random_range(&rng, -PI_F, PI_F));
        gdr_quat pitch = gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, test_random_range(&rng, -1.2f, 0.3f));
        gdr_camera camera = {
            .position = {test_random_range(&rng, -40, 40), test_random_range(&rng, 0.5f, 30), test_random_range(&rng, -40, 40)},
            .rotation = gdr_quat_mul(yaw, pitch),
            .yfov = test_random_range(&rng, 0.4f, 1.6f),
            .znear = test_random_range(&rng, 0.05f, 2.0f),
        };
        check_camera(&camera, n);
    }
    check_resubmission();
    gdr_frame_stats stats;
    gdr_camera demo_camera = scene->cameras[0];
    CHECK(render(&demo_camera, GDR_CULL_ON, image_culled, &stats));
    CHECK(stats.validation_messages == 0);
    free(visible);
    free(image_culled);
    free(image_all);
    gdr_renderer_destroy(renderer);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_culling");
}
