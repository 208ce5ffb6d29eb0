/* The public renderer API: device and resources, scene upload, the frame loop and its statistics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/renderer_internal.h"
#include "vk/vk_descriptors.h"
#include "vk/vk_pipeline.h"
#include "render/cpu_driven.h"
#include "render/frame.h"
#include "render/frame_stats.h"
#include "render/gpu_scene.h"
#include "render/pvs_frame.h"
#include "render/streaming.h"
#include "render/target_memory.h"

double gdr_now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

/* The frame pipelines' layout (the push-constant block, set 0 for the depth pyramid, set
 * GDR_TEXTURE_SET for the bindless textures), then the registry's pipelines that the device can run. */
static gdr_status create_pipelines(gdr_renderer *r, gdr_error *err)
{
    const VkDescriptorSetLayout sets[2] = {r->occlusion.set_layout, r->materials.set_layout};
    _Static_assert(GDR_TEXTURE_SET == 1, "the set layouts' order");
    gdr_status status = gdr_vk_pipeline_layout_create_with_sets(r->ctx, sets, 2, VK_SHADER_STAGE_ALL,
                                                                sizeof(GdrGpuPushConstants), &r->layout, err);
    const bool available[3] = {[GDR_NEEDS_CORE] = true,
                               [GDR_NEEDS_MESH_SHADER] = r->ctx->has_mesh_shader,
                               [GDR_NEEDS_VISIBILITY_BUFFER] = r->vis.supported};
    if (status == GDR_OK)
        status = gdr_pipelines_create(r->ctx, r->layout, available, r->pipelines, err);
    return status;
}

static gdr_status create_targets(gdr_renderer *r, gdr_error *err)
{
    gdr_vk_image_desc color = {.width = r->width, .height = r->height, .format = GDR_COLOR_FORMAT,
                               .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                        VK_IMAGE_USAGE_STORAGE_BIT}; /* the visibility buffer's resolve */
    gdr_vk_image_desc depth = {.width = r->width, .height = r->height, .format = GDR_DEPTH_FORMAT,
                               .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                        VK_IMAGE_USAGE_SAMPLED_BIT |      /* the depth pyramid */
                                        VK_IMAGE_USAGE_TRANSFER_SRC_BIT,  /* tests read it back */
                               .aspect = VK_IMAGE_ASPECT_DEPTH_BIT};
    gdr_status status = gdr_vk_image_create(&r->allocator, &color, &r->color, err);
    if (status == GDR_OK)
        status = gdr_vk_image_create(&r->allocator, &depth, &r->depth, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, (VkDeviceSize)r->width * r->height * 4,
                                      VK_BUFFER_USAGE_TRANSFER_DST_BIT, GDR_VK_BUFFER_READBACK, &r->color_readback, err);
    if (status == GDR_OK) /* a count per pixel, then the maximum */
        status = gdr_vk_buffer_create(&r->allocator, ((VkDeviceSize)r->width * r->height + 1) * sizeof(uint32_t),
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                          VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                      GDR_VK_BUFFER_DEVICE, &r->overdraw, err);
    if (status != GDR_OK)
        return status;
    VkQueryPoolCreateInfo query = {.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO, .queryType = VK_QUERY_TYPE_TIMESTAMP,
                                   .queryCount = GDR_FRAMES_IN_FLIGHT * GDR_FRAME_MAX_TIMESTAMPS};
    GDR_VK_TRY(err, vkCreateQueryPool(r->ctx->device, &query, NULL, &r->timestamps));
    return GDR_OK;
}

/* The desc with every zero field (or a NULL desc) given its default. */
static gdr_renderer_desc renderer_desc_defaults(const gdr_renderer_desc *in)
{
    gdr_renderer_desc d = in ? *in : (gdr_renderer_desc){0};
    d.width = d.width ? d.width : 1280;
    d.height = d.height ? d.height : 720;
    return d;
}

gdr_status gdr_renderer_create(const gdr_renderer_desc *desc_in, gdr_renderer **out, gdr_error *err)
{
    gdr_renderer_desc desc = renderer_desc_defaults(desc_in);
    if (desc.width > 16384 || desc.height > 16384)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render size %ux%u exceeds 16384x16384", desc.width,
                             desc.height);
    gdr_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
    r->width = desc.width;
    r->height = desc.height;
    r->last_slot = -1;
    r->busy_wait = desc.busy_wait;
    r->record_every_frame = desc.record_every_frame;
    gdr_vk_context_desc context_desc = {.device = desc.device, .validate = desc.validate,
                                        .synchronization_validation = desc.synchronization_validation,
                                        .disable_mesh_shaders = desc.disable_mesh_shaders,
                                        .disable_texture_compression_bc = desc.disable_texture_compression_bc,
                                        .instance_extensions = desc.instance_extensions,
                                        .instance_extension_count = desc.instance_extension_count,
                                        .swapchain = desc.presentable};
    gdr_status status = gdr_vk_context_create(&context_desc, &r->ctx, err);
    if (status == GDR_OK) {
        gdr_vk_allocator_init(&r->allocator, r->ctx);
        status = gdr_vk_staging_create(&r->allocator, &r->staging, err);
    }
    if (status == GDR_OK)
        status = gdr_target_memory_check(r->ctx, r->width, r->height, err);
    if (status == GDR_OK)
        status = create_targets(r, err);
    if (status == GDR_OK)
        status = gdr_occlusion_create(r, err);
    if (status == GDR_OK)
        status = gdr_visbuffer_create(r, desc.disable_visibility_buffer, err);
    if (status == GDR_OK)
        status = gdr_materials_create(r, err);
    if (status == GDR_OK)
        status = create_pipelines(r, err);
    if (status != GDR_OK) {
        gdr_renderer_destroy(r);
        return status;
    }
    *out = r;
    return GDR_OK;
}

void gdr_renderer_destroy(gdr_renderer *r)
{
    if (!r)
        return;
    if (r->ctx) {
        vkDeviceWaitIdle(r->ctx->device);
        gdr_frame_slots_destroy(r);
        gdr_gpu_scene_destroy(r);
        gdr_streaming_destroy(r);
        gdr_cpu_path_destroy(r);
        gdr_render_pvs_destroy(r);
        gdr_visbuffer_destroy(r);
        VkDevice device = r->ctx->device;
        if (r->timestamps)
            vkDestroyQueryPool(device, r->timestamps, NULL);
        gdr_pipelines_destroy(r->ctx, r->pipelines);
        if (r->layout)
            vkDestroyPipelineLayout(device, r->layout, NULL);
        gdr_occlusion_destroy(r);
        gdr_materials_destroy(r);
        gdr_vk_image_destroy(r->ctx, &r->color);
        gdr_vk_image_destroy(r->ctx, &r->depth);
        gdr_vk_buffer_destroy(r->ctx, &r->color_readback);
        gdr_vk_buffer_destroy(r->ctx, &r->overdraw);
        gdr_vk_buffer_destroy(r->ctx, &r->visible_meshlets);
        gdr_vk_buffer_destroy(r->ctx, &r->staging);
        gdr_vk_allocator_destroy(&r->allocator);
        gdr_vk_context_destroy(r->ctx);
    }
    free(r);
}

/* The scene's upload, streamed (`stream` not NULL) or whole. */
static gdr_status set_scene(gdr_renderer *r, const gdr_scene *scene, const gdr_streaming_desc *stream, gdr_error *err)
{
    /* Device memory is sub-allocated linearly and released with the renderer. */
    if (r->has_scene)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "the renderer already holds a scene: create another renderer for a new scene");
    if (!stream && scene->geometry_in_pages)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "the scene was read for streaming and holds no geometry: "
                             "render it with gdr_renderer_set_scene_streamed");
    if (stream && !r->ctx->has_mesh_shader)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "streaming draws with the mesh pipeline, not available on "
                             "'%s': %s", r->ctx->properties.deviceName, r->ctx->mesh_shader_missing);
    double start = gdr_now_ms();
    gdr_status status = stream ? gdr_streaming_open(r, scene, stream, err) : GDR_OK;
    double opened = gdr_now_ms();
    if (status == GDR_OK)
        status = gdr_gpu_scene_upload(r, scene, err);
    if (status == GDR_OK)
        status = gdr_materials_upload(r, scene, err);
    if (stream) /* vertex colours are indexed by the mesh's vertices, which pages repeat per cluster */
        r->materials.scene_flags &= ~GDR_MATERIALS_VERTEX_COLORS;
    if (status == GDR_OK && (r->materials.scene_flags & (GDR_MATERIALS_MASKED | GDR_MATERIALS_DOUBLE_SIDED)))
        status = gdr_pipelines_for_materials(r->ctx, r->layout, r->materials.scene_flags & GDR_MATERIALS_DOUBLE_SIDED,
                                             r->pipelines, err);
    if (status == GDR_OK)
        status = gdr_frame_slots_create(r, err);
    if (status == GDR_OK)
        status = gdr_cpu_path_create(r, scene, err);
    if (status == GDR_OK)
        status = gdr_render_pvs_scene(r, err);
    if (status == GDR_OK)
        status = gdr_visbuffer_set_scene(r, err);
    if (status == GDR_OK)
        status = gdr_occlusion_scene_create(r, err);
    if (status == GDR_OK)
        status = gdr_gpu_scene_write_refs(r, err);
    if (stream) {
        r->stream.stats.setup_open_ms = opened - start;
        r->stream.stats.setup_scene_ms = gdr_now_ms() - opened;
    }
    if (status == GDR_OK && stream)
        status = gdr_streaming_start(r, err);
    if (status == GDR_OK)
        r->has_scene = true;
    return status;
}

gdr_status gdr_renderer_set_scene(gdr_renderer *r, const gdr_scene *scene, gdr_error *err)
{
    return set_scene(r, scene, NULL, err);
}

gdr_status gdr_renderer_set_scene_streamed(gdr_renderer *r, const gdr_scene *scene, const gdr_streaming_desc *desc,
                                           gdr_error *err)
{
    if (!desc)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "set_scene_streamed: no streaming description");
    return set_scene(r, scene, desc, err);
}

gdr_status gdr_renderer_update_instance(gdr_renderer *r, uint32_t index, const gdr_mat4 *transform,
                                        const gdr_vec4 *color, gdr_error *err)
{
    gdr_gpu_scene *g = &r->scene;
    if (!r->has_scene || index >= g->instance_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "update_instance: instance %u does not exist (%u instances)",
                             index, g->instance_count);
    if (g->pending_count == g->pending_capacity) {
        uint32_t capacity = g->pending_capacity ? g->pending_capacity * 2 : 256;
        GdrGpuInstanceUpdate *grown = realloc(g->pending, sizeof *grown * capacity);
        if (!grown)
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "update_instance: out of memory");
        g->pending = grown;
        g->pending_capacity = capacity;
    }
    GdrGpuInstance *instance = &g->cpu_instances[index];
    if (transform) {
        instance->model = *transform;
        gdr_render_pvs_moved(r, index); /* the PVS was baked where it stood */
    }
    if (color)
        instance->color = *color;
    g->pending[g->pending_count++] = (GdrGpuInstanceUpdate){.tag = GDR_UPDATE_TAG_INSTANCE, .index = index,
                                                            .instance = *instance};
    return gdr_cpu_path_update_instance(r, index, err);
}

const char *gdr_pipeline_name(gdr_pipeline pipeline)
{
    switch (pipeline) {
    case GDR_PIPELINE_MESH: return "mesh";
    case GDR_PIPELINE_INDIRECT: return "indirect";
    case GDR_PIPELINE_CPU: return "cpu";
    default: return "default";
    }
}

const char *gdr_raster_name(gdr_raster raster)
{
    static const char *const names[] = {"default", "hybrid", "hw", "sw", "forward"};
    return (unsigned)raster < sizeof names / sizeof names[0] ? names[raster] : "unknown";
}

const char *gdr_view_name(gdr_view view)
{
    static const char *const names[] = {"shaded", "meshlets", "instances", "triangles", "overdraw", "lod"};
    return (unsigned)view < sizeof names / sizeof names[0] ? names[view] : "unknown";
}

bool gdr_renderer_has_mesh_pipeline(const gdr_renderer *r, const char **why_not)
{
    if (why_not)
        *why_not = r->ctx->has_mesh_shader ? "" : r->ctx->mesh_shader_missing;
    return r->ctx->has_mesh_shader;
}

/* The pipeline a frame asks for, resolved against the device; fails for mesh without mesh shaders. */
static gdr_status resolve_pipeline(const gdr_renderer *r, const gdr_frame_desc *frame, gdr_pipeline *out, char *reason,
                                   size_t reason_size, gdr_error *err)
{
    switch (frame->pipeline) {
    case GDR_PIPELINE_DEFAULT:
        *out = r->ctx->has_mesh_shader ? GDR_PIPELINE_MESH : GDR_PIPELINE_INDIRECT;
        if (r->ctx->has_mesh_shader)
            snprintf(reason, reason_size, "default: the device has VK_EXT_mesh_shader");
        else
            snprintf(reason, reason_size, "default: no mesh pipeline (%s)", r->ctx->mesh_shader_missing);
        return GDR_OK;
    case GDR_PIPELINE_MESH:
        if (!r->ctx->has_mesh_shader)
            return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "pipeline mesh: not available on '%s': %s",
                                 r->ctx->properties.deviceName, r->ctx->mesh_shader_missing);
        /* fall through */
    case GDR_PIPELINE_INDIRECT:
    case GDR_PIPELINE_CPU:
        *out = frame->pipeline;
        snprintf(reason, reason_size, "asked for");
        return GDR_OK;
    }
    return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: unknown pipeline %d", (int)frame->pipeline);
}

/* The frame description's checks; the pipeline and raster mode it asks for on this device. */
static gdr_status check_frame(gdr_renderer *r, const gdr_frame_desc *frame, uint32_t frames, gdr_pipeline *pipeline,
                              char *reason, size_t reason_size, gdr_error *err)
{
    if (!r->has_scene)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: no scene (call gdr_renderer_set_scene first)");
    if (frames == 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: frames must be at least 1");
    const gdr_camera *camera = &frame->camera;
    if (camera->ymag != 0.0f) {
        if (!(camera->ymag > 0.0f && camera->ymag <= 1e30f) || !(camera->znear >= 0.0f) ||
            !(camera->zfar > camera->znear && camera->zfar <= 1e30f))
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                 "render: an orthographic camera needs ymag > 0, znear >= 0 and a finite zfar > znear "
                                 "(ymag %g, znear %g, zfar %g)", (double)camera->ymag, (double)camera->znear,
                                 (double)camera->zfar);
    } else if (!(camera->yfov > 0.0f && camera->yfov < 3.14159f) || !(camera->znear > 0.0f) ||
               !(camera->zfar == 0.0f || camera->zfar > camera->znear)) {
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "render: camera needs 0 < yfov < pi, znear > 0 and zfar = 0 or > znear "
                             "(yfov %g, znear %g, zfar %g)", (double)camera->yfov, (double)camera->znear,
                             (double)camera->zfar);
    }
    const gdr_camera *cull = frame->cull_camera;
    if (cull && (cull->yfov != camera->yfov || cull->aspect != camera->aspect || cull->znear != camera->znear ||
                 cull->zfar != camera->zfar || cull->ymag != camera->ymag))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "render: the culling camera's projection (yfov, ymag, aspect, znear, zfar) must be the "
                             "camera's");
    if ((unsigned)frame->view > GDR_VIEW_MODE_LOD)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: unknown view %d", (int)frame->view);
    if (!(frame->lod_error_px >= 0.0f && frame->lod_error_px <= 1e30f))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: lod_error_px must be finite and >= 0 (%g)",
                             (double)frame->lod_error_px);
    if (!(frame->min_screen_size >= 0.0f && frame->min_screen_size <= 1e30f))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: min_screen_size must be finite and >= 0 (%g)",
                             (double)frame->min_screen_size);
    const float *plane = &frame->clip_plane.x;
    for (int i = 0; i < 4; i++)
        if (!isfinite(plane[i]))
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: clip_plane must be finite");
    if ((unsigned)frame->pvs > GDR_CULL_OFF)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: unknown pvs mode %d", (int)frame->pvs);
    /* A build without the culling module (gdr/config.h) has neither the CPU pipeline nor a PVS. */
    if (!GDR_HAVE_CULL && (frame->pipeline == GDR_PIPELINE_CPU || frame->pvs == GDR_CULL_ON))
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "render: %s: built without the culling module "
                             "(GDR_EXCLUDE_MODULES)", frame->pipeline == GDR_PIPELINE_CPU ? "pipeline cpu" : "pvs on");
    if (frame->pvs == GDR_CULL_ON && !r->pvs.pvs)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: pvs on, but the renderer holds no precomputed "
                             "visibility (gdr_renderer_set_pvs; gdr build --pvs writes it into a scene's cache)");
    gdr_status status = resolve_pipeline(r, frame, pipeline, reason, reason_size, err);
    /* Streamed geometry is drawn only through the LOD cut over resident groups. */
    if (status == GDR_OK && r->scene.streamed && (*pipeline != GDR_PIPELINE_MESH || frame->lod_fixed_depth ||
                                                  !(frame->lod_error_px > 0.0f) || frame->lod_hierarchy == GDR_CULL_OFF))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render: a streamed scene draws with the mesh pipeline "
                             "and a LOD cut by error (lod_error_px > 0) through the LOD hierarchy (lod_hierarchy on)");
    if (status == GDR_OK)
        status = gdr_visbuffer_resolve_mode(r, frame, *pipeline, &r->vis.mode, r->vis.reason, sizeof r->vis.reason, err);
    if (status == GDR_OK && frame->record_visible_meshlets && !r->visible_meshlets.buffer) {
        /* Every cluster of every instance's DAG at most: cannot overflow. */
        uint64_t total = r->scene.instance_lod_cluster_count;
        status = gdr_vk_buffer_create(&r->allocator, 8 * (total ? total : 1),
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                      GDR_VK_BUFFER_DEVICE, &r->visible_meshlets, err);
    }
    return status;
}

/* One frame: its slot's previous frame waited for, culled on the CPU where the pipeline does, and
 * recorded or resubmitted. Adds its CPU time to frame_cpu_ms. */
static gdr_status run_frame(gdr_renderer *r, const gdr_frame_desc *frame, gdr_pipeline pipeline, bool read_back,
                            double *frame_cpu_ms, double *submit_ms, uint32_t *recorded, gdr_error *err)
{
    gdr_frame_slot *slot = &r->slots[r->frame_index % GDR_FRAMES_IN_FLIGHT];
    gdr_status status = gdr_frame_slot_wait(r, slot, err);
    if (status != GDR_OK)
        return status;
    double start = gdr_now_ms();
    gdr_render_pvs_begin_frame(r, slot, frame, pipeline);
    if (pipeline == GDR_PIPELINE_CPU)
        status = gdr_cpu_path_cull(r, frame, err);
    if (status == GDR_OK)
        status = gdr_streaming_begin_frame(r, slot, err);
    if (status == GDR_OK) {
        slot->cpu_visible_count = r->cpu.visible_count;
        slot->cpu_triangles = r->cpu.triangles;
        slot->cpu_pvs_culled = r->cpu.pvs_culled;
        if (pipeline == GDR_PIPELINE_CPU)
            slot->pvs_cell_found = r->cpu.pvs_cell_found;
        status = gdr_frame_record_and_submit(r, slot, frame, pipeline, read_back, submit_ms, err);
    }
    *frame_cpu_ms = gdr_now_ms() - start;
    if (status != GDR_OK)
        return status;
    *recorded += !slot->resubmitted;
    r->last_slot = (int)(slot - r->slots);
    r->frame_index++;
    return GDR_OK;
}

gdr_status gdr_renderer_render(gdr_renderer *r, const gdr_frame_desc *frame, uint32_t frames, gdr_frame_stats *stats,
                               gdr_error *err)
{
    gdr_pipeline pipeline = GDR_PIPELINE_INDIRECT;
    char reason[160] = "";
    gdr_status status = check_frame(r, frame, frames, &pipeline, reason, sizeof reason, err);
    if (status != GDR_OK)
        return status;
    double *frame_cpu_ms = malloc(sizeof(double) * frames);
    if (!frame_cpu_ms)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "render: out of memory");
    r->timings = (gdr_frame_timings){0};
    r->cpu.cull_ms = 0.0;
    r->pvs.cpu_ms = 0.0;
    r->color_read_back = false;
    double submit_ms = 0.0;
    uint32_t recorded = 0;
    for (uint32_t f = 0; f < frames && status == GDR_OK; f++)
        status = run_frame(r, frame, pipeline, f + 1 == frames && frame->read_back, &frame_cpu_ms[f], &submit_ms,
                           &recorded, err);
    /* Drain every slot so the last frame's results are on the host. */
    for (uint32_t i = 0; i < GDR_FRAMES_IN_FLIGHT && status == GDR_OK; i++)
        status = gdr_frame_slot_wait(r, &r->slots[i], err);
    if (status == GDR_OK) {
        r->color_read_back = frame->read_back;
        if (stats)
            gdr_frame_stats_fill(r, pipeline, reason, frame_cpu_ms, frames, submit_ms, recorded, stats);
    }
    free(frame_cpu_ms);
    return status;
}

gdr_status gdr_renderer_read_color(gdr_renderer *r, uint8_t *rgba, gdr_error *err)
{
    if (!r->color_read_back)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "read_color: the last frame was not rendered with read_back");
    memcpy(rgba, r->color_readback.mapped, (size_t)r->width * r->height * 4);
    return GDR_OK;
}

gdr_status gdr_renderer_read_visible(gdr_renderer *r, uint32_t *indices, uint32_t capacity, uint32_t *count,
                                     gdr_error *err)
{
    if (r->last_slot < 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "read_visible: no frame rendered yet");
    gdr_frame_slot *slot = &r->slots[r->last_slot];
    GdrGpuDrawStats gpu;
    memcpy(&gpu, slot->stats_readback.mapped, sizeof gpu);
    bool late = slot->occlusion_applied;
    *count = slot->pipeline == GDR_PIPELINE_CPU ? slot->cpu_visible_count
                                                : gpu.draw_count + (late ? gpu.instances_late_drawn : 0);
    if (*count > capacity)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "read_visible: %u visible instances, room for %u", *count,
                             capacity);
    if (slot->pipeline == GDR_PIPELINE_CPU) {
        /* The CPU's list of the last frame (frames are culled and recorded in order). */
        memcpy(indices, r->cpu.visible, sizeof(uint32_t) * *count);
        return GDR_OK;
    }
    if (*count == 0)
        return GDR_OK;
    gdr_vk_buffer readback = {0};
    gdr_status status;
    uint32_t n = 0;
    if (slot->pipeline == GDR_PIPELINE_MESH) {
        /* The instance cull lists the visible instances in the draw-command list: the early (or
         * only) phase's, then those of the late phase that it did not draw early. */
        status = gdr_vk_buffer_read_back(&r->allocator, slot->draws.buffer, 0,
                                         sizeof(GdrGpuDrawCommand) * (VkDeviceSize)*count, &readback, err);
        const GdrGpuDrawCommand *draws = readback.mapped;
        for (uint32_t i = 0; status == GDR_OK && i < gpu.instances_listed && n < *count; i++)
            indices[n++] = draws[i].first_instance;
    } else {
        status = gdr_vk_buffer_read_back(&r->allocator, slot->draws.buffer, 0,
                                         sizeof(GdrGpuDrawCommand) * 2 * (VkDeviceSize)r->scene.instance_count,
                                         &readback, err);
        const GdrGpuDrawCommand *draws = readback.mapped;
        for (uint32_t i = 0; status == GDR_OK && i < gpu.draw_count && n < *count; i++)
            indices[n++] = draws[i].first_instance;
        for (uint32_t i = 0; status == GDR_OK && late && i < gpu.late_draw_count && n < *count; i++)
            indices[n++] = draws[r->scene.instance_count + i].first_instance;
    }
    if (status == GDR_OK && n != *count)
        status = gdr_error_set(err, GDR_ERROR_VULKAN, "read_visible: %u instances counted, %u in the command lists",
                               *count, n);
    gdr_vk_buffer_destroy(r->ctx, &readback);
    return status;
}

gdr_status gdr_renderer_read_visible_meshlets(gdr_renderer *r, gdr_visible_meshlet *meshlets, uint32_t capacity,
                                              uint32_t *count, gdr_error *err)
{
    if (r->last_slot < 0 || r->slots[r->last_slot].pipeline != GDR_PIPELINE_MESH || !r->visible_meshlets.buffer)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "read_visible_meshlets: the last frame was not a mesh-pipeline frame with "
                             "record_visible_meshlets");
    GdrGpuDrawStats gpu;
    memcpy(&gpu, r->slots[r->last_slot].stats_readback.mapped, sizeof gpu);
    *count = gpu.meshlets_recorded;
    if (*count > capacity)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "read_visible_meshlets: %u clusters, room for %u", *count,
                             capacity);
    if (*count == 0)
        return GDR_OK;
    gdr_vk_buffer readback = {0};
    gdr_status status = gdr_vk_buffer_read_back(&r->allocator, r->visible_meshlets.buffer, 0, 8 * (VkDeviceSize)*count,
                                                &readback, err);
    for (uint32_t i = 0; status == GDR_OK && i < *count; i++) {
        const uint32_t *pair = (const uint32_t *)readback.mapped + 2 * i;
        uint32_t mesh = r->scene.cpu_instances[pair[0]].mesh, record_mesh = mesh;
        /* Streamed, a record of the record pool: its slot's page says which cluster. */
        uint32_t cluster = r->scene.streamed ? gdr_streaming_record_cluster(r, pair[1], &record_mesh)
                                             : pair[1] - r->scene.cpu_meshes[mesh].meshlet_offset;
        meshlets[i] = (gdr_visible_meshlet){pair[0], record_mesh == mesh ? cluster : UINT32_MAX};
    }
    gdr_vk_buffer_destroy(r->ctx, &readback);
    return status;
}

void gdr_renderer_size(const gdr_renderer *r, uint32_t *width, uint32_t *height)
{
    *width = r->width;
    *height = r->height;
}

void gdr_renderer_set_debug(gdr_renderer *r, const gdr_renderer_debug *debug) { r->debug = *debug; }
