#include "vk/vk_buffer.h"

#include <string.h>

gdr_status gdr_vk_buffer_create(gdr_vk_allocator *allocator, VkDeviceSize size, VkBufferUsageFlags usage,
                                gdr_vk_buffer_memory memory, gdr_vk_buffer *out, gdr_error *err)
{
    VkDevice device = allocator->ctx->device;
    memset(out, 0, sizeof *out);
    if (size == 0)
        size = 16;
    VkBufferCreateInfo info = {.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, .size = size,
                               .usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                               .sharingMode = VK_SHARING_MODE_EXCLUSIVE};
    GDR_VK_TRY(err, vkCreateBuffer(device, &info, NULL, &out->buffer));
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(device, out->buffer, &requirements);
    VkMemoryPropertyFlags properties = memory == GDR_VK_BUFFER_DEVICE
                                           ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT
                                           : VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    gdr_vk_allocation allocation;
    gdr_status status = GDR_ERROR_UNSUPPORTED;
    if (memory == GDR_VK_BUFFER_READBACK)
        status = gdr_vk_allocate(allocator, requirements, properties | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, &allocation, NULL);
    if (status != GDR_OK)
        status = gdr_vk_allocate(allocator, requirements, properties, &allocation, err);
    if (status != GDR_OK) {
        vkDestroyBuffer(device, out->buffer, NULL);
        out->buffer = VK_NULL_HANDLE;
        return status;
    }
    GDR_VK_TRY(err, vkBindBufferMemory(device, out->buffer, allocation.memory, allocation.offset));
    VkBufferDeviceAddressInfo address = {.sType = VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, .buffer = out->buffer};
    out->address = vkGetBufferDeviceAddress(device, &address);
    out->size = size;
    out->mapped = allocation.mapped;
    return GDR_OK;
}

void gdr_vk_buffer_destroy(gdr_vk_context *ctx, gdr_vk_buffer *buffer)
{
    if (buffer->buffer)
        vkDestroyBuffer(ctx->device, buffer->buffer, NULL);
    memset(buffer, 0, sizeof *buffer);
}

gdr_status gdr_vk_staging_create(gdr_vk_allocator *allocator, gdr_vk_buffer *out, gdr_error *err)
{
    return gdr_vk_buffer_create(allocator, GDR_VK_STAGING_SIZE, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, GDR_VK_BUFFER_UPLOAD,
                                out, err);
}

gdr_status gdr_vk_buffer_upload(gdr_vk_context *ctx, gdr_vk_buffer *staging, gdr_vk_buffer *dst,
                                VkDeviceSize offset, const void *data, VkDeviceSize size, gdr_error *err)
{
    if (offset + size > dst->size)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "upload of %llu bytes at %llu exceeds buffer size %llu",
                             (unsigned long long)size, (unsigned long long)offset, (unsigned long long)dst->size);
    gdr_status status = GDR_OK;
    for (VkDeviceSize done = 0; status == GDR_OK && done < size; done += staging->size) {
        VkDeviceSize part = size - done < staging->size ? size - done : staging->size;
        memcpy(staging->mapped, (const char *)data + done, part);
        VkCommandBuffer cmd;
        status = gdr_vk_begin_one_time(ctx, &cmd, err);
        if (status != GDR_OK)
            break;
        VkBufferCopy region = {0, offset + done, part};
        vkCmdCopyBuffer(cmd, staging->buffer, dst->buffer, 1, &region);
        status = gdr_vk_end_one_time(ctx, cmd, err);
    }
    return status;
}
