/* gdr bench: the demo scene at several sizes (or one scene given with --scene), each pipeline and LOD
 * threshold asked for; CPU ms per frame (record + submit) and GPU ms per pass. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "bench_plot.h"
#include "cli_args.h"
#include "cli_pvs.h"
#include "commands.h"
#include "stats_output.h"
#include "gdr/gdr.h"

#define MAX_SIZES 16

static bool parse_sizes(const char *text, uint32_t *sizes, uint32_t *count)
{
    char buffer[256];
    if (strlen(text) >= sizeof buffer) {
        fprintf(stderr, "gdr: --sizes: too long\n");
        return false;
    }
    strcpy(buffer, text);
    *count = 0;
    for (char *save = NULL, *item = strtok_r(buffer, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
        if (*count == MAX_SIZES) {
            fprintf(stderr, "gdr: --sizes: at most %d sizes\n", MAX_SIZES);
            return false;
        }
        if (!cli_parse_u32("--sizes", item, 1, 16000000, &sizes[(*count)++]))
            return false;
    }
    if (*count == 0)
        fprintf(stderr, "gdr: --sizes: no sizes given\n");
    return *count > 0;
}

#define MAX_LOD_ERRORS 8

static bool parse_lod_errors(const char *text, float *errors, uint32_t *count)
{
    char buffer[256];
    snprintf(buffer, sizeof buffer, "%s", text);
    *count = 0;
    for (char *save = NULL, *item = strtok_r(buffer, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
        if (*count == MAX_LOD_ERRORS) {
            fprintf(stderr, "gdr: --lod-errors: at most %d values\n", MAX_LOD_ERRORS);
            return false;
        }
        if (!cli_parse_float("--lod-errors", item, 0.0f, 1e6f, &errors[(*count)++]))
            return false;
    }
    if (*count == 0)
        fprintf(stderr, "gdr: --lod-errors: no values given\n");
    return *count > 0;
}

/* What gdr bench was asked to run. */
typedef struct bench_options {
    uint32_t sizes[MAX_SIZES], size_count;
    uint32_t frames, width, height;
    const char *device, *json_path, *scene_spec, *path_file, *plot_path, *plot_from;
    float lod_errors[MAX_LOD_ERRORS];
    uint32_t lod_error_count;
    bool occlusion_modes[2], occlusion_given;
    uint32_t occlusion_count;
    bool validate, has_camera, record_every_frame, lod_hierarchy, point_level;
    gdr_pipeline pipelines[3];
    uint32_t pipeline_count;
    gdr_vec3 camera_position;
    gdr_quat camera_rotation;
} bench_options;

/* --occlusion on, off, or both side by side. */
static bool parse_occlusion(const char *arg, const char *value, bench_options *o)
{
    o->occlusion_given = true;
    o->occlusion_count = strcmp(value, "on,off") == 0 || strcmp(value, "off,on") == 0 ? 2 : 1;
    if (o->occlusion_count == 1)
        return cli_parse_on_off(arg, value, &o->occlusion_modes[0]);
    o->occlusion_modes[0] = value[1] == 'n', o->occlusion_modes[1] = !o->occlusion_modes[0];
    return true;
}

/* --pipelines mesh,indirect,cpu (at most 3). */
static bool parse_pipelines(const char *arg, const char *value, bench_options *o)
{
    char list[64];
    snprintf(list, sizeof list, "%s", value);
    o->pipeline_count = 0;
    bool ok = true;
    for (char *save = NULL, *item = strtok_r(list, ",", &save); item && ok; item = strtok_r(NULL, ",", &save)) {
        if (o->pipeline_count == 3) {
            fprintf(stderr, "gdr: --pipelines: at most 3\n");
            return false;
        }
        ok = cli_parse_pipeline(arg, item, &o->pipelines[o->pipeline_count++]);
    }
    if (ok && o->pipeline_count == 0) {
        fprintf(stderr, "gdr: --pipelines '%s': no pipeline named (expected mesh, indirect or cpu, "
                "comma-separated)\n", value);
        ok = false;
    }
    return ok;
}

/* One option that takes a value; false (with a message) for a bad value or an unknown option. */
static bool parse_option(const char *arg, const char *value, bench_options *o)
{
    if (strcmp(arg, "--sizes") == 0)
        return parse_sizes(value, o->sizes, &o->size_count);
    if (strcmp(arg, "--frames") == 0)
        return cli_parse_u32(arg, value, 1, 100000, &o->frames);
    if (strcmp(arg, "--width") == 0)
        return cli_parse_u32(arg, value, 1, 16384, &o->width);
    if (strcmp(arg, "--height") == 0)
        return cli_parse_u32(arg, value, 1, 16384, &o->height);
    if (strcmp(arg, "--camera") == 0)
        return o->has_camera = cli_parse_camera(arg, value, &o->camera_position, &o->camera_rotation);
    if (strcmp(arg, "--lod-hierarchy") == 0)
        return cli_parse_on_off(arg, value, &o->lod_hierarchy);
    if (strcmp(arg, "--point-level") == 0)
        return cli_parse_on_off(arg, value, &o->point_level);
    if (strcmp(arg, "--lod-errors") == 0)
        return parse_lod_errors(value, o->lod_errors, &o->lod_error_count);
    if (strcmp(arg, "--occlusion") == 0)
        return parse_occlusion(arg, value, o);
    if (strcmp(arg, "--pipelines") == 0)
        return parse_pipelines(arg, value, o);
    const char **text = strcmp(arg, "--device") == 0        ? &o->device
                        : strcmp(arg, "--json") == 0        ? &o->json_path
                        : strcmp(arg, "--scene") == 0       ? &o->scene_spec
                        : strcmp(arg, "--camera-path") == 0 ? &o->path_file
                        : strcmp(arg, "--plot") == 0        ? &o->plot_path
                        : strcmp(arg, "--plot-from") == 0   ? &o->plot_from
                                                            : NULL;
    if (!text) {
        fprintf(stderr, "gdr bench: unknown option '%s' (see gdr --help)\n", arg);
        return false;
    }
    *text = value;
    return true;
}

/* The command line into *o; 0, or the exit status of a usage error (2). */
static int parse_bench_options(int argc, char **argv, bench_options *o)
{
    *o = (bench_options){.sizes = {1000, 10000, 100000, 1000000}, .size_count = 4, .frames = 20, .width = 1920,
                         .height = 1080, .lod_errors = {1.0f}, .lod_error_count = 1, .occlusion_modes = {true, false},
                         .occlusion_count = 1, .lod_hierarchy = true, .point_level = true, .pipelines = {GDR_PIPELINE_DEFAULT},
                         .pipeline_count = 1};
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i], *value;
        if (strcmp(arg, "--validate") == 0) {
            o->validate = true;
            continue;
        }
        if (strcmp(arg, "--record-every-frame") == 0) {
            o->record_every_frame = true;
            continue;
        }
        /* The options that take a value (an unknown one is reported as such). */
        static const char *const known[] = {
            "--sizes", "--frames", "--width", "--height", "--device", "--camera", "--json", "--scene",
            "--camera-path", "--plot", "--plot-from", "--lod-hierarchy", "--point-level", "--lod-errors", "--occlusion",
            "--pipelines", NULL};
        if (!(value = cli_known_value("bench", known, argc, argv, &i)) || !parse_option(arg, value, o))
            return 2;
    }
    return 0;
}

/* Run `run`'s frame description: its pipeline, LOD threshold and occlusion, on the scene's camera
 * (or --camera's). */
static gdr_frame_desc run_frame(const bench_options *o, const gdr_scene *scene, uint32_t run)
{
    uint32_t p = run / (o->lod_error_count * o->occlusion_count);
    bool occlusion = o->occlusion_modes[run % o->occlusion_count];
    gdr_camera camera = scene->camera_count > 0 ? scene->cameras[0] : gdr_scene_framing_camera(scene);
    gdr_frame_desc frame = {.camera = camera, .cull = GDR_CULL_ON, .pipeline = o->pipelines[p],
                            .lod_error_px = o->lod_errors[run / o->occlusion_count % o->lod_error_count],
                            .occlusion = !o->occlusion_given ? GDR_CULL_DEFAULT
                                         : occlusion         ? GDR_CULL_ON
                                                             : GDR_CULL_OFF,
                            .lod_hierarchy = o->lod_hierarchy ? GDR_CULL_ON : GDR_CULL_OFF,
                            .point_level = o->point_level ? GDR_CULL_ON : GDR_CULL_OFF};
    if (o->has_camera) {
        frame.camera.position = o->camera_position;
        frame.camera.rotation = o->camera_rotation;
    }
    return frame;
}

static void print_header(void)
{
    printf("%10s %9s %7s %4s %10s %12s %10s %10s %10s %10s %10s %10s %10s %10s\n", "instances", "pipeline", "lod_px",
           "occl", "visible", "triangles", "meshlets", "cpu_ms", "cpu_median", "submit_ms", "gpu_update", "gpu_cull",
           "gpu_draw", "gpu_frame");
}

static void print_row(const gdr_frame_stats *stats, const gdr_frame_desc *frame)
{
    printf("%10u %9s %7.2f %4s %10u %12llu %10u %10.4f %10.4f %10.4f %10.4f %10.4f %10.4f %10.4f\n",
           stats->instances_total, gdr_pipeline_name(stats->pipeline),
           stats->lod.applied ? (double)frame->lod_error_px : 0.0, stats->occlusion.applied ? "on" : "off",
           stats->instances_visible, (unsigned long long)stats->triangles, stats->meshlets_visible,
           stats->cpu_ms_per_frame, stats->cpu_ms_per_frame_median, stats->cpu_submit_ms_per_frame,
           stats->passes[0].gpu_ms, stats->passes[1].gpu_ms, stats->passes[2].gpu_ms, stats->gpu_ms_per_frame);
    fflush(stdout);
}

/* One timed run's JSON row; first_cpu is the first run's median CPU ms (the ratio's base). */
static cJSON *row_json(const gdr_frame_stats *stats, const gdr_frame_desc *frame, const char *scene, double first_cpu)
{
    cJSON *row = cJSON_CreateObject();
    cJSON_AddStringToObject(row, "pipeline", gdr_pipeline_name(stats->pipeline));
    cJSON_AddStringToObject(row, "scene", scene);
    cJSON_AddNumberToObject(row, "lod_error_px", frame->lod_error_px);
    cJSON_AddNumberToObject(row, "draw_calls", stats->draw_calls);
    cJSON_AddNumberToObject(row, "cpu_cull_ms_per_frame", stats->cpu_cull_ms_per_frame);
    stats_add_meshlet_json(row, stats);
    stats_add_occlusion_json(row, stats);
    stats_add_traversal_json(row, stats);
    stats_add_memory_json(row, stats);
    cJSON_AddNumberToObject(row, "instances_total", stats->instances_total);
    cJSON_AddNumberToObject(row, "instances_visible", stats->instances_visible);
    cJSON_AddNumberToObject(row, "triangles", (double)stats->triangles);
    cJSON_AddNumberToObject(row, "cpu_ms_per_frame", stats->cpu_ms_per_frame);
    cJSON_AddNumberToObject(row, "cpu_submit_ms_per_frame", stats->cpu_submit_ms_per_frame);
    cJSON_AddNumberToObject(row, "cpu_ms_per_frame_median", stats->cpu_ms_per_frame_median);
    cJSON_AddNumberToObject(row, "cpu_median_ratio_to_first",
                            first_cpu > 0 ? stats->cpu_ms_per_frame_median / first_cpu : 0);
    cJSON *passes = cJSON_AddObjectToObject(row, "gpu_ms");
    for (uint32_t pass = 0; pass < stats->pass_count; pass++)
        cJSON_AddNumberToObject(passes, stats->passes[pass].name, stats->passes[pass].gpu_ms);
    cJSON_AddNumberToObject(row, "gpu_ms_per_frame", stats->gpu_ms_per_frame);
    cJSON_AddStringToObject(row, "device", stats->device);
    cJSON_AddStringToObject(row, "driver", stats->driver);
    cJSON_AddNumberToObject(row, "validation_messages", stats->validation_messages);
    return row;
}

/* The scene of size index `s` (the demo at sizes[s], or the scene given), loaded with its cache's PVS,
 * on a renderer of its own; 0, or the exit status. */
static int open_scene(const bench_options *o, uint32_t s, gdr_scene **scene, gdr_pvs **pvs, gdr_renderer **renderer)
{
    gdr_error err = {0};
    gdr_demo_desc demo = {.instances = o->sizes[s]};
    gdr_renderer_desc desc = {.width = o->width, .height = o->height, .device = o->device, .validate = o->validate,
                              .busy_wait = true, .record_every_frame = o->record_every_frame,
                              .disable_texture_compression_bc = cli_bc_textures_disabled()};
    gdr_load_options load = {.pvs = pvs}; /* a cache's precomputed visibility culls as in gdr render */
    gdr_status loaded = o->scene_spec ? gdr_scene_load(o->scene_spec, &load, scene, &err)
                                      : gdr_scene_create_demo(&demo, scene, &err);
    if (loaded != GDR_OK)
        return cli_load_failed(o->scene_spec ? o->scene_spec : "demo", &err);
    if (gdr_renderer_create(&desc, renderer, &err) != GDR_OK)
        return cli_renderer_failed(&err); /* 2 for a --device the machine does not have */
    if (gdr_renderer_set_scene(*renderer, *scene, &err) != GDR_OK || gdr_renderer_set_pvs(*renderer, *pvs, &err) != GDR_OK) {
        fprintf(stderr, "gdr: %s\n", err.message);
        return 1;
    }
    return 0;
}

/* Every pipeline, LOD threshold and occlusion mode on scene size `s`, one after the other on the same
 * scene, renderer and camera: a row each (a row per pose along a camera path); 0, or the exit status. */
static int run_scene(const bench_options *o, uint32_t s, const camera_path *path, cJSON *rows, double *first_cpu)
{
    gdr_scene *scene = NULL;
    gdr_pvs *pvs = NULL;
    gdr_renderer *renderer = NULL;
    int result = open_scene(o, s, &scene, &pvs, &renderer);
    for (uint32_t run = 0; run < o->pipeline_count * o->lod_error_count * o->occlusion_count && result == 0; run++) {
        gdr_error err = {0};
        gdr_frame_desc frame = run_frame(o, scene, run);
        gdr_frame_stats stats;
        if (path->count) { /* a frame per pose, each timed */
            if (bench_run_path(renderer, &frame, path, rows, &err) != GDR_OK) {
                fprintf(stderr, "gdr: %s\n", err.message);
                result = 1;
            }
            continue;
        }
        /* Untimed warm-up frames: first-use costs (pipeline caches, page faults) are not per-frame costs. */
        if (gdr_renderer_render(renderer, &frame, 3, NULL, &err) != GDR_OK ||
            gdr_renderer_render(renderer, &frame, o->frames, &stats, &err) != GDR_OK) {
            fprintf(stderr, "gdr: %s\n", err.message);
            result = 1;
            break;
        }
        if (s == 0 && run == 0)
            *first_cpu = stats.cpu_ms_per_frame_median;
        print_row(&stats, &frame);
        cJSON_AddItemToArray(rows, row_json(&stats, &frame, o->scene_spec ? o->scene_spec : "demo", *first_cpu));
        if (stats.validation_messages)
            result = 3;
    }
    gdr_renderer_destroy(renderer);
    cli_pvs_destroy(pvs);
    gdr_scene_destroy(scene);
    return result;
}

/* --plot-from: an earlier run's JSON plotted, nothing run. */
static int plot_earlier_run(const bench_options *o)
{
    gdr_error err = {0};
    if (!o->plot_path) {
        fprintf(stderr, "gdr bench: --plot-from needs --plot FILE.svg\n");
        return 2;
    }
    if (bench_plot_from_json(o->plot_from, o->plot_path, &err) != GDR_OK) {
        fprintf(stderr, "gdr: %s\n", err.message);
        return 1;
    }
    printf("plot                %s\n", o->plot_path);
    return 0;
}

/* The rows printed as JSON, written to --json and plotted to --plot; the exit status given the runs'. */
static int write_results(const bench_options *o, const cJSON *rows, bool along_path, int result)
{
    char *json = cJSON_Print(rows);
    if (json) {
        gdr_error err = {0};
        printf("%s\n", json);
        if (o->json_path && gdr_write_file_atomic(o->json_path, json, strlen(json), &err) != GDR_OK) {
            fprintf(stderr, "gdr: %s\n", err.message);
            result = result ? result : 1;
        }
        free(json);
    }
    gdr_error plot_err = {0};
    if (result == 0 && o->plot_path && bench_plot_svg(o->plot_path, rows, along_path, &plot_err) != GDR_OK) {
        fprintf(stderr, "gdr: %s\n", plot_err.message);
        result = 1;
    } else if (result == 0 && o->plot_path) {
        printf("plot                %s\n", o->plot_path);
    }
    return result;
}

int gdr_cmd_bench(int argc, char **argv)
{
    bench_options o;
    int usage = parse_bench_options(argc, argv, &o);
    if (usage)
        return usage;
    if (o.plot_from)
        return plot_earlier_run(&o);
    camera_path path = {0};
    gdr_error path_err = {0};
    if (o.path_file && camera_path_read(o.path_file, &path, &path_err) != GDR_OK) {
        fprintf(stderr, "gdr: --camera-path: %s\n", path_err.message);
        return 1;
    }
    cJSON *rows = cJSON_CreateArray();
    if (o.scene_spec)
        o.size_count = 1; /* the one scene given */
    print_header();
    double first_cpu = 0.0;
    int result = 0;
    for (uint32_t s = 0; s < o.size_count && result == 0; s++)
        result = run_scene(&o, s, &path, rows, &first_cpu);
    result = write_results(&o, rows, path.count > 0, result);
    cJSON_Delete(rows);
    camera_path_free(&path);
    return result;
}
