#include "vk/vk_buffer.h"

#include <string.h>

#include "vk/vk_image.h"

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

static const gdr_vk_scope everything_before = {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT};
static const gdr_vk_scope copy_read = {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT};
static const gdr_vk_scope copy_write = {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
static const gdr_vk_scope host_read = {VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT};

/* A host-visible buffer of `size` bytes for a read-back, and a one-time command buffer begun for it. */
static gdr_status begin_read_back(gdr_vk_allocator *allocator, VkDeviceSize size, gdr_vk_buffer *out,
                                  VkCommandBuffer *cmd, gdr_error *err)
{
    gdr_status status = gdr_vk_buffer_create(allocator, size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, GDR_VK_BUFFER_READBACK,
                                             out, err);
    return status == GDR_OK ? gdr_vk_begin_one_time(allocator->ctx, cmd, err) : status;
}

gdr_status gdr_vk_buffer_read_back(gdr_vk_allocator *allocator, VkBuffer source, VkDeviceSize offset,
                                   VkDeviceSize size, gdr_vk_buffer *out, gdr_error *err)
{
    VkCommandBuffer cmd;
    gdr_status status = begin_read_back(allocator, size, out, &cmd, err);
    if (status != GDR_OK)
        return status;
    gdr_vk_memory_barrier(cmd, everything_before, copy_read);
    VkBufferCopy region = {offset, 0, size};
    vkCmdCopyBuffer(cmd, source, out->buffer, 1, &region);
    gdr_vk_memory_barrier(cmd, copy_write, host_read);
    return gdr_vk_end_one_time(allocator->ctx, cmd, err);
}

gdr_status gdr_vk_image_read_back(gdr_vk_allocator *allocator, const gdr_vk_image *image, VkImageAspectFlags aspect,
                                  VkImageLayout layout, uint32_t texel_size, gdr_vk_buffer *out, gdr_error *err)
{
    VkDeviceSize size = (VkDeviceSize)image->width * image->height * texel_size;
    VkCommandBuffer cmd;
    gdr_status status = begin_read_back(allocator, size, out, &cmd, err);
    if (status != GDR_OK)
        return status;
    gdr_vk_image_transition to_copy = {.image = image->image, .aspect = aspect, .from = layout,
                                       .to = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, .src = everything_before,
                                       .dst = copy_read};
    gdr_vk_barrier(cmd, &(gdr_vk_barrier_desc){.images = &to_copy, .image_count = 1});
    VkBufferImageCopy region = {.imageSubresource = {aspect, 0, 0, 1}, .imageExtent = {image->width, image->height, 1}};
    vkCmdCopyImageToBuffer(cmd, image->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, out->buffer, 1, &region);
    gdr_vk_image_transition back = {.image = image->image, .aspect = aspect, .from = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                    .to = layout, .src = {VK_PIPELINE_STAGE_2_COPY_BIT, 0},
                                    .dst = {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0}};
    gdr_vk_barrier(cmd, &(gdr_vk_barrier_desc){.src = copy_write, .dst = host_read, .images = &back, .image_count = 1});
    return gdr_vk_end_one_time(allocator->ctx, cmd, err);
}
