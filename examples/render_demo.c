/* A program using the installed gdr library: load the built-in scene, render it, save a PNG and
 * print the frame's statistics.
 *
 *   cc render_demo.c $(pkg-config --cflags --libs gdr) -o render_demo
 *   ./render_demo out.png
 */
#include <stdio.h>
#include <stdlib.h>

#include <gdr/gdr.h>

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : "render_demo.png";
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_renderer *renderer = NULL;
    gdr_renderer_desc desc = {.width = 320, .height = 180};
    uint8_t *pixels = malloc(320 * 180 * 4);
    int status = 1;
    if (pixels && gdr_scene_load("demo:instances=1000", NULL, &scene, &err) == GDR_OK &&
        gdr_renderer_create(&desc, &renderer, &err) == GDR_OK && gdr_renderer_set_scene(renderer, scene, &err) == GDR_OK) {
        gdr_frame_desc frame = {.camera = scene->cameras[0], .read_back = true};
        gdr_frame_stats stats;
        if (gdr_renderer_render(renderer, &frame, 1, &stats, &err) == GDR_OK &&
            gdr_renderer_read_color(renderer, pixels, &err) == GDR_OK &&
            gdr_write_png(path, pixels, desc.width, desc.height, &err) == GDR_OK) {
            printf("gdr %s on %s: %u of %u instances visible, %llu triangles -> %s\n", gdr_version(), stats.device,
                   stats.instances_visible, stats.instances_total, (unsigned long long)stats.triangles, path);
            status = 0;
        }
    }
    if (status != 0)
        fprintf(stderr, "render_demo: %s\n", err.message[0] ? err.message : "out of memory");
    gdr_renderer_destroy(renderer);
    gdr_scene_destroy(scene);
    free(pixels);
    return status;
}
