#include "vk/vk_image.h"

#include <string.h>

gdr_status gdr_vk_image_create(gdr_vk_allocator *allocator, uint32_t width, uint32_t height, VkFormat format,
                               VkImageUsageFlags usage, VkImageAspectFlags aspect, gdr_vk_image *out, gdr_error *err)
{
    VkDevice device = allocator->ctx->device;
    memset(out, 0, sizeof *out);
    VkImageCreateInfo info = {.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO, .imageType = VK_IMAGE_TYPE_2D,
                              .format = format, .extent = {width, height, 1}, .mipLevels = 1, .arrayLayers = 1,
                              .samples = VK_SAMPLE_COUNT_1_BIT, .tiling = VK_IMAGE_TILING_OPTIMAL, .usage = usage,
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
                                  .viewType = VK_IMAGE_VIEW_TYPE_2D, .format = format,
                                  .subresourceRange = {aspect, 0, 1, 0, 1}};
    GDR_VK_TRY(err, vkCreateImageView(device, &view, NULL, &out->view));
    out->format = format;
    out->width = width;
    out->height = height;
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

void gdr_vk_image_barrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout from,
                          VkImageLayout to, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                          VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access)
{
    VkImageMemoryBarrier2 barrier = {.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2, .srcStageMask = src_stage,
                                     .srcAccessMask = src_access, .dstStageMask = dst_stage,
                                     .dstAccessMask = dst_access, .oldLayout = from, .newLayout = to,
                                     .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
                                     .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .image = image,
                                     .subresourceRange = {aspect, 0, 1, 0, 1}};
    VkDependencyInfo dependency = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = 1,
                                   .pImageMemoryBarriers = &barrier};
    vkCmdPipelineBarrier2(cmd, &dependency);
}
