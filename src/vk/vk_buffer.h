/* Buffers with device addresses, and staging uploads. */
#ifndef GDR_VK_BUFFER_H
#define GDR_VK_BUFFER_H

#include "vk/vk_memory.h"

typedef struct gdr_vk_buffer {
    VkBuffer buffer;
    VkDeviceSize size;
    VkDeviceAddress address;
    void *mapped; /* for host-visible buffers */
} gdr_vk_buffer;

typedef enum gdr_vk_buffer_memory {
    GDR_VK_BUFFER_DEVICE, /* device-local */
    GDR_VK_BUFFER_UPLOAD, /* host-visible, coherent: the CPU writes, the GPU reads */
    GDR_VK_BUFFER_READBACK, /* host-visible, coherent, cached when possible: the GPU writes, the CPU reads */
} gdr_vk_buffer_memory;

gdr_status gdr_vk_buffer_create(gdr_vk_allocator *allocator, VkDeviceSize size, VkBufferUsageFlags usage,
                                gdr_vk_buffer_memory memory, gdr_vk_buffer *out, gdr_error *err);
void gdr_vk_buffer_destroy(gdr_vk_context *ctx, gdr_vk_buffer *buffer);

#define GDR_VK_STAGING_SIZE (32ull << 20)

/* A host-visible staging buffer of GDR_VK_STAGING_SIZE bytes, reused for every upload. */
gdr_status gdr_vk_staging_create(gdr_vk_allocator *allocator, gdr_vk_buffer *out, gdr_error *err);

/* Copies `size` bytes into a device-local buffer at `offset` through `staging`, in chunks of the
 * staging size, and waits for the copies. */
gdr_status gdr_vk_buffer_upload(gdr_vk_context *ctx, gdr_vk_buffer *staging, gdr_vk_buffer *dst,
                                VkDeviceSize offset, const void *data, VkDeviceSize size, gdr_error *err);

/* A new host-visible buffer (*out) holding a copy of `size` bytes of `source` from `offset`, made
 * after every earlier submission's writes; waits for the copy. For tests and tools: the memory
 * goes back with the allocator. */
gdr_status gdr_vk_buffer_read_back(gdr_vk_allocator *allocator, VkBuffer source, VkDeviceSize offset,
                                   VkDeviceSize size, gdr_vk_buffer *out, gdr_error *err);

/* The same for mip level 0 of an image left in `layout` (tightly packed texels of `aspect`, whose
 * texel is `texel_size` bytes); the image is given back in `layout`. */
struct gdr_vk_image;
gdr_status gdr_vk_image_read_back(gdr_vk_allocator *allocator, const struct gdr_vk_image *image,
                                  VkImageAspectFlags aspect, VkImageLayout layout, uint32_t texel_size,
                                  gdr_vk_buffer *out, gdr_error *err);

#endif
