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

int gdr_cmd_bench(int argc, char **argv)
{
    uint32_t sizes[MAX_SIZES] = {1000, 10000, 100000, 1000000}, size_count = 4;
    uint32_t frames = 20, width = 1920, height = 1080;
    const char *device = NULL, *json_path = NULL, *scene_spec = NULL, *path_file = NULL, *plot_path = NULL, *plot_from = NULL;
    camera_path path = {0};
    float lod_errors[MAX_LOD_ERRORS] = {1.0f};
    uint32_t lod_error_count = 1;
    bool occlusion_modes[2] = {true, false}, occlusion_given = false;
    uint32_t occlusion_count = 1;
    bool validate = false, has_camera = false, record_every_frame = false, lod_hierarchy = true;
    gdr_pipeline pipelines[3] = {GDR_PIPELINE_DEFAULT};
    uint32_t pipeline_count = 1;
    gdr_vec3 camera_position;
    gdr_quat camera_rotation;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i], *value;
        if (strcmp(arg, "--validate") == 0) {
            validate = true;
            continue;
        }
        if (strcmp(arg, "--record-every-frame") == 0) {
            record_every_frame = true;
            continue;
        }
        /* The options that take a value (an unknown one is reported as such). */
        static const char *const known[] = {
            "--sizes", "--frames", "--width", "--height", "--device", "--camera", "--json", "--scene",
            "--camera-path", "--plot", "--plot-from", "--lod-hierarchy", "--lod-errors", "--occlusion",
            "--pipelines", NULL};
        if (!(value = cli_known_value("bench", known, argc, argv, &i)))
            return 2;
        bool ok = true;
        if (strcmp(arg, "--sizes") == 0)
            ok = parse_sizes(value, sizes, &size_count);
        else if (strcmp(arg, "--frames") == 0)
            ok = cli_parse_u32(arg, value, 1, 100000, &frames);
        else if (strcmp(arg, "--width") == 0)
            ok = cli_parse_u32(arg, value, 1, 16384, &width);
        else if (strcmp(arg, "--height") == 0)
            ok = cli_parse_u32(arg, value, 1, 16384, &height);
        else if (strcmp(arg, "--device") == 0)
            device = value;
        else if (strcmp(arg, "--camera") == 0)
            ok = has_camera = cli_parse_camera(arg, value, &camera_position, &camera_rotation);
        else if (strcmp(arg, "--json") == 0)
            json_path = value;
        else if (strcmp(arg, "--scene") == 0)
            scene_spec = value;
        else if (strcmp(arg, "--camera-path") == 0)
            path_file = value;
        else if (strcmp(arg, "--plot") == 0)
            plot_path = value;
        else if (strcmp(arg, "--plot-from") == 0)
            plot_from = value;
        else if (strcmp(arg, "--lod-hierarchy") == 0)
            ok = cli_parse_on_off(arg, value, &lod_hierarchy);
        else if (strcmp(arg, "--lod-errors") == 0)
            ok = parse_lod_errors(value, lod_errors, &lod_error_count);
        else if (strcmp(arg, "--occlusion") == 0) {
            /* on, off, or both side by side */
            occlusion_given = true;
            occlusion_count = strcmp(value, "on,off") == 0 || strcmp(value, "off,on") == 0 ? 2 : 1;
            if (occlusion_count == 2)
                occlusion_modes[0] = value[1] == 'n', occlusion_modes[1] = !occlusion_modes[0];
            else
                ok = cli_parse_on_off(arg, value, &occlusion_modes[0]);
        }
        else if (strcmp(arg, "--pipelines") == 0) {
            char list[64];
            snprintf(list, sizeof list, "%s", value);
            pipeline_count = 0;
            for (char *save = NULL, *item = strtok_r(list, ",", &save); item && ok; item = strtok_r(NULL, ",", &save)) {
                if (pipeline_count == 3) {
                    fprintf(stderr, "gdr: --pipelines: at most 3\n");
                    return 2;
                }
                ok = cli_parse_pipeline(arg, item, &pipelines[pipeline_count++]);
            }
            if (ok && pipeline_count == 0) {
                fprintf(stderr, "gdr: --pipelines '%s': no pipeline named (expected mesh, indirect or cpu, "
                        "comma-separated)\n", value);
                ok = false;
            }
        }
        else {
            fprintf(stderr, "gdr bench: unknown option '%s' (see gdr --help)\n", arg);
            return 2;
        }
        if (!ok)
            return 2;
    }

    gdr_error path_err = {0};
    if (plot_from) { /* plot an earlier run's JSON, run nothing */
        if (!plot_path) {
            fprintf(stderr, "gdr bench: --plot-from needs --plot FILE.svg\n");
            return 2;
        }
        if (bench_plot_from_json(plot_from, plot_path, &path_err) != GDR_OK) {
            fprintf(stderr, "gdr: %s\n", path_err.message);
            return 1;
        }
        printf("plot                %s\n", plot_path);
        return 0;
    }
    if (path_file && camera_path_read(path_file, &path, &path_err) != GDR_OK) {
        fprintf(stderr, "gdr: --camera-path: %s\n", path_err.message);
        return 1;
    }
    cJSON *rows = cJSON_CreateArray();
    if (scene_spec)
        size_count = 1; /* the one scene given */
    printf("%10s %9s %7s %4s %10s %12s %10s %10s %10s %10s %10s %10s %10s %10s\n", "instances", "pipeline", "lod_px", "occl",
           "visible",
           "triangles", "meshlets", "cpu_ms", "cpu_median", "submit_ms", "gpu_update", "gpu_cull", "gpu_draw",
           "gpu_frame");
    double first_cpu = 0.0;
    int result = 0;
    for (uint32_t s = 0; s < size_count && result == 0; s++) {
        gdr_error err = {0};
        gdr_scene *scene = NULL;
        gdr_renderer *renderer = NULL;
        gdr_frame_stats stats;
        gdr_demo_desc demo = {.instances = sizes[s]};
        gdr_renderer_desc desc = {.width = width, .height = height, .device = device, .validate = validate,
                                  .busy_wait = true, .record_every_frame = record_every_frame};
        gdr_pvs *pvs = NULL; /* a cache's precomputed visibility culls as in gdr render (on by default) */
        gdr_load_options load = {.pvs = &pvs};
        gdr_status loaded = scene_spec ? gdr_scene_load(scene_spec, &load, &scene, &err) : gdr_scene_create_demo(&demo, &scene, &err);
        if (loaded != GDR_OK) {
            result = cli_load_failed(scene_spec ? scene_spec : "demo", &err);
        } else if (gdr_renderer_create(&desc, &renderer, &err) != GDR_OK) {
            result = cli_renderer_failed(&err); /* 2 for a --device the machine does not have */
        } else if (gdr_renderer_set_scene(renderer, scene, &err) != GDR_OK ||
                   gdr_renderer_set_pvs(renderer, pvs, &err) != GDR_OK) {
            fprintf(stderr, "gdr: %s\n", err.message);
            result = 1;
        }
        /* Every pipeline and LOD threshold on the same scene, renderer and camera, one after the other. */
        for (uint32_t run = 0; run < pipeline_count * lod_error_count * occlusion_count && result == 0; run++) {
            uint32_t p = run / (lod_error_count * occlusion_count);
            bool occlusion = occlusion_modes[run % occlusion_count];
            gdr_camera camera = scene->camera_count > 0 ? scene->cameras[0] : gdr_scene_framing_camera(scene);
            gdr_frame_desc frame = {.camera = camera, .cull = GDR_CULL_ON, .pipeline = pipelines[p],
                                    .lod_error_px = lod_errors[run / occlusion_count % lod_error_count],
                                    .occlusion = !occlusion_given ? GDR_CULL_DEFAULT
                                                 : occlusion      ? GDR_CULL_ON
                                                                  : GDR_CULL_OFF,
                                    .lod_hierarchy = lod_hierarchy ? GDR_CULL_ON : GDR_CULL_OFF};
            if (has_camera) {
                frame.camera.position = camera_position;
                frame.camera.rotation = camera_rotation;
            }
            if (path.count) { /* a frame per pose, each timed */
                if (bench_run_path(renderer, &frame, &path, rows, &err) != GDR_OK) {
                    fprintf(stderr, "gdr: %s\n", err.message);
                    result = 1;
                }
                continue;
            }
            /* Untimed warm-up frames: first-use costs (pipeline caches, page faults) are not per-frame costs. */
            if (gdr_renderer_render(renderer, &frame, 3, NULL, &err) != GDR_OK ||
                gdr_renderer_render(renderer, &frame, frames, &stats, &err) != GDR_OK) {
                fprintf(stderr, "gdr: %s\n", err.message);
                result = 1;
                break;
            }
            if (s == 0 && run == 0)
                first_cpu = stats.cpu_ms_per_frame_median;
            printf("%10u %9s %7.2f %4s %10u %12llu %10u %10.4f %10.4f %10.4f %10.4f %10.4f %10.4f %10.4f\n",
                   stats.instances_total, gdr_pipeline_name(stats.pipeline),
                   stats.lod.applied ? (double)frame.lod_error_px : 0.0, stats.occlusion.applied ? "on" : "off",
                   stats.instances_visible,
                   (unsigned long long)stats.triangles,
                   stats.meshlets_visible, stats.cpu_ms_per_frame, stats.cpu_ms_per_frame_median,
                   stats.cpu_submit_ms_per_frame, stats.passes[0].gpu_ms, stats.passes[1].gpu_ms, stats.passes[2].gpu_ms,
                   stats.gpu_ms_per_frame);
            fflush(stdout);
            cJSON *row = cJSON_CreateObject();
            cJSON_AddStringToObject(row, "pipeline", gdr_pipeline_name(stats.pipeline));
            cJSON_AddStringToObject(row, "scene", scene_spec ? scene_spec : "demo");
            cJSON_AddNumberToObject(row, "lod_error_px", frame.lod_error_px);
            cJSON_AddNumberToObject(row, "draw_calls", stats.draw_calls);
            cJSON_AddNumberToObject(row, "cpu_cull_ms_per_frame", stats.cpu_cull_ms_per_frame);
            stats_add_meshlet_json(row, &stats);
            stats_add_occlusion_json(row, &stats);
            stats_add_traversal_json(row, &stats);
            stats_add_memory_json(row, &stats);
            cJSON_AddNumberToObject(row, "instances_total", stats.instances_total);
            cJSON_AddNumberToObject(row, "instances_visible", stats.instances_visible);
            cJSON_AddNumberToObject(row, "triangles", (double)stats.triangles);
            cJSON_AddNumberToObject(row, "cpu_ms_per_frame", stats.cpu_ms_per_frame);
            cJSON_AddNumberToObject(row, "cpu_submit_ms_per_frame", stats.cpu_submit_ms_per_frame);
            cJSON_AddNumberToObject(row, "cpu_ms_per_frame_median", stats.cpu_ms_per_frame_median);
            cJSON_AddNumberToObject(row, "cpu_median_ratio_to_first",
                                    first_cpu > 0 ? stats.cpu_ms_per_frame_median / first_cpu : 0);
            cJSON *passes = cJSON_AddObjectToObject(row, "gpu_ms");
            for (uint32_t pass = 0; pass < stats.pass_count; pass++)
                cJSON_AddNumberToObject(passes, stats.passes[pass].name, stats.passes[pass].gpu_ms);
            cJSON_AddNumberToObject(row, "gpu_ms_per_frame", stats.gpu_ms_per_frame);
            cJSON_AddStringToObject(row, "device", stats.device);
            cJSON_AddStringToObject(row, "driver", stats.driver);
            cJSON_AddNumberToObject(row, "validation_messages", stats.validation_messages);
            cJSON_AddItemToArray(rows, row);
            if (stats.validation_messages)
                result = 3;
        }
        gdr_renderer_destroy(renderer);
        cli_pvs_destroy(pvs);
        gdr_scene_destroy(scene);
    }
    char *json = cJSON_Print(rows);
    if (json) {
        gdr_error err = {0};
        printf("%s\n", json);
        if (json_path && gdr_write_file_atomic(json_path, json, strlen(json), &err) != GDR_OK) {
            fprintf(stderr, "gdr: %s\n", err.message);
            result = result ? result : 1;
        }
        free(json);
    }
    gdr_error plot_err = {0};
    if (result == 0 && plot_path && bench_plot_svg(plot_path, rows, path.count > 0, &plot_err) != GDR_OK) {
        fprintf(stderr, "gdr: %s\n", plot_err.message);
        result = 1;
    } else if (result == 0 && plot_path) {
        printf("plot                %s\n", plot_path);
    }
    cJSON_Delete(rows);
    camera_path_free(&path);
    return result;
}
