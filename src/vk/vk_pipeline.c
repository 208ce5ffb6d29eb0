#include "vk/vk_pipeline.h"

static gdr_status create_module(gdr_vk_context *ctx, const gdr_spirv *shader, VkShaderModule *out, gdr_error *err)
{
    VkShaderModuleCreateInfo info = {.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
                                     .codeSize = shader->size, .pCode = shader->code};
    GDR_VK_TRY(err, vkCreateShaderModule(ctx->device, &info, NULL, out));
    return GDR_OK;
}

gdr_status gdr_vk_pipeline_layout_create(gdr_vk_context *ctx, uint32_t push_constant_size, VkPipelineLayout *out,
                                         gdr_error *err)
{
    VkPushConstantRange range = {.stageFlags = VK_SHADER_STAGE_ALL, .offset = 0, .size = push_constant_size};
    VkPipelineLayoutCreateInfo info = {.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
                                       .pushConstantRangeCount = 1, .pPushConstantRanges = &range};
    GDR_VK_TRY(err, vkCreatePipelineLayout(ctx->device, &info, NULL, out));
    return GDR_OK;
}

gdr_status gdr_vk_compute_pipeline_create(gdr_vk_context *ctx, VkPipelineLayout layout, const gdr_spirv *shader,
                                          VkPipeline *out, gdr_error *err)
{
    VkShaderModule module;
    gdr_status status = create_module(ctx, shader, &module, err);
    if (status != GDR_OK)
        return status;
    VkComputePipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage = {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_COMPUTE_BIT,
                  .module = module, .pName = "main"},
        .layout = layout,
    };
    VkResult result = vkCreateComputePipelines(ctx->device, VK_NULL_HANDLE, 1, &info, NULL, out);
    vkDestroyShaderModule(ctx->device, module, NULL);
    GDR_VK_TRY(err, result);
    return GDR_OK;
}

gdr_status gdr_vk_graphics_pipeline_create(gdr_vk_context *ctx, const gdr_vk_graphics_pipeline_desc *desc,
                                           VkPipeline *out, gdr_error *err)
{
    VkShaderModule vertex, fragment;
    gdr_status status = create_module(ctx, desc->vertex_shader, &vertex, err);
    if (status != GDR_OK)
        return status;
    status = create_module(ctx, desc->fragment_shader, &fragment, err);
    if (status != GDR_OK) {
        vkDestroyShaderModule(ctx->device, vertex, NULL);
        return status;
    }
    VkPipelineShaderStageCreateInfo stages[2] = {
        {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_VERTEX_BIT,
         .module = vertex, .pName = "main"},
        {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_FRAGMENT_BIT,
         .module = fragment, .pName = "main"},
    };
    VkPipelineVertexInputStateCreateInfo vertex_input = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
        .vertexBindingDescriptionCount = desc->vertex_binding ? 1u : 0u,
        .pVertexBindingDescriptions = desc->vertex_binding,
        .vertexAttributeDescriptionCount = desc->vertex_attribute_count,
        .pVertexAttributeDescriptions = desc->vertex_attributes,
    };
    VkPipelineInputAssemblyStateCreateInfo input_assembly = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
        .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST};
    VkPipelineViewportStateCreateInfo viewport = {.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
                                                  .viewportCount = 1, .scissorCount = 1};
    /* Counter-clockwise front faces: the negative-height viewport keeps glTF's winding. */
    VkPipelineRasterizationStateCreateInfo raster = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO, .polygonMode = VK_POLYGON_MODE_FILL,
        .cullMode = desc->cull_mode, .frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE, .lineWidth = 1.0f};
    VkPipelineMultisampleStateCreateInfo multisample = {.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
                                                        .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT};
    VkPipelineDepthStencilStateCreateInfo depth = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO, .depthTestEnable = VK_TRUE,
        .depthWriteEnable = VK_TRUE, .depthCompareOp = VK_COMPARE_OP_GREATER};
    VkPipelineColorBlendAttachmentState blend_attachment = {.colorWriteMask = 0xF};
    VkPipelineColorBlendStateCreateInfo blend = {.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
                                                 .attachmentCount = 1, .pAttachments = &blend_attachment};
    VkDynamicState dynamic_states[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic = {.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
                                                .dynamicStateCount = 2, .pDynamicStates = dynamic_states};
    VkPipelineRenderingCreateInfo rendering = {.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO,
                                               .colorAttachmentCount = 1,
                                               .pColorAttachmentFormats = &desc->color_format,
                                               .depthAttachmentFormat = desc->depth_format};
    VkGraphicsPipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO, .pNext = &rendering, .stageCount = 2,
        .pStages = stages, .pVertexInputState = &vertex_input, .pInputAssemblyState = &input_assembly,
        .pViewportState = &viewport, .pRasterizationState = &raster, .pMultisampleState = &multisample,
        .pDepthStencilState = &depth, .pColorBlendState = &blend, .pDynamicState = &dynamic, .layout = desc->layout};
    VkResult result = vkCreateGraphicsPipelines(ctx->device, VK_NULL_HANDLE, 1, &info, NULL, out);
    vkDestroyShaderModule(ctx->device, vertex, NULL);
    vkDestroyShaderModule(ctx->device, fragment, NULL);
    GDR_VK_TRY(err, result);
    return GDR_OK;
}
