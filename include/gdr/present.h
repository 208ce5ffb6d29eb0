/* gdr presentation: the renderer's image shown in a window, or handed to an application.
 *
 * The renderer renders into an image of its own (gdr_renderer_desc.width x height). An application
 * that embeds gdr either lets a gdr_presenter copy that image into a swapchain on its window's
 * VkSurfaceKHR, or takes the Vulkan handles (gdr_renderer_vulkan) and copies the image itself.
 *
 * The frame loop (docs/VIEWER.md; examples/view_demo.c shows it with GLFW):
 *
 *   desc.instance_extensions = <the window system's, e.g. glfwGetRequiredInstanceExtensions>;
 *   desc.presentable = true;
 *   gdr_renderer_create(&desc, &renderer, &err);  gdr_renderer_set_scene(renderer, scene, &err);
 *   <create a VkSurfaceKHR with gdr_renderer_vulkan(renderer).instance>
 *   gdr_presenter_create(renderer, &(gdr_presenter_desc){.surface = surface, ...}, &presenter, &err);
 *   while (<window open>) {
 *       <poll events; on a new framebuffer size: gdr_presenter_resize(presenter, w, h)>
 *       gdr_renderer_render(renderer, &frame, 1, &stats, &err);       // into the renderer's image
 *       gdr_presenter_present(presenter, &present, &shown, &err);      // into the window
 *   }
 *   gdr_presenter_destroy(presenter);  vkDestroySurfaceKHR(...);  gdr_renderer_destroy(renderer);
 *
 * gdr_renderer_render returns once its frames have finished on the GPU, so the image may be read
 * by the caller's own commands on the same queue without further waiting. */
#ifndef GDR_PRESENT_H
#define GDR_PRESENT_H

#include <stdbool.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

#include "gdr/renderer.h"
#include "gdr/renderer_vulkan.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct gdr_presenter gdr_presenter;

typedef struct gdr_presenter_desc {
    VkSurfaceKHR surface;  /* the application's; it stays the application's to destroy, after the presenter */
    uint32_t width, height; /* the window's framebuffer size, used where the surface does not fix one */
    bool no_vsync;          /* present without waiting for the refresh (mailbox or immediate), if the surface can */
} gdr_presenter_desc;

/* Makes a swapchain on `surface` for the renderer's device. Fails with GDR_ERROR_UNSUPPORTED and a
 * message naming the device when its queue cannot present to the surface or the renderer was
 * created without `presentable`. */
GDR_API gdr_status gdr_presenter_create(gdr_renderer *renderer, const gdr_presenter_desc *desc, gdr_presenter **out,
                                        gdr_error *err);
GDR_API void gdr_presenter_destroy(gdr_presenter *presenter);

/* The window's framebuffer size changed (0 x 0: minimised); the swapchain is made again before the
 * next present. Swapchains the surface reports out of date or suboptimal are made again too. */
GDR_API void gdr_presenter_resize(gdr_presenter *presenter, uint32_t width, uint32_t height);
GDR_API void gdr_presenter_set_vsync(gdr_presenter *presenter, bool vsync);

typedef struct gdr_present_desc {
    /* Text drawn over the image's top left corner (lines separated by '\n'; NULL: none). */
    const char *overlay_text;
    /* Keep a copy of the image as presented, for gdr_presenter_read_capture. */
    bool capture;
} gdr_present_desc;

/* Shows the renderer's last image: into the next swapchain image, scaled to fit the window with
 * its aspect ratio kept (1:1 when the sizes match), the overlay on top, then presented.
 * *presented is false when nothing could be shown (a minimised window); that is not an error. */
GDR_API gdr_status gdr_presenter_present(gdr_presenter *presenter, const gdr_present_desc *desc, bool *presented,
                                         gdr_error *err);

/* The size of the last captured image, and its pixels as tightly packed RGBA8 rows, top row first
 * (width * height * 4 bytes). */
GDR_API void gdr_presenter_capture_size(const gdr_presenter *presenter, uint32_t *width, uint32_t *height);
GDR_API gdr_status gdr_presenter_read_capture(gdr_presenter *presenter, uint8_t *rgba, gdr_error *err);

#ifdef __cplusplus
}
#endif
#endif
