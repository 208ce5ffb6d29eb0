/* The point level (shared/point_level.h) on the default device (lavapipe in CI), validation on: a
 * field of instances, most of them far, drawn by the compute rasteriser at a 1 px LOD threshold
 * with the point level on and off. Against a CPU reference of the rule and the splat:
 *  - the instances drawn as points are those of the field that pass gdr_point_level_passes and are
 *    in the frustum (up to a few within float rounding of either test);
 *  - every pixel the visibility buffer names as a point lies within the splat disc of its instance
 *    (a splat larger than the mesh's coverage disc, or at another place, fails), and every pixel
 *    centre well inside the disc of a passing instance is covered (a splat not drawn fails);
 *  - with the point level off, no point and no point pixel;
 *  - the image stays close to the one without points (the far field keeps its coverage). */
#include <math.h>

#include "gpu_test_util.h"
#include "gpu_shared/point_level.h"
#include "render/frame.h"
#include "render/visbuffer.h"

#define WIDTH 256
#define HEIGHT 144
#define PIXELS (WIDTH * HEIGHT)

typedef struct point_frame {
    uint8_t rgba[PIXELS * 4];
    gdr_visbuffer_pixel vis[PIXELS];
    gdr_frame_stats stats;
} point_frame;

static point_frame frames[2]; /* point level on, off */

/* Where an instance's splat lands: its centre in framebuffer pixels and its radius. */
typedef struct splat {
    bool passes;   /* gdr_point_level_passes */
    int visible;   /* cpu_instance_visibility */
    gdr_vec2 centre;
    float radius;
} splat;

static splat reference_splat(const gdr_scene *scene, uint32_t i, const gdr_camera *camera, gdr_mat4 projection,
                             gdr_mat4 view, float surface_area)
{
    const gdr_instance *instance = &scene->instances[i];
    const gdr_mesh *mesh = &scene->meshes[instance->mesh];
    const gdr_mat4 *m = &instance->transform;
    gdr_vec3 c0 = {m->m[0], m->m[1], m->m[2]}, c1 = {m->m[4], m->m[5], m->m[6]}, c2 = {m->m[8], m->m[9], m->m[10]};
    gdr_vec3 c3 = {m->m[12], m->m[13], m->m[14]};
    float projection_scale = fabsf(projection.m[5]) * 0.5f * (float)HEIGHT;
    splat s = {0};
    s.passes = gdr_point_level_passes(mesh->bounds, mesh->bounds.w, c0, c1, c2, c3, camera->position, camera->znear,
                                      projection_scale, 1.0f);
    s.visible = cpu_instance_visibility(scene, i, camera, (float)WIDTH / HEIGHT);
    gdr_vec3 world = gdr_mat4_transform_point(*m, (gdr_vec3){mesh->bounds.x, mesh->bounds.y, mesh->bounds.z});
    gdr_vec4 clip = gdr_mat4_mul_vec4(gdr_mat4_mul(projection, view), (gdr_vec4){world.x, world.y, world.z, 1.0f});
    s.centre = (gdr_vec2){0.5f * WIDTH * (1.0f + clip.x / clip.w), 0.5f * HEIGHT * (1.0f - clip.y / clip.w)};
    s.radius = gdr_point_radius(surface_area, mesh->bounds.w) * gdr_mat4_max_axis_scale(*m) * projection_scale /
               clip.w;
    return s;
}

static float mesh_area(const gdr_mesh *mesh)
{
    double area = 0.0;
    for (uint32_t t = 0; t + 2 < mesh->index_count; t += 3) {
        gdr_vec3 a = mesh->positions[mesh->indices[t]], b = mesh->positions[mesh->indices[t + 1]];
        gdr_vec3 c = mesh->positions[mesh->indices[t + 2]];
        gdr_vec3 n = gdr_vec3_cross(gdr_vec3_sub(b, a), gdr_vec3_sub(c, a));
        area += 0.5 * sqrt((double)n.x * n.x + (double)n.y * n.y + (double)n.z * n.z);
    }
    return (float)area;
}

static bool render(gdr_renderer *r, const gdr_camera *camera, gdr_cull_mode points, point_frame *out)
{
    gdr_error err = {0};
    gdr_frame_desc frame = {.camera = *camera, .raster = GDR_RASTER_SW, .lod_error_px = 1.0f,
                            .occlusion = GDR_CULL_OFF, .point_level = points, .read_back = true};
    bool ok = gdr_renderer_render(r, &frame, 1, &out->stats, &err) == GDR_OK &&
              gdr_renderer_read_color(r, out->rgba, &err) == GDR_OK &&
              gdr_visbuffer_read_pixels(r, out->vis, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "render: %s\n", err.message);
    CHECK(ok && out->stats.validation_messages == 0);
    return ok;
}

static double psnr(const uint8_t *a, const uint8_t *b)
{
    double sum = 0.0;
    for (int i = 0; i < PIXELS * 4; i++)
        if (i % 4 != 3)
            sum += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    double mse = sum / (PIXELS * 3.0);
    return mse > 0.0 ? 10.0 * log10(255.0 * 255.0 / mse) : 99.0;
}

/* The pixels of the frame drawn with points against the reference splats. */
static void check_pixels(const gdr_scene *scene, const splat *splats)
{
    uint32_t point_pixels = 0, outside = 0, missing = 0, expected = 0;
    for (int p = 0; p < PIXELS; p++) {
        const gdr_visbuffer_pixel *v = &frames[0].vis[p];
        if (v->triangle != GDR_VISBUFFER_POINT_TRIANGLE || v->instance == UINT32_MAX)
            continue;
        point_pixels++;
        const splat *s = &splats[v->instance];
        float dx = (float)(p % WIDTH) + 0.5f - s->centre.x, dy = (float)(p / WIDTH) + 0.5f - s->centre.y;
        if (v->instance >= scene->instance_count || !s->passes || sqrtf(dx * dx + dy * dy) > s->radius + 0.01f)
            outside++;
    }
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        const splat *s = &splats[i];
        if (!s->passes || s->visible != 1)
            continue;
        for (int y = 0; y < HEIGHT; y++)
            for (int x = 0; x < WIDTH; x++) {
                float dx = (float)x + 0.5f - s->centre.x, dy = (float)y + 0.5f - s->centre.y;
                if (sqrtf(dx * dx + dy * dy) > s->radius - 0.01f)
                    continue;
                expected++;
                missing += frames[0].vis[y * WIDTH + x].instance == UINT32_MAX;
            }
    }
    printf("point pixels %u (%u outside their splat); pixel centres inside a splat %u, %u of them empty\n",
           point_pixels, outside, expected, missing);
    CHECK(point_pixels > 0 && outside == 0 && expected > 0 && missing == 0);
}

int main(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_load_options options = {.no_cache = 1, .no_progress = 1};
    if (gdr_scene_load("lod-field:instances=2000,triangles=5000", &options, &scene, &err) != GDR_OK) {
        fprintf(stderr, "scene: %s\n", err.message);
        return 1;
    }
    CHECK(scene->camera_count > 0);
    gdr_renderer *r = gpu_test_renderer(WIDTH, HEIGHT, scene);
    CHECK(r != NULL);
    if (!r || scene->camera_count == 0) {
        gdr_scene_destroy(scene);
        return test_finish("test_gpu_point_level");
    }
    const gdr_camera *camera = &scene->cameras[0];
    bool ok = render(r, camera, GDR_CULL_ON, &frames[0]) && render(r, camera, GDR_CULL_OFF, &frames[1]);
    gdr_mat4 projection, view;
    gdr_frame_matrices(r, camera, &projection, &view);
    gdr_renderer_destroy(r);

    splat *splats = calloc(scene->instance_count, sizeof *splats);
    float *areas = calloc(scene->mesh_count, sizeof *areas);
    CHECK(splats && areas);
    if (ok && splats && areas) {
        for (uint32_t m = 0; m < scene->mesh_count; m++)
            areas[m] = mesh_area(&scene->meshes[m]);
        uint32_t surely = 0, maybe = 0;
        for (uint32_t i = 0; i < scene->instance_count; i++) {
            splats[i] = reference_splat(scene, i, camera, projection, view, areas[scene->instances[i].mesh]);
            surely += splats[i].passes && splats[i].visible == 1;
            maybe += splats[i].passes && splats[i].visible >= 0;
        }
        uint32_t drawn = frames[0].stats.instances_points;
        printf("instances %u: %u drawn as points (the reference: %u to %u)\n", scene->instance_count, drawn, surely,
               maybe);
        CHECK(drawn > 100 && drawn + 2 >= surely && drawn <= maybe + 2);
        check_pixels(scene, splats);
        uint32_t off_pixels = 0;
        for (int p = 0; p < PIXELS; p++)
            off_pixels += frames[1].vis[p].triangle == GDR_VISBUFFER_POINT_TRIANGLE;
        CHECK(frames[1].stats.instances_points == 0 && off_pixels == 0);
        double db = psnr(frames[0].rgba, frames[1].rgba);
        printf("image with points against without: %.1f dB; triangles %llu against %llu\n", db,
               (unsigned long long)frames[0].stats.triangles, (unsigned long long)frames[1].stats.triangles);
        CHECK(db >= 30.0 && frames[0].stats.triangles < frames[1].stats.triangles);
    }
    free(splats);
    free(areas);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_point_level");
}
