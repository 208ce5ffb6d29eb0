/* gdr bench --camera-path: a frame per pose, timed one by one. */
#include <stdio.h>

#include "bench_plot.h"
#include "stats_output.h"

static void add_row(cJSON *rows, uint32_t index, const gdr_frame_desc *frame, const gdr_frame_stats *stats)
{
    cJSON *row = cJSON_CreateObject();
    cJSON_AddNumberToObject(row, "frame", index);
    cJSON_AddStringToObject(row, "pipeline", gdr_pipeline_name(stats->pipeline));
    cJSON_AddNumberToObject(row, "lod_error_px", frame->lod_error_px);
    cJSON_AddNumberToObject(row, "instances_total", stats->instances_total);
    cJSON_AddNumberToObject(row, "instances_visible", stats->instances_visible);
    cJSON_AddNumberToObject(row, "triangles", (double)stats->triangles);
    cJSON_AddNumberToObject(row, "meshlets_visible", stats->meshlets_visible);
    stats_add_occlusion_json(row, stats);
    cJSON_AddNumberToObject(row, "cpu_ms_per_frame", stats->cpu_ms_per_frame);
    cJSON *passes = cJSON_AddObjectToObject(row, "gpu_ms");
    for (uint32_t p = 0; p < stats->pass_count; p++)
        cJSON_AddNumberToObject(passes, stats->passes[p].name, stats->passes[p].gpu_ms);
    cJSON_AddNumberToObject(row, "gpu_ms_per_frame", stats->gpu_ms_per_frame);
    cJSON_AddStringToObject(row, "device", stats->device);
    cJSON_AddNumberToObject(row, "validation_messages", stats->validation_messages);
    cJSON_AddItemToArray(rows, row);
}

gdr_status bench_run_path(gdr_renderer *renderer, gdr_frame_desc *frame, const camera_path *path, cJSON *rows,
                          gdr_error *err)
{
    frame->camera.position = path->poses[0].position;
    frame->camera.rotation = path->poses[0].rotation;
    gdr_status status = gdr_renderer_render(renderer, frame, 3, NULL, err);
    printf("%6s %9s %10s %12s %10s %10s\n", "frame", "pipeline", "visible", "triangles", "cpu_ms", "gpu_frame");
    for (uint32_t i = 0; i < path->count && status == GDR_OK; i++) {
        gdr_frame_stats stats;
        frame->camera.position = path->poses[i].position;
        frame->camera.rotation = path->poses[i].rotation;
        status = gdr_renderer_render(renderer, frame, 1, &stats, err);
        if (status != GDR_OK)
            break;
        printf("%6u %9s %10u %12llu %10.4f %10.4f\n", i, gdr_pipeline_name(stats.pipeline), stats.instances_visible,
               (unsigned long long)stats.triangles, stats.cpu_ms_per_frame, stats.gpu_ms_per_frame);
        add_row(rows, i, frame, &stats);
        if (stats.validation_messages)
            status = gdr_error_set(err, GDR_ERROR_VULKAN, "the validation layer reported %u message(s)",
                                   stats.validation_messages);
    }
    return status;
}
