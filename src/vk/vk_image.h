/* 2D images (render targets, the depth pyramid) sub-allocated from device memory blocks, and the
 * barrier helper every recorded dependency goes through. */
#ifndef GDR_VK_IMAGE_H
#define GDR_VK_IMAGE_H

#include "vk/vk_memory.h"

typedef struct gdr_vk_image {
    VkImage image;
    VkImageView view; /* every mip level */
    VkFormat format;
    uint32_t width, height;
    uint32_t mip_levels;
    VkDeviceSize bytes; /* the device memory it was given (its memory requirements' size) */
} gdr_vk_image;

/* Zero fields take the defaults of gdr_vk_image_desc_defaults. */
typedef struct gdr_vk_image_desc {
    uint32_t width, height;   /* > 0 */
    VkFormat format;          /* required */
    VkImageUsageFlags usage;  /* required */
    VkImageAspectFlags aspect; /* 0: COLOR */
    uint32_t mip_levels;      /* 0: 1 */
    VkComponentMapping components; /* the view's swizzle; zero: identity */
} gdr_vk_image_desc;

/* `desc` with every default applied. */
gdr_vk_image_desc gdr_vk_image_desc_defaults(const gdr_vk_image_desc *desc);
gdr_status gdr_vk_image_create(gdr_vk_allocator *allocator, const gdr_vk_image_desc *desc, gdr_vk_image *out,
                               gdr_error *err);
void gdr_vk_image_destroy(gdr_vk_context *ctx, gdr_vk_image *image);

/* One side of a dependency: pipeline stages and the accesses in them. */
typedef struct gdr_vk_scope {
    VkPipelineStageFlags2 stages;
    VkAccessFlags2 access;
} gdr_vk_scope;

/* A layout transition (with its memory dependency) of some mip levels of an image. */
typedef struct gdr_vk_image_transition {
    VkImage image;
    VkImageAspectFlags aspect;
    VkImageLayout from, to; /* from UNDEFINED: the old contents are discarded */
    gdr_vk_scope src, dst;
    uint32_t first_mip;
    uint32_t mip_count;     /* 0: every level from first_mip */
} gdr_vk_image_transition;

/* One vkCmdPipelineBarrier2: a global memory barrier (left out when src and dst are both empty)
 * and any number of image transitions. */
typedef struct gdr_vk_barrier_desc {
    gdr_vk_scope src, dst;
    const gdr_vk_image_transition *images;
    uint32_t image_count;
} gdr_vk_barrier_desc;

void gdr_vk_barrier(VkCommandBuffer cmd, const gdr_vk_barrier_desc *desc);
/* The global memory barrier alone. */
void gdr_vk_memory_barrier(VkCommandBuffer cmd, gdr_vk_scope src, gdr_vk_scope dst);
/* One transition of every level of an image. */
void gdr_vk_image_barrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout from,
                          VkImageLayout to, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                          VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access);

#endif
