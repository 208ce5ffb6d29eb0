/* A camera looking at a known part of the demo grid culls the expected instances; instance
 * updates sent through the per-frame ring reach the GPU. */
#include <math.h>

#include "gdr/io.h"
#include "gpu_test_util.h"

#define WIDTH 160
#define HEIGHT 120
#define PI_F 3.14159265f

int main(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    /* A 10 x 10 grid, spacing 4: object centres at x, z in {-18, -14, ..., 18}; instance 0 is the ground. */
    CHECK(gdr_scene_load("demo:instances=100,seed=5", NULL, &scene, &err) == GDR_OK);
    gdr_renderer *renderer = scene ? gpu_test_renderer(WIDTH, HEIGHT, scene) : NULL;
    if (!renderer) {
        CHECK(false);
        return test_finish("test_gpu_known_view");
    }
    /* At the centre, 3.5 m up, looking straight down -X (yaw +90 degrees), 60-degree vertical fov. */
    gdr_camera camera = {.position = {0, 3.5f, 0},
                         .rotation = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, 0.5f * PI_F),
                         .yfov = 60.0f * PI_F / 180.0f, .znear = 0.1f};
    gdr_frame_desc frame = {.camera = camera, .cull = GDR_CULL_ON, .read_back = true};
    gdr_frame_stats stats;
    CHECK(gdr_renderer_render(renderer, &frame, 1, &stats, &err) == GDR_OK);
    uint32_t *visible = calloc(scene->instance_count, sizeof *visible), count = 0;
    CHECK(gdr_renderer_read_visible(renderer, visible, scene->instance_count, &count, &err) == GDR_OK);
    bool *is_visible = calloc(scene->instance_count, sizeof *is_visible);
    for (uint32_t i = 0; i < count; i++)
        is_visible[visible[i]] = true;

    CHECK(is_visible[0]); /* the ground is under the camera */
    /* Horizontal half-angle: atan(tan(30 deg) * 4/3) = 37.6 deg. Objects (radius <= 1.5) behind the
     * camera must be culled; objects well inside the view cone ahead must be drawn. */
    uint32_t behind = 0, ahead = 0;
    for (uint32_t i = 1; i < scene->instance_count; i++) {
        const float *m = scene->instances[i].transform.m;
        float x = m[12], z = m[14];
        if (x > 1.6f) {
            behind++;
            if (is_visible[i])
                fprintf(stderr, "instance %u at (%g, %g) behind the camera is drawn\n", i, x, z);
            CHECK(!is_visible[i]);
        }
        if (x < -5.0f && fabsf(z) < 0.6f * -x) {
            ahead++;
            if (!is_visible[i])
                fprintf(stderr, "instance %u at (%g, %g) ahead of the camera is culled\n", i, x, z);
            CHECK(is_visible[i]);
        }
    }
    CHECK(behind == 50 && ahead > 10); /* 5 columns of 10 lie at x = 2..18 */

    /* Move an object that is behind the camera to 6 m straight ahead through the instance ring. */
    uint32_t moved = 0;
    for (uint32_t i = 1; i < scene->instance_count && !moved; i++)
        if (scene->instances[i].transform.m[12] > 10.0f)
            moved = i;
    uint8_t *before = malloc(WIDTH * HEIGHT * 4), *after = malloc(WIDTH * HEIGHT * 4);
    CHECK(gdr_renderer_read_color(renderer, before, &err) == GDR_OK);
    gdr_mat4 transform = gdr_mat4_from_trs((gdr_vec3){-6.0f, 3.5f, 0.0f}, gdr_quat_identity(), (gdr_vec3){1, 1, 1});
    gdr_vec4 red = {1, 0, 0, 1};
    CHECK(gdr_renderer_update_instance(renderer, moved, &transform, &red, &err) == GDR_OK);
    CHECK(gdr_renderer_update_instance(renderer, scene->instance_count, &transform, NULL, &err) == GDR_ERROR_INVALID_ARGUMENT);
    CHECK(gdr_renderer_render(renderer, &frame, 1, &stats, &err) == GDR_OK);
    CHECK(gdr_renderer_read_visible(renderer, visible, scene->instance_count, &count, &err) == GDR_OK);
    bool found = false;
    for (uint32_t i = 0; i < count; i++)
        found |= visible[i] == moved;
    CHECK(found);
    CHECK(gdr_renderer_read_color(renderer, after, &err) == GDR_OK);
    /* The centre pixel now shows the red object. */
    const uint8_t *centre = after + ((HEIGHT / 2) * WIDTH + WIDTH / 2) * 4;
    CHECK(centre[0] > 100 && centre[1] < 60 && centre[2] < 60);
    CHECK(memcmp(before, after, WIDTH * HEIGHT * 4) != 0);
    CHECK(stats.validation_messages == 0);

    free(before);
    free(after);
    free(visible);
    free(is_visible);
    gdr_renderer_destroy(renderer);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_known_view");
}
