/* Device memory sub-allocated from a few large blocks (no vkAllocateMemory per object).
 * Allocation is linear within a block; everything is released together when the allocator
 * is destroyed, which matches gdr's lifetimes (a scene's resources live as long as the renderer). */
#ifndef GDR_VK_MEMORY_H
#define GDR_VK_MEMORY_H

#include "vk/vk_context.h"

#define GDR_VK_BLOCK_SIZE (64ull << 20)
#define GDR_VK_MAX_BLOCKS 64

typedef struct gdr_vk_allocation {
    VkDeviceMemory memory;
    VkDeviceSize offset;
    VkDeviceSize size;
    void *mapped; /* host pointer for host-visible memory, else NULL */
} gdr_vk_allocation;

typedef struct gdr_vk_memory_block {
    VkDeviceMemory memory;
    VkDeviceSize size, used;
    uint32_t type_index;
    void *mapped;
} gdr_vk_memory_block;

typedef struct gdr_vk_allocator {
    gdr_vk_context *ctx;
    gdr_vk_memory_block blocks[GDR_VK_MAX_BLOCKS];
    uint32_t block_count;
    VkDeviceSize bytes_allocated; /* sum of block sizes */
} gdr_vk_allocator;

void gdr_vk_allocator_init(gdr_vk_allocator *allocator, gdr_vk_context *ctx);
void gdr_vk_allocator_destroy(gdr_vk_allocator *allocator);

/* Sub-allocates memory meeting `requirements` with at least `properties`; host-visible memory
 * comes back mapped. */
gdr_status gdr_vk_allocate(gdr_vk_allocator *allocator, VkMemoryRequirements requirements,
                           VkMemoryPropertyFlags properties, gdr_vk_allocation *out, gdr_error *err);

#endif
