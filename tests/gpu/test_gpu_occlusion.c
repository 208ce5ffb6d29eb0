/* Two-phase occlusion culling on the default device (lavapipe in CI), with validation and
 * synchronization validation on:
 *  - along the occlusion scene's camera path (240 frames: dolly, turns, camera cuts, objects coming
 *    out from behind the wall), the image with occlusion culling equals the image without it, pixel
 *    for pixel, every frame, for the mesh pipeline (instances and clusters) and the indirect one
 *    (instances); camera cuts are announced to the mesh pipeline and not to the indirect one (the
 *    result must be right either way);
 *  - most of the objects hidden behind the wall are culled (the fraction is reported and checked);
 *  - the per-phase statistics add up. */
#include <math.h>

#include "gdr/procedural.h"
#include "gpu_test_util.h"

#define WIDTH 192
#define HEIGHT 108

static bool render(gdr_renderer *renderer, const gdr_frame_desc *frame, uint8_t *pixels, gdr_frame_stats *stats)
{
    gdr_error err = {0};
    if (gdr_renderer_render(renderer, frame, 1, stats, &err) != GDR_OK ||
        gdr_renderer_read_color(renderer, pixels, &err) != GDR_OK) {
        fprintf(stderr, "render: %s\n", err.message);
        return false;
    }
    return true;
}

static gdr_renderer *occlusion_renderer(const gdr_scene *scene)
{
    gdr_error err = {0};
    gdr_renderer *renderer = NULL;
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true, .synchronization_validation = true};
    if (gdr_renderer_create(&desc, &renderer, &err) != GDR_OK || gdr_renderer_set_scene(renderer, scene, &err) != GDR_OK) {
        fprintf(stderr, "renderer: %s\n", err.message);
        gdr_renderer_destroy(renderer);
        return NULL;
    }
    return renderer;
}

/* Of the hidden objects (the scene's last `hidden` instances) inside the view frustum, the fraction
 * the last frame did not draw. */
static double hidden_culled_fraction(gdr_renderer *renderer, const gdr_scene *scene, uint32_t hidden,
                                     const gdr_camera *camera, uint32_t *in_frustum)
{
    gdr_error err = {0};
    uint32_t *visible = malloc(sizeof *visible * scene->instance_count), count = 0;
    uint8_t *drawn = calloc(scene->instance_count, 1);
    if (!visible || !drawn || gdr_renderer_read_visible(renderer, visible, scene->instance_count, &count, &err) != GDR_OK) {
        CHECK(false);
        free(visible);
        free(drawn);
        return 0.0;
    }
    for (uint32_t i = 0; i < count; i++)
        drawn[visible[i]] = 1;
    uint32_t inside = 0, culled = 0;
    for (uint32_t i = scene->instance_count - hidden; i < scene->instance_count; i++) {
        if (cpu_instance_visibility(scene, i, camera, (float)WIDTH / HEIGHT) <= 0)
            continue;
        inside++;
        culled += !drawn[i];
    }
    free(visible);
    free(drawn);
    *in_frustum = inside;
    return inside ? (double)culled / inside : 0.0;
}

static void check_path(const gdr_scene *scene, uint32_t hidden, gdr_pipeline pipeline, bool announce_cuts)
{
    gdr_renderer *with = occlusion_renderer(scene), *without = gpu_test_renderer(WIDTH, HEIGHT, scene);
    uint8_t *a = malloc(WIDTH * HEIGHT * 4), *b = malloc(WIDTH * HEIGHT * 4);
    if (!with || !without || !a || !b) {
        CHECK(false);
        goto done;
    }
    const char *name = gdr_pipeline_name(pipeline);
    uint32_t differing_frames = 0, frames = GDR_OCCLUSION_PATH_FRAMES;
    uint64_t early_occluded = 0, late_occluded = 0, late_tested = 0, meshlets_occluded = 0;
    for (uint32_t f = 0; f < frames; f++) {
        bool cut = false;
        gdr_camera camera = gdr_scene_occlusion_camera_path(f, &cut);
        gdr_frame_desc frame = {.camera = camera, .read_back = true, .pipeline = pipeline,
                                .occlusion = GDR_CULL_ON, .occlusion_camera_cut = announce_cuts && cut};
        gdr_frame_stats on, off;
        bool ok = render(with, &frame, a, &on);
        frame.occlusion = GDR_CULL_OFF;
        ok = ok && render(without, &frame, b, &off);
        if (!ok) {
            CHECK(false);
            break;
        }
        uint32_t differ = 0;
        for (size_t p = 0; p < (size_t)WIDTH * HEIGHT; p++)
            differ += memcmp(a + 4 * p, b + 4 * p, 4) != 0;
        if (differ) {
            if (differing_frames++ < 5)
                fprintf(stderr, "%s frame %u%s: %u pixels differ with occlusion culling\n", name, f, cut ? " (cut)" : "",
                        differ);
        }
        CHECK(on.occlusion.applied && !off.occlusion.applied);
        CHECK(on.validation_messages == 0);
        /* The phases add up: what is drawn is drawn once, in one phase. */
        CHECK(on.instances_visible == on.occlusion.instances_early_drawn + on.occlusion.instances_late_drawn);
        CHECK(on.occlusion.instances_late_occluded <= on.occlusion.instances_late_tested);
        /* The late phase retests exactly what the early phase deferred; without a history (the first
         * frame, an announced cut) nothing is deferred. */
        CHECK(on.occlusion.instances_late_tested == on.occlusion.instances_early_occluded);
        CHECK(on.occlusion.overflow == 0);
        if (f == 0 || (announce_cuts && cut))
            CHECK(on.occlusion.instances_early_occluded == 0 && on.occlusion.meshlets_early_occluded == 0 &&
                  on.occlusion.instances_late_drawn == 0);
        if (pipeline == GDR_PIPELINE_MESH) {
            CHECK(on.meshlets_visible == on.occlusion.meshlets_early_drawn + on.occlusion.meshlets_late_drawn);
            CHECK(on.occlusion.meshlets_late_occluded <= on.occlusion.meshlets_late_tested);
        }
        early_occluded += on.occlusion.instances_early_occluded;
        late_occluded += on.occlusion.instances_late_occluded;
        late_tested += on.occlusion.instances_late_tested;
        meshlets_occluded += on.occlusion.meshlets_late_occluded;
        if (f == 1) { /* the dolly towards the wall, with one frame of history */
            uint32_t inside = 0;
            double fraction = hidden_culled_fraction(with, scene, hidden, &camera, &inside);
            printf("%s: frame 1: %.1f%% of the %u hidden objects in the frustum culled (%u instances drawn of %u)\n",
                   name, 100.0 * fraction, inside, on.instances_visible, scene->instance_count);
            CHECK(inside > 100 && fraction > 0.8);
        }
    }
    CHECK(differing_frames == 0);
    printf("%s: %u frames%s, %u differ; instances occluded early %llu, late %llu of %llu tested; clusters occluded "
           "%llu\n",
           name, frames, announce_cuts ? " (cuts announced)" : "", differing_frames, (unsigned long long)early_occluded,
           (unsigned long long)late_occluded, (unsigned long long)late_tested, (unsigned long long)meshlets_occluded);
done:
    free(a);
    free(b);
    gdr_renderer_destroy(with);
    gdr_renderer_destroy(without);
}

int main(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_occlusion_scene_desc desc = {.hidden = 1500, .visible = 120};
    if (gdr_scene_create_occlusion(&desc, &scene, &err) != GDR_OK) {
        fprintf(stderr, "occlusion scene: %s\n", err.message);
        return 1;
    }
    check_path(scene, desc.hidden, GDR_PIPELINE_MESH, true);
    check_path(scene, desc.hidden, GDR_PIPELINE_INDIRECT, false);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_occlusion");
}
