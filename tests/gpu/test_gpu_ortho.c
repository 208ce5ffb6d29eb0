/* Orthographic cameras (lavapipe, validation on):
 *  - the assimp corpus's Cameras.gltf, whose second camera is orthographic (xmag = ymag = 1, at
 *    (0.5, 0.5, 3) looking down -Z) over a unit square turned 45 degrees about X: on every path the
 *    square covers the pixels a CPU projection of its corners gives (ymag kept, the width from the
 *    image's aspect), at 1:1 and 16:9;
 *  - the demo scene seen from above by an orthographic camera: culling on and off give the same
 *    image on every pipeline, with the LOD cut on, while culling removes instances; the camera moved
 *    30 m further back along its axis gives the same LOD cut and image (but for at most 0.1% of the
 *    pixels, where the rasteriser rounds the other view-space depths differently) (an orthographic
 *    projection's error in pixels does not depend on distance), and half the ymag a finer cut. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/gdr.h"
#include "gpu_test_util.h"
#include "test_util.h"

#define MODELS "/usr/share/assimp/models/glTF2/"

typedef struct raster_path {
    const char *name;
    gdr_pipeline pipeline;
    gdr_raster raster;
} raster_path;

static const raster_path paths[] = {
    {"mesh/forward", GDR_PIPELINE_MESH, GDR_RASTER_FORWARD}, {"mesh/hybrid", GDR_PIPELINE_MESH, GDR_RASTER_HYBRID},
    {"mesh/sw", GDR_PIPELINE_MESH, GDR_RASTER_SW},           {"indirect", GDR_PIPELINE_INDIRECT, GDR_RASTER_DEFAULT},
    {"cpu", GDR_PIPELINE_CPU, GDR_RASTER_DEFAULT},
};
#define PATH_COUNT (sizeof paths / sizeof paths[0])

static bool render(gdr_renderer *r, const gdr_camera *camera, const raster_path *path, gdr_cull_mode cull,
                   uint8_t *rgba, gdr_frame_stats *stats)
{
    gdr_error err = {0};
    gdr_frame_desc frame = {.camera = *camera, .cull = cull, .read_back = true, .pipeline = path->pipeline,
                            .raster = path->raster, .lod_error_px = 1.0f};
    bool ok = gdr_renderer_render(r, &frame, 1, stats, &err) == GDR_OK && gdr_renderer_read_color(r, rgba, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "%s: %s\n", path->name, err.message);
    return ok && stats->validation_messages == 0;
}

/* The box of pixels whose colour differs from the top-left corner's (the background). */
static void covered_box(const uint8_t *rgba, uint32_t w, uint32_t h, int box[4])
{
    box[0] = box[1] = INT32_MAX;
    box[2] = box[3] = -1;
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++)
            if (memcmp(rgba + ((size_t)y * w + x) * 4, rgba, 3) != 0) {
                box[0] = (int)x < box[0] ? (int)x : box[0];
                box[1] = (int)y < box[1] ? (int)y : box[1];
                box[2] = (int)x > box[2] ? (int)x : box[2];
                box[3] = (int)y > box[3] ? (int)y : box[3];
            }
}

static void test_square(uint32_t w, uint32_t h)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    gdr_load_options options = {.no_cache = 1, .no_progress = 1};
    if (gdr_scene_load(MODELS "cameras/Cameras.gltf", &options, &s, &err) != GDR_OK) {
        fprintf(stderr, "Cameras.gltf: %s\n", err.message);
        CHECK(false);
        return;
    }
    CHECK(s->camera_count == 2 && s->cameras[0].ymag == 0.0f && s->cameras[1].ymag == 1.0f &&
          s->cameras[1].aspect == 1.0f);
    gdr_camera camera = s->cameras[1];
    /* The square's corners (0,0,0), (1,0,0), (0,1,0), (1,1,0) turned by the node's rotation about X:
     * x in [0, 1], y in [0, cos(angle)]; the view spans x in 0.5 -+ ymag * aspect, y in 0.5 -+ ymag. */
    double angle = 2.0 * acos(0.92375 / sqrt(0.383 * 0.383 + 0.92375 * 0.92375));
    double ymag = 1.0, xmag = ymag * (double)w / (double)h, top = cos(angle);
    double expected[4] = {(0.0 - (0.5 - xmag)) / (2 * xmag) * w, (0.5 + ymag - top) / (2 * ymag) * h,
                          (1.0 - (0.5 - xmag)) / (2 * xmag) * w, (0.5 + ymag - 0.0) / (2 * ymag) * h};
    gdr_renderer *r = gpu_test_renderer(w, h, s);
    CHECK(r != NULL);
    uint8_t *rgba = malloc((size_t)w * h * 4);
    for (size_t p = 0; r && p < PATH_COUNT; p++) {
        gdr_frame_stats stats;
        if (!render(r, &camera, &paths[p], GDR_CULL_ON, rgba, &stats)) {
            CHECK(false);
            continue;
        }
        int box[4];
        covered_box(rgba, w, h, box);
        /* pixel centres inside [a, b) are the columns ceil(a - 0.5) .. ceil(b - 0.5) - 1 */
        int want[4] = {(int)ceil(expected[0] - 0.5), (int)ceil(expected[1] - 0.5), (int)ceil(expected[2] - 0.5) - 1,
                       (int)ceil(expected[3] - 0.5) - 1};
        bool near = true;
        for (int k = 0; k < 4; k++)
            near = near && abs(box[k] - want[k]) <= 1;
        printf("square %ux%u, %s: pixels %d..%d x %d..%d, expected %d..%d x %d..%d\n", w, h, paths[p].name, box[0],
               box[2], box[1], box[3], want[0], want[2], want[1], want[3]);
        CHECK(near);
    }
    free(rgba);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(s);
}

static void test_culling(void)
{
    enum { W = 192, H = 108 };
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create_demo(&(gdr_demo_desc){.instances = 400}, &s, &err) == GDR_OK);
    CHECK(s && gdr_scene_build_lod(s, NULL, NULL, &err) == GDR_OK);
    /* looking straight down on part of the field, a little turned */
    gdr_quat down = gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, -1.5707963f);
    gdr_quat turn = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, 0.3f);
    gdr_camera camera = {.position = {3.0f, 40.0f, -2.0f}, .rotation = gdr_quat_mul(turn, down), .ymag = 9.0f,
                         .znear = 0.5f, .zfar = 80.0f};
    gdr_renderer *r = gpu_test_renderer(W, H, s);
    CHECK(r != NULL);
    uint8_t *on = malloc((size_t)W * H * 4), *off = malloc((size_t)W * H * 4);
    for (size_t p = 0; r && p < PATH_COUNT; p++) {
        gdr_frame_stats a, b;
        if (!render(r, &camera, &paths[p], GDR_CULL_ON, on, &a) || !render(r, &camera, &paths[p], GDR_CULL_OFF, off, &b)) {
            CHECK(false);
            continue;
        }
        uint32_t differ = 0;
        for (uint32_t i = 0; i < W * H; i++)
            differ += memcmp(on + i * 4, off + i * 4, 3) != 0;
        printf("field, %s: %u of %u instances drawn with culling (%u without), %u clusters frustum-culled, "
               "%llu triangles; %u pixels differ from culling off\n", paths[p].name, a.instances_visible,
               a.instances_total, b.instances_visible, a.meshlets_frustum_culled, (unsigned long long)a.triangles,
               differ);
        CHECK(differ == 0);
        CHECK(a.instances_visible > 0 && a.instances_visible < a.instances_total / 2);
        gdr_camera back = camera, closer = camera;
        back.position.y += 30.0f;
        back.zfar += 30.0f;
        closer.ymag *= 0.5f;
        gdr_frame_stats c, d;
        CHECK(render(r, &back, &paths[p], GDR_CULL_ON, off, &c));
        differ = 0;
        for (uint32_t i = 0; i < W * H; i++)
            differ += memcmp(on + i * 4, off + i * 4, 3) != 0;
        CHECK(render(r, &closer, &paths[p], GDR_CULL_ON, off, &d));
        /* triangles per drawn instance: the instances in view change with the zoom */
        double per = (double)a.triangles / a.instances_visible, per_closer = (double)d.triangles / d.instances_visible;
        printf("field, %s: 30 m further back %llu triangles (%u pixels differ); half the ymag %.0f triangles per "
               "instance (%.0f before)\n", paths[p].name, (unsigned long long)c.triangles, differ, per_closer, per);
        CHECK(c.triangles == a.triangles && differ <= W * H / 1000); /* float rounding of the nearer view */
        if (paths[p].pipeline == GDR_PIPELINE_MESH)
            CHECK(per_closer > 1.5 * per);
    }
    free(on);
    free(off);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(s);
}

int main(void)
{
    test_square(100, 100);
    test_square(160, 90);
    test_culling();
    return test_finish("test_gpu_ortho");
}
