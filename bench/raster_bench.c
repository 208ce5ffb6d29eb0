/* Hybrid rasterisation: throughput of each rasteriser and the frame time it buys.
 *
 * 1. Triangle fields: one grid of right triangles with legs of S pixels facing the camera and
 *    filling the view (2 * (W / S) * (H / S) triangles), for each S of --sizes, drawn by the mesh
 *    shaders forward (no visibility buffer), by the mesh shaders into the visibility buffer (hw)
 *    and by the compute rasteriser (sw). Triangles per second = triangles / the rasteriser's GPU
 *    time (timestamps: the "draw" pass forward; the mesh-shader pass for hw; the compute dispatch
 *    for sw). The cluster cull (tests, binning and launches) and the resolve are timed apart: they
 *    cost the same for every rasteriser.
 * 2. A scene: the lod-field scene (--instances copies of a --triangles mesh with a LOD DAG, cut at
 *    --lod-error pixels) at W x H, GPU ms per frame for hw and for hybrid at each --thresholds.
 * Occlusion culling is off (one raster phase per frame). Prints a table and JSON (--json FILE).
 * GPU figures come from a real GPU only (docs/PERFORMANCE.md); on lavapipe use small sizes, e.g.
 *   raster_bench --width 320 --height 180 --frames 3 --instances 20 --triangles 5000
 * usage: raster_bench [--device NAME|INDEX] [--width W] [--height H] [--frames N] [--sizes 1,3,6,12]
 *                     [--instances N] [--triangles T] [--lod-error PX] [--thresholds 2,4,8,16]
 *                     [--validate] [--json FILE] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/gdr.h"

#define MAX_LIST 16

static char device_name[256]; /* of the last run, for the JSON */

typedef struct options {
    const char *device, *json;
    uint32_t width, height, frames, instances, triangles;
    float lod_error;
    float sizes[MAX_LIST], thresholds[MAX_LIST];
    uint32_t size_count, threshold_count;
    bool validate;
} options;

typedef struct field_result {
    float size_px;
    uint64_t triangles;
    double forward_ms, cull_ms, hw_ms, sw_ms, resolve_ms;
} field_result;

typedef struct scene_result {
    const char *raster;
    float threshold;
    double gpu_ms, cull_ms, hw_ms, sw_ms, resolve_ms;
    uint32_t sw_clusters, hw_clusters;
    uint64_t sw_triangles, hw_triangles;
} scene_result;

static bool parse_list(const char *text, float *out, uint32_t *count)
{
    char buffer[256];
    snprintf(buffer, sizeof buffer, "%s", text);
    *count = 0;
    for (char *save = NULL, *item = strtok_r(buffer, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
        char *end;
        float v = strtof(item, &end);
        if (*end || !(v > 0.0f && v < 1e6f) || *count == MAX_LIST)
            return false;
        out[(*count)++] = v;
    }
    return *count > 0;
}

static bool parse_options(int argc, char **argv, options *o)
{
    *o = (options){.width = 2560, .height = 1440, .frames = 20, .instances = 1000, .triangles = 100000,
                   .lod_error = 1.0f, .sizes = {1, 3, 6, 12}, .size_count = 4,
                   .thresholds = {GDR_DEFAULT_SW_THRESHOLD_PX}, .threshold_count = 1};
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i], *value = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(arg, "--validate")) {
            o->validate = true;
            continue;
        }
        if (!value)
            return false;
        i++;
        if (!strcmp(arg, "--device"))
            o->device = value;
        else if (!strcmp(arg, "--json"))
            o->json = value;
        else if (!strcmp(arg, "--width"))
            o->width = (uint32_t)strtoul(value, NULL, 10);
        else if (!strcmp(arg, "--height"))
            o->height = (uint32_t)strtoul(value, NULL, 10);
        else if (!strcmp(arg, "--frames"))
            o->frames = (uint32_t)strtoul(value, NULL, 10);
        else if (!strcmp(arg, "--instances"))
            o->instances = (uint32_t)strtoul(value, NULL, 10);
        else if (!strcmp(arg, "--triangles"))
            o->triangles = (uint32_t)strtoul(value, NULL, 10);
        else if (!strcmp(arg, "--lod-error"))
            o->lod_error = strtof(value, NULL);
        else if (!strcmp(arg, "--sizes")) {
            if (!parse_list(value, o->sizes, &o->size_count))
                return false;
        } else if (!strcmp(arg, "--thresholds")) {
            if (!parse_list(value, o->thresholds, &o->threshold_count))
                return false;
        } else
            return false;
    }
    return o->width >= 16 && o->height >= 16 && o->width <= 16384 && o->height <= 16384 && o->frames > 0;
}

/* The camera of the fields: at the origin looking down -Z with tan(yfov / 2) = 1/10, so the plane
 * z = -10 shows y in [-1, 1] over the height and x in [-W/H, W/H] over the width; far enough that
 * no cluster's sphere reaches the near plane (the compute rasteriser takes them all). */
#define FIELD_DEPTH 10.0f
static gdr_camera field_camera(void)
{
    return (gdr_camera){.rotation = gdr_quat_identity(), .yfov = 2.0f * atanf(1.0f / FIELD_DEPTH), .znear = 0.1f};
}

/* A grid of cells of `size_px` pixels (two triangles each) filling the view on the plane z = -10. */
static gdr_status field_scene(const options *o, float size_px, gdr_scene **out, uint64_t *triangles, gdr_error *err)
{
    uint32_t cells_x = (uint32_t)ceilf((float)o->width / size_px), cells_y = (uint32_t)ceilf((float)o->height / size_px);
    uint64_t vertex_count = (uint64_t)(cells_x + 1) * (cells_y + 1), index_count = 6ull * cells_x * cells_y;
    if (vertex_count > UINT32_MAX / 2 || index_count > UINT32_MAX / 2)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "field of %g px at %ux%u is too large", (double)size_px,
                             o->width, o->height);
    gdr_vec3 *positions = malloc(sizeof *positions * vertex_count);
    gdr_vec3 *normals = malloc(sizeof *normals * vertex_count);
    uint32_t *indices = malloc(sizeof *indices * index_count);
    gdr_status status = GDR_OK;
    if (!positions || !normals || !indices)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "field: out of memory");
    float step = 2.0f * size_px / (float)o->height, aspect = (float)o->width / (float)o->height;
    for (uint32_t y = 0; status == GDR_OK && y <= cells_y; y++)
        for (uint32_t x = 0; x <= cells_x; x++) {
            positions[(size_t)y * (cells_x + 1) + x] = (gdr_vec3){-aspect + step * (float)x, 1.0f - step * (float)y, -FIELD_DEPTH};
            normals[(size_t)y * (cells_x + 1) + x] = (gdr_vec3){0.0f, 0.0f, 1.0f};
        }
    size_t n = 0;
    for (uint32_t y = 0; status == GDR_OK && y < cells_y; y++)
        for (uint32_t x = 0; x < cells_x; x++) {
            uint32_t a = y * (cells_x + 1) + x, b = a + 1, c = a + cells_x + 1, d = c + 1; /* a b / c d, y down */
            uint32_t quad[6] = {a, c, d, a, d, b}; /* counter-clockwise as seen */
            memcpy(indices + n, quad, sizeof quad);
            n += 6;
        }
    gdr_scene *scene = NULL;
    uint32_t mesh = 0;
    if (status == GDR_OK)
        status = gdr_scene_create(&scene, err);
    if (status == GDR_OK)
        status = gdr_scene_add_mesh(scene, "field", positions, normals, NULL, (uint32_t)vertex_count, indices,
                                    (uint32_t)index_count, &mesh, err);
    gdr_instance instance = {.transform = gdr_mat4_identity(), .mesh = mesh, .material = GDR_NO_INDEX,
                             .color = {0.7f, 0.7f, 0.7f, 1.0f}};
    if (status == GDR_OK)
        status = gdr_scene_add_instance(scene, &instance, err);
    if (status == GDR_OK)
        status = gdr_scene_build_clusters(scene, NULL, err);
    free(positions);
    free(normals);
    free(indices);
    if (status != GDR_OK) {
        gdr_scene_destroy(scene);
        return status;
    }
    *out = scene;
    *triangles = index_count / 3;
    return GDR_OK;
}

static gdr_status make_renderer(const options *o, const gdr_scene *scene, gdr_renderer **out, gdr_error *err)
{
    gdr_renderer_desc desc = {.width = o->width, .height = o->height, .device = o->device, .validate = o->validate,
                              .busy_wait = true};
    gdr_status status = gdr_renderer_create(&desc, out, err);
    if (status == GDR_OK)
        status = gdr_renderer_set_scene(*out, scene, err);
    if (status == GDR_OK) {
        const char *why = NULL;
        if (!gdr_renderer_has_mesh_pipeline(*out, &why))
            status = gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "raster_bench needs the mesh pipeline: %s", why);
    }
    return status;
}

/* One warm-up frame, then `frames` timed ones. */
static gdr_status render(const options *o, gdr_renderer *r, gdr_frame_desc frame, gdr_raster raster, float threshold,
                         gdr_frame_stats *stats, gdr_error *err)
{
    frame.pipeline = GDR_PIPELINE_MESH;
    frame.raster = raster;
    frame.sw_threshold_px = threshold;
    frame.occlusion = GDR_CULL_OFF;
    gdr_status status = gdr_renderer_render(r, &frame, 1, NULL, err);
    if (status == GDR_OK)
        status = gdr_renderer_render(r, &frame, o->frames, stats, err);
    if (status == GDR_OK)
        snprintf(device_name, sizeof device_name, "%s", stats->device);
    if (status == GDR_OK && stats->validation_messages)
        status = gdr_error_set(err, GDR_ERROR_VULKAN, "the validation layer reported %u message(s)",
                               stats->validation_messages);
    return status;
}

static double draw_pass_ms(const gdr_frame_stats *s)
{
    for (uint32_t p = 0; p < s->pass_count; p++)
        if (!strcmp(s->passes[p].name, "draw"))
            return s->passes[p].gpu_ms;
    return 0.0;
}

static gdr_status run_field(const options *o, float size_px, field_result *out, gdr_error *err)
{
    gdr_scene *scene = NULL;
    gdr_renderer *r = NULL;
    *out = (field_result){.size_px = size_px};
    gdr_status status = field_scene(o, size_px, &scene, &out->triangles, err);
    if (status == GDR_OK)
        status = make_renderer(o, scene, &r, err);
    gdr_frame_desc frame = {.camera = field_camera()};
    gdr_frame_stats stats;
    if (status == GDR_OK)
        status = render(o, r, frame, GDR_RASTER_FORWARD, 0.0f, &stats, err);
    if (status == GDR_OK) {
        out->forward_ms = draw_pass_ms(&stats);
        status = render(o, r, frame, GDR_RASTER_HW, 0.0f, &stats, err);
    }
    if (status == GDR_OK) {
        out->hw_ms = stats.raster.hw_ms;
        out->cull_ms = stats.raster.cull_ms;
        out->resolve_ms = stats.raster.resolve_ms;
        status = render(o, r, frame, GDR_RASTER_SW, 0.0f, &stats, err);
    }
    if (status == GDR_OK) {
        out->sw_ms = stats.raster.sw_ms;
        if (stats.raster.hw_clusters > 0)
            fprintf(stderr, "raster_bench: %u clusters of the %g px field went to the mesh shaders in sw mode "
                            "(their spheres leave the guard band)\n", stats.raster.hw_clusters, (double)size_px);
    }
    gdr_renderer_destroy(r);
    gdr_scene_destroy(scene);
    return status;
}

static gdr_status run_scene(const options *o, scene_result *results, uint32_t *count, gdr_error *err)
{
    char spec[128];
    snprintf(spec, sizeof spec, "lod-field:instances=%u,triangles=%u", o->instances, o->triangles);
    gdr_load_options load = {.no_progress = 1};
    gdr_scene *scene = NULL;
    gdr_renderer *r = NULL;
    gdr_status status = gdr_scene_load(spec, &load, &scene, err);
    if (status == GDR_OK)
        status = make_renderer(o, scene, &r, err);
    gdr_frame_desc frame = {.lod_error_px = o->lod_error};
    if (status == GDR_OK)
        frame.camera = scene->cameras[0];
    *count = 0;
    for (uint32_t t = 0; status == GDR_OK && t <= o->threshold_count; t++) {
        gdr_raster raster = t == 0 ? GDR_RASTER_HW : GDR_RASTER_HYBRID;
        float threshold = t == 0 ? 0.0f : o->thresholds[t - 1];
        gdr_frame_stats stats;
        status = render(o, r, frame, raster, threshold, &stats, err);
        if (status == GDR_OK)
            results[(*count)++] = (scene_result){gdr_raster_name(raster), threshold, stats.gpu_ms_per_frame,
                                                 stats.raster.cull_ms, stats.raster.hw_ms, stats.raster.sw_ms, stats.raster.resolve_ms,
                                                 stats.raster.sw_clusters, stats.raster.hw_clusters,
                                                 stats.raster.sw_triangles, stats.raster.hw_triangles};
    }
    gdr_renderer_destroy(r);
    gdr_scene_destroy(scene);
    return status;
}

static double per_second(uint64_t triangles, double ms)
{
    return ms > 0.0 ? (double)triangles / (ms * 1e-3) : 0.0;
}

static void write_json(FILE *f, const options *o, const field_result *fields, const scene_result *scenes,
                       uint32_t scene_count, const char *device)
{
    fprintf(f, "{\n  \"device\": \"%s\",\n  \"width\": %u,\n  \"height\": %u,\n  \"frames\": %u,\n  \"fields\": [\n",
            device, o->width, o->height, o->frames);
    for (uint32_t i = 0; i < o->size_count; i++) {
        const field_result *r = &fields[i];
        fprintf(f, "    {\"size_px\": %g, \"triangles\": %llu, \"forward_ms\": %.4f, \"hw_ms\": %.4f, \"sw_ms\": %.4f, "
                   "\"resolve_ms\": %.4f, \"cull_ms\": %.4f, \"forward_tris_per_s\": %.4g, "
                   "\"hw_tris_per_s\": %.4g, \"sw_tris_per_s\": %.4g}%s\n",
                (double)r->size_px, (unsigned long long)r->triangles, r->forward_ms, r->hw_ms, r->sw_ms, r->resolve_ms,
                r->cull_ms, per_second(r->triangles, r->forward_ms), per_second(r->triangles, r->hw_ms),
                per_second(r->triangles, r->sw_ms), i + 1 < o->size_count ? "," : "");
    }
    fprintf(f, "  ],\n  \"scene\": {\"instances\": %u, \"triangles\": %u, \"lod_error_px\": %g, \"runs\": [\n",
            o->instances, o->triangles, (double)o->lod_error);
    for (uint32_t i = 0; i < scene_count; i++) {
        const scene_result *s = &scenes[i];
        fprintf(f, "    {\"raster\": \"%s\", \"sw_threshold_px\": %g, \"gpu_ms_per_frame\": %.4f, \"cull_ms\": %.4f, \"hw_ms\": %.4f, "
                   "\"sw_ms\": %.4f, \"resolve_ms\": %.4f, \"sw_clusters\": %u, \"hw_clusters\": %u, "
                   "\"sw_triangles\": %llu, \"hw_triangles\": %llu}%s\n",
                s->raster, (double)s->threshold, s->gpu_ms, s->cull_ms, s->hw_ms, s->sw_ms, s->resolve_ms,
                s->sw_clusters, s->hw_clusters, (unsigned long long)s->sw_triangles, (unsigned long long)s->hw_triangles,
                i + 1 < scene_count ? "," : "");
    }
    fprintf(f, "  ]}\n}\n");
}

int main(int argc, char **argv)
{
    options o;
    if (!parse_options(argc, argv, &o)) {
        fprintf(stderr, "usage: raster_bench [--device NAME|INDEX] [--width W] [--height H] [--frames N] "
                        "[--sizes 1,3,6,12] [--instances N] [--triangles T] [--lod-error PX] "
                        "[--thresholds 2,4,8,16] [--validate] [--json FILE]\n");
        return 2;
    }
    gdr_error err = {0};
    field_result fields[MAX_LIST];
    scene_result scenes[MAX_LIST + 1];
    uint32_t scene_count = 0;
    printf("triangle fields at %ux%u, %u frames each (GPU ms of the rasteriser; triangles/s)\n", o.width, o.height,
           o.frames);
    printf("%8s %12s %10s %10s %10s %10s %12s %12s %12s\n", "size_px", "triangles", "forward", "hw", "sw", "resolve",
           "forward/s", "hw/s", "sw/s");
    for (uint32_t i = 0; i < o.size_count; i++) {
        if (run_field(&o, o.sizes[i], &fields[i], &err) != GDR_OK) {
            fprintf(stderr, "raster_bench: field %g px: %s\n", (double)o.sizes[i], err.message);
            return 1;
        }
        const field_result *r = &fields[i];
        printf("%8g %12llu %10.3f %10.3f %10.3f %10.3f %12.4g %12.4g %12.4g\n", (double)r->size_px,
               (unsigned long long)r->triangles, r->forward_ms, r->hw_ms, r->sw_ms, r->resolve_ms,
               per_second(r->triangles, r->forward_ms), per_second(r->triangles, r->hw_ms),
               per_second(r->triangles, r->sw_ms));
    }
    printf("\nlod-field: %u instances of %u triangles, LOD error %g px, %ux%u (GPU ms per frame)\n", o.instances,
           o.triangles, (double)o.lod_error, o.width, o.height);
    if (run_scene(&o, scenes, &scene_count, &err) != GDR_OK) {
        fprintf(stderr, "raster_bench: lod-field: %s\n", err.message);
        return 1;
    }
    printf("%8s %10s %10s %10s %10s %10s %10s %22s %22s\n", "raster", "threshold", "frame", "cull", "hw", "sw",
           "resolve", "sw clusters/triangles", "hw clusters/triangles");
    for (uint32_t i = 0; i < scene_count; i++) {
        const scene_result *s = &scenes[i];
        char sw[32], hw[32];
        snprintf(sw, sizeof sw, "%u/%llu", s->sw_clusters, (unsigned long long)s->sw_triangles);
        snprintf(hw, sizeof hw, "%u/%llu", s->hw_clusters, (unsigned long long)s->hw_triangles);
        printf("%8s %10g %10.3f %10.3f %10.3f %10.3f %10.3f %22s %22s\n", s->raster, (double)s->threshold, s->gpu_ms,
               s->cull_ms, s->hw_ms, s->sw_ms, s->resolve_ms, sw, hw);
    }
    if (scene_count > 1)
        printf("hybrid (%g px) vs hw: %.2fx faster per frame\n", (double)scenes[1].threshold,
               scenes[1].gpu_ms > 0.0 ? scenes[0].gpu_ms / scenes[1].gpu_ms : 0.0);
    if (o.json) {
        FILE *f = fopen(o.json, "w");
        if (!f) {
            fprintf(stderr, "raster_bench: cannot write %s\n", o.json);
            return 1;
        }
        write_json(f, &o, fields, scenes, scene_count, device_name);
        fclose(f);
    }
    write_json(stdout, &o, fields, scenes, scene_count, device_name);
    return 0;
}
