/* Streaming on the GPU (docs/STREAMING.md, "Benchmarks"): a paged cache drawn whole and streamed
 * through a page pool of --budget MiB, from the scene's camera, then after a jump to the far side
 * of the scene. Reports the time from opening the cache (read without the geometry its pages hold)
 * to the first frame, the bytes the open read, the frames and time
 * to converge (no request left and residency unchanged for 10 frames), the converged GPU frame
 * time against the whole upload's (where the whole fits), and the uploads per frame.
 *     stream_bench SCENE.gdrc --budget MIB [--upload MIB] [--width W] [--height H] [--no-whole]
 *                  [--json FILE]
 * SCENE.gdrc: written with pages (gdr build --pages). GPU figures: timestamp queries. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gdr/gdr.h"
#include "gdr/io.h"
#include "io/loaders.h"

#define MAX_FRAMES 600
#define SETTLED_FRAMES 10
#define TIMED_FRAMES 30
#define WARM_FRAMES 300 /* before the timed frames: the GPU's clocks up after the CPU-only set-up */

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec;
}

typedef struct view_result {
    uint32_t frames_to_converge;
    double converge_ms;       /* wall time of those frames */
    double frame_gpu_ms;      /* mean over TIMED_FRAMES converged frames */
    uint64_t max_upload_bytes; /* the largest frame's uploads */
    uint64_t uploads, evictions;
    uint32_t resident_pages, absent_groups;
    uint64_t triangles;        /* drawn in the last frame */
    uint32_t clusters;
} view_result;

/* Frames of one view until it converges, then WARM_FRAMES, then TIMED_FRAMES more, timed. */
static int converge(gdr_renderer *r, const gdr_frame_desc *frame, view_result *out)
{
    gdr_error err = {0};
    gdr_frame_stats stats;
    *out = (view_result){0};
    uint64_t uploads0 = 0, evictions0 = 0;
    double start = now_ms();
    uint32_t f = 0;
    for (; f < MAX_FRAMES; f++) {
        if (gdr_renderer_render(r, frame, 1, &stats, &err) != GDR_OK) {
            fprintf(stderr, "stream_bench: %s\n", err.message);
            return 0;
        }
        if (f == 0) {
            uploads0 = stats.streaming.uploads_total - stats.streaming.uploads;
            evictions0 = stats.streaming.evictions_total - stats.streaming.evictions;
        }
        if (stats.streaming.upload_bytes > out->max_upload_bytes)
            out->max_upload_bytes = stats.streaming.upload_bytes;
        if (!stats.streaming.enabled ||
            (stats.streaming.requests == 0 && stats.streaming.frames_since_change >= SETTLED_FRAMES))
            break;
    }
    out->frames_to_converge = f + 1;
    out->converge_ms = now_ms() - start;
    out->uploads = stats.streaming.uploads_total - uploads0;
    out->evictions = stats.streaming.evictions_total - evictions0;
    if (gdr_renderer_render(r, frame, WARM_FRAMES, &stats, &err) != GDR_OK ||
        gdr_renderer_render(r, frame, TIMED_FRAMES, &stats, &err) != GDR_OK) {
        fprintf(stderr, "stream_bench: %s\n", err.message);
        return 0;
    }
    out->frame_gpu_ms = stats.gpu_ms_per_frame;
    out->resident_pages = stats.streaming.resident_pages;
    out->absent_groups = (uint32_t)stats.streaming.absent_groups;
    out->triangles = stats.triangles;
    out->clusters = stats.meshlets_visible;
    return 1;
}

static void print_view(FILE *out, const char *name, const view_result *v, const char *tail)
{
    fprintf(out, "    \"%s\": {\"frames_to_converge\": %u, \"converge_ms\": %.1f, \"frame_gpu_ms\": %.4f, "
                 "\"max_upload_bytes\": %llu, \"uploads\": %llu, \"evictions\": %llu, \"resident_pages\": %u, "
                 "\"absent_groups\": %u, \"triangles\": %llu, \"clusters\": %u}%s\n", name, v->frames_to_converge,
            v->converge_ms, v->frame_gpu_ms, (unsigned long long)v->max_upload_bytes, (unsigned long long)v->uploads,
            (unsigned long long)v->evictions, v->resident_pages, v->absent_groups,
            (unsigned long long)v->triangles, v->clusters, tail);
}

typedef struct bench_options {
    const char *path, *json;
    uint32_t budget_mib, upload_mib, width, height;
    int whole;
} bench_options;

/* 0, or 2 after the usage. */
static int parse_options(int argc, char **argv, bench_options *o)
{
    *o = (bench_options){.upload_mib = 16, .width = 2560, .height = 1440, .whole = 1};
    for (int i = 1; i < argc; i++) {
        const char *value = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(argv[i], "--budget") == 0 && value)
            o->budget_mib = (uint32_t)strtoul(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--upload") == 0 && value)
            o->upload_mib = (uint32_t)strtoul(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--width") == 0 && value)
            o->width = (uint32_t)strtoul(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--height") == 0 && value)
            o->height = (uint32_t)strtoul(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--json") == 0 && value)
            o->json = argv[++i];
        else if (strcmp(argv[i], "--no-whole") == 0)
            o->whole = 0;
        else if (argv[i][0] != '-' && !o->path)
            o->path = argv[i];
        else {
            fprintf(stderr, "usage: stream_bench SCENE.gdrc --budget MIB [--upload MIB] [--width W] [--height H] "
                            "[--no-whole] [--json FILE]\n");
            return 2;
        }
    }
    if (!o->path || o->budget_mib == 0 || o->budget_mib > 4096 || o->upload_mib == 0 || !o->width || !o->height) {
        fprintf(stderr, "stream_bench: needs SCENE.gdrc and --budget MIB in [1, 4096]\n");
        return 2;
    }
    return 0;
}

/* The scene loaded whole and uploaded whole, the same two views; *load_ms: the load's time. */
static int run_whole(const bench_options *o, const gdr_frame_desc *frame, const gdr_frame_desc *jump,
                     view_result *a, view_result *b, double *load_ms)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_renderer *r = NULL;
    gdr_load_options load = {.no_progress = 1};
    gdr_renderer_desc desc = {.width = o->width, .height = o->height};
    *load_ms = now_ms();
    int ok = gdr_scene_load(o->path, &load, &scene, &err) == GDR_OK;
    *load_ms = now_ms() - *load_ms;
    ok = ok && gdr_renderer_create(&desc, &r, &err) == GDR_OK && gdr_renderer_set_scene(r, scene, &err) == GDR_OK &&
         converge(r, frame, a) && converge(r, jump, b);
    if (!ok)
        fprintf(stderr, "stream_bench: whole upload: %s\n", err.message);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(scene);
    return ok;
}

/* What a run measured: the open (ms, bytes read), the set-up, the first frame after the open's
 * start, the whole scene's load (with --whole), the first streamed frame's figures and the views. */
typedef struct bench_results {
    double open_ms, setup_ms, first_frame_ms, load_ms;
    uint64_t open_bytes;
    gdr_frame_stats stats;
    view_result whole_a, whole_b, near, far;
} bench_results;

static void print_results(FILE *out, const bench_options *o, const bench_results *res)
{
    const gdr_frame_stats *stats = &res->stats;
    const gdr_streaming_stats *st = &stats->streaming;
    fprintf(out, "{\n    \"scene\": \"%s\", \"device\": \"%s\", \"driver\": \"%s\", \"width\": %u, \"height\": %u,\n",
            o->path, stats->device, stats->driver, o->width, o->height);
    fprintf(out, "    \"budget_mib\": %u, \"upload_mib\": %u, \"pool_bytes\": %llu, \"slot_bytes\": %u, "
                 "\"slots\": %u,\n    \"open_ms\": %.1f, \"open_bytes\": %llu, \"streamed_setup_ms\": %.1f, "
                 "\"first_frame_ms\": %.1f, \"whole_scene_load_ms\": %.1f,\n",
            o->budget_mib, o->upload_mib, (unsigned long long)st->pool_bytes, st->slot_bytes, st->slot_count,
            res->open_ms, (unsigned long long)res->open_bytes, res->setup_ms, res->first_frame_ms, res->load_ms);
    fprintf(out, "    \"setup_steps_ms\": {\"open\": %.1f, \"scene\": %.1f, \"node_counts\": %.1f, "
                 "\"first_pages\": %.1f},\n",
            st->setup_open_ms, st->setup_scene_ms, st->setup_node_counts_ms, st->setup_first_pages_ms);
    if (o->whole) {
        print_view(out, "whole_view", &res->whole_a, ",");
        print_view(out, "whole_jump", &res->whole_b, ",");
    }
    print_view(out, "streamed_view", &res->near, ",");
    print_view(out, "streamed_jump", &res->far, "");
    fprintf(out, "}\n");
}

int main(int argc, char **argv)
{
    bench_options o;
    int usage = parse_options(argc, argv, &o);
    if (usage)
        return usage;
    const char *path = o.path, *json = o.json;
    bench_results res = {0};
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    /* The open: the cache without the geometry its pages hold. */
    double t_open = now_ms();
    if (gdr_cache_read_for_streaming(path, NULL, &scene, NULL, &res.open_bytes, &err) != GDR_OK) {
        fprintf(stderr, "stream_bench: %s\n", err.message);
        return 1;
    }
    res.open_ms = now_ms() - t_open;
    /* View A: the scene's camera; view B: the jump to the far side, looking back. */
    gdr_camera a = scene->camera_count ? scene->cameras[0] : gdr_scene_framing_camera(scene);
    float centre_z = 0.0f;
    for (uint32_t i = 0; i < scene->instance_count; i++)
        centre_z += scene->instances[i].transform.m[14] / (float)scene->instance_count;
    gdr_camera b = a;
    b.position.z = 2.0f * centre_z - a.position.z;
    b.rotation = gdr_quat_mul(gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, 3.14159265f), a.rotation);
    gdr_frame_desc frame = {.camera = a, .pipeline = GDR_PIPELINE_MESH, .lod_error_px = 1.0f};
    gdr_frame_desc jump = frame;
    jump.camera = b;

    gdr_renderer_desc desc = {.width = o.width, .height = o.height};
    gdr_renderer *r = NULL;
    gdr_paged_cache *paged = NULL;
    gdr_streaming_desc stream = {.cache = NULL, .geometry_budget_bytes = (uint64_t)o.budget_mib << 20,
                                 .upload_budget_bytes = (uint64_t)o.upload_mib << 20};
    int ok = gdr_renderer_create(&desc, &r, &err) == GDR_OK;
    if (ok) {
        double t0 = now_ms();
        ok = gdr_paged_cache_open(path, &paged, &err) == GDR_OK;
        stream.cache = paged;
        ok = ok && gdr_renderer_set_scene_streamed(r, scene, &stream, &err) == GDR_OK;
        res.setup_ms = now_ms() - t0;
        ok = ok && gdr_renderer_render(r, &frame, 1, &res.stats, &err) == GDR_OK;
        res.first_frame_ms = res.open_ms + now_ms() - t0; /* from the open's start */
        ok = ok && converge(r, &frame, &res.near) && converge(r, &jump, &res.far);
    }
    if (!ok)
        fprintf(stderr, "stream_bench: streamed: %s\n", err.message);
    gdr_renderer_destroy(r);
    gdr_paged_cache_close(paged);
    /* The whole upload after the streamed run, whose frames have brought the GPU's clocks up. */
    if (ok && o.whole)
        ok = run_whole(&o, &frame, &jump, &res.whole_a, &res.whole_b, &res.load_ms);
    FILE *out = json ? fopen(json, "w") : stdout;
    if (ok && out)
        print_results(out, &o, &res);
    if (out && out != stdout)
        fclose(out);
    gdr_scene_destroy(scene);
    return ok && out ? 0 : 1;
}
