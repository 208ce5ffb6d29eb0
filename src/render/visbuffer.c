/* The visibility buffer and the hybrid rasteriser of the mesh pipeline; see visbuffer.h. */
#include "render/visbuffer.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/renderer_internal.h"
#include "vk/vk_pipeline.h"
#include "render/frame.h"
#include "render/frame_record.h"
#include "gpu_shared/point_level.h"

gdr_status gdr_visbuffer_create(gdr_renderer *r, bool disabled, gdr_error *err)
{
    gdr_visbuffer *v = &r->vis;
    /* The parameters always: the mesh pipeline's shaders read the mode even when drawing forward. */
    gdr_status status = GDR_OK;
    for (uint32_t i = 0; i < GDR_FRAMES_IN_FLIGHT && status == GDR_OK; i++)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuRasterParams), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                      GDR_VK_BUFFER_UPLOAD, &v->params[i], err);
    if (status != GDR_OK)
        return status;
    const char *why = NULL;
    if (disabled)
        why = "the visibility buffer was disabled by the caller";
    else if (!r->ctx->has_mesh_shader)
        why = r->ctx->mesh_shader_missing;
    else if (!r->ctx->has_buffer_int64_atomics)
        why = "the device has no 64-bit buffer atomics (shaderBufferInt64Atomics)";
    if (why) {
        snprintf(v->missing, sizeof v->missing, "%s", why);
        return GDR_OK;
    }
    status = gdr_vk_buffer_create(&r->allocator, (VkDeviceSize)r->width * r->height * sizeof(uint64_t),
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                          VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                      GDR_VK_BUFFER_DEVICE, &v->pixels, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuRasterCounters),
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                                          VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                      GDR_VK_BUFFER_DEVICE, &v->counters, err);
    for (uint32_t i = 0; i < GDR_FRAMES_IN_FLIGHT && status == GDR_OK; i++)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuRasterCounters), VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                      GDR_VK_BUFFER_READBACK, &v->counters_readback[i], err);
    v->supported = status == GDR_OK;
    return status;
}

gdr_status gdr_visbuffer_set_scene(gdr_renderer *r, gdr_error *err)
{
    gdr_visbuffer *v = &r->vis;
    if (!v->supported)
        return GDR_OK;
    /* Every cluster of every instance's DAG is the most one frame can draw; the tiny ones go to the
     * part of their size class (or, when it is full, to the front). All parts share the slots a
     * visibility-buffer id can name: beyond that, the tiny parts keep all their clusters up to half of
     * them (shared in proportion). A large field of distant instances draws mostly roots, tiny
     * clusters, from DAGs of a thousand clusters each: a share in proportion to the whole DAG would
     * leave most of them to the front. */
    uint64_t total = r->scene.instance_lod_cluster_count ? r->scene.instance_lod_cluster_count : 1;
    uint64_t tiny[GDR_SW_TINY_CLASSES], tiny_sum = 0;
    for (uint32_t k = 0; k < GDR_SW_TINY_CLASSES; k++) {
        tiny[k] = r->debug.tiny_raster_off        ? 0
                  : r->debug.tiny_raster_capacity ? r->debug.tiny_raster_capacity
                                                  : r->scene.instance_tiny_cluster_count[k];
        tiny_sum += tiny[k];
    }
    if (total + tiny_sum > GDR_RASTER_MAX_CLUSTERS) {
        const uint64_t half = GDR_RASTER_MAX_CLUSTERS / 2;
        uint64_t kept = 0;
        for (uint32_t k = 0; k < GDR_SW_TINY_CLASSES; k++) {
            if (tiny_sum > half)
                tiny[k] = (uint64_t)((double)half * (double)tiny[k] / (double)tiny_sum);
            kept += tiny[k];
        }
        tiny_sum = kept;
        total = GDR_RASTER_MAX_CLUSTERS - tiny_sum;
    }
    v->capacity = (uint32_t)total;
    uint64_t base = total;
    for (uint32_t k = 0; k < GDR_SW_TINY_CLASSES; k++) {
        v->tiny_capacity[k] = (uint32_t)tiny[k];
        v->tiny_base[k] = (uint32_t)base;
        base += tiny[k];
    }
    v->slots = (uint32_t)base;
    return gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuRasterCluster) * (VkDeviceSize)base,
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                GDR_VK_BUFFER_DEVICE, &v->clusters, err);
}

void gdr_visbuffer_destroy(gdr_renderer *r)
{
    gdr_visbuffer *v = &r->vis;
    gdr_vk_buffer_destroy(r->ctx, &v->pixels);
    gdr_vk_buffer_destroy(r->ctx, &v->clusters);
    gdr_vk_buffer_destroy(r->ctx, &v->counters);
    for (uint32_t i = 0; i < GDR_FRAMES_IN_FLIGHT; i++) {
        gdr_vk_buffer_destroy(r->ctx, &v->params[i]);
        gdr_vk_buffer_destroy(r->ctx, &v->counters_readback[i]);
    }
    memset(v, 0, sizeof *v);
}

gdr_raster gdr_visbuffer_public_mode(uint32_t mode)
{
    switch (mode) {
    case GDR_GPU_RASTER_HYBRID: return GDR_RASTER_HYBRID;
    case GDR_GPU_RASTER_HW: return GDR_RASTER_HW;
    case GDR_GPU_RASTER_SW: return GDR_RASTER_SW;
    default: return GDR_RASTER_FORWARD;
    }
}

float gdr_visbuffer_threshold(const gdr_frame_desc *frame)
{
    return frame->sw_threshold_px > 0.0f ? frame->sw_threshold_px : GDR_DEFAULT_SW_THRESHOLD_PX;
}

gdr_status gdr_visbuffer_resolve_mode(const gdr_renderer *r, const gdr_frame_desc *frame, gdr_pipeline pipeline,
                                      uint32_t *mode, char *reason, size_t reason_size, gdr_error *err)
{
    const gdr_visbuffer *v = &r->vis;
    if (!(frame->sw_threshold_px >= 0.0f && frame->sw_threshold_px <= 1e6f))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: sw_threshold_px must be in [0, 1e6] (%g)",
                             (double)frame->sw_threshold_px);
    switch (frame->raster) {
    case GDR_RASTER_DEFAULT:
        if (pipeline == GDR_PIPELINE_MESH && v->supported) {
            *mode = GDR_GPU_RASTER_HYBRID;
            snprintf(reason, reason_size, "default: the device has 64-bit buffer atomics");
        } else {
            *mode = GDR_GPU_RASTER_FORWARD;
            if (pipeline != GDR_PIPELINE_MESH)
                snprintf(reason, reason_size, "default: the %s pipeline draws forward", gdr_pipeline_name(pipeline));
            else
                snprintf(reason, reason_size, "default: no visibility buffer (%s)", v->missing);
        }
        return GDR_OK;
    case GDR_RASTER_FORWARD:
        *mode = GDR_GPU_RASTER_FORWARD;
        snprintf(reason, reason_size, "asked for");
        return GDR_OK;
    case GDR_RASTER_HYBRID:
    case GDR_RASTER_HW:
    case GDR_RASTER_SW:
        if (pipeline != GDR_PIPELINE_MESH)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "raster %s: needs the mesh pipeline (not %s)",
                                 gdr_raster_name(frame->raster), gdr_pipeline_name(pipeline));
        if (!v->supported)
            return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "raster %s: not available on '%s': %s",
                                 gdr_raster_name(frame->raster), r->ctx->properties.deviceName, v->missing);
        *mode = frame->raster == GDR_RASTER_HYBRID ? GDR_GPU_RASTER_HYBRID
                : frame->raster == GDR_RASTER_HW   ? GDR_GPU_RASTER_HW
                                                   : GDR_GPU_RASTER_SW;
        snprintf(reason, reason_size, "asked for");
        return GDR_OK;
    }
    return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: unknown raster %d", (int)frame->raster);
}

void gdr_visbuffer_begin_frame(gdr_renderer *r, uint32_t slot_index, const gdr_frame_desc *frame, uint32_t mode)
{
    gdr_visbuffer *v = &r->vis;
    v->slot_mode[slot_index] = mode;
    if (!v->params[slot_index].mapped)
        return; /* no mesh pipeline */
    gdr_mat4 projection, view;
    gdr_frame_matrices(r, &frame->camera, &projection, &view);
    /* Launches of whole rows (raster_submit.comp) within the device's mesh launch limits. */
    const VkPhysicalDeviceMeshShaderPropertiesEXT *mesh = &r->ctx->mesh_shader_properties;
    uint64_t rows = mesh->maxMeshWorkGroupTotalCount / GDR_MESH_GROUPS_PER_ROW;
    if (rows > mesh->maxMeshWorkGroupCount[1])
        rows = mesh->maxMeshWorkGroupCount[1];
    GdrGpuRasterParams params = {
        .clusters = v->clusters.address,
        .counters = v->counters.address,
        .mode = mode,
        .capacity = v->capacity,
        .sw_threshold_px = gdr_visbuffer_threshold(frame),
        .ndc_scale = {fabsf(projection.m[0]), fabsf(projection.m[5])},
        .hw_launch_limit = (uint32_t)(rows * GDR_MESH_GROUPS_PER_ROW),
    };
    for (uint32_t k = 0; k < GDR_SW_TINY_CLASSES; k++) {
        params.tiny_capacity[k] = v->tiny_capacity[k];
        params.tiny_base[k] = v->tiny_base[k];
    }
    memcpy(v->params[slot_index].mapped, &params, sizeof params);
}

/* --- the passes (frame_passes.c lists what each uses) -------------------------------------------- */

/* The cluster cull over the phase's task commands, launched with what tasksubmit.comp wrote. */
void gdr_visbuffer_record_cluster_cull(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                       VkCommandBuffer cmd)
{
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->pipelines[GDR_PIPE_CLUSTER_CULL + pass->phase]);
    vkCmdDispatchIndirect(cmd, slot->draw_stats.buffer,
                          pass->phase == GDR_PHASE_LATE ? offsetof(GdrGpuDrawStats, late_cull_groups_x)
                                                        : offsetof(GdrGpuDrawStats, cull_groups_x));
}

/* The launches of both rasterisers. */
void gdr_visbuffer_record_raster_submit(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                        VkCommandBuffer cmd)
{
    (void)slot, (void)pass;
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->pipelines[GDR_PIPE_RASTER_SUBMIT]);
    vkCmdDispatch(cmd, 1, 1, 1);
}

/* The mesh-shader pass: one mesh workgroup per cluster at the back of the list; the fragments write
 * the visibility buffer. */
void gdr_visbuffer_record_raster_hw(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                    VkCommandBuffer cmd)
{
    (void)slot, (void)pass;
    VkRenderingInfo rendering = {.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                                 .renderArea = {{0, 0}, {r->width, r->height}}, .layerCount = 1};
    vkCmdBeginRendering(cmd, &rendering);
    gdr_frame_set_viewport(r, cmd, true);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, r->pipelines[GDR_PIPE_RASTER_HW]);
    r->ctx->cmd_draw_mesh_tasks_indirect(cmd, r->vis.counters.buffer, offsetof(GdrGpuRasterCounters, draw_x), 1,
                                         sizeof(VkDrawMeshTasksIndirectCommandEXT));
    vkCmdEndRendering(cmd);
}

/* The compute rasteriser over the tiny classes' parts of the list, several clusters per workgroup,
 * then over the clusters at the front, one per workgroup. All only add to the visibility buffer with
 * atomics, so none needs a barrier after another. */
void gdr_visbuffer_record_raster_sw(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                    VkCommandBuffer cmd)
{
    (void)slot, (void)pass;
    for (uint32_t k = 0; k < GDR_SW_TINY_CLASSES; k++) {
        if (r->vis.tiny_capacity[k] == 0)
            continue;
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->pipelines[GDR_PIPE_RASTER_SW_TINY + k]);
        vkCmdDispatchIndirect(cmd, r->vis.counters.buffer,
                              offsetof(GdrGpuRasterCounters, tiny_launch) + sizeof(VkDispatchIndirectCommand) * k);
    }
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->pipelines[GDR_PIPE_RASTER_SW]);
    vkCmdDispatchIndirect(cmd, r->vis.counters.buffer, offsetof(GdrGpuRasterCounters, dispatch_x));
}

/* The resolve: shades every pixel into the colour image, launched with what raster_submit.comp wrote:
 * the whole screen in the frame's first raster phase and in a late phase that drew something,
 * nothing otherwise (the image then holds the early phase's, which is the frame's). */
void gdr_visbuffer_record_resolve(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                  VkCommandBuffer cmd)
{
    (void)slot, (void)pass;
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->pipelines[GDR_PIPE_RESOLVE]);
    vkCmdDispatchIndirect(cmd, r->vis.counters.buffer, offsetof(GdrGpuRasterCounters, resolve_x));
}

void gdr_visbuffer_stats(gdr_renderer *r, uint32_t slot_index, gdr_frame_stats *stats)
{
    gdr_visbuffer *v = &r->vis;
    uint32_t mode = v->slot_mode[slot_index];
    stats->raster.mode = gdr_visbuffer_public_mode(mode);
    if (mode == GDR_GPU_RASTER_FORWARD || !v->supported)
        return;
    GdrGpuRasterCounters counters;
    memcpy(&counters, v->counters_readback[slot_index].mapped, sizeof counters);
    GdrGpuRasterParams params;
    memcpy(&params, v->params[slot_index].mapped, sizeof params);
    stats->raster.sw_threshold_px = params.sw_threshold_px;
    stats->raster.sw_clusters = counters.sw_clusters;
    stats->raster.sw_tiny_clusters = 0;
    for (uint32_t k = 0; k < GDR_SW_TINY_CLASSES; k++) {
        /* Those asked beyond the part's end went to the front, and count in sw_clusters there. */
        uint32_t drawn = counters.tiny_clusters[k] < params.tiny_capacity[k] ? counters.tiny_clusters[k]
                                                                             : params.tiny_capacity[k];
        stats->raster.sw_tiny_class_clusters[k] = drawn;
        stats->raster.sw_tiny_clusters += drawn;
    }
    stats->raster.sw_clusters += stats->raster.sw_tiny_clusters;
    stats->raster.hw_clusters = counters.hw_clusters;
    stats->raster.sw_triangles = counters.sw_triangles;
    stats->raster.hw_triangles = counters.hw_triangles;
    stats->raster.overflow = counters.overflow;
    const gdr_frame_timings *t = &r->timings;
    if (t->raster_frames > 0) {
        stats->raster.cull_ms = t->raster_ms[GDR_RASTER_TIMER_CULL] / t->raster_frames;
        stats->raster.hw_ms = t->raster_ms[GDR_RASTER_TIMER_HW] / t->raster_frames;
        stats->raster.sw_ms = t->raster_ms[GDR_RASTER_TIMER_SW] / t->raster_frames;
        stats->raster.resolve_ms = t->raster_ms[GDR_RASTER_TIMER_RESOLVE] / t->raster_frames;
    }
}

/* --- readbacks for tests and tools ------------------------------------------------------------ */

static gdr_status check_frame(gdr_renderer *r, bool needs_visbuffer, gdr_error *err)
{
    if (r->last_slot < 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "visibility buffer: no frame rendered yet");
    if (needs_visbuffer && r->vis.slot_mode[r->last_slot] == GDR_GPU_RASTER_FORWARD)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "visibility buffer: the last frame drew forward");
    return GDR_OK;
}

gdr_status gdr_visbuffer_read_pixels(gdr_renderer *r, gdr_visbuffer_pixel *pixels, gdr_error *err)
{
    gdr_visbuffer *v = &r->vis;
    gdr_vk_buffer values = {0}, clusters = {0};
    size_t count = (size_t)r->width * r->height;
    gdr_status status = check_frame(r, true, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_read_back(&r->allocator, v->pixels.buffer, 0, count * sizeof(uint64_t), &values, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_read_back(&r->allocator, v->clusters.buffer, 0, v->clusters.size, &clusters, err);
    for (size_t p = 0; status == GDR_OK && p < count; p++) {
        uint64_t value = ((const uint64_t *)values.mapped)[p];
        uint32_t depth_bits = (uint32_t)(value >> 32), id = (uint32_t)value;
        uint32_t slot = id >> GDR_VISBUFFER_TRIANGLE_BITS;
        pixels[p] = (gdr_visbuffer_pixel){0.0f, UINT32_MAX, 0, 0};
        if (depth_bits == 0)
            continue;
        memcpy(&pixels[p].depth, &depth_bits, sizeof depth_bits);
        if ((id & ((1u << GDR_VISBUFFER_TRIANGLE_BITS) - 1u)) == GDR_VISBUFFER_POINT_TRIANGLE) {
            if (slot >= r->scene.instance_count) {
                status = gdr_error_set(err, GDR_ERROR_VULKAN, "visibility buffer: pixel %zu names point %u of %u", p,
                                       slot, r->scene.instance_count);
                break;
            }
            pixels[p].instance = slot; /* a point level's splat: the instance, no cluster */
            pixels[p].meshlet = UINT32_MAX;
            pixels[p].triangle = GDR_VISBUFFER_POINT_TRIANGLE;
            continue;
        }
        if (slot >= v->slots) {
            status = gdr_error_set(err, GDR_ERROR_VULKAN, "visibility buffer: pixel %zu names slot %u of %u", p, slot,
                                   v->slots);
            break;
        }
        const GdrGpuRasterCluster *entry = (const GdrGpuRasterCluster *)clusters.mapped + slot;
        pixels[p].instance = entry->instance;
        pixels[p].meshlet = entry->meshlet;
        pixels[p].triangle = id & ((1u << GDR_VISBUFFER_TRIANGLE_BITS) - 1u);
    }
    gdr_vk_buffer_destroy(r->ctx, &values);
    gdr_vk_buffer_destroy(r->ctx, &clusters);
    return status;
}

/* The depth of a visibility-buffer frame is the high word of each pixel (the depth image is not
 * written); a forward frame's is the depth image. */
gdr_status gdr_visbuffer_read_depth(gdr_renderer *r, float *depth, gdr_error *err)
{
    gdr_vk_buffer copy = {0};
    size_t count = (size_t)r->width * r->height;
    gdr_status status = check_frame(r, false, err);
    bool from_visbuffer = status == GDR_OK && r->vis.slot_mode[r->last_slot] != GDR_GPU_RASTER_FORWARD;
    if (status == GDR_OK && from_visbuffer)
        status = gdr_vk_buffer_read_back(&r->allocator, r->vis.pixels.buffer, 0, count * sizeof(uint64_t), &copy, err);
    else if (status == GDR_OK)
        status = gdr_vk_image_read_back(&r->allocator, &r->depth, VK_IMAGE_ASPECT_DEPTH_BIT,
                                        VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, sizeof(float), &copy, err);
    for (size_t p = 0; status == GDR_OK && p < count; p++) {
        uint32_t bits = from_visbuffer ? (uint32_t)(((const uint64_t *)copy.mapped)[p] >> 32)
                                       : ((const uint32_t *)copy.mapped)[p];
        memcpy(&depth[p], &bits, sizeof bits);
    }
    gdr_vk_buffer_destroy(r->ctx, &copy);
    return status;
}

gdr_status gdr_visbuffer_read_overdraw(gdr_renderer *r, uint32_t *counts, gdr_error *err)
{
    gdr_vk_buffer copy = {0};
    size_t bytes = (size_t)r->width * r->height * sizeof(uint32_t);
    gdr_status status = check_frame(r, false, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_read_back(&r->allocator, r->overdraw.buffer, 0, bytes, &copy, err);
    if (status == GDR_OK)
        memcpy(counts, copy.mapped, bytes);
    gdr_vk_buffer_destroy(r->ctx, &copy);
    return status;
}
