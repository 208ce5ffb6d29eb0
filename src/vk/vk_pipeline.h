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

typedef struct gdr_vk_graphics_pipeline_desc {
    VkPipelineLayout layout;
    const gdr_spirv *vertex_shader;
    const gdr_spirv *fragment_shader;
    const VkVertexInputBindingDescription *vertex_binding; /* NULL: no vertex input */
    const VkVertexInputAttributeDescription *vertex_attributes;
    uint32_t vertex_attribute_count;
    VkFormat color_format;
    VkFormat depth_format;
    VkCullModeFlags cull_mode;
} gdr_vk_graphics_pipeline_desc;

/* A graphics pipeline for dynamic rendering, reverse-Z depth (compare GREATER, write on), with a
 * dynamic viewport and scissor. */
gdr_status gdr_vk_graphics_pipeline_create(gdr_vk_context *ctx, const gdr_vk_graphics_pipeline_desc *desc,
                                           VkPipeline *out, gdr_error *err);

#endif
