/* The renderer's Vulkan objects for applications that present or copy its image themselves. */
#include "gdr/renderer_vulkan.h"
#include "render/renderer_internal.h"

gdr_vulkan_handles gdr_renderer_vulkan(const gdr_renderer *r)
{
    return (gdr_vulkan_handles){.instance = r->ctx->instance, .physical_device = r->ctx->physical_device,
                                .device = r->ctx->device, .queue = r->ctx->queue,
                                .queue_family = r->ctx->queue_family, .color_image = r->color.image,
                                .color_format = GDR_COLOR_FORMAT,
                                /* every frame, and the read-back after it, end in this layout */
                                .color_layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                .width = r->width, .height = r->height};
}
