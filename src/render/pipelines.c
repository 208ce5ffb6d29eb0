/* The pipeline registry (pipelines.h). */
#include "render/pipelines.h"

#include <stddef.h>

#include "render/renderer_internal.h"
#include "vk/vk_pipeline.h"

typedef enum gdr_pipeline_targets {
    GDR_TARGETS_COLOR_DEPTH, /* the frame's colour and depth attachments */
    GDR_TARGETS_COLOR,       /* colour only, no depth test (a full-screen pass) */
    GDR_TARGETS_NONE,        /* no attachments, no depth test (the visibility buffer's atomics) */
} gdr_pipeline_targets;

typedef struct gdr_pipeline_entry {
    const char *name;
    gdr_pipeline_needs needs;
    const gdr_spirv *compute;                        /* compute pipelines */
    const gdr_spirv *vertex, *task, *mesh, *fragment; /* graphics pipelines */
    const gdr_spirv *alpha_fragment; /* the fragment shader that alpha-tests, for scenes with MASK or BLEND materials */
    uint32_t constants[2];  /* specialisation constants 0, 1 of the compute or the task shader */
    uint32_t constant_count;
    gdr_pipeline_targets targets;
    bool vertex_input;      /* GdrGpuVertex position, normal and uv at locations 0, 1 and 2 */
    bool cull_back;
} gdr_pipeline_entry;

static const gdr_pipeline_entry entries[GDR_PIPE_COUNT] = {
    [GDR_PIPE_INSTANCE_SCATTER] = {"instance_scatter", .compute = &gdr_shader_instance_scatter_comp},
    [GDR_PIPE_CULL_DRAWS] = {"cull_draws", .compute = &gdr_shader_drawcull_comp, .constants = {0, 0}, .constant_count = 2},
    [GDR_PIPE_CULL_DRAWS + 1] = {"cull_draws_early", .compute = &gdr_shader_drawcull_comp, .constants = {0, 1},
                                 .constant_count = 2},
    [GDR_PIPE_CULL_DRAWS + 2] = {"cull_draws_late", .compute = &gdr_shader_drawcull_comp, .constants = {0, 2},
                                 .constant_count = 2},
    [GDR_PIPE_CULL_TASKS] = {"cull_tasks", GDR_NEEDS_MESH_SHADER, .compute = &gdr_shader_drawcull_comp,
                             .constants = {1, 0}, .constant_count = 2},
    [GDR_PIPE_CULL_TASKS + 1] = {"cull_tasks_early", GDR_NEEDS_MESH_SHADER, .compute = &gdr_shader_drawcull_comp,
                                 .constants = {1, 1}, .constant_count = 2},
    [GDR_PIPE_CULL_TASKS + 2] = {"cull_tasks_late", GDR_NEEDS_MESH_SHADER, .compute = &gdr_shader_drawcull_comp,
                                 .constants = {1, 2}, .constant_count = 2},
    [GDR_PIPE_CULL_POINTS] = {"cull_points", GDR_NEEDS_VISIBILITY_BUFFER, .compute = &gdr_shader_drawcull_points_comp,
                              .constants = {1, 0}, .constant_count = 2},
    [GDR_PIPE_CULL_POINTS + 1] = {"cull_points_early", GDR_NEEDS_VISIBILITY_BUFFER,
                                  .compute = &gdr_shader_drawcull_points_comp, .constants = {1, 1}, .constant_count = 2},
    [GDR_PIPE_CULL_POINTS + 2] = {"cull_points_late", GDR_NEEDS_VISIBILITY_BUFFER,
                                  .compute = &gdr_shader_drawcull_points_comp, .constants = {1, 2}, .constant_count = 2},
    [GDR_PIPE_LOD_TRAVERSE] = {"lod_traverse", GDR_NEEDS_MESH_SHADER, .compute = &gdr_shader_lodtraverse_comp,
                               .constants = {0}, .constant_count = 1},
    [GDR_PIPE_LOD_TRAVERSE + 1] = {"lod_traverse_early", GDR_NEEDS_MESH_SHADER,
                                   .compute = &gdr_shader_lodtraverse_comp, .constants = {1}, .constant_count = 1},
    [GDR_PIPE_LOD_TRAVERSE + 2] = {"lod_traverse_late", GDR_NEEDS_MESH_SHADER,
                                   .compute = &gdr_shader_lodtraverse_comp, .constants = {2}, .constant_count = 1},
    [GDR_PIPE_TASK_SUBMIT] = {"task_submit", GDR_NEEDS_MESH_SHADER, .compute = &gdr_shader_tasksubmit_comp},
    [GDR_PIPE_TASK_SUBMIT_LATE] = {"task_submit_late", GDR_NEEDS_MESH_SHADER, .compute = &gdr_shader_tasksubmit_comp,
                                   .constants = {1}, .constant_count = 1},
    [GDR_PIPE_DRAW_INDEXED] = {"draw_indexed", .vertex = &gdr_shader_mesh_vert, .fragment = &gdr_shader_mesh_frag,
                               .alpha_fragment = &gdr_shader_mesh_alpha_frag, .vertex_input = true, .cull_back = true},
    [GDR_PIPE_MESHLETS] = {"meshlets", GDR_NEEDS_MESH_SHADER, .task = &gdr_shader_meshlet_task,
                           .mesh = &gdr_shader_meshlet_mesh, .fragment = &gdr_shader_meshlet_frag,
                           .alpha_fragment = &gdr_shader_meshlet_alpha_frag, .constants = {0},
                           .constant_count = 1, .cull_back = true},
    [GDR_PIPE_MESHLETS + 1] = {"meshlets_early", GDR_NEEDS_MESH_SHADER, .task = &gdr_shader_meshlet_task,
                               .mesh = &gdr_shader_meshlet_mesh, .fragment = &gdr_shader_meshlet_frag,
                           .alpha_fragment = &gdr_shader_meshlet_alpha_frag,
                               .constants = {1}, .constant_count = 1, .cull_back = true},
    [GDR_PIPE_MESHLETS + 2] = {"meshlets_late", GDR_NEEDS_MESH_SHADER, .task = &gdr_shader_meshlet_task,
                               .mesh = &gdr_shader_meshlet_mesh, .fragment = &gdr_shader_meshlet_frag,
                           .alpha_fragment = &gdr_shader_meshlet_alpha_frag,
                               .constants = {2}, .constant_count = 1, .cull_back = true},
    [GDR_PIPE_OVERDRAW_MAX] = {"overdraw_max", .compute = &gdr_shader_overdraw_max_comp},
    [GDR_PIPE_OVERDRAW_PAINT] = {"overdraw_paint", .vertex = &gdr_shader_overdraw_paint_vert,
                                 .fragment = &gdr_shader_overdraw_paint_frag, .targets = GDR_TARGETS_COLOR},
    [GDR_PIPE_CLUSTER_CULL] = {"cluster_cull", GDR_NEEDS_VISIBILITY_BUFFER, .compute = &gdr_shader_clustercull_comp,
                               .constants = {0}, .constant_count = 1},
    [GDR_PIPE_CLUSTER_CULL + 1] = {"cluster_cull_early", GDR_NEEDS_VISIBILITY_BUFFER,
                                   .compute = &gdr_shader_clustercull_comp, .constants = {1}, .constant_count = 1},
    [GDR_PIPE_CLUSTER_CULL + 2] = {"cluster_cull_late", GDR_NEEDS_VISIBILITY_BUFFER,
                                   .compute = &gdr_shader_clustercull_comp, .constants = {2}, .constant_count = 1},
    [GDR_PIPE_RASTER_SUBMIT] = {"raster_submit", GDR_NEEDS_VISIBILITY_BUFFER, .compute = &gdr_shader_raster_submit_comp},
    [GDR_PIPE_RASTER_HW] = {"raster_hw", GDR_NEEDS_VISIBILITY_BUFFER, .mesh = &gdr_shader_meshlet_list_mesh,
                            .fragment = &gdr_shader_meshlet_visbuffer_frag,
                            .alpha_fragment = &gdr_shader_meshlet_visbuffer_alpha_frag, .targets = GDR_TARGETS_NONE,
                            .cull_back = true},
    [GDR_PIPE_RASTER_SW] = {"raster_sw", GDR_NEEDS_VISIBILITY_BUFFER, .compute = &gdr_shader_raster_sw_comp,
                            .constants = {GDR_SW_RASTER_WORKGROUP_SIZE, GDR_SW_TINY_CLASSES}, .constant_count = 2},
    [GDR_PIPE_RASTER_SW_TINY] = {"raster_sw_tiny8", GDR_NEEDS_VISIBILITY_BUFFER, .compute = &gdr_shader_raster_sw_comp,
                                 .constants = {GDR_SW_TINY_LANES, 0}, .constant_count = 2},
    [GDR_PIPE_RASTER_SW_TINY + 1] = {"raster_sw_tiny16", GDR_NEEDS_VISIBILITY_BUFFER,
                                     .compute = &gdr_shader_raster_sw_comp, .constants = {GDR_SW_TINY_LANES << 1, 1},
                                     .constant_count = 2},
    [GDR_PIPE_RASTER_SW_TINY + 2] = {"raster_sw_tiny32", GDR_NEEDS_VISIBILITY_BUFFER,
                                     .compute = &gdr_shader_raster_sw_comp, .constants = {GDR_SW_TINY_LANES << 2, 2},
                                     .constant_count = 2},
    [GDR_PIPE_RESOLVE] = {"resolve", GDR_NEEDS_VISIBILITY_BUFFER, .compute = &gdr_shader_visbuffer_resolve_comp,
                          .constants = {0}, .constant_count = 1},
};

_Static_assert(GDR_PIPE_RESOLVE - GDR_PIPE_RASTER_SW_TINY == GDR_SW_TINY_CLASSES,
               "a compute-raster pipeline per tiny size class");

const char *gdr_pipeline_id_name(gdr_pipeline_id id)
{
    return (unsigned)id < GDR_PIPE_COUNT ? entries[id].name : "unknown";
}

static gdr_status create_graphics(gdr_vk_context *ctx, VkPipelineLayout layout, const gdr_pipeline_entry *e,
                                  VkPipeline *out, gdr_error *err)
{
    static const VkVertexInputBindingDescription binding = {0, sizeof(GdrGpuVertex), VK_VERTEX_INPUT_RATE_VERTEX};
    static const VkVertexInputAttributeDescription attributes[3] = {
        {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(GdrGpuVertex, position)},
        {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(GdrGpuVertex, normal)},
        {2, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(GdrGpuVertex, uv)},
    };
    VkSpecializationMapEntry constant_entries[2] = {{0, 0, 4}, {1, 4, 4}};
    VkSpecializationInfo constants = {e->constant_count, constant_entries, 4 * e->constant_count, e->constants};
    gdr_vk_graphics_pipeline_desc desc = {
        .layout = layout, .vertex_shader = e->vertex, .task_shader = e->task,
        .task_specialization = e->constant_count ? &constants : NULL, .mesh_shader = e->mesh,
        .fragment_shader = e->fragment, .vertex_binding = e->vertex_input ? &binding : NULL,
        .vertex_attributes = e->vertex_input ? attributes : NULL, .vertex_attribute_count = e->vertex_input ? 3 : 0,
        .color_format = e->targets == GDR_TARGETS_NONE ? VK_FORMAT_UNDEFINED : GDR_COLOR_FORMAT,
        .depth_format = e->targets == GDR_TARGETS_COLOR_DEPTH ? GDR_DEPTH_FORMAT : VK_FORMAT_UNDEFINED,
        .cull_mode = e->cull_back ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE,
        .no_depth_test = e->targets != GDR_TARGETS_COLOR_DEPTH};
    return gdr_vk_graphics_pipeline_create(ctx, &desc, out, err);
}

gdr_status gdr_pipelines_create(gdr_vk_context *ctx, VkPipelineLayout layout, const bool available[3],
                                VkPipeline pipelines[GDR_PIPE_COUNT], gdr_error *err)
{
    for (uint32_t id = 0; id < GDR_PIPE_COUNT; id++) {
        const gdr_pipeline_entry *e = &entries[id];
        pipelines[id] = VK_NULL_HANDLE;
        if (!available[e->needs])
            continue;
        gdr_status status = e->compute ? gdr_vk_compute_pipeline_create_specialized(ctx, layout, e->compute,
                                                                                     e->constants, e->constant_count,
                                                                                     &pipelines[id], err)
                                       : create_graphics(ctx, layout, e, &pipelines[id], err);
        if (status != GDR_OK)
            return status;
    }
    return GDR_OK;
}

gdr_status gdr_pipelines_for_materials(gdr_vk_context *ctx, VkPipelineLayout layout, bool double_sided,
                                       VkPipeline pipelines[GDR_PIPE_COUNT], gdr_error *err)
{
    for (uint32_t id = 0; id < GDR_PIPE_COUNT; id++) {
        if (!pipelines[id] || !(entries[id].alpha_fragment || (double_sided && entries[id].cull_back)))
            continue;
        gdr_pipeline_entry alpha = entries[id];
        alpha.fragment = alpha.alpha_fragment ? alpha.alpha_fragment : alpha.fragment;
        alpha.cull_back = alpha.cull_back && !double_sided;
        VkPipeline created;
        gdr_status status = create_graphics(ctx, layout, &alpha, &created, err);
        if (status != GDR_OK)
            return status;
        vkDestroyPipeline(ctx->device, pipelines[id], NULL);
        pipelines[id] = created;
    }
    return GDR_OK;
}

void gdr_pipelines_destroy(gdr_vk_context *ctx, VkPipeline pipelines[GDR_PIPE_COUNT])
{
    for (uint32_t id = 0; id < GDR_PIPE_COUNT; id++) {
        if (pipelines[id])
            vkDestroyPipeline(ctx->device, pipelines[id], NULL);
        pipelines[id] = VK_NULL_HANDLE;
    }
}
