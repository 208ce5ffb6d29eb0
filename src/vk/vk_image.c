#include "vk/vk_image.h"

#include <string.h>

gdr_vk_image_desc gdr_vk_image_desc_defaults(const gdr_vk_image_desc *desc)
{
    gdr_vk_image_desc d = *desc;
    if (d.aspect == 0)
        d.aspect = VK_IMAGE_ASPECT_COLOR_BIT;
    if (d.mip_levels == 0)
        d.mip_levels = 1;
    return d;
}

gdr_status gdr_vk_image_create(gdr_vk_allocator *allocator, const gdr_vk_image_desc *desc_in, gdr_vk_image *out,
                               gdr_error *err)
{
    VkDevice device = allocator->ctx->device;
    gdr_vk_image_desc desc = gdr_vk_image_desc_defaults(desc_in);
    memset(out, 0, sizeof *out);
    if (desc.width == 0 || desc.height == 0 || desc.format == VK_FORMAT_UNDEFINED || desc.usage == 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "image: size %ux%u, format %d, usage 0x%x", desc.width,
                             desc.height, (int)desc.format, (unsigned)desc.usage);
    VkImageCreateInfo info = {.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO, .imageType = VK_IMAGE_TYPE_2D,
                              .format = desc.format, .extent = {desc.width, desc.height, 1},
                              .mipLevels = desc.mip_levels, .arrayLayers = 1, .samples = VK_SAMPLE_COUNT_1_BIT,
                              .tiling = VK_IMAGE_TILING_OPTIMAL, .usage = desc.usage,
                              .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED};
    GDR_VK_TRY(err, vkCreateImage(device, &info, NULL, &out->image));
    VkMemoryRequirements requirements;
    vkGetImageMemoryRequirements(device, out->image, &requirements);
    gdr_vk_allocation allocation;
    gdr_status status = gdr_vk_allocate(allocator, requirements, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &allocation, err);
    if (status != GDR_OK)
        return status;
    GDR_VK_TRY(err, vkBindImageMemory(device, out->image, allocation.memory, allocation.offset));
    VkImageViewCreateInfo view = {.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, .image = out->image,
                                  .viewType = VK_IMAGE_VIEW_TYPE_2D, .format = desc.format,
                                  .components = desc.components, .subresourceRange = {desc.aspect, 0, desc.mip_levels, 0, 1}};
    GDR_VK_TRY(err, vkCreateImageView(device, &view, NULL, &out->view));
    out->format = desc.format;
    out->width = desc.width;
    out->height = desc.height;
    out->mip_levels = desc.mip_levels;
    out->bytes = requirements.size;
    return GDR_OK;
}

void gdr_vk_image_destroy(gdr_vk_context *ctx, gdr_vk_image *image)
{
    if (image->view)
        vkDestroyImageView(ctx->device, image->view, NULL);
    if (image->image)
        vkDestroyImage(ctx->device, image->image, NULL);
    memset(image, 0, sizeof *image);
}

#define GDR_VK_MAX_TRANSITIONS 8

void gdr_vk_barrier(VkCommandBuffer cmd, const gdr_vk_barrier_desc *desc)
{
    VkMemoryBarrier2 memory = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2, .srcStageMask = desc->src.stages,
                               .srcAccessMask = desc->src.access, .dstStageMask = desc->dst.stages,
                               .dstAccessMask = desc->dst.access};
    VkImageMemoryBarrier2 images[GDR_VK_MAX_TRANSITIONS];
    uint32_t count = desc->image_count < GDR_VK_MAX_TRANSITIONS ? desc->image_count : GDR_VK_MAX_TRANSITIONS;
    for (uint32_t i = 0; i < count; i++) {
        const gdr_vk_image_transition *t = &desc->images[i];
        images[i] = (VkImageMemoryBarrier2){
            .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2, .srcStageMask = t->src.stages,
            .srcAccessMask = t->src.access, .dstStageMask = t->dst.stages, .dstAccessMask = t->dst.access,
            .oldLayout = t->from, .newLayout = t->to, .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
            .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .image = t->image,
            .subresourceRange = {t->aspect, t->first_mip, t->mip_count ? t->mip_count : VK_REMAINING_MIP_LEVELS, 0, 1}};
    }
    bool has_memory = desc->src.stages || desc->dst.stages;
    VkDependencyInfo dependency = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = has_memory,
                                   .pMemoryBarriers = &memory, .imageMemoryBarrierCount = count,
                                   .pImageMemoryBarriers = images};
    vkCmdPipelineBarrier2(cmd, &dependency);
}

void gdr_vk_memory_barrier(VkCommandBuffer cmd, gdr_vk_scope src, gdr_vk_scope dst)
{
    gdr_vk_barrier(cmd, &(gdr_vk_barrier_desc){.src = src, .dst = dst});
}

void gdr_vk_image_barrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout from,
                          VkImageLayout to, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                          VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access)
{
    gdr_vk_image_transition t = {.image = image, .aspect = aspect, .from = from, .to = to,
                                 .src = {src_stage, src_access}, .dst = {dst_stage, dst_access}};
    gdr_vk_barrier(cmd, &(gdr_vk_barrier_desc){.images = &t, .image_count = 1});
}
