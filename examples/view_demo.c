/* gdr embedded in an application's window: GLFW makes the window and the Vulkan surface, gdr renders
 * the built-in scene and presents it there, turning the camera a little every frame.
 *
 *   cc view_demo.c $(pkg-config --cflags --libs gdr glfw3 vulkan) -o view_demo
 *   ./view_demo [FRAMES]      (0 or nothing: until the window is closed)
 */
#include <stdio.h>
#include <stdlib.h>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <gdr/gdr.h>
#include <gdr/present.h>

static int fail(const char *what, const gdr_error *err)
{
    fprintf(stderr, "view_demo: %s%s\n", what, err ? err->message : "");
    return 1;
}

/* The frame loop: render into the renderer's image, present it into the window. */
static int run(GLFWwindow *window, gdr_renderer *renderer, gdr_presenter *presenter, const gdr_scene *scene,
               long frames)
{
    gdr_frame_desc frame = {.camera = scene->cameras[0]};
    gdr_quat turn = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, 0.002f);
    gdr_error err = {0};
    for (long f = 0; (frames <= 0 || f < frames) && !glfwWindowShouldClose(window); f++) {
        glfwPollEvents();
        int width, height;
        glfwGetFramebufferSize(window, &width, &height);
        gdr_presenter_resize(presenter, (uint32_t)width, (uint32_t)height);
        frame.camera.rotation = gdr_quat_normalize(gdr_quat_mul(turn, frame.camera.rotation));
        gdr_frame_stats stats;
        if (gdr_renderer_render(renderer, &frame, 1, &stats, &err) != GDR_OK)
            return fail("", &err);
        char text[128];
        snprintf(text, sizeof text, "%u of %u instances, %.3f GPU ms", stats.instances_visible, stats.instances_total,
                 stats.gpu_ms_per_frame);
        bool shown;
        if (gdr_presenter_present(presenter, &(gdr_present_desc){.overlay_text = text}, &shown, &err) != GDR_OK)
            return fail("", &err);
    }
    return 0;
}

int main(int argc, char **argv)
{
    long frames = argc > 1 ? strtol(argv[1], NULL, 10) : 0;
    if (!glfwInit())
        return fail("cannot open a window (no display?)", NULL);
    uint32_t extension_count = 0;
    const char **extensions = glfwGetRequiredInstanceExtensions(&extension_count);
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    GLFWwindow *window = extensions ? glfwCreateWindow(320, 180, "gdr view_demo", NULL, NULL) : NULL;
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_renderer *renderer = NULL;
    gdr_presenter *presenter = NULL;
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    gdr_renderer_desc desc = {.width = 320, .height = 180, .instance_extensions = extensions,
                              .instance_extension_count = extension_count, .presentable = true};
    int status = 1;
    if (!window)
        fail("no window, or no Vulkan driver that can present to one", NULL);
    else if (gdr_scene_create_demo(&(gdr_demo_desc){.instances = 1000}, &scene, &err) != GDR_OK ||
             gdr_renderer_create(&desc, &renderer, &err) != GDR_OK ||
             gdr_renderer_set_scene(renderer, scene, &err) != GDR_OK)
        fail("", &err);
    else if (glfwCreateWindowSurface(gdr_renderer_vulkan(renderer).instance, window, NULL, &surface) != VK_SUCCESS)
        fail("cannot make a surface for the window", NULL);
    else if (gdr_presenter_create(renderer, &(gdr_presenter_desc){.surface = surface, .width = 320, .height = 180},
                                  &presenter, &err) != GDR_OK)
        fail("", &err);
    else
        status = run(window, renderer, presenter, scene, frames);
    gdr_presenter_destroy(presenter); /* before the surface it presents to */
    if (surface)
        vkDestroySurfaceKHR(gdr_renderer_vulkan(renderer).instance, surface, NULL);
    gdr_renderer_destroy(renderer);
    gdr_scene_destroy(scene);
    if (window)
        glfwDestroyWindow(window);
    glfwTerminate();
    return status;
}
