/* gdr renderer, Vulkan side: the renderer's device, queue and image, for an application that
 * presents the image itself or records its own commands around it (gdr/present.h presents it). */
#ifndef GDR_RENDERER_VULKAN_H
#define GDR_RENDERER_VULKAN_H

#include <stdint.h>
#include <vulkan/vulkan.h>

#include "gdr/renderer.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The renderer's Vulkan objects, for an application that records its own commands. The image is
 * `color_format`, usage includes TRANSFER_SRC, and between gdr_renderer_render calls it is in
 * `color_layout`; commands that use it must leave it in that layout again. */
typedef struct gdr_vulkan_handles {
    VkInstance instance;
    VkPhysicalDevice physical_device;
    VkDevice device;
    VkQueue queue;
    uint32_t queue_family;
    VkImage color_image;
    VkFormat color_format;
    VkImageLayout color_layout;
    uint32_t width, height;
} gdr_vulkan_handles;

GDR_API gdr_vulkan_handles gdr_renderer_vulkan(const gdr_renderer *renderer);

#ifdef __cplusplus
}
#endif
#endif
