/* One frame. GPU-driven (indirect: instance culling -> one indirect-count draw; mesh: instance
 * culling -> task commands -> one mesh-tasks launch), where the number of commands recorded does
 * not depend on the scene, or CPU-driven (culling on the CPU, a draw per visible instance). */
#include <math.h>
#include <string.h>

#include "render/renderer_internal.h"

static void memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                           VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access)
{
    VkMemoryBarrier2 barrier = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2, .srcStageMask = src_stage,
                                .srcAccessMask = src_access, .dstStageMask = dst_stage, .dstAccessMask = dst_access};
    VkDependencyInfo dependency = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1,
                                   .pMemoryBarriers = &barrier};
    vkCmdPipelineBarrier2(cmd, &dependency);
}

static void timestamp(gdr_renderer *r, VkCommandBuffer cmd, gdr_frame_slot *slot, enum gdr_timestamp which)
{
    uint32_t base = (uint32_t)(slot - r->slots) * GDR_TS_COUNT;
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, r->timestamps, base + which);
}

void gdr_frame_matrices(const gdr_renderer *r, const gdr_camera *camera, gdr_mat4 *projection, gdr_mat4 *view)
{
    float aspect = camera->aspect > 0.0f ? camera->aspect : (float)r->width / (float)r->height;
    *projection = camera->zfar > 0.0f ? gdr_perspective_reverse_z(camera->yfov, aspect, camera->znear, camera->zfar)
                                      : gdr_perspective_reverse_z_infinite(camera->yfov, aspect, camera->znear);
    *view = gdr_view_from_pose(camera->position, camera->rotation);
}

static void write_globals(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_desc *frame, gdr_pipeline pipeline,
                          uint32_t update_count, bool occlusion, bool history)
{
    const gdr_camera *camera = &frame->camera;
    gdr_mat4 projection, view;
    gdr_frame_matrices(r, camera, &projection, &view);
    gdr_vec3 light = gdr_vec3_normalize((gdr_vec3){0.35f, 0.85f, 0.4f});
    /* The LOD cut (issue 5): only where the mesh pipeline draws clusters, and only when it asks for
     * something other than level 0 (threshold 0 and depth 0 both select exactly level 0). */
    bool lod = pipeline == GDR_PIPELINE_MESH &&
               (frame->lod_fixed_depth ? frame->lod_depth > 0 : frame->lod_error_px > 0.0f);
    GdrGpuFrameGlobals globals = {
        .view = view,
        .view_projection = gdr_mat4_mul(projection, view),
        .frustum = gdr_frustum_symmetric(projection),
        .camera_position = {camera->position.x, camera->position.y, camera->position.z, 1.0f},
        .light_direction = {light.x, light.y, light.z, 0.0f},
        .znear = camera->znear,
        .zfar = camera->zfar > 0.0f ? camera->zfar : INFINITY,
        .instance_count = r->scene.instance_count,
        .cull_enabled = frame->cull != GDR_CULL_OFF,
        .update_count = update_count,
        .flags = (frame->meshlet_frustum_cull != GDR_CULL_OFF ? GDR_FRAME_MESHLET_FRUSTUM : 0u) |
                 (frame->meshlet_cone_cull != GDR_CULL_OFF ? GDR_FRAME_MESHLET_CONE : 0u) |
                 (frame->triangle_cull != GDR_CULL_OFF ? GDR_FRAME_TRIANGLE_CULL : 0u) |
                 (frame->record_visible_meshlets ? GDR_FRAME_RECORD_MESHLETS : 0u) |
                 (lod ? GDR_FRAME_LOD : 0u) | (lod && frame->lod_fixed_depth ? GDR_FRAME_LOD_DEPTH : 0u) |
                 (occlusion ? GDR_FRAME_OCCLUSION : 0u) | (history ? GDR_FRAME_HISTORY : 0u),
        .view_mode = (uint32_t)frame->view,
        .task_capacity = r->scene.task_capacity,
        .viewport = {(float)r->width, (float)r->height},
        .lod_threshold = frame->lod_error_px,
        .lod_projection_scale = fabsf(projection.m[5]) * 0.5f * (float)r->height,
        .lod_depth = frame->lod_depth > INT32_MAX ? INT32_MAX : (int32_t)frame->lod_depth,
        .instance_visibility = r->occlusion.instance_visibility.address,
        .meshlet_visibility = r->occlusion.meshlet_visibility.address,
    };
    gdr_occlusion_params(r, &projection, camera->znear, &globals.occlusion);
    memcpy(slot->globals.mapped, &globals, sizeof globals);
    slot->lod_applied = lod;
    slot->occlusion_applied = occlusion;
}

/* Moves up to one frame's worth of pending instance updates into the slot's ring segment. */
static uint32_t take_updates(gdr_renderer *r, gdr_frame_slot *slot)
{
    gdr_gpu_scene *g = &r->scene;
    uint32_t count = g->pending_count < GDR_INSTANCE_UPDATES_PER_FRAME ? g->pending_count : GDR_INSTANCE_UPDATES_PER_FRAME;
    memcpy(slot->updates.mapped, g->pending, sizeof(GdrGpuInstanceUpdate) * count);
    memmove(g->pending, g->pending + count, sizeof(GdrGpuInstanceUpdate) * (g->pending_count - count));
    g->pending_count -= count;
    return count;
}

/* `clear`: the frame's first raster phase (targets cleared); else the late phase of occlusion
 * culling, which draws over the early phase's colour and depth. */
static void begin_rendering(gdr_renderer *r, VkCommandBuffer cmd, bool clear)
{
    if (clear) {
        gdr_vk_image_barrier(cmd, r->color.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                             VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, 0,
                             VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
        gdr_vk_image_barrier(cmd, r->depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                             VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, 0,
                             VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                             VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
    } else { /* depth came back from the pyramid build with its own barrier */
        memory_barrier(cmd, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                       VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    }
    const VkAttachmentLoadOp load = clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
    VkRenderingAttachmentInfo color = {.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                                       .imageView = r->color.view, .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                       .loadOp = load, .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
                                       .clearValue.color = GDR_CLEAR_COLOR};
    VkRenderingAttachmentInfo depth = {.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                                       .imageView = r->depth.view, .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                                       .loadOp = load, .storeOp = VK_ATTACHMENT_STORE_OP_STORE, /* the pyramid reads it */
                                       .clearValue.depthStencil = {0.0f, 0}}; /* reverse-Z: 0 is infinitely far */
    VkRenderingInfo rendering = {.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                                 .renderArea = {{0, 0}, {r->width, r->height}}, .layerCount = 1,
                                 .colorAttachmentCount = 1, .pColorAttachments = &color, .pDepthAttachment = &depth};
    vkCmdBeginRendering(cmd, &rendering);
    gdr_viewport flipped = gdr_viewport_flip_y((float)r->width, (float)r->height);
    VkViewport viewport = {flipped.x, flipped.y, flipped.width, flipped.height, 0.0f, 1.0f};
    VkRect2D scissor = {{0, 0}, {r->width, r->height}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

/* Indirect pipeline: the cull appends VkDrawIndexedIndirectCommands; one indirect-count draw. */
static void cull_for_indirect(gdr_renderer *r, VkCommandBuffer cmd, VkPipeline cull)
{
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, cull);
    if (r->scene.instance_count > 0)
        vkCmdDispatch(cmd, (r->scene.instance_count + GDR_CULL_WORKGROUP_SIZE - 1) / GDR_CULL_WORKGROUP_SIZE, 1, 1);
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
                       VK_PIPELINE_STAGE_2_COPY_BIT,
                   VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT);
}

/* `late`: the late phase's draws, which follow the early phase's region of the list. */
static void draw_indirect(gdr_renderer *r, gdr_frame_slot *slot, VkCommandBuffer cmd, bool late)
{
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, r->draw_pipeline);
    VkDeviceSize zero = 0;
    vkCmdBindVertexBuffers(cmd, 0, 1, &r->scene.vertices.buffer, &zero);
    vkCmdBindIndexBuffer(cmd, r->scene.indices.buffer, 0, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexedIndirectCount(cmd, slot->draws.buffer,
                                  late ? sizeof(GdrGpuDrawCommand) * (VkDeviceSize)r->scene.instance_count : 0,
                                  slot->draw_stats.buffer,
                                  late ? offsetof(GdrGpuDrawStats, late_draw_count) : offsetof(GdrGpuDrawStats, draw_count),
                                  r->scene.instance_count, sizeof(GdrGpuDrawCommand));
}

/* Mesh pipeline: the cull appends task commands; the submit pass turns their count into the launch. */
static void cull_for_mesh(gdr_renderer *r, VkCommandBuffer cmd, VkPipeline cull, VkPipeline submit)
{
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, cull);
    if (r->scene.instance_count > 0)
        vkCmdDispatch(cmd, (r->scene.instance_count + GDR_CULL_WORKGROUP_SIZE - 1) / GDR_CULL_WORKGROUP_SIZE, 1, 1);
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, submit);
    vkCmdDispatch(cmd, 1, 1, 1);
    /* To the task shader, or (visibility-buffer modes) the cluster-cull compute pass. */
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT |
                       VK_PIPELINE_STAGE_2_MESH_SHADER_BIT_EXT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT |
                       VK_PIPELINE_STAGE_2_COPY_BIT,
                   VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT |
                       VK_ACCESS_2_TRANSFER_READ_BIT);
}

static void draw_mesh(gdr_renderer *r, gdr_frame_slot *slot, VkCommandBuffer cmd, VkPipeline mesh, bool late)
{
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, mesh);
    r->ctx->cmd_draw_mesh_tasks_indirect(cmd, slot->draw_stats.buffer,
                                         late ? offsetof(GdrGpuDrawStats, late_task_groups_x)
                                              : offsetof(GdrGpuDrawStats, task_groups_x),
                                         1, sizeof(VkDrawMeshTasksIndirectCommandEXT));
}

/* One phase of a GPU-driven frame: cull, then raster. phase 0: the only one (no occlusion
 * culling), 1: early, 2: late. */
static void cull_and_draw(gdr_renderer *r, gdr_frame_slot *slot, VkCommandBuffer cmd, gdr_pipeline pipeline, int phase)
{
    if (pipeline == GDR_PIPELINE_INDIRECT)
        cull_for_indirect(r, cmd, phase ? r->cull_phase_pipelines[phase - 1] : r->cull_pipeline);
    else if (pipeline == GDR_PIPELINE_MESH)
        cull_for_mesh(r, cmd, phase ? r->cull_tasks_phase_pipelines[phase - 1] : r->cull_tasks_pipeline,
                      phase == 2 ? r->task_submit_late_pipeline : r->task_submit_pipeline);
    timestamp(r, cmd, slot, phase == 2 ? GDR_TS_AFTER_LATE_CULL : GDR_TS_AFTER_CULL);
    if (pipeline == GDR_PIPELINE_MESH && r->vis.slot_mode[slot - r->slots] != GDR_GPU_RASTER_FORWARD) {
        /* issue 8: the visibility buffer, then the resolve */
        gdr_visbuffer_record_raster(r, slot, cmd, phase,
                                    phase == 2 ? offsetof(GdrGpuDrawStats, late_cull_groups_x)
                                               : offsetof(GdrGpuDrawStats, cull_groups_x));
        return;
    }
    begin_rendering(r, cmd, phase != 2);
    if (pipeline == GDR_PIPELINE_INDIRECT)
        draw_indirect(r, slot, cmd, phase == 2);
    else if (pipeline == GDR_PIPELINE_MESH)
        draw_mesh(r, slot, cmd, phase ? r->mesh_phase_pipelines[phase - 1] : r->mesh_pipeline, phase == 2);
    vkCmdEndRendering(cmd);
}

/* Overdraw view: the fragment shaders counted fragments per pixel; find the maximum, then paint the
 * counts over the image as a heat map. */
static void overdraw_resolve(gdr_renderer *r, VkCommandBuffer cmd)
{
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->overdraw_max_pipeline);
    uint32_t pixels = r->width * r->height;
    vkCmdDispatch(cmd, (pixels + GDR_REDUCE_WORKGROUP_SIZE - 1) / GDR_REDUCE_WORKGROUP_SIZE, 1, 1);
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_READ_BIT);
    VkRenderingAttachmentInfo color = {.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                                       .imageView = r->color.view, .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                       .loadOp = VK_ATTACHMENT_LOAD_OP_LOAD, .storeOp = VK_ATTACHMENT_STORE_OP_STORE};
    VkRenderingInfo rendering = {.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                                 .renderArea = {{0, 0}, {r->width, r->height}}, .layerCount = 1,
                                 .colorAttachmentCount = 1, .pColorAttachments = &color};
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                   VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    vkCmdBeginRendering(cmd, &rendering);
    VkViewport viewport = {0.0f, 0.0f, (float)r->width, (float)r->height, 0.0f, 1.0f};
    VkRect2D scissor = {{0, 0}, {r->width, r->height}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, r->overdraw_paint_pipeline);
    vkCmdDraw(cmd, 3, 1, 0, 0);
    vkCmdEndRendering(cmd);
}

/* What every frame pipeline expects bound: the push constants and the depth pyramid (set 0). */
static void bind_frame_state(gdr_renderer *r, VkCommandBuffer cmd, const GdrGpuPushConstants *push)
{
    vkCmdPushConstants(cmd, r->layout, VK_SHADER_STAGE_ALL, 0, sizeof *push, push);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->layout, 0, 1, &r->occlusion.set, 0, NULL);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, r->layout, 0, 1, &r->occlusion.set, 0, NULL);
}

gdr_status gdr_frame_record_color_readback(gdr_renderer *r, VkCommandBuffer cmd, gdr_error *err)
{
    VkCommandBufferBeginInfo begin = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    GDR_VK_TRY(err, vkBeginCommandBuffer(cmd, &begin));
    gdr_vk_image_barrier(cmd, r->color.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                         VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                         VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_TRANSFER_READ_BIT);
    VkBufferImageCopy region = {.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                                .imageExtent = {r->width, r->height, 1}};
    vkCmdCopyImageToBuffer(cmd, r->color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, r->color_readback.buffer, 1,
                           &region);
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                   VK_ACCESS_2_HOST_READ_BIT);
    GDR_VK_TRY(err, vkEndCommandBuffer(cmd));
    return GDR_OK;
}

/* Submits the slot's frame and, when `copy_color`, the colour readback after it. */
static gdr_status submit(gdr_renderer *r, gdr_frame_slot *slot, bool copy_color, double *submit_ms, gdr_error *err)
{
    VkCommandBufferSubmitInfo cmd_info[2] = {
        {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO, .commandBuffer = slot->cmd},
        {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO, .commandBuffer = slot->readback_cmd}};
    VkSubmitInfo2 submit = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2, .commandBufferInfoCount = copy_color ? 2 : 1,
                            .pCommandBufferInfos = cmd_info};
    double start = gdr_now_ms();
    GDR_VK_TRY(err, vkQueueSubmit2(r->ctx->queue, 1, &submit, slot->fence));
    *submit_ms += gdr_now_ms() - start;
    slot->submitted = true;
    return GDR_OK;
}

static bool same_recording(const gdr_recorded_frame *a, const gdr_recorded_frame *b)
{
    return a->valid && b->valid && a->pipeline == b->pipeline && a->raster_mode == b->raster_mode &&
           a->occlusion == b->occlusion && a->overdraw == b->overdraw && a->updates == b->updates && memcmp(&a->push, &b->push, sizeof a->push) == 0;
}

gdr_status gdr_frame_record_and_submit(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_desc *frame,
                                       gdr_pipeline pipeline, bool copy_color, double *submit_ms, gdr_error *err)
{
    VkCommandBuffer cmd = slot->cmd;
    uint32_t slot_index = (uint32_t)(slot - r->slots);
    uint32_t update_count = take_updates(r, slot);
    /* Occlusion culling (issue 6) with its history when the last frame left a usable one. */
    bool occlusion = pipeline != GDR_PIPELINE_CPU && frame->cull != GDR_CULL_OFF && frame->occlusion != GDR_CULL_OFF;
    bool history = occlusion && r->occlusion.history_valid && r->occlusion.history_pipeline == pipeline &&
                   !frame->occlusion_camera_cut;
    write_globals(r, slot, frame, pipeline, update_count, occlusion, history);
    r->occlusion.history_valid = occlusion;
    r->occlusion.history_pipeline = pipeline;
    GdrGpuPushConstants push = {
        .globals = slot->globals.address,
        .instances = r->scene.instances.address,
        .meshes = r->scene.meshes.address,
        .draws = slot->draws.address,
        .draw_stats = slot->draw_stats.address,
        .updates = slot->updates.address,
        .vertices = r->scene.vertices.address,
        .meshlets = r->scene.meshlets.address,
        .meshlet_vertices = r->scene.meshlet_vertices.address,
        .meshlet_triangles = r->scene.meshlet_triangles.address,
        .tasks = slot->tasks.address,
        .overdraw = r->overdraw.address,
        .visible_meshlets = r->visible_meshlets.address,
        .visbuffer = r->vis.pixels.address,
        .raster = r->vis.params[slot_index].address,
    };
    bool overdraw = frame->view == GDR_VIEW_MODE_OVERDRAW;
    uint32_t raster_mode = pipeline == GDR_PIPELINE_MESH ? r->vis.mode : GDR_GPU_RASTER_FORWARD;
    gdr_visbuffer_begin_frame(r, slot_index, frame, raster_mode);
    uint32_t query_base = slot_index * GDR_TS_COUNT;
    vkResetQueryPool(r->ctx->device, r->timestamps, query_base, GDR_TS_COUNT);
    slot->timestamps_written = true;
    slot->pipeline = pipeline;

    /* A GPU-driven frame whose commands are already in the slot: submit them again. */
    gdr_recorded_frame key = {.valid = pipeline != GDR_PIPELINE_CPU && !r->record_every_frame, .pipeline = pipeline,
                              .raster_mode = raster_mode, .occlusion = occlusion, .overdraw = overdraw,
                              .updates = update_count > 0, .push = push};
    if (same_recording(&slot->recorded, &key)) {
        r->vis.slot_phases[slot_index] = slot->recorded.raster_phases;
        slot->resubmitted = true;
        return submit(r, slot, copy_color, submit_ms, err);
    }
    slot->recorded.valid = false;
    slot->resubmitted = false;
    /* Task and mesh stages may only be named where the device has them enabled. */
    const VkPipelineStageFlags2 mesh_stages =
        r->ctx->has_mesh_shader ? VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT | VK_PIPELINE_STAGE_2_MESH_SHADER_BIT_EXT : 0;

    GDR_VK_TRY(err, vkResetCommandBuffer(cmd, 0));
    VkCommandBufferBeginInfo begin = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    GDR_VK_TRY(err, vkBeginCommandBuffer(cmd, &begin));
    /* The previous frame shares the instance buffer and the render targets: let it finish with them. */
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
    timestamp(r, cmd, slot, GDR_TS_BEGIN);
    bind_frame_state(r, cmd, &push);

    /* 1. Instance updates from the ring (sized for a full ring slot, so that frames with any number
     * of updates share one recording; the shader reads the count); counters (and overdraw counts)
     * to zero. */
    if (update_count > 0) {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->scatter_pipeline);
        vkCmdDispatch(cmd, (GDR_INSTANCE_UPDATES_PER_FRAME + GDR_SCATTER_WORKGROUP_SIZE - 1) / GDR_SCATTER_WORKGROUP_SIZE,
                      1, 1);
    }
    vkCmdFillBuffer(cmd, slot->draw_stats.buffer, 0, VK_WHOLE_SIZE, 0);
    if (overdraw)
        vkCmdFillBuffer(cmd, r->overdraw.buffer, 0, VK_WHOLE_SIZE, 0);
    gdr_visbuffer_record_fills(r, slot_index, cmd);
    /* (vkCmdFillBuffer is a transfer: COPY or CLEAR stage depending on the implementation.) */
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                   VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | mesh_stages |
                       VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT |
                       VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                   VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_TRANSFER_READ_BIT |
                       VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
    timestamp(r, cmd, slot, GDR_TS_AFTER_UPDATE);

    /* 2. Culling and raster: on the GPU, or (CPU pipeline) culled before recording. With occlusion
     * culling: the early phase, the pyramid of its depth, the late phase against it, and the
     * pyramid of the whole frame for the next one (docs/OCCLUSION.md). */
    if (pipeline == GDR_PIPELINE_CPU) {
        timestamp(r, cmd, slot, GDR_TS_AFTER_CULL);
        begin_rendering(r, cmd, true);
        gdr_cpu_path_record_draws(r, cmd, &push);
        vkCmdEndRendering(cmd);
    } else {
        cull_and_draw(r, slot, cmd, pipeline, occlusion ? 1 : 0);
    }
    timestamp(r, cmd, slot, GDR_TS_AFTER_DRAW);
    if (occlusion) {
        gdr_occlusion_record_pyramid(r, cmd);
        bind_frame_state(r, cmd, &push); /* the build bound its own layout */
        timestamp(r, cmd, slot, GDR_TS_AFTER_PYRAMID);
        /* The early phase's visibility records and counters before the late phase's culling. */
        memory_barrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | mesh_stages | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                       VK_ACCESS_2_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | mesh_stages | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                       VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
        cull_and_draw(r, slot, cmd, pipeline, 2);
    } else {
        timestamp(r, cmd, slot, GDR_TS_AFTER_PYRAMID);
        timestamp(r, cmd, slot, GDR_TS_AFTER_LATE_CULL);
    }
    if (overdraw)
        overdraw_resolve(r, cmd);
    timestamp(r, cmd, slot, GDR_TS_AFTER_LATE_DRAW);
    if (occlusion) {
        gdr_occlusion_record_pyramid(r, cmd); /* for the next frame's early phase */
        bind_frame_state(r, cmd, &push);
    }
    timestamp(r, cmd, slot, GDR_TS_AFTER_LATE_PYRAMID);

    /* 4. Statistics (always) and the image (when asked) for the CPU. */
    memory_barrier(cmd, mesh_stages | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                   VK_ACCESS_2_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    VkBufferCopy stats_copy = {0, 0, sizeof(GdrGpuDrawStats)};
    vkCmdCopyBuffer(cmd, slot->draw_stats.buffer, slot->stats_readback.buffer, 1, &stats_copy);
    gdr_visbuffer_record_readback(r, (uint32_t)(slot - r->slots), cmd);
    memory_barrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                   VK_ACCESS_2_HOST_READ_BIT);
    timestamp(r, cmd, slot, GDR_TS_END);
    GDR_VK_TRY(err, vkEndCommandBuffer(cmd));

    key.raster_phases = r->vis.slot_phases[slot_index];
    slot->recorded = key;
    return submit(r, slot, copy_color, submit_ms, err);
}

gdr_status gdr_frame_slot_wait(gdr_renderer *r, gdr_frame_slot *slot, double gpu_ms[GDR_TS_COUNT - 1], gdr_error *err)
{
    if (!slot->submitted)
        return GDR_OK;
    if (r->busy_wait) {
        VkResult result;
        while ((result = vkGetFenceStatus(r->ctx->device, slot->fence)) == VK_NOT_READY)
            ;
        GDR_VK_TRY(err, result);
    } else {
        GDR_VK_TRY(err, vkWaitForFences(r->ctx->device, 1, &slot->fence, VK_TRUE, UINT64_MAX));
    }
    GDR_VK_TRY(err, vkResetFences(r->ctx->device, 1, &slot->fence));
    slot->submitted = false;
    gdr_visbuffer_collect_timings(r, (uint32_t)(slot - r->slots));
    if (gpu_ms && slot->timestamps_written) {
        uint64_t ticks[GDR_TS_COUNT];
        uint32_t base = (uint32_t)(slot - r->slots) * GDR_TS_COUNT;
        GDR_VK_TRY(err, vkGetQueryPoolResults(r->ctx->device, r->timestamps, base, GDR_TS_COUNT, sizeof ticks, ticks,
                                              sizeof ticks[0], VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
        double period_ms = r->ctx->properties.limits.timestampPeriod * 1e-6;
        for (int i = 0; i + 1 < GDR_TS_COUNT; i++)
            gpu_ms[i] = (double)(ticks[i + 1] - ticks[i]) * period_ms;
    }
    return GDR_OK;
}
