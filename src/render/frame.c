/* One frame: its globals, its plan (frame_plan.h) recorded with the derived barriers and timestamps
 * or its recorded commands submitted again, and its timings once it has finished. */
#include <math.h>
#include <string.h>

#include "render/renderer_internal.h"
#include "render/frame.h"
#include "render/frame_record.h"
#include "gpu_shared/point_level.h"

void gdr_frame_matrices(const gdr_renderer *r, const gdr_camera *camera, gdr_mat4 *projection, gdr_mat4 *view)
{
    /* The vertical field of view is kept and the aspect is the image's, whatever the camera's own
     * (glTF's rule for an aspectRatio that differs from the viewport's: no stretching, no cropping). */
    float aspect = (float)r->width / (float)r->height;
    if (camera->ymag > 0.0f) /* orthographic: ymag kept, the width from the image's aspect, by the same rule */
        *projection = gdr_orthographic_reverse_z(camera->ymag * aspect, camera->ymag, camera->znear, camera->zfar);
    else
        *projection = camera->zfar > 0.0f ? gdr_perspective_reverse_z(camera->yfov, aspect, camera->znear, camera->zfar)
                                          : gdr_perspective_reverse_z_infinite(camera->yfov, aspect, camera->znear);
    *view = gdr_view_from_pose(camera->position, camera->rotation);
}

/* Where the culling and shading see a camera from (gdr_gpu_types.h, GdrGpuFrameGlobals.lod_znear):
 * its position, or for an orthographic camera a point far behind it along its axis, from which
 * every direction to the scene is the camera's own. */
static gdr_vec3 viewer_position(const gdr_camera *camera)
{
    if (!(camera->ymag > 0.0f))
        return camera->position;
    gdr_vec3 forward = gdr_quat_rotate(gdr_quat_normalize(camera->rotation), (gdr_vec3){0.0f, 0.0f, -1.0f});
    return gdr_vec3_sub(camera->position, gdr_vec3_scale(forward, GDR_ORTHO_VIEWER_DISTANCE));
}

GdrGpuPushConstants gdr_frame_push_constants(const gdr_renderer *r, const gdr_frame_slot *slot)
{
    return (GdrGpuPushConstants){.globals = slot->globals.address, .frame = slot->frame_buffers.address,
                                 .scene = r->scene.refs.address, .visbuffer = r->vis.pixels.address};
}

static GdrGpuFrameBuffers frame_buffers(const gdr_renderer *r, const gdr_frame_slot *slot)
{
    return (GdrGpuFrameBuffers){
        .draws = slot->draws.address, .draw_stats = slot->draw_stats.address, .updates = slot->updates.address,
        .tasks = slot->tasks.address, .overdraw = r->overdraw.address, .visible_meshlets = r->visible_meshlets.address,
        .raster = r->vis.params[slot - r->slots].address, .traversal = r->scene.traversal.address,
        .occluded_instances = r->occlusion.occluded_instances.address,
        .occluded_nodes = r->occlusion.occluded_nodes.address, .retest_masks = r->occlusion.retest_masks.address,
        .stream_requests = slot->stream_requests.address,
        .used_groups = slot->used_groups.address, .pvs_visible = slot->pvs_visible.address};
}

static uint32_t frame_flags(const gdr_frame_desc *frame, bool lod, bool occlusion, bool history, bool hierarchy)
{
    return (frame->meshlet_frustum_cull != GDR_CULL_OFF ? GDR_FRAME_MESHLET_FRUSTUM : 0u) |
           (frame->meshlet_cone_cull != GDR_CULL_OFF ? GDR_FRAME_MESHLET_CONE : 0u) |
           (frame->triangle_cull != GDR_CULL_OFF ? GDR_FRAME_TRIANGLE_CULL : 0u) |
           (frame->record_visible_meshlets ? GDR_FRAME_RECORD_MESHLETS : 0u) | (lod ? GDR_FRAME_LOD : 0u) |
           (lod && frame->lod_fixed_depth ? GDR_FRAME_LOD_DEPTH : 0u) | (occlusion ? GDR_FRAME_OCCLUSION : 0u) |
           (history ? GDR_FRAME_HISTORY : 0u) | (hierarchy ? GDR_FRAME_LOD_HIERARCHY : 0u);
}

/* Whether the frame draws instances within a pixel as their point level (shared/point_level.h):
 * the visibility buffer's modes of the mesh pipeline, the LOD cut by error, a perspective camera. */
static bool points_drawn(const gdr_renderer *r, const gdr_frame_desc *frame, gdr_pipeline pipeline, bool ortho)
{
    bool by_error = !frame->lod_fixed_depth && frame->lod_error_px > 0.0f;
    return pipeline == GDR_PIPELINE_MESH && r->vis.mode != GDR_GPU_RASTER_FORWARD && by_error && !ortho &&
           frame->point_level != GDR_CULL_OFF && r->scene.instance_count <= GDR_POINT_MAX_INSTANCES;
}

/* The levels of the LOD hierarchy traversal a frame runs: the deepest hierarchy's, where the mesh
 * pipeline selects the cut by error and the frame does not turn the traversal off. */
static uint32_t traversal_levels(const gdr_renderer *r, const gdr_frame_desc *frame, gdr_pipeline pipeline)
{
    bool by_error = !frame->lod_fixed_depth && frame->lod_error_px > 0.0f;
    return pipeline == GDR_PIPELINE_MESH && by_error && frame->lod_hierarchy != GDR_CULL_OFF ? r->scene.traversal_levels
                                                                                             : 0;
}

/* The frame's LOD threshold: a streamed scene raises it while its cut needs more pages than the
 * pool holds (stream/lod_budget.h); the statistics report what was drawn with. */
static float lod_threshold(gdr_renderer *r, const gdr_frame_slot *slot, const gdr_frame_desc *frame)
{
    if (!r->scene.streamed)
        return frame->lod_error_px;
    float threshold = frame->lod_error_px * slot->stream_lod_scale;
    r->stream.stats.lod_error_px = threshold;
    return threshold;
}

static void write_globals(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_desc *frame, gdr_pipeline pipeline,
                          uint32_t update_count, bool occlusion, bool history)
{
    const gdr_camera *camera = &frame->camera;
    /* Culling and LOD use `view`, `frustum` and `camera_position`; drawing uses view_projection. */
    const gdr_camera *cull_camera = frame->cull_camera ? frame->cull_camera : camera;
    gdr_mat4 projection, view, cull_projection, cull_view;
    gdr_frame_matrices(r, camera, &projection, &view);
    gdr_frame_matrices(r, cull_camera, &cull_projection, &cull_view);
    gdr_vec3 light = gdr_vec3_normalize((gdr_vec3){GDR_LIGHT_TOWARDS_X, GDR_LIGHT_TOWARDS_Y, GDR_LIGHT_TOWARDS_Z});
    /* The LOD cut: only where the mesh pipeline draws clusters, and only when it asks for something
     * other than level 0 (threshold 0 and depth 0 both select exactly level 0). */
    bool lod = pipeline == GDR_PIPELINE_MESH &&
               (frame->lod_fixed_depth ? frame->lod_depth > 0 : frame->lod_error_px > 0.0f);
    bool ortho = camera->ymag > 0.0f; /* the culling camera's projection is the camera's (check_frame) */
    gdr_vec3 cull_eye = viewer_position(cull_camera), eye = viewer_position(camera);
    float lod_znear = ortho ? GDR_ORTHO_LOD_DISTANCE : camera->znear;
    GdrGpuFrameGlobals globals = {
        .view = cull_view,
        .view_projection = gdr_mat4_mul(projection, view),
        .frustum = ortho ? (gdr_vec4){1.0f, 0.0f, 1.0f, 0.0f} : gdr_frustum_symmetric(cull_projection),
        .frustum_offset = ortho ? (gdr_vec2){1.0f / cull_projection.m[0], 1.0f / cull_projection.m[5]}
                                : (gdr_vec2){0.0f, 0.0f},
        .camera_position = {cull_eye.x, cull_eye.y, cull_eye.z, 1.0f},
        .lod_znear = lod_znear,
        .orthographic = ortho ? 1u : 0u,
        .light_direction = {light.x, light.y, light.z, 0.0f},
        .znear = camera->znear,
        .zfar = camera->zfar > 0.0f ? camera->zfar : INFINITY,
        .instance_count = r->scene.instance_count,
        .cull_enabled = frame->cull != GDR_CULL_OFF,
        .update_count = update_count,
        .flags = frame_flags(frame, lod, occlusion, history, traversal_levels(r, frame, pipeline) > 0) |
                 (r->debug.shrink_lod_nodes ? GDR_FRAME_DEBUG_SHRINK_NODES : 0u) |
                 (r->scene.absent_groups > 0 ? GDR_FRAME_PARTIAL_RESIDENCY : 0u) |
                 (r->scene.streamed ? GDR_FRAME_PAGED_RECORDS : 0u) |
                 (r->materials.scene_flags & GDR_MATERIALS_MASKED ? GDR_FRAME_ALPHA_TEST : 0u) |
                 (r->materials.scene_flags & GDR_MATERIALS_DOUBLE_SIDED ? GDR_FRAME_DOUBLE_SIDED : 0u) |
                 (r->materials.scene_flags & GDR_MATERIALS_VERTEX_COLORS ? GDR_FRAME_VERTEX_COLORS : 0u) |
                 (slot->pvs_cell_found && pipeline != GDR_PIPELINE_CPU ? GDR_FRAME_PVS : 0u) |
                 (pipeline == GDR_PIPELINE_MESH && r->vis.mode != GDR_GPU_RASTER_FORWARD ? GDR_FRAME_DIRECT_CLUSTERS
                                                                                        : 0u) |
                 (points_drawn(r, frame, pipeline, ortho) ? GDR_FRAME_POINTS : 0u),
        .view_mode = (uint32_t)frame->view,
        .task_capacity = r->scene.task_capacity,
        .viewport = {(float)r->width, (float)r->height},
        .lod_threshold = lod_threshold(r, slot, frame),
        .lod_projection_scale = fabsf(projection.m[5]) * 0.5f * (float)r->height * (ortho ? lod_znear : 1.0f),
        .lod_depth = frame->lod_depth > INT32_MAX ? INT32_MAX : (int32_t)frame->lod_depth,
        .traversal_capacity = r->scene.traversal_capacity,
        .records_per_slot = r->scene.streamed ? r->stream.records_per_slot : 0u,
        .occluded_node_capacity = r->occlusion.occluded_node_capacity,
        .min_screen_size = frame->min_screen_size,
        .clip_plane = frame->clip_plane,
        .screen_scale = fmaxf(fabsf(projection.m[0]), fabsf(projection.m[5])) * (ortho ? GDR_ORTHO_VIEWER_DISTANCE : 1.0f),
        .stream_frame = slot->stream_frame,
        .eye_position = {eye.x, eye.y, eye.z, 1.0f},
    };
    gdr_occlusion_params(r, &projection, camera->znear, &globals.occlusion);
    /* The early phase tests against last frame's pyramid as last frame's camera saw it. */
    globals.previous_view = history ? r->occlusion.previous_view : view;
    globals.previous_occlusion = history ? r->occlusion.previous_params : globals.occlusion;
    r->occlusion.previous_view = view;
    r->occlusion.previous_params = globals.occlusion;
    memcpy(slot->globals.mapped, &globals, sizeof globals);
    GdrGpuFrameBuffers buffers = frame_buffers(r, slot); /* (visible_meshlets is made on first use) */
    memcpy(slot->frame_buffers.mapped, &buffers, sizeof buffers);
    slot->lod_applied = lod;
    slot->occlusion_applied = occlusion;
}

/* Two-phase occlusion culling where the frame asks for it, by default where it pays: on the indirect
 * pipeline, not on the mesh pipeline, whose frames it made slower on every scene measured on the
 * H100 (docs/OCCLUSION.md, "Which pipelines cull by default"). */
static bool occlusion_wanted(const gdr_frame_desc *frame, gdr_pipeline pipeline)
{
    /* The depth pyramid's sphere test is perspective's (docs/OCCLUSION.md): none for an
     * orthographic camera. */
    if (pipeline == GDR_PIPELINE_CPU || frame->cull == GDR_CULL_OFF || frame->occlusion == GDR_CULL_OFF ||
        frame->cull_camera || frame->camera.ymag > 0.0f)
        return false;
    return frame->occlusion == GDR_CULL_ON || pipeline == GDR_PIPELINE_INDIRECT;
}

/* Moves up to one frame's worth of pending instance updates into the slot's ring segment. */
static uint32_t take_updates(gdr_renderer *r, gdr_frame_slot *slot)
{
    gdr_gpu_scene *g = &r->scene;
    uint32_t count = g->pending_count < GDR_INSTANCE_UPDATES_PER_FRAME ? g->pending_count : GDR_INSTANCE_UPDATES_PER_FRAME;
    if (count == 0)
        return 0;
    memcpy(slot->updates.mapped, g->pending, sizeof(GdrGpuInstanceUpdate) * count);
    memmove(g->pending, g->pending + count, sizeof(GdrGpuInstanceUpdate) * (g->pending_count - count));
    g->pending_count -= count;
    return count;
}

static void record_barrier(gdr_renderer *r, VkCommandBuffer cmd, const gdr_frame_barrier *b)
{
    if (!b->src.stages && !b->dst.stages && b->image_count == 0)
        return;
    gdr_vk_image_transition images[3];
    for (uint32_t i = 0; i < b->image_count; i++) {
        const gdr_image_transition *t = &b->images[i];
        const gdr_vk_image *image = t->resource == GDR_RES_COLOR ? &r->color
                                    : t->resource == GDR_RES_DEPTH ? &r->depth
                                                                   : &r->occlusion.hzb.pyramid;
        images[i] = (gdr_vk_image_transition){
            .image = image->image, .aspect = t->resource == GDR_RES_DEPTH ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT,
            .from = t->from, .to = t->to, .src = t->src, .dst = t->dst};
    }
    gdr_vk_barrier(cmd, &(gdr_vk_barrier_desc){.src = b->src, .dst = b->dst, .images = images,
                                               .image_count = b->image_count});
}

static void timestamp(gdr_renderer *r, gdr_frame_slot *slot, VkCommandBuffer cmd, uint32_t which)
{
    uint32_t base = (uint32_t)(slot - r->slots) * GDR_FRAME_MAX_TIMESTAMPS;
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, r->timestamps, base + which);
}

/* The slot's plan into its command buffer: before each pass its barrier and, where its timing
 * section begins, a timestamp. */
static gdr_status record_plan(gdr_renderer *r, gdr_frame_slot *slot, gdr_error *err)
{
    VkCommandBuffer cmd = slot->cmd;
    const gdr_frame_plan *plan = &slot->plan;
    GDR_VK_TRY(err, vkResetCommandBuffer(cmd, 0));
    VkCommandBufferBeginInfo begin = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    GDR_VK_TRY(err, vkBeginCommandBuffer(cmd, &begin));
    gdr_frame_bind_state(r, slot, cmd);
    for (uint32_t i = 0; i < plan->pass_count; i++) {
        const gdr_frame_pass *pass = &plan->passes[i];
        record_barrier(r, cmd, &pass->barrier);
        if (pass->timestamp >= 0)
            timestamp(r, slot, cmd, (uint32_t)pass->timestamp);
        if (pass->template_->record)
            pass->template_->record(r, slot, pass, cmd);
    }
    record_barrier(r, cmd, &plan->end_barrier);
    timestamp(r, slot, cmd, plan->timestamp_count - 1);
    GDR_VK_TRY(err, vkEndCommandBuffer(cmd));
    return GDR_OK;
}

gdr_status gdr_frame_record_color_readback(gdr_renderer *r, VkCommandBuffer cmd, gdr_error *err)
{
    VkCommandBufferBeginInfo begin = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    GDR_VK_TRY(err, vkBeginCommandBuffer(cmd, &begin));
    /* After whatever the frame before it did last (its end leaves the image in this layout). */
    gdr_vk_image_barrier(cmd, r->color.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                         VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                         VK_ACCESS_2_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    VkBufferImageCopy region = {.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                                .imageExtent = {r->width, r->height, 1}};
    vkCmdCopyImageToBuffer(cmd, r->color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, r->color_readback.buffer, 1,
                           &region);
    /* The copy for the host, and the image back in the layout frames begin with. */
    gdr_vk_image_transition back = {.image = r->color.image, .aspect = VK_IMAGE_ASPECT_COLOR_BIT,
                                    .from = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                    .to = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                    .src = {VK_PIPELINE_STAGE_2_COPY_BIT, 0},
                                    .dst = {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0}};
    gdr_vk_barrier(cmd, &(gdr_vk_barrier_desc){.src = {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT},
                                               .dst = {VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT},
                                               .images = &back, .image_count = 1});
    GDR_VK_TRY(err, vkEndCommandBuffer(cmd));
    return GDR_OK;
}

/* Submits the slot's frame: streaming's copies before it where it has some, the colour readback
 * after it when `copy_color`. */
static gdr_status submit(gdr_renderer *r, gdr_frame_slot *slot, bool copy_color, double *submit_ms, gdr_error *err)
{
    VkCommandBufferSubmitInfo cmd_info[3];
    uint32_t count = 0;
    VkCommandBuffer buffers[3] = {slot->stream_copies ? slot->stream_cmd : VK_NULL_HANDLE, slot->cmd,
                                  copy_color ? slot->readback_cmd : VK_NULL_HANDLE};
    for (int i = 0; i < 3; i++)
        if (buffers[i])
            cmd_info[count++] = (VkCommandBufferSubmitInfo){.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO,
                                                            .commandBuffer = buffers[i]};
    VkSubmitInfo2 submit = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2, .commandBufferInfoCount = count,
                            .pCommandBufferInfos = cmd_info};
    uint32_t query_base = (uint32_t)(slot - r->slots) * GDR_FRAME_MAX_TIMESTAMPS;
    vkResetQueryPool(r->ctx->device, r->timestamps, query_base, GDR_FRAME_MAX_TIMESTAMPS);
    double start = gdr_now_ms();
    GDR_VK_TRY(err, vkQueueSubmit2(r->ctx->queue, 1, &submit, slot->fence));
    *submit_ms += gdr_now_ms() - start;
    slot->submitted = true;
    slot->timed = true;
    return GDR_OK;
}

static bool same_config(const gdr_frame_config *a, const gdr_frame_config *b)
{
    return a->pipeline == b->pipeline && a->visbuffer == b->visbuffer && a->occlusion == b->occlusion &&
           a->overdraw == b->overdraw && a->updates == b->updates && a->traversal_levels == b->traversal_levels;
}

gdr_status gdr_frame_record_and_submit(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_desc *frame,
                                       gdr_pipeline pipeline, bool copy_color, double *submit_ms, gdr_error *err)
{
    uint32_t update_count = take_updates(r, slot);
    /* Occlusion culling, with its history when the last frame left a usable one. */
    bool occlusion = occlusion_wanted(frame, pipeline);
    bool history = occlusion && r->occlusion.history_valid && r->occlusion.history_pipeline == pipeline &&
                   !frame->occlusion_camera_cut;
    write_globals(r, slot, frame, pipeline, update_count, occlusion, history);
    r->occlusion.history_valid = occlusion;
    r->occlusion.history_pipeline = pipeline;
    uint32_t raster_mode = pipeline == GDR_PIPELINE_MESH ? r->vis.mode : GDR_GPU_RASTER_FORWARD;
    gdr_visbuffer_begin_frame(r, (uint32_t)(slot - r->slots), frame, raster_mode);
    slot->pipeline = pipeline;
    gdr_frame_config config = {.pipeline = pipeline, .visbuffer = raster_mode != GDR_GPU_RASTER_FORWARD,
                               .occlusion = occlusion, .overdraw = frame->view == GDR_VIEW_MODE_OVERDRAW,
                               .updates = update_count > 0,
                               .traversal_levels = traversal_levels(r, frame, pipeline)};
    /* A GPU-driven frame whose commands are already in the slot: submit them again. */
    slot->resubmitted = slot->recorded && same_config(&slot->plan.config, &config);
    if (slot->resubmitted)
        return submit(r, slot, copy_color, submit_ms, err);
    gdr_frame_plan_build(&config, &slot->plan);
    gdr_status status = record_plan(r, slot, err);
    slot->recorded = status == GDR_OK && pipeline != GDR_PIPELINE_CPU && !r->record_every_frame;
    return status == GDR_OK ? submit(r, slot, copy_color, submit_ms, err) : status;
}

/* Adds the slot's finished frame's timings to r->timings. */
static gdr_status collect_timings(gdr_renderer *r, gdr_frame_slot *slot, gdr_error *err)
{
    const gdr_frame_plan *plan = &slot->plan;
    uint64_t ticks[GDR_FRAME_MAX_TIMESTAMPS];
    uint32_t base = (uint32_t)(slot - r->slots) * GDR_FRAME_MAX_TIMESTAMPS;
    GDR_VK_TRY(err, vkGetQueryPoolResults(r->ctx->device, r->timestamps, base, plan->timestamp_count, sizeof ticks,
                                          ticks, sizeof ticks[0], VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    double period_ms = r->ctx->properties.limits.timestampPeriod * 1e-6;
    for (uint32_t i = 0; i + 1 < plan->timestamp_count; i++) {
        double ms = (double)(ticks[i + 1] - ticks[i]) * period_ms;
        r->timings.section_ms[plan->interval_section[i]] += ms;
        r->timings.raster_ms[plan->interval_timer[i]] += ms;
    }
    r->timings.frames++;
    r->timings.raster_frames += plan->config.visbuffer;
    return GDR_OK;
}

gdr_status gdr_frame_slot_wait(gdr_renderer *r, gdr_frame_slot *slot, gdr_error *err)
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
    if (!slot->timed)
        return GDR_OK;
    slot->timed = false;
    return collect_timings(r, slot, err);
}
