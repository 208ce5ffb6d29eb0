/* The frame's pipelines: one static table (shaders, specialisation constants, raster state, what
 * the device must have) from which they are created and destroyed in loops. Every frame pipeline
 * shares the renderer's layout: GdrGpuPushConstants and set 0 (the depth pyramid). */
#ifndef GDR_RENDER_PIPELINES_H
#define GDR_RENDER_PIPELINES_H

#include "gdr/core.h"
#include "vk/vk_context.h"

/* Pipelines that exist per occlusion phase are laid out ONLY, EARLY, LATE from their first id
 * (gdr_occlusion_phase). */
typedef enum gdr_pipeline_id {
    GDR_PIPE_INSTANCE_SCATTER,
    GDR_PIPE_CULL_DRAWS,        /* instance cull writing indirect draws, per phase */
    GDR_PIPE_CULL_TASKS = GDR_PIPE_CULL_DRAWS + 3, /* instance cull writing task commands, per phase */
    GDR_PIPE_LOD_TRAVERSE = GDR_PIPE_CULL_TASKS + 3, /* one level of the LOD hierarchy traversal, per phase */
    GDR_PIPE_TASK_SUBMIT = GDR_PIPE_LOD_TRAVERSE + 3,
    GDR_PIPE_TASK_SUBMIT_LATE,
    GDR_PIPE_DRAW_INDEXED,      /* the vertex pipeline of the indirect and CPU pipelines */
    GDR_PIPE_MESHLETS,          /* task + mesh + fragment shaders (forward raster), per phase */
    GDR_PIPE_OVERDRAW_MAX = GDR_PIPE_MESHLETS + 3,
    GDR_PIPE_OVERDRAW_PAINT,
    GDR_PIPE_CLUSTER_CULL,      /* visibility-buffer raster: the per-cluster tests and binning, per phase */
    GDR_PIPE_RASTER_SUBMIT = GDR_PIPE_CLUSTER_CULL + 3,
    GDR_PIPE_RASTER_HW,
    GDR_PIPE_RASTER_SW,
    GDR_PIPE_RASTER_SW_TINY,    /* the compute rasteriser's tiny variants, per size class (GDR_SW_TINY_CLASSES) */
    GDR_PIPE_RESOLVE = GDR_PIPE_RASTER_SW_TINY + 3,
    GDR_PIPE_CULL_POINTS,       /* the visibility buffer's instance cull: task commands and point splats, per phase */
    GDR_PIPE_COUNT = GDR_PIPE_CULL_POINTS + 3
} gdr_pipeline_id;

/* What a pipeline needs of the device beyond Vulkan 1.3. */
typedef enum gdr_pipeline_needs {
    GDR_NEEDS_CORE = 0,
    GDR_NEEDS_MESH_SHADER,      /* VK_EXT_mesh_shader */
    GDR_NEEDS_VISIBILITY_BUFFER /* mesh shaders and 64-bit buffer atomics */
} gdr_pipeline_needs;

/* The registry's name of a pipeline (for messages and the frame's description). */
const char *gdr_pipeline_id_name(gdr_pipeline_id id);

/* Creates every pipeline of the table whose needs `available` (indexed by gdr_pipeline_needs)
 * says the device meets; the others stay VK_NULL_HANDLE. */
gdr_status gdr_pipelines_create(gdr_vk_context *ctx, VkPipelineLayout layout, const bool available[3],
                                VkPipeline pipelines[GDR_PIPE_COUNT], gdr_error *err);
/* For a scene with MASK, BLEND or double-sided materials: replaces the raster pipelines (vertex and
 * mesh shaders, forward and visibility buffer) by their alpha-testing variants, which also drop the
 * back faces of single-sided materials; with `double_sided`, those are made without the pipeline
 * state's back-face culling. */
gdr_status gdr_pipelines_for_materials(gdr_vk_context *ctx, VkPipelineLayout layout, bool double_sided,
                                       VkPipeline pipelines[GDR_PIPE_COUNT], gdr_error *err);
void gdr_pipelines_destroy(gdr_vk_context *ctx, VkPipeline pipelines[GDR_PIPE_COUNT]);

#endif
