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
    return gdr_vk_compute_pipeline_create_specialized(ctx, layout, shader, NULL, 0, out, err);
}

gdr_status gdr_vk_compute_pipeline_create_specialized(gdr_vk_context *ctx, VkPipelineLayout layout,
                                                      const gdr_spirv *shader, const uint32_t *constants,
                                                      uint32_t constant_count, VkPipeline *out, gdr_error *err)
{
    VkSpecializationMapEntry entries[8];
    if (constant_count > 8)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "at most 8 specialization constants");
    for (uint32_t i = 0; i < constant_count; i++)
        entries[i] = (VkSpecializationMapEntry){i, i * (uint32_t)sizeof(uint32_t), sizeof(uint32_t)};
    VkSpecializationInfo specialization = {constant_count, entries, constant_count * sizeof(uint32_t), constants};
    VkShaderModule module;
    gdr_status status = create_module(ctx, shader, &module, err);
    if (status != GDR_OK)
        return status;
    VkComputePipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage = {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_COMPUTE_BIT,
                  .module = module, .pName = "main", .pSpecializationInfo = constant_count ? &specialization : NULL},
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
    /* Vertex + fragment, or task + mesh + fragment. */
    struct {
        const gdr_spirv *code;
        VkShaderStageFlagBits stage;
    } wanted[3] = {{desc->task_shader, VK_SHADER_STAGE_TASK_BIT_EXT},
                   {desc->mesh_shader ? desc->mesh_shader : desc->vertex_shader,
                    desc->mesh_shader ? VK_SHADER_STAGE_MESH_BIT_EXT : VK_SHADER_STAGE_VERTEX_BIT},
                   {desc->fragment_shader, VK_SHADER_STAGE_FRAGMENT_BIT}};
    VkPipelineShaderStageCreateInfo stages[3];
    uint32_t stage_count = 0;
    gdr_status status = GDR_OK;
    for (uint32_t i = 0; i < 3 && status == GDR_OK; i++) {
        if (!wanted[i].code)
            continue;
        stages[stage_count] = (VkPipelineShaderStageCreateInfo){
            .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = wanted[i].stage, .pName = "main",
            .pSpecializationInfo = i == 0 ? desc->task_specialization : NULL};
        status = create_module(ctx, wanted[i].code, &stages[stage_count].module, err);
        if (status == GDR_OK)
            stage_count++;
    }
    if (status != GDR_OK) {
        for (uint32_t i = 0; i < stage_count; i++)
            vkDestroyShaderModule(ctx->device, stages[i].module, NULL);
        return status;
    }
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
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO, .depthTestEnable = !desc->no_depth_test,
        .depthWriteEnable = !desc->no_depth_test,
        .depthCompareOp = desc->depth_always ? VK_COMPARE_OP_ALWAYS : VK_COMPARE_OP_GREATER};
    VkPipelineColorBlendAttachmentState blend_attachment = {.colorWriteMask = 0xF};
    uint32_t color_count = desc->color_format != VK_FORMAT_UNDEFINED ? 1u : 0u;
    VkPipelineColorBlendStateCreateInfo blend = {.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
                                                 .attachmentCount = color_count, .pAttachments = &blend_attachment};
    VkDynamicState dynamic_states[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic = {.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
                                                .dynamicStateCount = 2, .pDynamicStates = dynamic_states};
    VkPipelineRenderingCreateInfo rendering = {.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO,
                                               .colorAttachmentCount = color_count,
                                               .pColorAttachmentFormats = &desc->color_format,
                                               .depthAttachmentFormat = desc->depth_format};
    VkGraphicsPipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO, .pNext = &rendering, .stageCount = stage_count,
        .pStages = stages, .pVertexInputState = desc->mesh_shader ? NULL : &vertex_input,
        .pInputAssemblyState = desc->mesh_shader ? NULL : &input_assembly,
        .pViewportState = &viewport, .pRasterizationState = &raster, .pMultisampleState = &multisample,
        .pDepthStencilState = &depth, .pColorBlendState = &blend, .pDynamicState = &dynamic, .layout = desc->layout};
    VkResult result = vkCreateGraphicsPipelines(ctx->device, VK_NULL_HANDLE, 1, &info, NULL, out);
    for (uint32_t i = 0; i < stage_count; i++)
        vkDestroyShaderModule(ctx->device, stages[i].module, NULL);
    GDR_VK_TRY(err, result);
    return GDR_OK;
}
