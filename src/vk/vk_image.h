/* 2D images (render targets) sub-allocated from device memory blocks. */
#ifndef GDR_VK_IMAGE_H
#define GDR_VK_IMAGE_H

#include "vk/vk_memory.h"

typedef struct gdr_vk_image {
    VkImage image;
    VkImageView view;
    VkFormat format;
    uint32_t width, height;
} gdr_vk_image;

gdr_status gdr_vk_image_create(gdr_vk_allocator *allocator, uint32_t width, uint32_t height, VkFormat format,
                               VkImageUsageFlags usage, VkImageAspectFlags aspect, gdr_vk_image *out, gdr_error *err);
void gdr_vk_image_destroy(gdr_vk_context *ctx, gdr_vk_image *image);

/* Records a layout transition (synchronization2) of the whole image. */
void gdr_vk_image_barrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout from,
                          VkImageLayout to, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                          VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access);

#endif
