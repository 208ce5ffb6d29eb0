/* The presenter: the renderer's image copied into a swapchain image each frame (scaled to fit,
 * aspect kept), the overlay text drawn over it with clear rectangles, presented. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "present/presenter_internal.h"


#define OVERLAY_SCALE 2

static gdr_status create_sync(gdr_presenter *p, gdr_error *err)
{
    VkCommandPoolCreateInfo pool = {.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
                                    .flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
                                    .queueFamilyIndex = p->vk.queue_family};
    GDR_VK_TRY(err, vkCreateCommandPool(p->vk.device, &pool, NULL, &p->pool));
    VkCommandBufferAllocateInfo alloc = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, .commandPool = p->pool,
                                         .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, .commandBufferCount = 1};
    GDR_VK_TRY(err, vkAllocateCommandBuffers(p->vk.device, &alloc, &p->cmd));
    VkFenceCreateInfo fence = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    GDR_VK_TRY(err, vkCreateFence(p->vk.device, &fence, NULL, &p->done));
    VkSemaphoreCreateInfo semaphore = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    GDR_VK_TRY(err, vkCreateSemaphore(p->vk.device, &semaphore, NULL, &p->acquired));
    return GDR_OK;
}

gdr_status gdr_presenter_create(gdr_renderer *renderer, const gdr_presenter_desc *desc, gdr_presenter **out,
                                gdr_error *err)
{
    gdr_presenter *p = calloc(1, sizeof *p);
    if (!p)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "presenter: out of memory");
    p->renderer = renderer;
    p->vk = gdr_renderer_vulkan(renderer);
    p->overlay_rects = malloc(sizeof *p->overlay_rects * GDR_OVERLAY_MAX_RECTS);
    if (!p->overlay_rects) {
        free(p);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "presenter: out of memory");
    }
    p->surface = desc->surface;
    p->window_width = desc->width;
    p->window_height = desc->height;
    p->vsync = !desc->no_vsync;
    VkPhysicalDeviceProperties properties;
    vkGetPhysicalDeviceProperties(p->vk.physical_device, &properties);
    VkBool32 supported = VK_FALSE;
    VkResult asked = vkGetPhysicalDeviceSurfaceSupportKHR(p->vk.physical_device, p->vk.queue_family, p->surface,
                                                          &supported);
    gdr_status status = GDR_OK;
    if (asked != VK_SUCCESS || !supported)
        status = gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "device '%s' cannot present to this window (queue family %u%s)",
                               properties.deviceName, p->vk.queue_family,
                               asked != VK_SUCCESS ? ": the surface query failed" : "");
    VkFormatProperties format;
    vkGetPhysicalDeviceFormatProperties(p->vk.physical_device, p->vk.color_format, &format);
    p->linear_blit = (format.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) != 0;
    if (status == GDR_OK)
        status = create_sync(p, err);
    if (status == GDR_OK)
        status = gdr_swapchain_build(p, err);
    if (status != GDR_OK) {
        gdr_presenter_destroy(p);
        return status;
    }
    *out = p;
    return GDR_OK;
}

static void release_capture(gdr_presenter *p)
{
    if (p->capture)
        vkDestroyBuffer(p->vk.device, p->capture, NULL);
    if (p->capture_memory)
        vkFreeMemory(p->vk.device, p->capture_memory, NULL);
    p->capture = VK_NULL_HANDLE;
    p->capture_memory = VK_NULL_HANDLE;
    p->capture_mapped = NULL;
    p->capture_bytes = 0;
}

void gdr_presenter_destroy(gdr_presenter *p)
{
    if (!p)
        return;
    vkDeviceWaitIdle(p->vk.device);
    gdr_swapchain_release(p, &p->swapchain);
    release_capture(p);
    if (p->acquired)
        vkDestroySemaphore(p->vk.device, p->acquired, NULL);
    if (p->done)
        vkDestroyFence(p->vk.device, p->done, NULL);
    if (p->pool)
        vkDestroyCommandPool(p->vk.device, p->pool, NULL);
    free(p->overlay_rects);
    free(p);
}

void gdr_presenter_resize(gdr_presenter *p, uint32_t width, uint32_t height)
{
    p->stale |= width != p->window_width || height != p->window_height;
    p->window_width = width;
    p->window_height = height;
}

void gdr_presenter_set_vsync(gdr_presenter *p, bool vsync)
{
    p->stale |= vsync != p->vsync;
    p->vsync = vsync;
}

/* One host-visible buffer for the capture, of the swapchain's size. It is the presenter's only
 * memory allocation: an application's side of the API, made again only when the window's size
 * changes. */
static gdr_status ensure_capture(gdr_presenter *p, VkDeviceSize bytes, gdr_error *err)
{
    if (p->capture_bytes == bytes)
        return GDR_OK;
    release_capture(p);
    VkBufferCreateInfo info = {.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, .size = bytes,
                               .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT, .sharingMode = VK_SHARING_MODE_EXCLUSIVE};
    GDR_VK_TRY(err, vkCreateBuffer(p->vk.device, &info, NULL, &p->capture));
    VkMemoryRequirements needs;
    vkGetBufferMemoryRequirements(p->vk.device, p->capture, &needs);
    VkPhysicalDeviceMemoryProperties memory;
    vkGetPhysicalDeviceMemoryProperties(p->vk.physical_device, &memory);
    const VkMemoryPropertyFlags wanted = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    uint32_t type = UINT32_MAX;
    for (uint32_t i = 0; i < memory.memoryTypeCount && type == UINT32_MAX; i++)
        if ((needs.memoryTypeBits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & wanted) == wanted)
            type = i;
    if (type == UINT32_MAX)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "capture: no host-visible coherent memory");
    VkMemoryAllocateInfo alloc = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, .allocationSize = needs.size,
                                  .memoryTypeIndex = type};
    GDR_VK_TRY(err, vkAllocateMemory(p->vk.device, &alloc, NULL, &p->capture_memory));
    GDR_VK_TRY(err, vkBindBufferMemory(p->vk.device, p->capture, p->capture_memory, 0));
    GDR_VK_TRY(err, vkMapMemory(p->vk.device, p->capture_memory, 0, VK_WHOLE_SIZE, 0, &p->capture_mapped));
    p->capture_bytes = bytes;
    return GDR_OK;
}

static void image_barrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to,
                          VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access, VkPipelineStageFlags2 dst_stage,
                          VkAccessFlags2 dst_access)
{
    VkImageMemoryBarrier2 barrier = {.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2, .srcStageMask = src_stage,
                                     .srcAccessMask = src_access, .dstStageMask = dst_stage,
                                     .dstAccessMask = dst_access, .oldLayout = from, .newLayout = to,
                                     .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
                                     .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .image = image,
                                     .subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1}};
    VkDependencyInfo dependency = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = 1,
                                   .pImageMemoryBarriers = &barrier};
    vkCmdPipelineBarrier2(cmd, &dependency);
}

/* The renderer's image into the swapchain image (TRANSFER_DST_OPTIMAL): cleared, then the image
 * scaled to the largest size of the same aspect ratio that fits, centred. */
static void record_blit(gdr_presenter *p, VkCommandBuffer cmd, VkImage target)
{
    const gdr_vulkan_handles *vk = &p->vk;
    VkExtent2D e = p->swapchain.extent;
    VkClearColorValue background = {{0.0f, 0.0f, 0.0f, 1.0f}};
    VkImageSubresourceRange range = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &background, 1, &range);
    image_barrier(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_BLIT_BIT,
                  VK_ACCESS_2_TRANSFER_WRITE_BIT);
    /* Fit: width-bound or height-bound, whichever keeps the whole image inside. */
    uint64_t w = e.width, h = (uint64_t)e.width * vk->height / vk->width;
    if (h > e.height)
        h = e.height, w = (uint64_t)e.height * vk->width / vk->height;
    w = w ? w : 1;
    h = h ? h : 1;
    int32_t x0 = (int32_t)((e.width - w) / 2), y0 = (int32_t)((e.height - h) / 2);
    VkImageBlit region = {.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                          .srcOffsets = {{0, 0, 0}, {(int32_t)vk->width, (int32_t)vk->height, 1}},
                          .dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                          .dstOffsets = {{x0, y0, 0}, {x0 + (int32_t)w, y0 + (int32_t)h, 1}}};
    bool same_size = w == vk->width && h == vk->height;
    vkCmdBlitImage(cmd, vk->color_image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region,
                   same_size || !p->linear_blit ? VK_FILTER_NEAREST : VK_FILTER_LINEAR);
}

/* The overlay text over a dark box, drawn as clear rectangles in a rendering pass that keeps the
 * image (COLOR_ATTACHMENT_OPTIMAL). */
static void record_overlay(gdr_presenter *p, VkCommandBuffer cmd, uint32_t image, const char *text)
{
    VkClearRect *rects = p->overlay_rects;
    VkExtent2D e = p->swapchain.extent;
    uint32_t background = 0;
    uint32_t count = gdr_overlay_rects(text, 10, 10, OVERLAY_SCALE, e.width, e.height, rects, GDR_OVERLAY_MAX_RECTS,
                                       &background);
    VkRenderingAttachmentInfo color = {.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                                       .imageView = p->swapchain.views[image],
                                       .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                       .loadOp = VK_ATTACHMENT_LOAD_OP_LOAD, .storeOp = VK_ATTACHMENT_STORE_OP_STORE};
    VkRenderingInfo rendering = {.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = {{0, 0}, e},
                                 .layerCount = 1, .colorAttachmentCount = 1, .pColorAttachments = &color};
    vkCmdBeginRendering(cmd, &rendering);
    VkClearAttachment dark = {.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT, .colorAttachment = 0,
                              .clearValue = {.color = {{0.0f, 0.0f, 0.0f, 1.0f}}}};
    VkClearAttachment light = dark;
    light.clearValue.color = (VkClearColorValue){{1.0f, 1.0f, 0.85f, 1.0f}};
    if (background)
        vkCmdClearAttachments(cmd, 1, &dark, background, rects);
    if (count > background)
        vkCmdClearAttachments(cmd, 1, &light, count - background, rects + background);
    vkCmdEndRendering(cmd);
}

/* Everything between acquiring image `index` and presenting it. */
static gdr_status record_frame(gdr_presenter *p, uint32_t index, const gdr_present_desc *desc, gdr_error *err)
{
    VkCommandBuffer cmd = p->cmd;
    VkImage target = p->swapchain.images[index];
    VkExtent2D e = p->swapchain.extent;
    GDR_VK_TRY(err, vkResetCommandBuffer(cmd, 0));
    VkCommandBufferBeginInfo begin = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                      .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
    GDR_VK_TRY(err, vkBeginCommandBuffer(cmd, &begin));
    image_barrier(cmd, p->vk.color_image, p->vk.color_layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                  VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_2_BLIT_BIT,
                  VK_ACCESS_2_TRANSFER_READ_BIT);
    image_barrier(cmd, target, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, VK_PIPELINE_STAGE_2_CLEAR_BIT,
                  VK_ACCESS_2_TRANSFER_WRITE_BIT);
    record_blit(p, cmd, target);
    image_barrier(cmd, p->vk.color_image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, p->vk.color_layout,
                  VK_PIPELINE_STAGE_2_BLIT_BIT, 0, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0);
    VkImageLayout layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    if (desc->overlay_text && desc->overlay_text[0]) {
        image_barrier(cmd, target, layout, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_BLIT_BIT,
                      VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                      VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
        layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        record_overlay(p, cmd, index, desc->overlay_text);
    }
    if (desc->capture) {
        image_barrier(cmd, target, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                      VK_ACCESS_2_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        VkBufferImageCopy region = {.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                                    .imageExtent = {e.width, e.height, 1}};
        vkCmdCopyImageToBuffer(cmd, target, layout, p->capture, 1, &region);
    }
    image_barrier(cmd, target, layout, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                  VK_ACCESS_2_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0);
    if (desc->capture) {
        VkMemoryBarrier2 host = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2, .srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT,
                                 .srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                 .dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT, .dstAccessMask = VK_ACCESS_2_HOST_READ_BIT};
        VkDependencyInfo dependency = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1,
                                       .pMemoryBarriers = &host};
        vkCmdPipelineBarrier2(cmd, &dependency);
    }
    GDR_VK_TRY(err, vkEndCommandBuffer(cmd));
    return GDR_OK;
}

static gdr_status submit_and_present(gdr_presenter *p, uint32_t index, gdr_error *err)
{
    VkSemaphoreSubmitInfo wait = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO, .semaphore = p->acquired,
                                  .stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT};
    VkSemaphoreSubmitInfo signal = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO,
                                    .semaphore = p->swapchain.rendered[index],
                                    .stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT};
    VkCommandBufferSubmitInfo cmd = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO, .commandBuffer = p->cmd};
    VkSubmitInfo2 submit = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2, .waitSemaphoreInfoCount = 1,
                            .pWaitSemaphoreInfos = &wait, .commandBufferInfoCount = 1, .pCommandBufferInfos = &cmd,
                            .signalSemaphoreInfoCount = 1, .pSignalSemaphoreInfos = &signal};
    GDR_VK_TRY(err, vkQueueSubmit2(p->vk.queue, 1, &submit, p->done));
    p->submitted = true;
    VkPresentInfoKHR present = {.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR, .waitSemaphoreCount = 1,
                                .pWaitSemaphores = &p->swapchain.rendered[index], .swapchainCount = 1,
                                .pSwapchains = &p->swapchain.handle, .pImageIndices = &index};
    VkResult result = vkQueuePresentKHR(p->vk.queue, &present);
    if (result == VK_ERROR_OUT_OF_DATE_KHR || result == VK_SUBOPTIMAL_KHR)
        p->stale = true; /* made again before the next present */
    else
        GDR_VK_TRY(err, result);
    return GDR_OK;
}

static gdr_status wait_previous(gdr_presenter *p, gdr_error *err)
{
    if (!p->submitted)
        return GDR_OK;
    GDR_VK_TRY(err, vkWaitForFences(p->vk.device, 1, &p->done, VK_TRUE, UINT64_MAX));
    GDR_VK_TRY(err, vkResetFences(p->vk.device, 1, &p->done));
    p->submitted = false;
    return GDR_OK;
}

gdr_status gdr_presenter_present(gdr_presenter *p, const gdr_present_desc *desc_in, bool *presented, gdr_error *err)
{
    const gdr_present_desc desc = desc_in ? *desc_in : (gdr_present_desc){0};
    *presented = false;
    gdr_status status = wait_previous(p, err);
    if (status == GDR_OK && (p->stale || !p->swapchain.handle))
        status = gdr_swapchain_build(p, err);
    if (status != GDR_OK || !p->swapchain.handle)
        return status; /* minimised: nothing shown */
    VkExtent2D e = p->swapchain.extent;
    if (desc.capture && !(p->swapchain.usage & VK_IMAGE_USAGE_TRANSFER_SRC_BIT))
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "capture: the surface's images cannot be copied from");
    if (desc.capture && (status = ensure_capture(p, (VkDeviceSize)e.width * e.height * 4, err)) != GDR_OK)
        return status;
    uint32_t index;
    VkResult acquired = vkAcquireNextImageKHR(p->vk.device, p->swapchain.handle, UINT64_MAX, p->acquired,
                                              VK_NULL_HANDLE, &index);
    if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {
        p->stale = true; /* nothing was signalled: try again next frame with a new swapchain */
        return GDR_OK;
    }
    if (acquired == VK_SUBOPTIMAL_KHR)
        p->stale = true; /* the image is usable; present it, then make the swapchain again */
    else
        GDR_VK_TRY(err, acquired);
    status = record_frame(p, index, &desc, err);
    if (status == GDR_OK)
        status = submit_and_present(p, index, err);
    if (status == GDR_OK && desc.capture) {
        status = wait_previous(p, err);
        p->captured = status == GDR_OK;
        p->capture_width = e.width;
        p->capture_height = e.height;
        p->capture_format = p->swapchain.format;
    }
    *presented = status == GDR_OK;
    return status;
}

void gdr_presenter_capture_size(const gdr_presenter *p, uint32_t *width, uint32_t *height)
{
    *width = p->captured ? p->capture_width : 0;
    *height = p->captured ? p->capture_height : 0;
}

gdr_status gdr_presenter_read_capture(gdr_presenter *p, uint8_t *rgba, gdr_error *err)
{
    if (!p->captured)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "read_capture: no frame was presented with capture");
    size_t pixels = (size_t)p->capture_width * p->capture_height;
    const uint8_t *source = p->capture_mapped;
    bool bgra = p->capture_format == VK_FORMAT_B8G8R8A8_UNORM || p->capture_format == VK_FORMAT_B8G8R8A8_SRGB;
    for (size_t i = 0; i < pixels; i++) {
        rgba[i * 4 + 0] = source[i * 4 + (bgra ? 2 : 0)];
        rgba[i * 4 + 1] = source[i * 4 + 1];
        rgba[i * 4 + 2] = source[i * 4 + (bgra ? 0 : 2)];
        rgba[i * 4 + 3] = 255; /* what the window shows: opaque */
    }
    return GDR_OK;
}
