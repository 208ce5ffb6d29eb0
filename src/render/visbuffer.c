/* The visibility buffer and the hybrid rasteriser of the mesh pipeline (issue 8); see visbuffer.h. */
#include "render/visbuffer.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/renderer_internal.h"
#include "vk/vk_pipeline.h"

static void memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                           VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access)
{
    VkMemoryBarrier2 barrier = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2, .srcStageMask = src_stage,
                                .srcAccessMask = src_access, .dstStageMask = dst_stage, .dstAccessMask = dst_access};
    VkDependencyInfo dependency = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1,
                                   .pMemoryBarriers = &barrier};
    vkCmdPipelineBarrier2(cmd, &dependency);
}

static gdr_status create_pipelines(gdr_renderer *r, gdr_error *err)
{
    gdr_visbuffer *v = &r->vis;
    gdr_status status = GDR_OK;
    /* The cluster cull, one per occlusion-culling phase (its constant 0: none, early, late). */
    for (uint32_t phase = 0; phase < 3 && status == GDR_OK; phase++)
        status = gdr_vk_compute_pipeline_create_specialized(r->ctx, r->layout, &gdr_shader_clustercull_comp, &phase, 1,
                                                            &v->cull_pipelines[phase], err);
    /* The mesh-shader pass: no task shader, no attachments, the atomic is the depth test. */
    gdr_vk_graphics_pipeline_desc hw = {
        .layout = r->layout, .mesh_shader = &gdr_shader_meshlet_list_mesh,
        .fragment_shader = &gdr_shader_meshlet_visbuffer_frag, .color_format = VK_FORMAT_UNDEFINED,
        .depth_format = VK_FORMAT_UNDEFINED, .cull_mode = VK_CULL_MODE_BACK_BIT, .no_depth_test = true};
    if (status == GDR_OK)
        status = gdr_vk_graphics_pipeline_create(r->ctx, &hw, &v->hw_pipeline, err);
    if (status == GDR_OK)
        status = gdr_vk_compute_pipeline_create(r->ctx, r->layout, &gdr_shader_raster_sw_comp, &v->sw_pipeline, err);
    if (status == GDR_OK)
        status = gdr_vk_compute_pipeline_create(r->ctx, r->layout, &gdr_shader_raster_submit_comp,
                                                &v->submit_pipeline, err);
    /* The resolve, shading or (constant 0) depth only. */
    for (uint32_t depth_only = 0; depth_only < 2 && status == GDR_OK; depth_only++)
        status = gdr_vk_compute_pipeline_create_specialized(r->ctx, r->layout, &gdr_shader_visbuffer_resolve_comp,
                                                            &depth_only, 1, &v->resolve_pipelines[depth_only], err);
    return status;
}

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
    status = create_pipelines(r, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, (VkDeviceSize)r->width * r->height * sizeof(uint64_t),
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                          VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                      GDR_VK_BUFFER_DEVICE, &v->pixels, err);
    if (status == GDR_OK) /* the resolve's colour and depth, copied into the images */
        status = gdr_vk_buffer_create(&r->allocator, (VkDeviceSize)r->width * r->height * 2 * sizeof(uint32_t),
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                      GDR_VK_BUFFER_DEVICE, &v->resolved, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuRasterCounters),
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                                          VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                      GDR_VK_BUFFER_DEVICE, &v->counters, err);
    for (uint32_t i = 0; i < GDR_FRAMES_IN_FLIGHT && status == GDR_OK; i++)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuRasterCounters), VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                      GDR_VK_BUFFER_READBACK, &v->counters_readback[i], err);
    if (status != GDR_OK)
        return status;
    VkQueryPoolCreateInfo query = {.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO, .queryType = VK_QUERY_TYPE_TIMESTAMP,
                                   .queryCount = GDR_FRAMES_IN_FLIGHT * 2 * GDR_VISBUFFER_TS_COUNT};
    GDR_VK_TRY(err, vkCreateQueryPool(r->ctx->device, &query, NULL, &v->timestamps));
    v->supported = true;
    return GDR_OK;
}

gdr_status gdr_visbuffer_set_scene(gdr_renderer *r, gdr_error *err)
{
    gdr_visbuffer *v = &r->vis;
    if (!v->supported)
        return GDR_OK;
    /* Every cluster of every instance's DAG is the most one frame can draw. */
    uint64_t total = r->scene.instance_lod_cluster_count;
    v->capacity = (uint32_t)(total < GDR_RASTER_MAX_CLUSTERS ? (total ? total : 1) : GDR_RASTER_MAX_CLUSTERS);
    return gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuRasterCluster) * (VkDeviceSize)v->capacity,
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                GDR_VK_BUFFER_DEVICE, &v->clusters, err);
}

void gdr_visbuffer_destroy(gdr_renderer *r)
{
    gdr_visbuffer *v = &r->vis;
    VkDevice device = r->ctx->device;
    VkPipeline pipelines[] = {v->cull_pipelines[0], v->cull_pipelines[1], v->cull_pipelines[2], v->hw_pipeline,
                              v->sw_pipeline, v->submit_pipeline, v->resolve_pipelines[0], v->resolve_pipelines[1]};
    for (size_t i = 0; i < sizeof pipelines / sizeof pipelines[0]; i++)
        if (pipelines[i])
            vkDestroyPipeline(device, pipelines[i], NULL);
    if (v->timestamps)
        vkDestroyQueryPool(device, v->timestamps, NULL);
    gdr_vk_buffer_destroy(r->ctx, &v->pixels);
    gdr_vk_buffer_destroy(r->ctx, &v->resolved);
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

void gdr_visbuffer_collect_timings(gdr_renderer *r, uint32_t slot_index)
{
    gdr_visbuffer *v = &r->vis;
    uint32_t phases = v->slot_phases[slot_index];
    if (phases == 0)
        return;
    v->slot_phases[slot_index] = 0;
    uint64_t ticks[2 * GDR_VISBUFFER_TS_COUNT];
    VkResult result = vkGetQueryPoolResults(r->ctx->device, v->timestamps, slot_index * 2 * GDR_VISBUFFER_TS_COUNT,
                                            phases * GDR_VISBUFFER_TS_COUNT, sizeof ticks, ticks, sizeof ticks[0],
                                            VK_QUERY_RESULT_64_BIT);
    if (result != VK_SUCCESS)
        return; /* timings only: a frame without them is left out of the means */
    double period_ms = r->ctx->properties.limits.timestampPeriod * 1e-6;
    for (uint32_t p = 0; p < phases; p++)
        for (int i = 0; i + 1 < GDR_VISBUFFER_TS_COUNT; i++)
            v->pass_ms[i] += (double)(ticks[p * GDR_VISBUFFER_TS_COUNT + i + 1] - ticks[p * GDR_VISBUFFER_TS_COUNT + i]) *
                             period_ms;
    v->timed_frames++;
}

void gdr_visbuffer_begin_render(gdr_renderer *r)
{
    gdr_visbuffer *v = &r->vis;
    for (uint32_t i = 0; i < GDR_FRAMES_IN_FLIGHT; i++)
        v->slot_phases[i] = 0;
    memset(v->pass_ms, 0, sizeof v->pass_ms);
    v->timed_frames = 0;
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
        .resolved = v->resolved.address,
    };
    memcpy(v->params[slot_index].mapped, &params, sizeof params);
}

void gdr_visbuffer_record_fills(gdr_renderer *r, uint32_t slot_index, VkCommandBuffer cmd)
{
    gdr_visbuffer *v = &r->vis;
    if (v->slot_mode[slot_index] != GDR_GPU_RASTER_FORWARD) {
        vkCmdFillBuffer(cmd, v->counters.buffer, 0, VK_WHOLE_SIZE, 0);
        vkCmdFillBuffer(cmd, v->pixels.buffer, 0, VK_WHOLE_SIZE, 0);
        vkCmdResetQueryPool(cmd, v->timestamps, slot_index * 2 * GDR_VISBUFFER_TS_COUNT, 2 * GDR_VISBUFFER_TS_COUNT);
    }
}

static void timestamp(gdr_renderer *r, VkCommandBuffer cmd, uint32_t slot_index, enum gdr_visbuffer_timestamp which)
{
    uint32_t phase = r->vis.slot_phases[slot_index];
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, r->vis.timestamps,
                         (slot_index * 2 + phase) * GDR_VISBUFFER_TS_COUNT + which);
}

static void set_viewport(gdr_renderer *r, VkCommandBuffer cmd)
{
    gdr_viewport flipped = gdr_viewport_flip_y((float)r->width, (float)r->height);
    VkViewport viewport = {flipped.x, flipped.y, flipped.width, flipped.height, 0.0f, 1.0f};
    VkRect2D scissor = {{0, 0}, {r->width, r->height}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

/* The cluster cull over the phase's task commands (its launch written by tasksubmit.comp at
 * `launch` in the slot's draw stats), then the launches of both rasterisers. */
static void record_cull(gdr_renderer *r, gdr_frame_slot *slot, VkCommandBuffer cmd, int phase, VkDeviceSize launch)
{
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->vis.cull_pipelines[phase]);
    vkCmdDispatchIndirect(cmd, slot->draw_stats.buffer, launch);
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->vis.submit_pipeline);
    vkCmdDispatch(cmd, 1, 1, 1);
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_MESH_SHADER_BIT_EXT |
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                   VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_READ_BIT);
}

/* The mesh-shader pass: one mesh workgroup per cluster at the back of the list; the fragments write
 * the visibility buffer. */
static void record_hw(gdr_renderer *r, VkCommandBuffer cmd)
{
    VkRenderingInfo rendering = {.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                                 .renderArea = {{0, 0}, {r->width, r->height}}, .layerCount = 1};
    vkCmdBeginRendering(cmd, &rendering);
    set_viewport(r, cmd);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, r->vis.hw_pipeline);
    r->ctx->cmd_draw_mesh_tasks_indirect(cmd, r->vis.counters.buffer, offsetof(GdrGpuRasterCounters, draw_x), 1,
                                         sizeof(VkDrawMeshTasksIndirectCommandEXT));
    vkCmdEndRendering(cmd);
}

/* The compute rasteriser over the clusters at the front of the list. (After the mesh-shader pass:
 * both write the visibility buffer, with atomics, but a barrier keeps the timings apart.) */
static void record_sw(gdr_renderer *r, VkCommandBuffer cmd)
{
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_MESH_SHADER_BIT_EXT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                   VK_ACCESS_2_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                   VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->vis.sw_pipeline);
    vkCmdDispatchIndirect(cmd, r->vis.counters.buffer, offsetof(GdrGpuRasterCounters, dispatch_x));
}

/* The resolve: a compute pass shades every pixel and writes its depth into the resolved buffer;
 * copies take them into the colour image and the depth image (for the depth pyramid), which are
 * then left as attachments. `depth_only`: the depth alone (the colour image is left as it was). */
static void record_resolve(gdr_renderer *r, VkCommandBuffer cmd, bool depth_only)
{
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_MESH_SHADER_BIT_EXT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                   VK_ACCESS_2_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                   VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->vis.resolve_pipelines[depth_only]);
    vkCmdDispatch(cmd, (r->width + GDR_RESOLVE_TILE - 1) / GDR_RESOLVE_TILE,
                  (r->height + GDR_RESOLVE_TILE - 1) / GDR_RESOLVE_TILE, 1);
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    VkDeviceSize pixels = (VkDeviceSize)r->width * r->height;
    /* Earlier users of the images: the last frame's readback copy, the previous raster phase's
     * copies and its depth pyramid (which returned the depth image to an attachment). */
    if (!depth_only) {
        gdr_vk_image_barrier(cmd, r->color.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                             VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                             VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        VkBufferImageCopy color = {.bufferOffset = 0, .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                                   .imageExtent = {r->width, r->height, 1}};
        vkCmdCopyBufferToImage(cmd, r->vis.resolved.buffer, r->color.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                               &color);
        gdr_vk_image_barrier(cmd, r->color.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                             VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                             VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                             VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    }
    gdr_vk_image_barrier(cmd, r->depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT |
                             VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    VkBufferImageCopy depth = {.bufferOffset = pixels * sizeof(uint32_t),
                               .imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1},
                               .imageExtent = {r->width, r->height, 1}};
    vkCmdCopyBufferToImage(cmd, r->vis.resolved.buffer, r->depth.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &depth);
    gdr_vk_image_barrier(cmd, r->depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_TRANSFER_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                         VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
}

void gdr_visbuffer_record_raster(gdr_renderer *r, gdr_frame_slot *slot, VkCommandBuffer cmd, int phase,
                                 VkDeviceSize launch)
{
    uint32_t slot_index = (uint32_t)(slot - r->slots);
    timestamp(r, cmd, slot_index, GDR_VISBUFFER_TS_BEGIN);
    record_cull(r, slot, cmd, phase, launch);
    timestamp(r, cmd, slot_index, GDR_VISBUFFER_TS_AFTER_CULL);
    record_hw(r, cmd);
    timestamp(r, cmd, slot_index, GDR_VISBUFFER_TS_AFTER_HW);
    record_sw(r, cmd);
    timestamp(r, cmd, slot_index, GDR_VISBUFFER_TS_AFTER_SW);
    record_resolve(r, cmd, phase == 1); /* the late phase shades what both phases drew */
    timestamp(r, cmd, slot_index, GDR_VISBUFFER_TS_AFTER_RESOLVE);
    r->vis.slot_phases[slot_index]++;
}

void gdr_visbuffer_record_readback(gdr_renderer *r, uint32_t slot_index, VkCommandBuffer cmd)
{
    if (!r->vis.supported)
        return;
    VkBufferCopy copy = {0, 0, sizeof(GdrGpuRasterCounters)};
    vkCmdCopyBuffer(cmd, r->vis.counters.buffer, r->vis.counters_readback[slot_index].buffer, 1, &copy);
}

void gdr_visbuffer_stats(gdr_renderer *r, uint32_t slot_index, gdr_frame_stats *stats)
{
    gdr_visbuffer *v = &r->vis;
    for (uint32_t i = 0; i < GDR_FRAMES_IN_FLIGHT; i++)
        gdr_visbuffer_collect_timings(r, i); /* every frame has finished: the renderer drained its slots */
    uint32_t mode = v->slot_mode[slot_index];
    stats->raster = gdr_visbuffer_public_mode(mode);
    if (mode == GDR_GPU_RASTER_FORWARD || !v->supported)
        return;
    GdrGpuRasterCounters counters;
    memcpy(&counters, v->counters_readback[slot_index].mapped, sizeof counters);
    GdrGpuRasterParams params;
    memcpy(&params, v->params[slot_index].mapped, sizeof params);
    stats->sw_threshold_px = params.sw_threshold_px;
    stats->raster_sw_clusters = counters.sw_clusters;
    stats->raster_hw_clusters = counters.hw_clusters;
    stats->raster_sw_triangles = counters.sw_triangles;
    stats->raster_hw_triangles = counters.hw_triangles;
    stats->raster_overflow = counters.overflow;
    if (v->timed_frames > 0) {
        stats->raster_cull_ms = v->pass_ms[0] / v->timed_frames;
        stats->raster_hw_ms = v->pass_ms[1] / v->timed_frames;
        stats->raster_sw_ms = v->pass_ms[2] / v->timed_frames;
        stats->raster_resolve_ms = v->pass_ms[3] / v->timed_frames;
    }
}

/* --- readbacks for tests and tools ------------------------------------------------------------ */

/* A host-visible copy of `size` bytes of `source` (a buffer) or of the depth image (source NULL).
 * Test/debug path: the memory goes back with the renderer (linear allocator). */
static gdr_status read_back(gdr_renderer *r, VkBuffer source, VkDeviceSize size, gdr_vk_buffer *out, gdr_error *err)
{
    gdr_status status = gdr_vk_buffer_create(&r->allocator, size, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                             GDR_VK_BUFFER_READBACK, out, err);
    VkCommandBuffer cmd;
    if (status == GDR_OK)
        status = gdr_vk_begin_one_time(r->ctx, &cmd, err);
    if (status != GDR_OK)
        return status;
    if (source) {
        VkBufferCopy region = {0, 0, size};
        vkCmdCopyBuffer(cmd, source, out->buffer, 1, &region);
    } else {
        gdr_vk_image_barrier(cmd, r->depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                             VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                             VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                             VK_ACCESS_2_TRANSFER_READ_BIT);
        VkBufferImageCopy region = {.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1},
                                    .imageExtent = {r->width, r->height, 1}};
        vkCmdCopyImageToBuffer(cmd, r->depth.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, out->buffer, 1, &region);
        gdr_vk_image_barrier(cmd, r->depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                             VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, 0,
                             VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT, 0);
    }
    return gdr_vk_end_one_time(r->ctx, cmd, err);
}

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
        status = read_back(r, v->pixels.buffer, count * sizeof(uint64_t), &values, err);
    if (status == GDR_OK)
        status = read_back(r, v->clusters.buffer, v->clusters.size, &clusters, err);
    for (size_t p = 0; status == GDR_OK && p < count; p++) {
        uint64_t value = ((const uint64_t *)values.mapped)[p];
        uint32_t depth_bits = (uint32_t)(value >> 32), id = (uint32_t)value;
        uint32_t slot = id >> GDR_VISBUFFER_TRIANGLE_BITS;
        pixels[p] = (gdr_visbuffer_pixel){0.0f, UINT32_MAX, 0, 0};
        if (depth_bits == 0)
            continue;
        if (slot >= v->capacity) {
            status = gdr_error_set(err, GDR_ERROR_VULKAN, "visibility buffer: pixel %zu names slot %u of %u", p, slot,
                                   v->capacity);
            break;
        }
        const GdrGpuRasterCluster *entry = (const GdrGpuRasterCluster *)clusters.mapped + slot;
        memcpy(&pixels[p].depth, &depth_bits, sizeof depth_bits);
        pixels[p].instance = entry->instance;
        pixels[p].meshlet = entry->meshlet;
        pixels[p].triangle = id & ((1u << GDR_VISBUFFER_TRIANGLE_BITS) - 1u);
    }
    gdr_vk_buffer_destroy(r->ctx, &values);
    gdr_vk_buffer_destroy(r->ctx, &clusters);
    return status;
}

gdr_status gdr_visbuffer_read_depth(gdr_renderer *r, float *depth, gdr_error *err)
{
    gdr_vk_buffer copy = {0};
    size_t bytes = (size_t)r->width * r->height * sizeof(float);
    gdr_status status = check_frame(r, false, err);
    if (status == GDR_OK)
        status = read_back(r, VK_NULL_HANDLE, bytes, &copy, err);
    if (status == GDR_OK)
        memcpy(depth, copy.mapped, bytes);
    gdr_vk_buffer_destroy(r->ctx, &copy);
    return status;
}

gdr_status gdr_visbuffer_read_overdraw(gdr_renderer *r, uint32_t *counts, gdr_error *err)
{
    gdr_vk_buffer copy = {0};
    size_t bytes = (size_t)r->width * r->height * sizeof(uint32_t);
    gdr_status status = check_frame(r, false, err);
    if (status == GDR_OK)
        status = read_back(r, r->overdraw.buffer, bytes, &copy, err);
    if (status == GDR_OK)
        memcpy(counts, copy.mapped, bytes);
    gdr_vk_buffer_destroy(r->ctx, &copy);
    return status;
}
