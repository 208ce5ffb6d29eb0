#include "stats_output.h"

#include <cjson/cJSON.h>

void stats_print(FILE *out, const stats_context *context, const gdr_frame_stats *s)
{
    fprintf(out, "scene               %s\n", context->scene);
    fprintf(out, "device              %s (%s)\n", s->device, s->driver);
    fprintf(out, "resolution          %ux%u, %u frame(s), culling %s\n", context->width, context->height, s->frames,
            context->cull);
    fprintf(out, "instances_total     %u\n", s->instances_total);
    fprintf(out, "instances_visible   %u\n", s->instances_visible);
    fprintf(out, "triangles           %llu\n", (unsigned long long)s->triangles);
    fprintf(out, "draws               %u (in %u indirect draw call)\n", s->draws, s->draw_calls);
    fprintf(out, "cpu_ms_per_frame    %.4f (of which vkQueueSubmit2 %.4f)\n", s->cpu_ms_per_frame,
            s->cpu_submit_ms_per_frame);
    fprintf(out, "gpu_ms_per_frame    %.4f\n", s->gpu_ms_per_frame);
    for (uint32_t p = 0; p < s->pass_count; p++)
        fprintf(out, "  gpu_ms.%-16s %.4f\n", s->passes[p].name, s->passes[p].gpu_ms);
    fprintf(out, "validation_messages %u\n", s->validation_messages);
}

char *stats_to_json(const stats_context *context, const gdr_frame_stats *s)
{
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return NULL;
    cJSON_AddStringToObject(root, "scene", context->scene);
    cJSON_AddStringToObject(root, "device", s->device);
    cJSON_AddStringToObject(root, "driver", s->driver);
    cJSON_AddNumberToObject(root, "width", context->width);
    cJSON_AddNumberToObject(root, "height", context->height);
    cJSON_AddNumberToObject(root, "frames", s->frames);
    cJSON_AddStringToObject(root, "cull", context->cull);
    cJSON_AddNumberToObject(root, "instances_total", s->instances_total);
    cJSON_AddNumberToObject(root, "instances_visible", s->instances_visible);
    cJSON_AddNumberToObject(root, "triangles", (double)s->triangles);
    cJSON_AddNumberToObject(root, "draws", s->draws);
    cJSON_AddNumberToObject(root, "draw_calls", s->draw_calls);
    cJSON_AddNumberToObject(root, "cpu_ms_per_frame", s->cpu_ms_per_frame);
    cJSON_AddNumberToObject(root, "cpu_submit_ms_per_frame", s->cpu_submit_ms_per_frame);
    cJSON_AddNumberToObject(root, "cpu_ms_per_frame_median", s->cpu_ms_per_frame_median);
    cJSON_AddNumberToObject(root, "gpu_ms_per_frame", s->gpu_ms_per_frame);
    cJSON *passes = cJSON_AddObjectToObject(root, "gpu_ms");
    for (uint32_t p = 0; passes && p < s->pass_count; p++)
        cJSON_AddNumberToObject(passes, s->passes[p].name, s->passes[p].gpu_ms);
    cJSON_AddNumberToObject(root, "validation_messages", s->validation_messages);
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    return text;
}
