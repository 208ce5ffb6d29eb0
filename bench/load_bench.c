/* Loading benchmark: wall time of each step from nothing to the first frame of a scene, as
 * `gdr render SCENE --frames 1` takes them (load the scene, create the renderer, give it the
 * scene, render one frame), and the process's peak resident memory after loading and after the
 * frame. One scene per run, since peak memory only grows: run it once per size. Prints a table
 * and JSON.
 *
 * usage: load_bench [--scene SPEC] [--json FILE]   (default lod-field:instances=100000) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "gdr/renderer.h"
#include "gdr/io.h"
#include "gdr/scene.h"

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec;
}

static double peak_rss_mb(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_maxrss / 1024.0; /* kilobytes on Linux */
}

int main(int argc, char **argv)
{
    const char *spec = "lod-field:instances=100000", *json_path = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--scene") && i + 1 < argc)
            spec = argv[++i];
        else if (!strcmp(argv[i], "--json") && i + 1 < argc)
            json_path = argv[++i];
        else {
            fprintf(stderr, "usage: load_bench [--scene SPEC] [--json FILE]\n");
            return 2;
        }
    }
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_renderer *renderer = NULL;
    double t0 = now_ms();
    if (gdr_scene_load(spec, &(gdr_load_options){.no_progress = 1}, &scene, &err) != GDR_OK) {
        fprintf(stderr, "load_bench: %s\n", err.message);
        return 1;
    }
    double t1 = now_ms();
    if (gdr_renderer_create(&(gdr_renderer_desc){0}, &renderer, &err) != GDR_OK) {
        fprintf(stderr, "load_bench: %s\n", err.message);
        return 1;
    }
    double t2 = now_ms();
    if (gdr_renderer_set_scene(renderer, scene, &err) != GDR_OK) {
        fprintf(stderr, "load_bench: %s\n", err.message);
        return 1;
    }
    double t3 = now_ms(), rss_loaded = peak_rss_mb();
    gdr_frame_desc frame = {.camera = gdr_scene_framing_camera(scene), .lod_error_px = 1.0f};
    if (gdr_renderer_render(renderer, &frame, 1, NULL, &err) != GDR_OK) {
        fprintf(stderr, "load_bench: %s\n", err.message);
        return 1;
    }
    double t4 = now_ms(), rss_frame = peak_rss_mb();
    uint32_t instances = scene->instance_count;
    double to_first_frame = t3 - t0;
    printf("scene %s: %u instances\n", spec, instances);
    printf("  scene load %.0f ms, renderer create %.0f ms, set_scene %.0f ms: first frame starts after %.0f ms "
           "(%.2f us per instance)\n", t1 - t0, t2 - t1, t3 - t2, to_first_frame, 1e3 * to_first_frame / instances);
    printf("  first frame %.0f ms; peak resident memory %.0f MB loaded (%.0f bytes per instance), %.0f MB after "
           "the frame\n", t4 - t3, rss_loaded, rss_loaded * 1048576.0 / instances, rss_frame);
    if (json_path) {
        FILE *json = fopen(json_path, "w");
        if (json) {
            fprintf(json, "{\"scene\": \"%s\", \"instances\": %u, \"scene_load_ms\": %.1f, \"renderer_create_ms\": "
                    "%.1f, \"set_scene_ms\": %.1f, \"first_frame_ms\": %.1f, \"peak_rss_loaded_mb\": %.1f, "
                    "\"peak_rss_frame_mb\": %.1f}\n", spec, instances, t1 - t0, t2 - t1, t3 - t2, t4 - t3,
                    rss_loaded, rss_frame);
            fclose(json);
        }
    }
    gdr_renderer_destroy(renderer);
    gdr_scene_destroy(scene);
    return 0;
}
