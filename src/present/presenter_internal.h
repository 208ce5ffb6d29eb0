/* The presenter's state, shared by the files of src/present. It uses only the renderer's public
 * API and its Vulkan handles (gdr/present.h), as an embedding application would. */
#ifndef GDR_PRESENTER_INTERNAL_H
#define GDR_PRESENTER_INTERNAL_H

#include "gdr/present.h"
#include "vk/vk_context.h" /* GDR_VK_TRY */

#define GDR_PRESENT_MAX_IMAGES 8
#define GDR_OVERLAY_MAX_RECTS 16384

typedef struct gdr_swapchain {
    VkSwapchainKHR handle;
    VkFormat format;
    VkExtent2D extent;
    VkImageUsageFlags usage;
    uint32_t image_count;
    VkImage images[GDR_PRESENT_MAX_IMAGES];
    VkImageView views[GDR_PRESENT_MAX_IMAGES];
    /* Signalled when an image's commands finish, waited on by its present; one per image, so a
     * semaphore is only reused once its image has been acquired again. */
    VkSemaphore rendered[GDR_PRESENT_MAX_IMAGES];
} gdr_swapchain;

struct gdr_presenter {
    gdr_renderer *renderer;
    gdr_vulkan_handles vk;
    VkSurfaceKHR surface;
    gdr_swapchain swapchain;
    uint32_t window_width, window_height;
    bool vsync;
    bool stale;               /* make the swapchain again before the next present */
    VkCommandPool pool;
    VkCommandBuffer cmd;
    VkFence done;             /* the last present's commands; waited for before reusing cmd */
    bool submitted;
    VkSemaphore acquired;     /* reused only after `done`: the submit that waited on it has finished */
    bool linear_blit;         /* the renderer's format can be blitted with linear filtering */
    VkClearRect *overlay_rects; /* GDR_OVERLAY_MAX_RECTS: the overlay's text as rectangles */
    /* The capture: one host-visible buffer of the swapchain's size. */
    VkBuffer capture;
    VkDeviceMemory capture_memory;
    void *capture_mapped;
    VkDeviceSize capture_bytes;
    uint32_t capture_width, capture_height;
    VkFormat capture_format;
    bool captured;
};

/* Makes (or makes again, retiring the old one) the swapchain for the surface's current size.
 * Leaves extent 0 x 0 and no swapchain while the window is minimised. */
gdr_status gdr_swapchain_build(gdr_presenter *p, gdr_error *err);
void gdr_swapchain_release(gdr_presenter *p, gdr_swapchain *swapchain);

/* Clear rectangles that draw `text` at (x, y) in pixels, scale `scale`, over a dark box; at most
 * `capacity` are written, clipped to width x height. Returns how many. */
uint32_t gdr_overlay_rects(const char *text, int x, int y, int scale, uint32_t width, uint32_t height,
                           VkClearRect *rects, uint32_t capacity, uint32_t *background_count);

#endif
