#include "vk/vk_descriptors.h"

#include <assert.h>

gdr_status gdr_vk_descriptor_set_layout_create(gdr_vk_context *ctx, const VkDescriptorSetLayoutBinding *bindings,
                                               uint32_t binding_count, VkDescriptorSetLayout *out, gdr_error *err)
{
    assert(bindings || binding_count == 0);
    VkDescriptorSetLayoutCreateInfo info = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
                                            .bindingCount = binding_count, .pBindings = bindings};
    GDR_VK_TRY(err, vkCreateDescriptorSetLayout(ctx->device, &info, NULL, out));
    return GDR_OK;
}

gdr_status gdr_vk_pipeline_layout_create_with_sets(gdr_vk_context *ctx, const VkDescriptorSetLayout *sets,
                                                   uint32_t set_count, VkShaderStageFlags push_constant_stages,
                                                   uint32_t push_constant_size, VkPipelineLayout *out, gdr_error *err)
{
    assert(sets || set_count == 0);
    VkPushConstantRange range = {.stageFlags = push_constant_stages, .offset = 0, .size = push_constant_size};
    VkPipelineLayoutCreateInfo info = {.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
                                       .setLayoutCount = set_count, .pSetLayouts = sets,
                                       .pushConstantRangeCount = push_constant_size ? 1u : 0u,
                                       .pPushConstantRanges = &range};
    GDR_VK_TRY(err, vkCreatePipelineLayout(ctx->device, &info, NULL, out));
    return GDR_OK;
}

gdr_status gdr_vk_descriptor_pool_create(gdr_vk_context *ctx, uint32_t max_sets, const VkDescriptorPoolSize *sizes,
                                         uint32_t size_count, VkDescriptorPool *out, gdr_error *err)
{
    assert(max_sets > 0 && sizes && size_count > 0);
    VkDescriptorPoolCreateInfo info = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, .maxSets = max_sets,
                                       .poolSizeCount = size_count, .pPoolSizes = sizes};
    GDR_VK_TRY(err, vkCreateDescriptorPool(ctx->device, &info, NULL, out));
    return GDR_OK;
}

gdr_status gdr_vk_descriptor_sets_allocate(gdr_vk_context *ctx, VkDescriptorPool pool, VkDescriptorSetLayout layout,
                                           uint32_t count, VkDescriptorSet *out, gdr_error *err)
{
    for (uint32_t i = 0; i < count; i++) {
        VkDescriptorSetAllocateInfo info = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
                                            .descriptorPool = pool, .descriptorSetCount = 1, .pSetLayouts = &layout};
        GDR_VK_TRY(err, vkAllocateDescriptorSets(ctx->device, &info, &out[i]));
    }
    return GDR_OK;
}

void gdr_vk_write_image_descriptor(gdr_vk_context *ctx, VkDescriptorSet set, uint32_t binding, VkDescriptorType type,
                                   VkSampler sampler, VkImageView view, VkImageLayout layout)
{
    assert(type == VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE || type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE ||
           type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER);
    VkDescriptorImageInfo image = {.sampler = type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER ? sampler : VK_NULL_HANDLE,
                                   .imageView = view, .imageLayout = layout};
    VkWriteDescriptorSet write = {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = set, .dstBinding = binding,
                                  .descriptorCount = 1, .descriptorType = type, .pImageInfo = &image};
    vkUpdateDescriptorSets(ctx->device, 1, &write, 0, NULL);
}

void gdr_vk_write_buffer_descriptor(gdr_vk_context *ctx, VkDescriptorSet set, uint32_t binding, VkDescriptorType type,
                                    VkBuffer buffer, VkDeviceSize offset, VkDeviceSize range)
{
    assert(type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER || type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER);
    VkDescriptorBufferInfo info = {.buffer = buffer, .offset = offset, .range = range};
    VkWriteDescriptorSet write = {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = set, .dstBinding = binding,
                                  .descriptorCount = 1, .descriptorType = type, .pBufferInfo = &info};
    vkUpdateDescriptorSets(ctx->device, 1, &write, 0, NULL);
}

gdr_status gdr_vk_sampler_create(gdr_vk_context *ctx, VkFilter filter, VkSamplerReductionMode reduction,
                                 VkSampler *out, gdr_error *err)
{
    VkSamplerReductionModeCreateInfo reduction_info = {.sType = VK_STRUCTURE_TYPE_SAMPLER_REDUCTION_MODE_CREATE_INFO,
                                                       .reductionMode = reduction};
    VkSamplerCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .pNext = reduction == VK_SAMPLER_REDUCTION_MODE_WEIGHTED_AVERAGE ? NULL : &reduction_info,
        .magFilter = filter, .minFilter = filter, .mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST,
        .addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, .addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, .minLod = 0.0f, .maxLod = VK_LOD_CLAMP_NONE};
    GDR_VK_TRY(err, vkCreateSampler(ctx->device, &info, NULL, out));
    return GDR_OK;
}
