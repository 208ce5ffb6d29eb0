/* gdr view SCENE: the renderer in a window (GLFW), a fly camera, keys for the frame's settings, an
 * overlay of statistics, screenshots and recorded camera paths (docs/VIEWER.md). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "gdr/io.h"
#include "camera_path.h"
#include "cli_args.h"
#include "cli_pvs.h"
#include "commands.h"
#include "gdr/present.h"
#include "render_options.h"
#include "stats_output.h"
#include "view.h"

typedef struct view_options {
    const char *record_path, *screenshot, *screenshot_dir;
    bool no_vsync, overlay;
    float max_fps; /* 0: no limit but the present mode's */
} view_options;

typedef struct view_app {
    const render_options *o;
    const view_options *v;
    GLFWwindow *window;
    gdr_renderer *renderer;
    gdr_paged_cache *paged; /* streaming: the scene's paged cache, closed after the renderer */
    gdr_presenter *presenter;
    VkSurfaceKHR surface;
    view_settings settings;
    fly_camera camera;
    gdr_camera base_camera; /* the scene's: projection and the starting pose */
    camera_path replay, recorded;
    double mouse_x, mouse_y, scroll;
    bool looking;
    uint32_t frames, screenshots;
    gdr_frame_stats stats;
    double fps, frame_ms;
} view_app;

static int view_extra_option(void *context, int argc, char **argv, int *i)
{
    view_options *v = context;
    const char *arg = argv[*i];
    if (strcmp(arg, "--no-vsync") == 0) {
        v->no_vsync = true;
        return 1;
    }
    const char **target = strcmp(arg, "--record-path") == 0      ? &v->record_path
                          : strcmp(arg, "--screenshot") == 0     ? &v->screenshot
                          : strcmp(arg, "--screenshot-dir") == 0 ? &v->screenshot_dir
                                                                 : NULL;
    bool overlay = strcmp(arg, "--overlay") == 0, max_fps = strcmp(arg, "--max-fps") == 0;
    if (!target && !overlay && !max_fps)
        return 0;
    const char *value = cli_value(argc, argv, i);
    if (!value)
        return -1;
    if (overlay)
        return cli_parse_on_off(arg, value, &v->overlay) ? 1 : -1;
    if (max_fps)
        return cli_parse_float(arg, value, 1.0f, 10000.0f, &v->max_fps) ? 1 : -1;
    *target = value;
    return 1;
}

static void on_glfw_error(int code, const char *description)
{
    (void)code;
    fprintf(stderr, "gdr view: %s\n", description);
}

static void on_key(GLFWwindow *window, int key, int scancode, int action, int mods)
{
    (void)scancode;
    view_app *app = glfwGetWindowUserPointer(window);
    if (action == GLFW_PRESS) {
        gdr_camera now = app->base_camera;
        now.position = app->camera.position;
        now.rotation = app->camera.rotation;
        view_key(&app->settings, &now, key, mods);
        if (app->settings.jump) {
            app->settings.jump = false;
            view_jump(&app->settings, &app->camera.position, &app->camera.rotation);
        }
    }
}

static void on_scroll(GLFWwindow *window, double dx, double dy)
{
    (void)dx;
    ((view_app *)glfwGetWindowUserPointer(window))->scroll += dy;
}

/* Held keys and the mouse since the last frame. */
static fly_input read_input(view_app *app)
{
    GLFWwindow *w = app->window;
    fly_input in = {0};
    in.forward = (glfwGetKey(w, GLFW_KEY_W) == GLFW_PRESS) - (glfwGetKey(w, GLFW_KEY_S) == GLFW_PRESS);
    in.right = (glfwGetKey(w, GLFW_KEY_D) == GLFW_PRESS) - (glfwGetKey(w, GLFW_KEY_A) == GLFW_PRESS);
    in.up = (glfwGetKey(w, GLFW_KEY_E) == GLFW_PRESS) - (glfwGetKey(w, GLFW_KEY_Q) == GLFW_PRESS);
    in.fast = glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
    double x, y;
    glfwGetCursorPos(w, &x, &y);
    bool looking = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
    if (looking && app->looking)
        in.look_dx = x - app->mouse_x, in.look_dy = y - app->mouse_y;
    app->looking = looking;
    app->mouse_x = x;
    app->mouse_y = y;
    return in;
}

/* The overlay's lines: rate, GPU time per pass, CPU time, what was drawn, the settings. */
static void overlay_text(const view_app *app, char *text, size_t size)
{
    const gdr_frame_stats *s = &app->stats;
    const view_settings *v = &app->settings;
    size_t n = (size_t)snprintf(text, size, "%.1f fps  %.2f ms/frame   gpu %.3f ms  cpu %.3f ms\n", app->fps,
                                app->frame_ms, s->gpu_ms_per_frame, s->cpu_ms_per_frame);
    for (uint32_t i = 0; i < s->pass_count && n < size; i++)
        n += (size_t)snprintf(text + n, size - n, "%s %.3f  ", s->passes[i].name, s->passes[i].gpu_ms);
    static const char *const occlusion[] = {"default", "on", "off"};
    if (n < size)
        n += (size_t)snprintf(text + n, size - n,
                              "\ninstances %u / %u  clusters %u  triangles %llu\n"
                              "pipeline %s  raster %s  view %s  culling %s%s  occlusion %s (%s)  LOD %g px\n%s\n%s",
                              s->instances_visible, s->instances_total, s->meshlets_visible,
                              (unsigned long long)s->triangles, gdr_pipeline_name(s->pipeline),
                              gdr_raster_name(s->raster.mode), gdr_view_name(v->frame.view),
                              v->frame.cull == GDR_CULL_OFF ? "off" : "on", v->freeze_culling ? " (frozen)" : "",
                              occlusion[v->frame.occlusion], s->occlusion.applied ? "applied" : "not applied",
                              (double)v->frame.lod_error_px, v->message, v->help ? view_key_help : "H: keys");
    const gdr_streaming_stats *st = &s->streaming;
    if (st->enabled && n < size)
        snprintf(text + n, size - n,
                 "\nstreaming  LOD %.3g px (x %.3g to fit the pool)\n"
                 "pages wanted %u / %u slots  resident %u  pool %.1f MiB\n"
                 "uploads %u  evictions %u  requests %u  settled %u frames",
                 (double)st->lod_error_px, (double)st->lod_error_scale, st->wanted_pages, st->slot_count,
                 st->resident_pages, (double)st->pool_bytes / (1 << 20), st->uploads, st->evictions, st->requests,
                 st->settled_frames);
}

static int fail(const char *what, const gdr_error *err)
{
    fprintf(stderr, "gdr view: %s%s\n", what, err->message);
    return 1;
}

/* The window, the renderer with the window system's instance extensions, the surface and the
 * presenter. Returns 0 or the exit status. */
static int open_window(view_app *app, const gdr_scene *scene, const gdr_pvs *pvs)
{
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) {
        fprintf(stderr, "gdr view: cannot open a window (no display?); gdr render needs none\n");
        return 1;
    }
    if (!glfwVulkanSupported()) {
        fprintf(stderr, "gdr view: no Vulkan loader or driver that can present to a window\n");
        return 1;
    }
    uint32_t extension_count = 0;
    const char **extensions = glfwGetRequiredInstanceExtensions(&extension_count);
    if (!extensions) {
        fprintf(stderr, "gdr view: the Vulkan drivers offer no way to present to a window (no surface extensions); "
                "gdr render needs none\n");
        return 1;
    }
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    char title[256];
    snprintf(title, sizeof title, "gdr view %s", app->o->scene);
    app->window = glfwCreateWindow((int)app->o->width, (int)app->o->height, title, NULL, NULL);
    if (!app->window)
        return 1; /* the error callback said why */
    glfwSetWindowUserPointer(app->window, app);
    glfwSetKeyCallback(app->window, on_key);
    glfwSetScrollCallback(app->window, on_scroll);
    gdr_error err = {0};
    gdr_renderer_desc desc = {.width = app->o->width, .height = app->o->height, .device = app->o->device,
                              .validate = app->o->validate, .instance_extensions = extensions,
                              .instance_extension_count = extension_count, .presentable = true,
                              .disable_texture_compression_bc = cli_bc_textures_disabled()};
    if (gdr_renderer_create(&desc, &app->renderer, &err) != GDR_OK)
        return cli_renderer_failed(&err); /* 2 for a --device the machine does not have */
    if (render_options_set_scene(app->renderer, scene, app->o, &app->paged, &err) != GDR_OK ||
        gdr_renderer_set_pvs(app->renderer, pvs, &err) != GDR_OK) /* the cache's PVS culls as in gdr render */
        return fail("", &err);
    VkResult made = glfwCreateWindowSurface(gdr_renderer_vulkan(app->renderer).instance, app->window, NULL,
                                            &app->surface);
    if (made != VK_SUCCESS) {
        fprintf(stderr, "gdr view: cannot make a Vulkan surface for the window (VkResult %d)\n", (int)made);
        return 1;
    }
    int w, h;
    glfwGetFramebufferSize(app->window, &w, &h);
    gdr_presenter_desc present = {.surface = app->surface, .width = (uint32_t)w, .height = (uint32_t)h,
                                  .no_vsync = app->v->no_vsync};
    if (gdr_presenter_create(app->renderer, &present, &app->presenter, &err) != GDR_OK)
        return fail("", &err);
    return 0;
}

static void close_window(view_app *app)
{
    gdr_presenter_destroy(app->presenter);
    if (app->surface)
        vkDestroySurfaceKHR(gdr_renderer_vulkan(app->renderer).instance, app->surface, NULL);
    gdr_renderer_destroy(app->renderer);
    gdr_paged_cache_close(app->paged);
    if (app->window)
        glfwDestroyWindow(app->window);
    glfwTerminate();
}

/* The presented image (overlay included) as a PNG. */
static int write_capture(view_app *app, const char *path)
{
    uint32_t w, h;
    gdr_presenter_capture_size(app->presenter, &w, &h);
    gdr_error err = {0};
    uint8_t *pixels = malloc((size_t)w * h * 4 + 4);
    int result = 0;
    if (!pixels || w == 0 || gdr_presenter_read_capture(app->presenter, pixels, &err) != GDR_OK ||
        gdr_write_png(path, pixels, w, h, &err) != GDR_OK)
        result = fail("screenshot: ", &err);
    else
        printf("screenshot          %s (%ux%u)\n", path, w, h);
    free(pixels);
    return result;
}

/* This frame's camera: the path's pose when replaying, else the fly camera moved by the input. */
static gdr_camera frame_camera(view_app *app, double seconds)
{
    gdr_camera camera = app->base_camera;
    if (app->replay.count) {
        const camera_pose *pose = &app->replay.poses[app->frames % app->replay.count];
        app->camera.position = pose->position;
        app->camera.rotation = pose->rotation;
    } else {
        fly_input input = read_input(app);
        fly_camera_scroll(&app->camera, app->scroll);
        app->scroll = 0.0;
        fly_camera_update(&app->camera, &input, seconds);
    }
    camera.position = app->camera.position;
    camera.rotation = app->camera.rotation;
    return camera;
}

/* Renders with the settings; a setting the device refuses (a key just pressed) is undone. */
static int render_frame(view_app *app, const gdr_camera *camera, gdr_frame_desc *last_good)
{
    view_settings *s = &app->settings;
    s->frame.camera = *camera;
    s->frame.cull_camera = s->freeze_culling ? &s->cull_camera : NULL;
    gdr_error err = {0};
    if (gdr_renderer_render(app->renderer, &s->frame, 1, &app->stats, &err) == GDR_OK) {
        *last_good = s->frame;
        return 0;
    }
    snprintf(s->message, sizeof s->message, "refused: %.140s", err.message);
    fprintf(stderr, "gdr view: %s\n", err.message);
    s->frame = *last_good;
    s->frame.camera = *camera;
    s->frame.cull_camera = s->freeze_culling ? &s->cull_camera : NULL;
    return gdr_renderer_render(app->renderer, &s->frame, 1, &app->stats, &err) == GDR_OK ? 0 : fail("", &err);
}

static int present_frame(view_app *app, bool capture)
{
    char text[2048];
    overlay_text(app, text, sizeof text);
    int w, h;
    glfwGetFramebufferSize(app->window, &w, &h);
    gdr_presenter_resize(app->presenter, (uint32_t)w, (uint32_t)h);
    gdr_presenter_set_vsync(app->presenter, app->settings.vsync);
    gdr_present_desc present = {.overlay_text = app->settings.overlay ? text : NULL, .capture = capture};
    bool shown;
    gdr_error err = {0};
    if (gdr_presenter_present(app->presenter, &present, &shown, &err) != GDR_OK)
        return fail("", &err);
    if (!app->settings.screenshot || !shown)
        return 0;
    app->settings.screenshot = false;
    char path[1024];
    snprintf(path, sizeof path, "%s/gdr-view-%04u.png", app->v->screenshot_dir ? app->v->screenshot_dir : ".",
             app->screenshots++);
    return write_capture(app, path);
}

/* One frame: camera, render, present, record. */
static int run_frame(view_app *app, double seconds, bool last, gdr_frame_desc *last_good)
{
    gdr_camera camera = frame_camera(app, seconds);
    int result = render_frame(app, &camera, last_good);
    bool capture = app->settings.screenshot || (last && app->v->screenshot);
    if (result == 0)
        result = present_frame(app, capture);
    gdr_error err = {0};
    if (result == 0 && app->v->record_path &&
        camera_path_append(&app->recorded, camera.position, camera.rotation, &err) != GDR_OK)
        result = fail("--record-path: ", &err);
    app->frames++;
    return result;
}

static int run_loop(view_app *app)
{
    uint32_t frames = app->o->frames_given ? app->o->frames : 0; /* 0: until closed */
    gdr_frame_desc last_good = app->settings.frame;
    double previous = glfwGetTime(), rate_start = previous;
    uint32_t rate_frames = 0;
    int result = 0;
    double next_frame = previous;
    while (result == 0) {
        /* --max-fps: wait for the frame's time, handling events meanwhile. */
        for (double now = glfwGetTime(); app->v->max_fps > 0 && now < next_frame; now = glfwGetTime())
            glfwWaitEventsTimeout(next_frame - now);
        next_frame = glfwGetTime() + (app->v->max_fps > 0 ? 1.0 / app->v->max_fps : 0.0);
        glfwPollEvents();
        bool closing = glfwWindowShouldClose(app->window) || app->settings.quit;
        bool last = closing || (frames && app->frames + 1 >= frames);
        double now = glfwGetTime();
        result = run_frame(app, now - previous, last, &last_good);
        previous = now;
        rate_frames++;
        if (now - rate_start >= 0.5) {
            app->fps = rate_frames / (now - rate_start);
            app->frame_ms = 1e3 / (app->fps > 0 ? app->fps : 1);
            rate_frames = 0;
            rate_start = now;
        }
        if (last)
            break;
    }
    return result;
}

static int finish(view_app *app, int result)
{
    gdr_error err = {0};
    if (result == 0 && app->v->screenshot)
        result = write_capture(app, app->v->screenshot);
    if (result == 0 && app->v->record_path) {
        if (camera_path_write(app->v->record_path, &app->recorded, &err) != GDR_OK)
            result = fail("--record-path: ", &err);
        else
            printf("camera path         %s (%u frames)\n", app->v->record_path, app->recorded.count);
    }
    printf("frames              %u\n", app->frames);
    stats_print_streaming(stdout, &app->stats.streaming); /* the last frame's, as the overlay showed them */
    if (result == 0 && app->stats.validation_messages > 0) {
        fprintf(stderr, "gdr view: the validation layer reported %u message(s)\n", app->stats.validation_messages);
        result = 3;
    }
    return result;
}

static void start_settings(view_app *app, const gdr_scene *scene)
{
    const render_options *o = app->o;
    app->base_camera = render_options_camera(scene, o);
    app->camera = (fly_camera){app->base_camera.position, app->base_camera.rotation, 10.0f};
    view_settings *s = &app->settings;
    s->frame = render_options_frame(o, app->base_camera);
    s->frame.read_back = false;
    s->overlay = app->v->overlay;
    s->vsync = !app->v->no_vsync;
    s->has_mesh_pipeline = gdr_renderer_has_mesh_pipeline(app->renderer, NULL);
    s->streamed = render_options_streamed(o);
    s->home_position = app->camera.position;
    s->home_rotation = app->camera.rotation;
    snprintf(s->message, sizeof s->message, "H: keys");
}

int gdr_cmd_view(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            printf("usage: gdr view SCENE [options]   (gdr --help lists the options)\nkeys:\n%s", view_key_help);
            return 0;
        }
    }
    render_options o;
    view_options v = {.overlay = true};
    int result = render_options_parse("view", argc, argv, &o, view_extra_option, &v);
    if (result)
        return result;
    if (o.out_png || o.stats_json || o.settle_frames || o.warm_up_frames) {
        fprintf(stderr, "gdr view: --out, --stats, --settle and --warm-up are gdr render's; use --screenshot FILE\n");
        return 2;
    }
    view_app app = {.o = &o, .v = &v};
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_pvs *pvs = NULL;
    if (o.camera_path && camera_path_read(o.camera_path, &app.replay, &err) != GDR_OK)
        return fail("--camera-path: ", &err);
    o.load.pvs = &pvs;
    if (render_options_load(&o, &scene, &err) != GDR_OK) {
        camera_path_free(&app.replay);
        gdr_import_report_free(&o.report);
        return cli_load_failed(o.scene, &err);
    }
    result = cli_strict_check(&o.warnings, o.scene);
    if (result == 0 && o.pvs == GDR_CULL_ON && !pvs) {
        fprintf(stderr, "gdr view: --pvs on: %s holds no precomputed visibility (write it with gdr build %s -o "
                "FILE.gdrc --pvs)\n", o.scene, o.scene);
        result = 2;
    }
    if (result == 0 && o.has_camera_index && o.camera_index >= scene->camera_count)
        result = cli_camera_index_refused("view", o.camera_index, scene, &o.report);
    if (result == 0)
        result = open_window(&app, scene, pvs);
    if (result == 0) {
        start_settings(&app, scene);
        result = finish(&app, run_loop(&app));
    }
    close_window(&app);
    cli_pvs_destroy(pvs); /* after the renderer that held it */
    gdr_import_report_free(&o.report);
    gdr_scene_destroy(scene);
    camera_path_free(&app.replay);
    camera_path_free(&app.recorded);
    return result;
}
