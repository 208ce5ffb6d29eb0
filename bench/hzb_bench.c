/* Depth pyramid (HZB) build time, measured with timestamp queries around each build:
 * median, minimum and maximum of N builds per depth size, after warm-up builds, all in one command
 * buffer (each build waits for the previous one through its own barriers). Prints a table and JSON.
 * usage: hzb_bench [--device NAME|INDEX] [--runs N] [--sizes WxH,WxH,...] [--validate] [--json FILE]
 * GPU figures for docs/PERFORMANCE.md come from a real GPU only (the H100), not from lavapipe. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/hzb.h"
#include "vk/vk_buffer.h"
#include "vk/vk_image.h"

#define WARMUP_BUILDS 5
#define MAX_SIZES 16

typedef struct bench_result {
    uint32_t depth_width, depth_height, width, height, levels;
    double median_ms, min_ms, max_ms;
} bench_result;

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static gdr_status fill_depth(gdr_vk_context *ctx, gdr_vk_buffer *upload, gdr_vk_image *depth, gdr_error *err)
{
    /* A plausible depth buffer: a smooth slope with noise, in [0, 1]. */
    float *values = upload->mapped;
    unsigned state = 1;
    for (uint32_t y = 0; y < depth->height; y++)
        for (uint32_t x = 0; x < depth->width; x++) {
            state = state * 1664525u + 1013904223u;
            values[(size_t)y * depth->width + x] = 0.5f * (float)y / (float)depth->height + 0.25f * (float)(state >> 8) / 16777216.0f;
        }
    VkCommandBuffer cmd;
    gdr_status status = gdr_vk_begin_one_time(ctx, &cmd, err);
    if (status != GDR_OK)
        return status;
    gdr_vk_image_barrier(cmd, depth->image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
                         VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    VkBufferImageCopy region = {.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1},
                                .imageExtent = {depth->width, depth->height, 1}};
    vkCmdCopyBufferToImage(cmd, upload->buffer, depth->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    gdr_vk_image_barrier(cmd, depth->image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                         GDR_HZB_DEPTH_READ_STAGE, GDR_HZB_DEPTH_READ_ACCESS);
    return gdr_vk_end_one_time(ctx, cmd, err);
}

static gdr_status time_builds(gdr_vk_context *ctx, const gdr_hzb *hzb, uint32_t runs, double *ms, gdr_error *err)
{
    VkQueryPoolCreateInfo pool_info = {.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
                                       .queryType = VK_QUERY_TYPE_TIMESTAMP, .queryCount = 2 * runs};
    VkQueryPool pool;
    GDR_VK_TRY(err, vkCreateQueryPool(ctx->device, &pool_info, NULL, &pool));
    vkResetQueryPool(ctx->device, pool, 0, 2 * runs);
    VkCommandBuffer cmd;
    gdr_status status = gdr_vk_begin_one_time(ctx, &cmd, err);
    if (status == GDR_OK) {
        for (uint32_t i = 0; i < WARMUP_BUILDS; i++)
            gdr_hzb_record_build(hzb, cmd, 0);
        for (uint32_t i = 0; i < runs; i++) {
            /* ALL_COMMANDS: the first stamp waits for everything before, the second for the build. */
            vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool, 2 * i);
            gdr_hzb_record_build(hzb, cmd, 0);
            vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool, 2 * i + 1);
        }
        status = gdr_vk_end_one_time(ctx, cmd, err);
    }
    uint64_t *stamps = calloc(2 * runs, sizeof *stamps);
    if (status == GDR_OK && !stamps)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
    if (status == GDR_OK) {
        VkResult result = vkGetQueryPoolResults(ctx->device, pool, 0, 2 * runs, 2 * runs * sizeof *stamps, stamps,
                                                sizeof *stamps, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
        if (result != VK_SUCCESS)
            status = gdr_error_set(err, GDR_ERROR_VULKAN, "vkGetQueryPoolResults: %s", gdr_vk_result_name(result));
    }
    if (status == GDR_OK)
        for (uint32_t i = 0; i < runs; i++)
            ms[i] = (double)(stamps[2 * i + 1] - stamps[2 * i]) * ctx->properties.limits.timestampPeriod * 1e-6;
    free(stamps);
    vkDestroyQueryPool(ctx->device, pool, NULL);
    return status;
}

static gdr_status bench_size(gdr_vk_context *ctx, uint32_t width, uint32_t height, uint32_t runs, bench_result *out,
                             gdr_error *err)
{
    gdr_vk_allocator allocator;
    gdr_vk_allocator_init(&allocator, ctx);
    gdr_vk_image depth = {0};
    gdr_vk_buffer upload = {0};
    gdr_hzb hzb = {0};
    double *ms = calloc(runs, sizeof *ms);
    gdr_status status = ms ? GDR_OK : gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
    if (status == GDR_OK)
        status = gdr_vk_image_create(&allocator, &(gdr_vk_image_desc){.width = width, .height = height, .format = VK_FORMAT_D32_SFLOAT,
                                  .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                           VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                                  .aspect = VK_IMAGE_ASPECT_DEPTH_BIT}, &depth, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&allocator, (VkDeviceSize)width * height * sizeof(float),
                                      VK_BUFFER_USAGE_TRANSFER_SRC_BIT, GDR_VK_BUFFER_UPLOAD, &upload, err);
    if (status == GDR_OK)
        status = fill_depth(ctx, &upload, &depth, err);
    gdr_hzb_desc desc = {.depth_width = width, .depth_height = height, .depth_view = depth.view};
    if (status == GDR_OK)
        status = gdr_hzb_create(ctx, &allocator, &desc, &hzb, err);
    if (status == GDR_OK)
        status = time_builds(ctx, &hzb, runs, ms, err);
    if (status == GDR_OK) {
        qsort(ms, runs, sizeof *ms, compare_double);
        *out = (bench_result){.depth_width = width, .depth_height = height, .width = hzb.width, .height = hzb.height,
                        .levels = hzb.level_count, .min_ms = ms[0], .max_ms = ms[runs - 1],
                        .median_ms = runs % 2 ? ms[runs / 2] : 0.5 * (ms[runs / 2 - 1] + ms[runs / 2])};
    }
    gdr_hzb_destroy(&hzb);
    gdr_vk_buffer_destroy(ctx, &upload);
    gdr_vk_image_destroy(ctx, &depth);
    gdr_vk_allocator_destroy(&allocator);
    free(ms);
    return status;
}

/* JSON string contents: drops quotes, backslashes and control characters. */
static void json_clean(char *s)
{
    char *w = s;
    for (; *s; s++)
        if (*s != '"' && *s != '\\' && (unsigned char)*s >= 0x20)
            *w++ = *s;
    *w = '\0';
}

int main(int argc, char **argv)
{
    const char *device = NULL, *json_path = NULL, *sizes_arg = "1920x1080,3840x2160";
    long runs = 50;
    bool validate = false;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--device") == 0 && i + 1 < argc)
            device = argv[++i];
        else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc)
            runs = strtol(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--sizes") == 0 && i + 1 < argc)
            sizes_arg = argv[++i];
        else if (strcmp(argv[i], "--json") == 0 && i + 1 < argc)
            json_path = argv[++i];
        else if (strcmp(argv[i], "--validate") == 0)
            validate = true;
        else {
            fprintf(stderr, "usage: hzb_bench [--device NAME|INDEX] [--runs N] [--sizes WxH,WxH,...] [--validate] "
                            "[--json FILE]\n");
            return 2;
        }
    }
    uint32_t sizes[MAX_SIZES][2], size_count = 0;
    for (const char *s = sizes_arg; *s;) {
        unsigned w, h;
        int used = 0;
        if (size_count == MAX_SIZES || sscanf(s, "%ux%u%n", &w, &h, &used) != 2 || w == 0 || h == 0 || w > 16384 ||
            h > 16384 || (s[used] != ',' && s[used] != '\0')) {
            fprintf(stderr, "hzb_bench: --sizes '%s': expected up to %d sizes WxH (1..16384), comma-separated\n",
                    sizes_arg, MAX_SIZES);
            return 2;
        }
        sizes[size_count][0] = w;
        sizes[size_count++][1] = h;
        s += used + (s[used] == ',');
    }
    if (runs < 1 || runs > 10000) {
        fprintf(stderr, "hzb_bench: --runs must be in [1, 10000]\n");
        return 2;
    }

    gdr_error err = {0};
    gdr_vk_context *ctx = NULL;
    gdr_vk_context_desc desc = {.device = device, .validate = validate};
    if (gdr_vk_context_create(&desc, &ctx, &err) != GDR_OK) {
        fprintf(stderr, "hzb_bench: %s\n", err.message);
        return 1;
    }
    bench_result results[MAX_SIZES];
    for (uint32_t i = 0; i < size_count; i++)
        if (bench_size(ctx, sizes[i][0], sizes[i][1], (uint32_t)runs, &results[i], &err) != GDR_OK) {
            fprintf(stderr, "hzb_bench: %ux%u: %s\n", sizes[i][0], sizes[i][1], err.message);
            gdr_vk_context_destroy(ctx);
            return 1;
        }

    char device_name[VK_MAX_PHYSICAL_DEVICE_NAME_SIZE], driver[sizeof ctx->driver_info];
    snprintf(device_name, sizeof device_name, "%s", ctx->properties.deviceName);
    snprintf(driver, sizeof driver, "%s", ctx->driver_info);
    json_clean(device_name);
    json_clean(driver);
    printf("depth pyramid build on %s (%s), %ld timed builds each\n", device_name, driver, runs);
    printf("%-11s %-11s %6s %10s %10s %10s\n", "depth", "pyramid", "levels", "median ms", "min ms", "max ms");
    for (uint32_t i = 0; i < size_count; i++) {
        const bench_result *r = &results[i];
        char depth_size[24], pyramid_size[24];
        snprintf(depth_size, sizeof depth_size, "%ux%u", r->depth_width, r->depth_height);
        snprintf(pyramid_size, sizeof pyramid_size, "%ux%u", r->width, r->height);
        printf("%-11s %-11s %6u %10.4f %10.4f %10.4f\n", depth_size, pyramid_size, r->levels, r->median_ms, r->min_ms,
               r->max_ms);
    }
    FILE *json = json_path ? fopen(json_path, "w") : stdout;
    if (!json) {
        fprintf(stderr, "hzb_bench: cannot write %s\n", json_path);
        gdr_vk_context_destroy(ctx);
        return 1;
    }
    fprintf(json, "{\"bench\": \"hzb\", \"device\": \"%s\", \"driver\": \"%s\", \"runs\": %ld, \"results\": [",
            device_name, driver, runs);
    for (uint32_t i = 0; i < size_count; i++) {
        const bench_result *r = &results[i];
        fprintf(json, "%s{\"depth_width\": %u, \"depth_height\": %u, \"pyramid_width\": %u, \"pyramid_height\": %u, "
                      "\"levels\": %u, \"median_ms\": %.5f, \"min_ms\": %.5f, \"max_ms\": %.5f}",
                i ? ", " : "", r->depth_width, r->depth_height, r->width, r->height, r->levels, r->median_ms, r->min_ms,
                r->max_ms);
    }
    fprintf(json, "]}\n");
    if (json_path)
        fclose(json);
    unsigned messages = ctx->validation_messages;
    gdr_vk_context_destroy(ctx);
    if (validate && messages) {
        fprintf(stderr, "hzb_bench: %u validation message(s)\n", messages);
        return 1;
    }
    return 0;
}
