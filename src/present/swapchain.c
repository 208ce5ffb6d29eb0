/* The swapchain: format, present mode and size chosen for the surface, made again when the window
 * changes. */
#include <stdio.h>
#include <string.h>

#include "present/presenter_internal.h"


/* 8-bit UNORM formats first: the renderer's image holds display values already, which a blit into
 * an sRGB image would encode a second time. */
static VkSurfaceFormatKHR choose_format(const VkSurfaceFormatKHR *formats, uint32_t count)
{
    static const VkFormat preferred[] = {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM};
    for (uint32_t k = 0; k < 2; k++)
        for (uint32_t i = 0; i < count; i++)
            if (formats[i].format == preferred[k])
                return formats[i];
    return formats[0];
}

static VkPresentModeKHR choose_present_mode(const gdr_presenter *p)
{
    if (p->vsync)
        return VK_PRESENT_MODE_FIFO_KHR; /* always supported */
    VkPresentModeKHR modes[16];
    uint32_t count = 16;
    if (vkGetPhysicalDeviceSurfacePresentModesKHR(p->vk.physical_device, p->surface, &count, modes) < 0)
        return VK_PRESENT_MODE_FIFO_KHR;
    VkPresentModeKHR best = VK_PRESENT_MODE_FIFO_KHR;
    for (uint32_t i = 0; i < count; i++) {
        if (modes[i] == VK_PRESENT_MODE_MAILBOX_KHR)
            return modes[i];
        if (modes[i] == VK_PRESENT_MODE_IMMEDIATE_KHR)
            best = modes[i];
    }
    return best;
}

static VkExtent2D choose_extent(const gdr_presenter *p, const VkSurfaceCapabilitiesKHR *caps)
{
    if (caps->currentExtent.width != UINT32_MAX)
        return caps->currentExtent;
    VkExtent2D e = {p->window_width, p->window_height};
    e.width = e.width < caps->minImageExtent.width ? caps->minImageExtent.width : e.width;
    e.height = e.height < caps->minImageExtent.height ? caps->minImageExtent.height : e.height;
    e.width = e.width > caps->maxImageExtent.width ? caps->maxImageExtent.width : e.width;
    e.height = e.height > caps->maxImageExtent.height ? caps->maxImageExtent.height : e.height;
    return e;
}

void gdr_swapchain_release(gdr_presenter *p, gdr_swapchain *s)
{
    for (uint32_t i = 0; i < s->image_count; i++) {
        if (s->views[i])
            vkDestroyImageView(p->vk.device, s->views[i], NULL);
        if (s->rendered[i])
            vkDestroySemaphore(p->vk.device, s->rendered[i], NULL);
    }
    if (s->handle)
        vkDestroySwapchainKHR(p->vk.device, s->handle, NULL);
    *s = (gdr_swapchain){0};
}

static gdr_status create_images(gdr_presenter *p, gdr_error *err)
{
    gdr_swapchain *s = &p->swapchain;
    uint32_t count = 0;
    GDR_VK_TRY(err, vkGetSwapchainImagesKHR(p->vk.device, s->handle, &count, NULL));
    if (count > GDR_PRESENT_MAX_IMAGES)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "the swapchain has %u images, at most %d are handled", count,
                             GDR_PRESENT_MAX_IMAGES);
    GDR_VK_TRY(err, vkGetSwapchainImagesKHR(p->vk.device, s->handle, &count, s->images));
    s->image_count = count;
    for (uint32_t i = 0; i < count; i++) {
        VkImageViewCreateInfo view = {.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, .image = s->images[i],
                                      .viewType = VK_IMAGE_VIEW_TYPE_2D, .format = s->format,
                                      .subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1}};
        GDR_VK_TRY(err, vkCreateImageView(p->vk.device, &view, NULL, &s->views[i]));
        VkSemaphoreCreateInfo semaphore = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
        GDR_VK_TRY(err, vkCreateSemaphore(p->vk.device, &semaphore, NULL, &s->rendered[i]));
    }
    return GDR_OK;
}

gdr_status gdr_swapchain_build(gdr_presenter *p, gdr_error *err)
{
    GDR_VK_TRY(err, vkDeviceWaitIdle(p->vk.device)); /* nothing may still use the old images */
    VkSurfaceCapabilitiesKHR caps;
    GDR_VK_TRY(err, vkGetPhysicalDeviceSurfaceCapabilitiesKHR(p->vk.physical_device, p->surface, &caps));
    gdr_swapchain old = p->swapchain;
    p->swapchain = (gdr_swapchain){0};
    VkExtent2D extent = choose_extent(p, &caps);
    if (extent.width == 0 || extent.height == 0) { /* minimised: nothing to present to */
        gdr_swapchain_release(p, &old);
        p->stale = true;
        return GDR_OK;
    }
    VkSurfaceFormatKHR formats[64];
    uint32_t format_count = 64;
    VkResult listed = vkGetPhysicalDeviceSurfaceFormatsKHR(p->vk.physical_device, p->surface, &format_count, formats);
    if ((listed != VK_SUCCESS && listed != VK_INCOMPLETE) || format_count == 0) {
        gdr_swapchain_release(p, &old);
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "the surface lists no image formats (VkResult %d)", (int)listed);
    }
    VkSurfaceFormatKHR format = choose_format(formats, format_count);
    VkImageUsageFlags usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                              (caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    uint32_t images = caps.minImageCount + 1;
    if (caps.maxImageCount && images > caps.maxImageCount)
        images = caps.maxImageCount;
    VkSwapchainCreateInfoKHR info = {
        .sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR, .surface = p->surface, .minImageCount = images,
        .imageFormat = format.format, .imageColorSpace = format.colorSpace, .imageExtent = extent,
        .imageArrayLayers = 1, .imageUsage = usage, .imageSharingMode = VK_SHARING_MODE_EXCLUSIVE,
        .preTransform = caps.currentTransform, .compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR,
        .presentMode = choose_present_mode(p), .clipped = VK_TRUE, .oldSwapchain = old.handle};
    if (!(caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR))
        info.compositeAlpha = VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR;
    VkResult created = vkCreateSwapchainKHR(p->vk.device, &info, NULL, &p->swapchain.handle);
    gdr_swapchain_release(p, &old);
    GDR_VK_TRY(err, created);
    p->swapchain.format = format.format;
    p->swapchain.extent = extent;
    p->swapchain.usage = usage;
    p->stale = false;
    return create_images(p, err);
}
