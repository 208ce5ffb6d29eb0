/* Streaming beside the renderer's other features, on the default device (lavapipe in CI),
 * validation on: for built-in scenes (textured materials, one mesh instanced many times, walls that
 * hide most of the scene) and frame configurations of the mesh pipeline (forward and visibility-
 * buffer rasterisers, occlusion culling on, debug views), a renderer streaming the scene's paged
 * cache with room for every page, once converged, draws the image of the renderer that uploaded
 * the scene whole, pixel for pixel, and the same triangles. (Seen failing before the pages kept
 * the triangles' corner order: the forward rasteriser's interpolation then differed by one level in
 * a pixel or two.) The camera is moved in so that pages past the coarsest are drawn. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "gpu_test_util.h"
#include "io/loaders.h"

#define WIDTH 160
#define HEIGHT 96
#define MAX_FRAMES 80

typedef struct feature_case {
    const char *what;
    gdr_raster raster;
    gdr_cull_mode occlusion;
    gdr_view view;
} feature_case;

static const feature_case cases[] = {
    {"forward", GDR_RASTER_FORWARD, GDR_CULL_OFF, GDR_VIEW_MODE_SHADED},
    {"hybrid visibility buffer", GDR_RASTER_HYBRID, GDR_CULL_OFF, GDR_VIEW_MODE_SHADED},
    {"occlusion on", GDR_RASTER_FORWARD, GDR_CULL_ON, GDR_VIEW_MODE_SHADED},
    {"lod view", GDR_RASTER_FORWARD, GDR_CULL_OFF, GDR_VIEW_MODE_LOD},
    {"triangle view", GDR_RASTER_FORWARD, GDR_CULL_OFF, GDR_VIEW_MODE_TRIANGLES},
};

static bool render(gdr_renderer *r, const gdr_frame_desc *frame, uint8_t *image, gdr_frame_stats *stats)
{
    gdr_error err = {0};
    bool ok = gdr_renderer_render(r, frame, 1, stats, &err) == GDR_OK &&
              gdr_renderer_read_color(r, image, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "render: %s\n", err.message);
    CHECK(ok && stats->validation_messages == 0);
    return ok;
}

/* Frames until no request is left and the residency stayed as it is for a few frames. */
static bool converge(gdr_renderer *r, const gdr_frame_desc *frame, uint8_t *image, gdr_frame_stats *stats)
{
    for (int f = 0; f < MAX_FRAMES; f++) {
        if (!render(r, frame, image, stats))
            return false;
        if (stats->streaming.pending == 0 && stats->streaming.frames_since_change >= 3 &&
            stats->streaming.distinct_requests == 0)
            return true;
    }
    return false;
}

static gdr_renderer *streamed(const gdr_scene *paged, const char *path)
{
    gdr_error err = {0};
    gdr_renderer *r = NULL;
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true};
    gdr_streaming_desc stream = {.cache = gpu_test_paged_cache(path), .geometry_budget_bytes = 256u << 20, .wait_for_loads = true};
    if (gdr_renderer_create(&desc, &r, &err) != GDR_OK || gdr_renderer_set_scene_streamed(r, paged, &stream, &err) != GDR_OK) {
        fprintf(stderr, "streamed renderer: %s\n", err.message);
        gdr_renderer_destroy(r);
        return NULL;
    }
    return r;
}

/* The framing camera moved `share` of the way to the scene's bounding sphere's centre, so that finer
 * groups, in pages beyond the coarsest, are drawn. */
static gdr_camera nearer(const gdr_scene *scene, float share)
{
    gdr_camera c = gdr_scene_framing_camera(scene);
    gdr_vec3 forward = gdr_quat_rotate(c.rotation, (gdr_vec3){0.0f, 0.0f, -1.0f});
    float lo = INFINITY, hi = -INFINITY; /* the instances' distances along the view */
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        const float *m = scene->instances[i].transform.m;
        gdr_vec3 d = {m[12] - c.position.x, m[13] - c.position.y, m[14] - c.position.z};
        float along = d.x * forward.x + d.y * forward.y + d.z * forward.z;
        lo = along < lo ? along : lo;
        hi = along > hi ? along : hi;
    }
    float step = share * (lo + hi) * 0.5f;
    c.position = (gdr_vec3){c.position.x + forward.x * step, c.position.y + forward.y * step,
                            c.position.z + forward.z * step};
    return c;
}

static void run_scene(const char *spec)
{
    gdr_scene *scene = NULL, *paged = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    char path[256];
    snprintf(path, sizeof path, "%s/gdr_streaming_features_%ld.gdrc", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp",
             (long)getpid());
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_MIN};
    CHECK(gdr_scene_load(spec, &load, &scene, &err) == GDR_OK && gdr_scene_quantize_vertices(scene, &err) == GDR_OK &&
          gdr_cache_write(path, scene, &write, &err) == GDR_OK &&
          gdr_cache_read_for_streaming(path, NULL, &paged, NULL, NULL, &err) == GDR_OK);
    gdr_renderer *whole = scene ? gpu_test_renderer(WIDTH, HEIGHT, scene) : NULL;
    gdr_renderer *r = paged ? streamed(paged, path) : NULL;
    uint8_t *a = malloc(WIDTH * HEIGHT * 4), *b = malloc(WIDTH * HEIGHT * 4);
    for (size_t k = 0; whole && r && a && b && k < sizeof cases / sizeof cases[0]; k++) {
        gdr_frame_desc frame = {.camera = nearer(scene, 0.7f), .pipeline = GDR_PIPELINE_MESH,
                                .read_back = true, .lod_error_px = 1.0f, .raster = cases[k].raster,
                                .occlusion = cases[k].occlusion, .view = cases[k].view,
                                /* a streamed mesh has no point level (its triangles stay in the
                                 * file: docs/GEOMETRY.md, "The point level"): both draw without */
                                .point_level = GDR_CULL_OFF};
        gdr_frame_stats ws = {0}, ss = {0};
        /* Then four more frames each: occlusion culling tests against the frame before, and both
         * reach the same history. */
        bool ok = converge(r, &frame, b, &ss);
        for (int f = 0; ok && f < 4; f++)
            ok = render(whole, &frame, a, &ws) && render(r, &frame, b, &ss);
        size_t differ = 0;
        for (size_t i = 0; ok && i < (size_t)WIDTH * HEIGHT * 4; i++)
            differ += a[i] != b[i];
        printf("%s, %s: %llu triangles whole, %llu streamed (%u pages resident), %zu bytes differ\n", spec,
               cases[k].what, (unsigned long long)ws.triangles, (unsigned long long)ss.triangles,
               ss.streaming.resident_pages, differ);
        CHECK(ok && differ == 0 && ws.triangles == ss.triangles && ws.triangles > 0);
    }
    free(a), free(b);
    gdr_renderer_destroy(r);
    gdr_renderer_destroy(whole);
    unlink(path);
    gdr_scene_destroy(paged);
    gdr_scene_destroy(scene);
}

int main(void)
{
    run_scene("demo:instances=24");
    run_scene("lod-field:instances=16,triangles=4000");
    run_scene("occlusion");
    return test_finish("test_gpu_streaming_features");
}
