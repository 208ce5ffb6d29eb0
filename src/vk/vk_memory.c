#include "vk/vk_memory.h"

#include <string.h>

void gdr_vk_allocator_init(gdr_vk_allocator *allocator, gdr_vk_context *ctx)
{
    memset(allocator, 0, sizeof *allocator);
    allocator->ctx = ctx;
}

void gdr_vk_allocator_destroy(gdr_vk_allocator *allocator)
{
    for (uint32_t i = 0; i < allocator->block_count; i++)
        vkFreeMemory(allocator->ctx->device, allocator->blocks[i].memory, NULL);
    allocator->block_count = 0;
}

static int find_memory_type(const VkPhysicalDeviceMemoryProperties *props, uint32_t type_bits,
                            VkMemoryPropertyFlags wanted)
{
    for (uint32_t i = 0; i < props->memoryTypeCount; i++)
        if ((type_bits & (1u << i)) && (props->memoryTypes[i].propertyFlags & wanted) == wanted)
            return (int)i;
    return -1;
}

static VkDeviceSize align_up(VkDeviceSize value, VkDeviceSize alignment)
{
    return (value + alignment - 1) / alignment * alignment;
}

gdr_status gdr_vk_allocate(gdr_vk_allocator *allocator, VkMemoryRequirements requirements,
                           VkMemoryPropertyFlags properties, gdr_vk_allocation *out, gdr_error *err)
{
    gdr_vk_context *ctx = allocator->ctx;
    int type = find_memory_type(&ctx->memory_properties, requirements.memoryTypeBits, properties);
    if (type < 0)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "no memory type with properties 0x%x for type bits 0x%x",
                             properties, requirements.memoryTypeBits);
    /* Buffers and images may share a block: keep them bufferImageGranularity apart. */
    VkDeviceSize alignment = requirements.alignment;
    if (ctx->properties.limits.bufferImageGranularity > alignment)
        alignment = ctx->properties.limits.bufferImageGranularity;

    for (uint32_t i = 0; i < allocator->block_count; i++) {
        gdr_vk_memory_block *block = &allocator->blocks[i];
        VkDeviceSize offset = align_up(block->used, alignment);
        if (block->type_index == (uint32_t)type && offset + requirements.size <= block->size) {
            block->used = offset + requirements.size;
            *out = (gdr_vk_allocation){block->memory, offset, requirements.size,
                                       block->mapped ? (char *)block->mapped + offset : NULL};
            return GDR_OK;
        }
    }
    if (allocator->block_count == GDR_VK_MAX_BLOCKS)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "device memory: all %d blocks are in use", GDR_VK_MAX_BLOCKS);

    VkDeviceSize size = requirements.size > GDR_VK_BLOCK_SIZE ? align_up(requirements.size, 1 << 20) : GDR_VK_BLOCK_SIZE;
    VkMemoryAllocateFlagsInfo flags = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO,
                                       .flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT};
    VkMemoryAllocateInfo info = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, .pNext = &flags,
                                 .allocationSize = size, .memoryTypeIndex = (uint32_t)type};
    gdr_vk_memory_block block = {.size = size, .type_index = (uint32_t)type};
    /* A scene or render target too large for the device: said before asking, and after a refusal,
     * with what is already held, so that the user knows which way to make it smaller. */
    uint32_t heap = ctx->memory_properties.memoryTypes[type].heapIndex;
    VkDeviceSize heap_size = ctx->memory_properties.memoryHeaps[heap].size;
    if (size > heap_size)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "device memory: %llu MiB in one piece exceed the %llu MiB "
                             "of memory heap %u (the scene or the render target is too large for this device)",
                             (unsigned long long)(size >> 20), (unsigned long long)(heap_size >> 20), heap);
    VkResult result = vkAllocateMemory(ctx->device, &info, NULL, &block.memory);
    if (result != VK_SUCCESS)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "device memory: allocating a %llu MiB block failed with "
                             "%llu MiB already allocated (heap %u: %llu MiB): %s; the scene or the render target is "
                             "too large for this device", (unsigned long long)(size >> 20),
                             (unsigned long long)(allocator->bytes_allocated >> 20), heap,
                             (unsigned long long)(heap_size >> 20), gdr_vk_result_name(result));
    if (ctx->memory_properties.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) {
        result = vkMapMemory(ctx->device, block.memory, 0, VK_WHOLE_SIZE, 0, &block.mapped);
        if (result != VK_SUCCESS) {
            vkFreeMemory(ctx->device, block.memory, NULL);
            return gdr_error_set(err, GDR_ERROR_VULKAN, "vkMapMemory failed: %s", gdr_vk_result_name(result));
        }
    }
    block.used = requirements.size;
    allocator->blocks[allocator->block_count++] = block;
    allocator->bytes_allocated += size;
    *out = (gdr_vk_allocation){block.memory, 0, requirements.size, block.mapped};
    return GDR_OK;
}
