/* Real third-party glTF files (Debian's assimp-testmodels) render to a plausible image: something
 * covers a sensible part of the frame, and culling does not change a pixel. */
#include "gdr/io.h"
#include "gpu_test_util.h"

#define WIDTH 200
#define HEIGHT 150
#define MODELS "/usr/share/assimp/models/glTF2/"

static void check_file(const char *relative, double min_coverage)
{
    char path[512];
    snprintf(path, sizeof path, "%s%s", MODELS, relative);
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_load_options options = {.no_cache = 1, .no_progress = 1};
    if (gdr_scene_load(path, &options, &scene, &err) != GDR_OK) {
        fprintf(stderr, "%s: %s\n", relative, err.message);
        CHECK(false);
        return;
    }
    gdr_renderer *renderer = gpu_test_renderer(WIDTH, HEIGHT, scene);
    uint8_t *culled = malloc(WIDTH * HEIGHT * 4), *all = malloc(WIDTH * HEIGHT * 4);
    gdr_frame_desc frame = {.camera = gdr_scene_framing_camera(scene), .cull = GDR_CULL_ON, .read_back = true};
    gdr_frame_stats stats;
    CHECK(renderer && gdr_renderer_render(renderer, &frame, 1, &stats, &err) == GDR_OK);
    CHECK(renderer && gdr_renderer_read_color(renderer, culled, &err) == GDR_OK);
    frame.cull = GDR_CULL_OFF;
    CHECK(renderer && gdr_renderer_render(renderer, &frame, 1, &stats, &err) == GDR_OK);
    CHECK(renderer && gdr_renderer_read_color(renderer, all, &err) == GDR_OK);
    /* Coverage: pixels that are not the clear colour of the sky. */
    uint32_t covered = 0;
    const uint8_t *corner = all; /* the framing camera leaves the corners empty */
    for (uint32_t p = 0; p < WIDTH * HEIGHT; p++)
        covered += memcmp(all + p * 4, corner, 4) != 0;
    double coverage = (double)covered / (WIDTH * HEIGHT);
    printf("%s: %u instances, %llu triangles, coverage %.1f%%\n", relative, stats.instances_total,
           (unsigned long long)stats.triangles, 100.0 * coverage);
    CHECK(coverage >= min_coverage && coverage < 0.95);
    CHECK(memcmp(culled, all, WIDTH * HEIGHT * 4) == 0);
    CHECK(renderer && stats.validation_messages == 0);
    free(culled);
    free(all);
    gdr_renderer_destroy(renderer);
    gdr_scene_destroy(scene);
}

int main(void)
{
    check_file("2CylinderEngine-glTF-Binary/2CylinderEngine.glb", 0.05);
    check_file("BoxTextured-glTF-Binary/BoxTextured.glb", 0.02);
    check_file("cameras/Cameras.gltf", 0.01);
    return test_finish("test_gpu_real_files");
}
