/* The compute rasteriser's tiny path (several tiny clusters per workgroup, by size class: see
 * docs/PIPELINE.md) on the default device (lavapipe in CI), validation on. Each scene is drawn by
 * three renderers, in the compute rasteriser's mode and in hybrid: with the tiny path (every size
 * class must be taken), without it (every cluster one to a workgroup, as before the tiny path), and
 * with the tiny parts of the visible-cluster list forced to two entries (the clusters that find
 * their part full join the front). All three must give the same frame bit for bit: the visibility
 * buffer decoded (depth bits, instance, cluster, triangle: a tiny variant that reads another
 * cluster's entry, slot or shared vertices names another cluster or triangle there), the colour
 * image, the depth, and the overdraw view's counts (a cluster drawn twice or not at all changes
 * them); and the same statistics but for the tiny counts, both raster phases of the occlusion
 * culling included (the second frame sees the first's depth pyramid). */
#include "gpu_test_util.h"
#include "render/renderer_debug.h"
#include "render/visbuffer.h"

#define WIDTH 256
#define HEIGHT 144
#define PIXELS (WIDTH * HEIGHT)
#define FORCED_CAPACITY 2

typedef struct tiny_result {
    uint8_t rgba[PIXELS * 4];
    gdr_visbuffer_pixel vis[PIXELS];
    float depth[PIXELS];
    uint32_t overdraw[PIXELS];
    gdr_frame_stats stats;
} tiny_result;

/* Per renderer, the two frames of render_frames. */
static tiny_result results[3][2];

/* One frame from `camera`, read back, then its overdraw view. */
static bool render_frame(gdr_renderer *r, const gdr_camera *camera, gdr_raster raster, tiny_result *out)
{
    gdr_error err = {0};
    gdr_frame_stats stats;
    gdr_frame_desc frame = {.camera = *camera, .raster = raster, .lod_error_px = 1.0f, .occlusion = GDR_CULL_ON,
                            .read_back = true};
    bool ok = gdr_renderer_render(r, &frame, 1, &out->stats, &err) == GDR_OK &&
              gdr_renderer_read_color(r, out->rgba, &err) == GDR_OK &&
              gdr_visbuffer_read_depth(r, out->depth, &err) == GDR_OK &&
              gdr_visbuffer_read_pixels(r, out->vis, &err) == GDR_OK;
    frame.view = GDR_VIEW_MODE_OVERDRAW;
    ok = ok && gdr_renderer_render(r, &frame, 1, &stats, &err) == GDR_OK &&
         gdr_visbuffer_read_overdraw(r, out->overdraw, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "render: %s\n", err.message);
    CHECK(ok && out->stats.validation_messages == 0 && stats.validation_messages == 0);
    return ok;
}

/* Two frames: the first without occlusion history (its late raster phase draws what the early one
 * could not test), the second with the first's. */
static bool render_frames(gdr_renderer *r, const gdr_camera cameras[2], gdr_raster raster, tiny_result out[2])
{
    return render_frame(r, &cameras[0], raster, &out[0]) && render_frame(r, &cameras[1], raster, &out[1]);
}

static bool render_with(const gdr_scene *scene, const gdr_renderer_debug *debug, const gdr_camera cameras[2],
                        gdr_raster raster, tiny_result out[2])
{
    gdr_error err = {0};
    gdr_renderer *r = NULL;
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true};
    bool ok = gdr_renderer_create(&desc, &r, &err) == GDR_OK;
    if (ok)
        gdr_renderer_set_debug(r, debug);
    ok = ok && gdr_renderer_set_scene(r, scene, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "renderer: %s\n", err.message);
    ok = ok && render_frames(r, cameras, raster, out);
    gdr_renderer_destroy(r);
    CHECK(ok);
    return ok;
}

static bool same_pixel(const gdr_visbuffer_pixel *a, const gdr_visbuffer_pixel *b)
{
    return memcmp(&a->depth, &b->depth, sizeof a->depth) == 0 && a->instance == b->instance &&
           a->meshlet == b->meshlet && a->triangle == b->triangle;
}

/* Pixels where `b` differs from `a` in any of the frame's read-backs. */
static uint32_t differing(const tiny_result *a, const tiny_result *b)
{
    uint32_t n = 0;
    for (int p = 0; p < PIXELS; p++)
        n += !same_pixel(&a->vis[p], &b->vis[p]) || memcmp(a->rgba + 4 * p, b->rgba + 4 * p, 4) != 0 ||
             memcmp(&a->depth[p], &b->depth[p], sizeof(float)) != 0 || a->overdraw[p] != b->overdraw[p];
    return n;
}

static bool same_counts(const gdr_frame_stats *a, const gdr_frame_stats *b)
{
    return a->meshlets_visible == b->meshlets_visible && a->raster.sw_clusters == b->raster.sw_clusters &&
           a->raster.hw_clusters == b->raster.hw_clusters && a->raster.sw_triangles == b->raster.sw_triangles &&
           a->raster.hw_triangles == b->raster.hw_triangles && a->raster.overflow == 0 && b->raster.overflow == 0;
}

static void check_frame(const char *spec, gdr_raster raster, int f, uint32_t *taken);

/* Draws `scene` the three ways and compares; adds the tiny path's clusters per class to `taken`.
 * cameras: NULL for the scene's camera, after a first frame from close in front of the field's
 * first row (lod-field: FIELD_NEAR of src/procedural/lod_field_scene.c), whose instance hides much
 * of the field: the second frame's late raster phase draws what it reveals, tiny clusters among
 * them, after the early phase's (each tiny part then has a second dispatch in the frame). */
static void check_scene(const char *spec, const gdr_camera *cameras, gdr_raster raster, uint32_t *taken)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_load_options options = {.no_cache = 1, .no_progress = 1};
    if (gdr_scene_load(spec, &options, &scene, &err) != GDR_OK) {
        fprintf(stderr, "%s: %s\n", spec, err.message);
        CHECK(false);
        return;
    }
    gdr_camera own[2];
    if (!cameras && scene->camera_count > 0) {
        own[0] = own[1] = scene->cameras[0];
        own[0].position = (gdr_vec3){0, 1.5f, -2.5f};
        own[0].rotation = gdr_quat_identity();
        cameras = own;
    }
    CHECK(cameras != NULL);
    const gdr_renderer_debug debugs[3] = {{0}, {.tiny_raster_off = true}, {.tiny_raster_capacity = FORCED_CAPACITY}};
    bool ok = cameras != NULL;
    for (int i = 0; i < 3 && ok; i++)
        ok = render_with(scene, &debugs[i], cameras, raster, results[i]);
    gdr_scene_destroy(scene);
    if (!ok)
        return;
    for (int f = 0; f < 2; f++)
        check_frame(spec, raster, f, taken);
}

/* Frame `f` of the three renderers. */
static void check_frame(const char *spec, gdr_raster raster, int f, uint32_t *taken)
{
    const tiny_result *with = &results[0][f];
    const gdr_raster_stats *tiny = &with->stats.raster, *off = &results[1][f].stats.raster,
                           *forced = &results[2][f].stats.raster;
    const uint32_t *classes = tiny->sw_tiny_class_clusters;
    printf("%s, %s, frame %d: %u compute-rasterised clusters, %u of them tiny (%u/%u/%u of 8/16/32 invocations), "
           "%u mesh-shader; without the tiny path %u tiny; forced to %u entries a class %u tiny\n",
           spec, gdr_raster_name(raster), f, tiny->sw_clusters, tiny->sw_tiny_clusters, classes[0], classes[1],
           classes[2], tiny->hw_clusters, off->sw_tiny_clusters, FORCED_CAPACITY, forced->sw_tiny_clusters);
    uint32_t tiny_sum = 0;
    for (int k = 0; k < GDR_RASTER_TINY_CLASSES; k++) {
        taken[k] += classes[k];
        tiny_sum += classes[k];
        /* The first FORCED_CAPACITY of a class fill its part, the rest go to the front. */
        uint32_t fit = classes[k] < FORCED_CAPACITY ? classes[k] : FORCED_CAPACITY;
        CHECK(forced->sw_tiny_class_clusters[k] == fit);
    }
    CHECK(tiny->sw_tiny_clusters == tiny_sum && tiny_sum > 0 && tiny_sum <= tiny->sw_clusters);
    CHECK(off->sw_tiny_clusters == 0);
    CHECK(forced->sw_tiny_clusters < tiny->sw_tiny_clusters);
    taken[GDR_RASTER_TINY_CLASSES] += forced->sw_tiny_clusters;
    CHECK(same_counts(&with->stats, &results[1][f].stats) && same_counts(&with->stats, &results[2][f].stats));
    CHECK(tiny->sw_clusters + tiny->hw_clusters == with->stats.meshlets_visible);
    for (int i = 1; i < 3; i++) {
        uint32_t n = differing(with, &results[i][f]);
        if (n) {
            fprintf(stderr, "%s, %s, frame %d: the frame %s differs from the tiny path's at %u pixels\n", spec,
                    gdr_raster_name(raster), f, i == 1 ? "without the tiny path" : "with full tiny parts", n);
            CHECK(false);
        }
    }
    uint32_t covered = 0;
    for (int p = 0; p < PIXELS; p++)
        covered += with->vis[p].instance != UINT32_MAX;
    printf("  %u of %u pixels covered; clusters drawn early %u, late %u\n", covered, PIXELS,
           with->stats.occlusion.meshlets_early_drawn, with->stats.occlusion.meshlets_late_drawn);
    taken[GDR_RASTER_TINY_CLASSES + 1] += with->stats.occlusion.meshlets_late_drawn;
    CHECK(covered > PIXELS / 10);
}

int main(void)
{
    /* Per class, then those of the forced-small parts, and the clusters drawn by the late raster
     * phase (a second dispatch of each part in the frame). */
    uint32_t taken[GDR_RASTER_TINY_CLASSES + 2] = {0};
    /* A field of instances from its camera, most of them far: their DAGs' coarse end, roots of 4
     * triangles and the levels just above. */
    check_scene("lod-field:instances=2000,triangles=5000", NULL, GDR_RASTER_SW, taken);
    /* The demo scene from its camera: clusters of every size, in front of each other. */
    check_scene("demo:instances=144,seed=5", NULL, GDR_RASTER_SW, taken);
    check_scene("demo:instances=144,seed=5", NULL, GDR_RASTER_HYBRID, taken);
    for (int k = 0; k < GDR_RASTER_TINY_CLASSES + 2; k++)
        CHECK(taken[k] > 0);
    return test_finish("test_gpu_raster_tiny");
}
