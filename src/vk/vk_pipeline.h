/* Pipelines from embedded SPIR-V. Every gdr pipeline uses one layout: a push-constant block of
 * buffer device addresses (GdrGpuPushConstants), no descriptor sets. */
#ifndef GDR_VK_PIPELINE_H
#define GDR_VK_PIPELINE_H

#include "shaders/embedded_shaders.h"
#include "vk/vk_context.h"

gdr_status gdr_vk_pipeline_layout_create(gdr_vk_context *ctx, uint32_t push_constant_size, VkPipelineLayout *out,
                                         gdr_error *err);
gdr_status gdr_vk_compute_pipeline_create(gdr_vk_context *ctx, VkPipelineLayout layout, const gdr_spirv *shader,
                                          VkPipeline *out, gdr_error *err);
/* The same with specialization constants: constants[i] is constant_id i (32-bit each, at most 8). */
gdr_status gdr_vk_compute_pipeline_create_specialized(gdr_vk_context *ctx, VkPipelineLayout layout,
                                                      const gdr_spirv *shader, const uint32_t *constants,
                                                      uint32_t constant_count, VkPipeline *out, gdr_error *err);

typedef struct gdr_vk_graphics_pipeline_desc {
    VkPipelineLayout layout;
    const gdr_spirv *vertex_shader; /* or: */
    const gdr_spirv *task_shader;   /* optional, with mesh_shader */
    const VkSpecializationInfo *task_specialization; /* optional: the task shader's constants */
    const gdr_spirv *mesh_shader;   /* replaces the vertex stage (VK_EXT_mesh_shader) */
    const gdr_spirv *fragment_shader;
    const VkVertexInputBindingDescription *vertex_binding; /* NULL: no vertex input */
    const VkVertexInputAttributeDescription *vertex_attributes;
    uint32_t vertex_attribute_count;
    VkFormat color_format;          /* VK_FORMAT_UNDEFINED: no colour attachment */
    VkFormat depth_format;
    VkCullModeFlags cull_mode;
    bool no_depth_test;             /* a full-screen pass over the colour target */
    bool depth_always;              /* depth test ALWAYS, write on (a pass that writes gl_FragDepth) */
} gdr_vk_graphics_pipeline_desc;

/* A graphics pipeline for dynamic rendering, reverse-Z depth (compare GREATER, write on), with a
 * dynamic viewport and scissor. */
gdr_status gdr_vk_graphics_pipeline_create(gdr_vk_context *ctx, const gdr_vk_graphics_pipeline_desc *desc,
                                           VkPipeline *out, gdr_error *err);

#endif
