/* The recording functions of the frame's passes (frame_passes.c lists them with their resources;
 * the barriers between them are derived and recorded by frame.c, not here). */
#include "render/renderer_internal.h"
#include "render/cpu_driven.h"
#include "render/frame.h"
#include "render/frame_record.h"

static void bind_compute(gdr_renderer *r, VkCommandBuffer cmd, gdr_pipeline_id id)
{
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->pipelines[id]);
}

static uint32_t groups_for(uint32_t items, uint32_t group_size)
{
    return (items + group_size - 1) / group_size;
}

void gdr_frame_bind_state(gdr_renderer *r, gdr_frame_slot *slot, VkCommandBuffer cmd)
{
    GdrGpuPushConstants push = gdr_frame_push_constants(r, slot);
    vkCmdPushConstants(cmd, r->layout, VK_SHADER_STAGE_ALL, 0, sizeof push, &push);
    const VkDescriptorSet sets[2] = {r->occlusion.set, r->materials.set}; /* set 0, set GDR_TEXTURE_SET */
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, r->layout, 0, 2, sets, 0, NULL);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, r->layout, 0, 2, sets, 0, NULL);
}

/* The colour and depth attachments: cleared in the frame's first raster phase, else loaded. */
static void begin_rendering(gdr_renderer *r, VkCommandBuffer cmd, bool clear)
{
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
    gdr_frame_set_viewport(r, cmd, true);
}

void gdr_frame_set_viewport(gdr_renderer *r, VkCommandBuffer cmd, bool flip_y)
{
    gdr_viewport flipped = gdr_viewport_flip_y((float)r->width, (float)r->height);
    VkViewport viewport = flip_y ? (VkViewport){flipped.x, flipped.y, flipped.width, flipped.height, 0.0f, 1.0f}
                                 : (VkViewport){0.0f, 0.0f, (float)r->width, (float)r->height, 0.0f, 1.0f};
    VkRect2D scissor = {{0, 0}, {r->width, r->height}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void gdr_pass_record_instance_scatter(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                      VkCommandBuffer cmd)
{
    (void)slot, (void)pass;
    /* Sized for a full ring slot, so that frames with any number of updates share one recording:
     * the shader reads the count. */
    bind_compute(r, cmd, GDR_PIPE_INSTANCE_SCATTER);
    vkCmdDispatch(cmd, groups_for(GDR_INSTANCE_UPDATES_PER_FRAME, GDR_SCATTER_WORKGROUP_SIZE), 1, 1);
}

void gdr_pass_record_clear(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass, VkCommandBuffer cmd)
{
    (void)pass;
    vkCmdFillBuffer(cmd, slot->draw_stats.buffer, 0, VK_WHOLE_SIZE, 0);
    if (slot->plan.config.overdraw)
        vkCmdFillBuffer(cmd, r->overdraw.buffer, 0, VK_WHOLE_SIZE, 0);
    if (slot->plan.config.visbuffer) {
        vkCmdFillBuffer(cmd, r->vis.counters.buffer, 0, VK_WHOLE_SIZE, 0);
        vkCmdFillBuffer(cmd, r->vis.pixels.buffer, 0, VK_WHOLE_SIZE, 0);
    }
}

void gdr_pass_record_instance_cull(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                   VkCommandBuffer cmd)
{
    gdr_pipeline_id first = slot->plan.config.pipeline != GDR_PIPELINE_MESH ? GDR_PIPE_CULL_DRAWS
                            : slot->plan.config.visbuffer            ? GDR_PIPE_CULL_POINTS
                                                                     : GDR_PIPE_CULL_TASKS;
    bind_compute(r, cmd, first + pass->phase);
    if (pass->phase == GDR_PHASE_LATE) /* the instances the early phase deferred */
        vkCmdDispatchIndirect(cmd, slot->draw_stats.buffer, offsetof(GdrGpuDrawStats, late_instances));
    else if (r->scene.instance_count > 0)
        vkCmdDispatch(cmd, groups_for(r->scene.instance_count, GDR_CULL_WORKGROUP_SIZE), 1, 1);
}

void gdr_pass_record_draw_indexed(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                  VkCommandBuffer cmd)
{
    bool late = pass->phase == GDR_PHASE_LATE; /* the late phase's draws follow the early phase's */
    begin_rendering(r, cmd, !late);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, r->pipelines[GDR_PIPE_DRAW_INDEXED]);
    VkDeviceSize zero = 0;
    vkCmdBindVertexBuffers(cmd, 0, 1, &r->scene.vertices.buffer, &zero);
    vkCmdBindIndexBuffer(cmd, r->scene.indices.buffer, 0, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexedIndirectCount(cmd, slot->draws.buffer,
                                  late ? sizeof(GdrGpuDrawCommand) * (VkDeviceSize)r->scene.instance_count : 0,
                                  slot->draw_stats.buffer,
                                  late ? offsetof(GdrGpuDrawStats, late_draw_count) : offsetof(GdrGpuDrawStats, draw_count),
                                  r->scene.instance_count, sizeof(GdrGpuDrawCommand));
    vkCmdEndRendering(cmd);
}

/* One level of the LOD hierarchy traversal, launched with what the level before queued. */
void gdr_pass_record_lod_traverse(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                  VkCommandBuffer cmd)
{
    bind_compute(r, cmd, GDR_PIPE_LOD_TRAVERSE + pass->phase);
    uint32_t step = pass->step;
    vkCmdPushConstants(cmd, r->layout, VK_SHADER_STAGE_ALL, offsetof(GdrGpuPushConstants, step), sizeof step, &step);
    uint32_t level = (pass->phase == GDR_PHASE_LATE ? GDR_LOD_TREE_LEVELS : 0) + pass->step;
    vkCmdDispatchIndirect(cmd, slot->draw_stats.buffer,
                          offsetof(GdrGpuDrawStats, traversal) + sizeof(GdrGpuTraversalLevel) * level);
}

void gdr_pass_record_task_submit(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                 VkCommandBuffer cmd)
{
    (void)slot;
    bind_compute(r, cmd, pass->phase == GDR_PHASE_LATE ? GDR_PIPE_TASK_SUBMIT_LATE : GDR_PIPE_TASK_SUBMIT);
    vkCmdDispatch(cmd, 1, 1, 1);
}

void gdr_pass_record_meshlets(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass, VkCommandBuffer cmd)
{
    bool late = pass->phase == GDR_PHASE_LATE;
    begin_rendering(r, cmd, !late);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, r->pipelines[GDR_PIPE_MESHLETS + pass->phase]);
    r->ctx->cmd_draw_mesh_tasks_indirect(cmd, slot->draw_stats.buffer,
                                         late ? offsetof(GdrGpuDrawStats, late_task_groups_x)
                                              : offsetof(GdrGpuDrawStats, task_groups_x),
                                         1, sizeof(VkDrawMeshTasksIndirectCommandEXT));
    vkCmdEndRendering(cmd);
}

void gdr_pass_record_pyramid(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass, VkCommandBuffer cmd)
{
    (void)pass; /* the visibility-buffer modes never write the depth image: their depth is the buffer's */
    gdr_hzb_record_build(&r->occlusion.hzb, cmd, slot->plan.config.visbuffer ? r->vis.pixels.address : 0);
    gdr_frame_bind_state(r, slot, cmd); /* the build bound its own layout */
}

void gdr_pass_record_overdraw_max(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                  VkCommandBuffer cmd)
{
    (void)slot, (void)pass;
    bind_compute(r, cmd, GDR_PIPE_OVERDRAW_MAX);
    vkCmdDispatch(cmd, groups_for(r->width * r->height, GDR_REDUCE_WORKGROUP_SIZE), 1, 1);
}

void gdr_pass_record_overdraw_paint(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                    VkCommandBuffer cmd)
{
    (void)slot, (void)pass;
    VkRenderingAttachmentInfo color = {.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                                       .imageView = r->color.view, .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                       .loadOp = VK_ATTACHMENT_LOAD_OP_LOAD, .storeOp = VK_ATTACHMENT_STORE_OP_STORE};
    VkRenderingInfo rendering = {.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                                 .renderArea = {{0, 0}, {r->width, r->height}}, .layerCount = 1,
                                 .colorAttachmentCount = 1, .pColorAttachments = &color};
    vkCmdBeginRendering(cmd, &rendering);
    gdr_frame_set_viewport(r, cmd, false);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, r->pipelines[GDR_PIPE_OVERDRAW_PAINT]);
    vkCmdDraw(cmd, 3, 1, 0, 0);
    vkCmdEndRendering(cmd);
}

void gdr_pass_record_cpu_draws(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass, VkCommandBuffer cmd)
{
    (void)pass;
    begin_rendering(r, cmd, true);
    GdrGpuPushConstants push = gdr_frame_push_constants(r, slot);
    gdr_cpu_path_record_draws(r, cmd, &push);
    vkCmdEndRendering(cmd);
}

void gdr_pass_record_readback(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass, VkCommandBuffer cmd)
{
    (void)pass;
    VkBufferCopy stats_copy = {0, 0, sizeof(GdrGpuDrawStats)};
    vkCmdCopyBuffer(cmd, slot->draw_stats.buffer, slot->stats_readback.buffer, 1, &stats_copy);
    if (slot->plan.config.visbuffer) {
        VkBufferCopy counters_copy = {0, 0, sizeof(GdrGpuRasterCounters)};
        vkCmdCopyBuffer(cmd, r->vis.counters.buffer, r->vis.counters_readback[slot - r->slots].buffer, 1,
                        &counters_copy);
    }
}
