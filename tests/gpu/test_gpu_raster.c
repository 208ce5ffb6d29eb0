/* Hybrid rasterisation on the default device (lavapipe in CI), validation on:
 *  - coverage rules: crafted triangles (edges through pixel centres, vertices on pixel centres, a
 *    fan around a sample, a jittered mesh with edges at every slope, slivers, sub-pixel triangles,
 *    back faces) are covered by the compute rasteriser exactly as by the hardware, pixel for pixel,
 *    and every pixel of a tiled region exactly once by each;
 *  - real scenes (the demo scene, a glTF file, a dense LOD scene): --raster sw, hw and hybrid name
 *    the same triangle at every pixel of the visibility buffer and give the same image up to a few
 *    pixels (MAX_RASTER_DIFFERENCE, justified there); culling on and off give the same image;
 *  - depth: the resolve writes the depth the hardware depth test leaves (bit for bit on the
 *    mesh-shader path, within a few ulps on the compute path);
 *  - the fallback: without 64-bit atomics the default is forward rendering and asking for the
 *    visibility buffer is a clear error. */
#include <math.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gpu_test_util.h"
#include "render/visbuffer.h"

#define WIDTH 192
#define HEIGHT 108
#define PIXELS (WIDTH * HEIGHT)
#define PI_F 3.14159265f

/* The compute rasteriser snaps the vertices the mesh shader also computes, but the two may round a
 * vertex's viewport transform differently (the hardware's own order of operations, a multiply by
 * 1/w); a vertex landing on the other side of a 1/256-pixel rounding boundary moves its edges by a
 * sub-pixel step, which changes the coverage of a pixel centre lying within that step of an edge:
 * about one pixel in 256 along such an edge. Measured on lavapipe: 0 on the crafted triangles, a
 * handful on real scenes at 192x108 (the number printed). A systematic error (a wrong rule, a
 * half-pixel offset, a missing edge) changes hundreds. */
#define MAX_RASTER_DIFFERENCE 12
/* Relative difference allowed between the compute rasteriser's depth and the hardware's at a pixel
 * both give to the same triangle: both interpolate the same plane in float, in different orders. */
#define DEPTH_TOLERANCE 2e-6f

static gdr_renderer *renderer;

typedef struct frame_result {
    uint8_t rgba[PIXELS * 4];
    gdr_visbuffer_pixel vis[PIXELS];
    float depth[PIXELS];
    gdr_frame_stats stats;
} frame_result;

static frame_result result_a, result_b, result_c, result_d;

/* Renders one frame and reads back the image, the depth and (visibility-buffer modes) the pixels. */
static bool render(const gdr_frame_desc *desc, gdr_raster raster, frame_result *out)
{
    gdr_error err = {0};
    gdr_frame_desc frame = *desc;
    frame.raster = raster;
    frame.read_back = true;
    bool ok = gdr_renderer_render(renderer, &frame, 1, &out->stats, &err) == GDR_OK &&
              gdr_renderer_read_color(renderer, out->rgba, &err) == GDR_OK &&
              gdr_visbuffer_read_depth(renderer, out->depth, &err) == GDR_OK &&
              (raster == GDR_RASTER_FORWARD || gdr_visbuffer_read_pixels(renderer, out->vis, &err) == GDR_OK);
    if (!ok)
        fprintf(stderr, "render (%s): %s\n", gdr_raster_name(raster), err.message);
    return ok;
}

static bool same_triangle(const gdr_visbuffer_pixel *a, const gdr_visbuffer_pixel *b)
{
    return a->instance == b->instance && (a->instance == UINT32_MAX ||
                                          (a->meshlet == b->meshlet && a->triangle == b->triangle));
}

static uint32_t differing_triangles(const frame_result *a, const frame_result *b)
{
    uint32_t n = 0;
    for (int p = 0; p < PIXELS; p++)
        n += !same_triangle(&a->vis[p], &b->vis[p]);
    return n;
}

static uint32_t differing_pixels(const frame_result *a, const frame_result *b)
{
    uint32_t n = 0;
    for (int p = 0; p < PIXELS; p++)
        n += memcmp(a->rgba + 4 * p, b->rgba + 4 * p, 4) != 0;
    return n;
}

/* --- real scenes ------------------------------------------------------------------------------ */

static void check_camera(const gdr_frame_desc *base, const char *what)
{
    frame_result *forward = &result_a, *hw = &result_b, *sw = &result_c, *hybrid = &result_d;
    /* Forward and hw without occlusion history (the last frame saw another camera), so that their
     * cluster statistics can be compared. */
    gdr_frame_desc fresh = *base;
    fresh.occlusion_camera_cut = true;
    if (!render(&fresh, GDR_RASTER_FORWARD, forward) || !render(&fresh, GDR_RASTER_HW, hw) ||
        !render(base, GDR_RASTER_SW, sw)) {
        CHECK(false);
        return;
    }
    CHECK(hw->stats.raster.mode == GDR_RASTER_HW && hw->stats.raster.sw_clusters == 0);
    CHECK(sw->stats.raster.mode == GDR_RASTER_SW && sw->stats.raster.overflow == 0);
    /* The forward path tests clusters in the task shader, the visibility-buffer paths in the
     * cluster-cull compute pass: the same tests (shared/cluster_cull.h), the same decisions. */
    const gdr_frame_stats *f = &forward->stats, *h = &hw->stats;
    CHECK(f->meshlets_tested == h->meshlets_tested && f->meshlets_visible == h->meshlets_visible &&
          f->meshlets_frustum_culled == h->meshlets_frustum_culled &&
          f->meshlets_cone_culled == h->meshlets_cone_culled && f->lod.meshlets_culled == h->lod.meshlets_culled);
    if (f->meshlets_visible != h->meshlets_visible)
        fprintf(stderr, "%s: forward tested %u visible %u frustum %u cone %u lod %u; hw tested %u visible %u frustum "
                "%u cone %u lod %u\n", what, f->meshlets_tested, f->meshlets_visible, f->meshlets_frustum_culled,
                f->meshlets_cone_culled, f->lod.meshlets_culled, h->meshlets_tested, h->meshlets_visible,
                h->meshlets_frustum_culled, h->meshlets_cone_culled, h->lod.meshlets_culled);
    CHECK(h->raster.hw_clusters == h->meshlets_visible);
    CHECK(sw->stats.raster.sw_clusters + sw->stats.raster.hw_clusters == sw->stats.meshlets_visible);

    /* The mesh-shader path stores gl_FragCoord.z: the depth buffer of the forward path, bit for
     * bit, wherever either drew (a tie between two triangles has one depth either way). */
    uint32_t depth_mismatch = 0, sw_depth_far = 0, compared = 0;
    for (int p = 0; p < PIXELS; p++)
        depth_mismatch += memcmp(&forward->depth[p], &hw->depth[p], sizeof(float)) != 0;
    /* The compute path: the same depth within DEPTH_TOLERANCE where it names the same triangle. */
    for (int p = 0; p < PIXELS; p++) {
        if (hw->vis[p].instance == UINT32_MAX || !same_triangle(&hw->vis[p], &sw->vis[p]))
            continue;
        compared++;
        sw_depth_far += fabsf(sw->depth[p] - hw->depth[p]) > DEPTH_TOLERANCE * hw->depth[p];
    }
    uint32_t sw_vs_hw = differing_triangles(sw, hw), sw_images = differing_pixels(sw, hw);
    printf("%s: sw vs hw: %u pixels name another triangle, %u differ in colour; %u of %u depths beyond "
           "tolerance; compute clusters %u of %u\n", what, sw_vs_hw, sw_images, sw_depth_far, compared,
           sw->stats.raster.sw_clusters, sw->stats.raster.sw_clusters + sw->stats.raster.hw_clusters);
    if (depth_mismatch) {
        fprintf(stderr, "%s: resolve depth differs from the hardware depth buffer at %u pixels\n", what, depth_mismatch);
        CHECK(false);
    }
    CHECK(sw_vs_hw <= MAX_RASTER_DIFFERENCE);
    CHECK(sw_images <= MAX_RASTER_DIFFERENCE);
    CHECK(sw_depth_far <= MAX_RASTER_DIFFERENCE);

    /* Hybrid, with the clusters split between the two: the same picture. */
    gdr_frame_desc frame = *base;
    frame.sw_threshold_px = 3.0f;
    if (!render(&frame, GDR_RASTER_HYBRID, hybrid)) {
        CHECK(false);
        return;
    }
    uint32_t hybrid_vs_hw = differing_triangles(hybrid, hw), hybrid_images = differing_pixels(hybrid, hw);
    printf("%s: hybrid (3 px: %u compute, %u mesh-shader clusters) vs hw: %u pixels name another triangle, %u differ "
           "in colour\n", what, hybrid->stats.raster.sw_clusters, hybrid->stats.raster.hw_clusters, hybrid_vs_hw,
           hybrid_images);
    CHECK(hybrid_vs_hw <= MAX_RASTER_DIFFERENCE);
    CHECK(hybrid_images <= MAX_RASTER_DIFFERENCE);

    /* Culling off at every level: the same picture on this path too. */
    frame.cull = GDR_CULL_OFF;
    if (!render(&frame, GDR_RASTER_HYBRID, sw)) {
        CHECK(false);
        return;
    }
    uint32_t culling = differing_pixels(sw, hybrid);
    if (culling) {
        fprintf(stderr, "%s: culling changed %u pixels of the hybrid image\n", what, culling);
        CHECK(false);
    }
}

static gdr_scene *load(const char *spec)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_load_options options = {.no_cache = 1, .no_progress = 1};
    if (gdr_scene_load(spec, &options, &scene, &err) != GDR_OK) {
        fprintf(stderr, "%s: %s\n", spec, err.message);
        CHECK(false);
        return NULL;
    }
    return scene;
}

static void check_demo(void)
{
    gdr_scene *scene = load("demo:instances=144,seed=5");
    renderer = scene ? gpu_test_renderer(WIDTH, HEIGHT, scene) : NULL;
    if (!renderer) {
        CHECK(false);
        gdr_scene_destroy(scene);
        return;
    }
    gdr_frame_desc frame = {.camera = scene->cameras[0]};
    check_camera(&frame, "demo camera 0");
    unsigned rng = 99;
    char what[64];
    for (int n = 0; n < 3; n++) {
        frame.camera = test_look((gdr_vec3){test_random_range(&rng, -20, 20), test_random_range(&rng, 0.5f, 8),
                                       test_random_range(&rng, -20, 20)},
                            test_random_range(&rng, -PI_F, PI_F), test_random_range(&rng, -0.6f, 0.1f), 1.0f, 0.05f);
        snprintf(what, sizeof what, "demo random camera %d", n);
        check_camera(&frame, what);
    }
    gdr_renderer_destroy(renderer);
    renderer = NULL;

    /* No 64-bit atomics: the default draws forward and says why; asking for the visibility buffer
     * is a clear error. */
    gdr_error err = {0};
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true, .disable_visibility_buffer = true};
    CHECK(gdr_renderer_create(&desc, &renderer, &err) == GDR_OK);
    CHECK(renderer && gdr_renderer_set_scene(renderer, scene, &err) == GDR_OK);
    if (renderer) {
        frame = (gdr_frame_desc){.camera = scene->cameras[0]};
        gdr_frame_stats stats;
        CHECK(gdr_renderer_render(renderer, &frame, 1, &stats, &err) == GDR_OK);
        CHECK(stats.raster.mode == GDR_RASTER_FORWARD && strstr(stats.raster.reason, "no visibility buffer"));
        frame.raster = GDR_RASTER_SW;
        CHECK_FAILS(gdr_renderer_render(renderer, &frame, 1, &stats, &err), err, GDR_ERROR_UNSUPPORTED);
        frame.raster = GDR_RASTER_HYBRID;
        frame.pipeline = GDR_PIPELINE_INDIRECT;
        CHECK_FAILS(gdr_renderer_render(renderer, &frame, 1, &stats, &err), err, GDR_ERROR_INVALID_ARGUMENT);
        CHECK(stats.validation_messages == 0);
        gdr_renderer_destroy(renderer);
        renderer = NULL;
    }
    gdr_scene_destroy(scene);
}

static void check_gltf(void)
{
    gdr_scene *scene = load("/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb");
    renderer = scene ? gpu_test_renderer(WIDTH, HEIGHT, scene) : NULL;
    if (!renderer) {
        CHECK(false);
        gdr_scene_destroy(scene);
        return;
    }
    gdr_camera framing = gdr_scene_framing_camera(scene);
    gdr_frame_desc frame = {.camera = framing};
    check_camera(&frame, "2CylinderEngine framing camera");
    /* Closer, from the side. */
    gdr_vec3 forward = gdr_quat_rotate(framing.rotation, (gdr_vec3){0, 0, -1});
    float distance = gdr_vec3_length(framing.position);
    frame.camera.position = gdr_vec3_add(framing.position, gdr_vec3_scale(forward, 0.4f * distance));
    check_camera(&frame, "2CylinderEngine closer");
    gdr_renderer_destroy(renderer);
    renderer = NULL;
    gdr_scene_destroy(scene);
}

static void check_lod(void)
{
    gdr_scene *scene = load("lod-field:instances=12,triangles=20000");
    renderer = scene ? gpu_test_renderer(WIDTH, HEIGHT, scene) : NULL;
    if (!renderer) {
        CHECK(false);
        gdr_scene_destroy(scene);
        return;
    }
    gdr_frame_desc frame = {.camera = scene->cameras[0], .lod_error_px = 1.0f};
    check_camera(&frame, "lod-field, LOD cut at 1 px");
    gdr_renderer_destroy(renderer);
    renderer = NULL;
    gdr_scene_destroy(scene);
}

/* --- coverage rules on crafted triangles ------------------------------------------------------ */

#define CRAFT_SIZE 64

typedef struct crafted {
    gdr_vec3 *positions;
    uint32_t *indices;
    uint32_t vertex_count, index_count;
} crafted;

/* A vertex at framebuffer position (x, y) (pixels, y down) on the plane z = -8 in front of a camera
 * at the origin with a square view of tan(yfov / 2) = 1/4: NDC = world x, y / 2. Far enough that
 * every cluster's sphere lies beyond the near plane, so --raster sw draws every cluster. */
static uint32_t craft_vertex(crafted *c, float x, float y)
{
    float half = 0.5f * CRAFT_SIZE;
    c->positions[c->vertex_count] = (gdr_vec3){2.0f * (x - half) / half, 2.0f * (half - y) / half, -8.0f};
    return c->vertex_count++;
}

/* Counter-clockwise as seen: front-facing. */
static void craft_triangle(crafted *c, uint32_t a, uint32_t b, uint32_t d)
{
    c->indices[c->index_count++] = a;
    c->indices[c->index_count++] = b;
    c->indices[c->index_count++] = d;
}

/* Sub-pixel positions on the 1/256 grid. */
static float snap(float v)
{
    return roundf(v * 256.0f) / 256.0f;
}

static void craft_scene(crafted *c, uint32_t *tiled_lo, uint32_t *tiled_hi)
{
    /* 1. A grid of 4-pixel squares with corners on pixel centres, split along alternating
     *    diagonals: horizontal, vertical and diagonal edges through rows of samples.
     *    As seen with y down, a b / d e; counter-clockwise as seen is a, d, e (y down flips it). */
    for (int j = 0; j < 6; j++)
        for (int i = 0; i < 6; i++) {
            float x = 4.5f + 4.0f * (float)i, y = 4.5f + 4.0f * (float)j;
            uint32_t a = craft_vertex(c, x, y), b = craft_vertex(c, x + 4, y);
            uint32_t d = craft_vertex(c, x, y + 4), e = craft_vertex(c, x + 4, y + 4);
            if ((i + j) % 2) {
                craft_triangle(c, a, d, e);
                craft_triangle(c, a, e, b);
            } else {
                craft_triangle(c, a, d, b);
                craft_triangle(c, b, d, e);
            }
        }
    tiled_lo[0] = 5, tiled_lo[1] = 5, tiled_hi[0] = 27, tiled_hi[1] = 27; /* pixels strictly inside */
    /* 2. A fan of 8 triangles around a vertex on a pixel centre. */
    uint32_t centre = craft_vertex(c, 44.5f, 12.5f), ring[8];
    const float dx[8] = {6, 6, 0, -6, -6, -6, 0, 6}, dy[8] = {0, -6, -6, -6, 0, 6, 6, 6};
    for (int k = 0; k < 8; k++)
        ring[k] = craft_vertex(c, 44.5f + dx[k], 12.5f + dy[k]);
    for (int k = 0; k < 8; k++) /* ring runs counter-clockwise as seen (y down: dy < 0 is up) */
        craft_triangle(c, centre, ring[k], ring[(k + 1) % 8]);
    /* 3. A jittered grid of 3-pixel cells, anywhere between the sub-pixel positions (both
     *    rasterisers must snap them alike): shared edges at every slope. */
    unsigned rng = 7;
    uint32_t grid[8][8];
    for (int j = 0; j < 8; j++)
        for (int i = 0; i < 8; i++)
            grid[j][i] = craft_vertex(c, 36.0f + 3.0f * (float)i + test_random_range(&rng, -0.9f, 0.9f),
                                      30.0f + 3.0f * (float)j + test_random_range(&rng, -0.9f, 0.9f));
    for (int j = 0; j < 7; j++)
        for (int i = 0; i < 7; i++) {
            craft_triangle(c, grid[j][i], grid[j + 1][i], grid[j + 1][i + 1]);
            craft_triangle(c, grid[j][i], grid[j + 1][i + 1], grid[j][i + 1]);
        }
    /* 4. Slivers and sub-pixel triangles, each in a 4x4 cell of its own, and back faces. */
    for (int k = 0; k < 24; k++) {
        float x = 4.0f + 4.0f * (float)(k % 6), y = 34.0f + 4.0f * (float)(k / 6);
        float ax = snap(x + test_random_range(&rng, 0, 3)), ay = snap(y + test_random_range(&rng, 0, 3));
        float bx = snap(x + test_random_range(&rng, 0, 3)), by = snap(y + test_random_range(&rng, 0, 3));
        float ex = snap(k % 3 ? x + test_random_range(&rng, 0, 3) : ax + 0.01f);
        float ey = snap(k % 3 ? y + test_random_range(&rng, 0, 3) : by + 0.02f);
        uint32_t a = craft_vertex(c, ax, ay), b = craft_vertex(c, bx, by), e = craft_vertex(c, ex, ey);
        /* Either winding: the back-facing ones must vanish in both rasterisers. */
        if (k % 2)
            craft_triangle(c, a, b, e);
        else
            craft_triangle(c, a, e, b);
    }
}

static void check_crafted(void)
{
    crafted c = {malloc(sizeof(gdr_vec3) * 1024), malloc(sizeof(uint32_t) * 3072), 0, 0};
    uint32_t lo[2], hi[2];
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    uint32_t mesh = 0;
    bool ok = c.positions && c.indices && gdr_scene_create(&scene, &err) == GDR_OK;
    if (ok) {
        craft_scene(&c, lo, hi);
        ok = gdr_scene_add_mesh(scene, "crafted", c.positions, NULL, NULL, c.vertex_count, c.indices, c.index_count,
                                &mesh, &err) == GDR_OK;
    }
    gdr_instance instance = {.transform = gdr_mat4_identity(), .mesh = mesh, .material = GDR_NO_INDEX,
                             .color = {0.8f, 0.8f, 0.8f, 1.0f}};
    ok = ok && gdr_scene_add_instance(scene, &instance, &err) == GDR_OK &&
         gdr_scene_build_clusters(scene, NULL, &err) == GDR_OK;
    gdr_renderer_desc desc = {.width = CRAFT_SIZE, .height = CRAFT_SIZE, .validate = true};
    ok = ok && gdr_renderer_create(&desc, &renderer, &err) == GDR_OK &&
         gdr_renderer_set_scene(renderer, scene, &err) == GDR_OK;
    if (!ok) {
        fprintf(stderr, "crafted scene: %s\n", err.message);
        CHECK(false);
    }
    gdr_frame_desc frame = {.camera = {.rotation = gdr_quat_identity(), .yfov = 2.0f * atanf(0.25f), .znear = 0.1f},
                            .view = GDR_VIEW_MODE_OVERDRAW, .read_back = true};
    const size_t n = CRAFT_SIZE * CRAFT_SIZE;
    gdr_visbuffer_pixel *vis[2] = {malloc(sizeof(gdr_visbuffer_pixel) * n), malloc(sizeof(gdr_visbuffer_pixel) * n)};
    uint32_t *counts[2] = {malloc(sizeof(uint32_t) * n), malloc(sizeof(uint32_t) * n)};
    const gdr_raster modes[2] = {GDR_RASTER_HW, GDR_RASTER_SW};
    for (int m = 0; ok && m < 2; m++) {
        gdr_frame_stats stats;
        frame.raster = modes[m];
        ok = vis[m] && counts[m] && gdr_renderer_render(renderer, &frame, 1, &stats, &err) == GDR_OK &&
             gdr_visbuffer_read_pixels(renderer, vis[m], &err) == GDR_OK &&
             gdr_visbuffer_read_overdraw(renderer, counts[m], &err) == GDR_OK;
        CHECK(ok && stats.validation_messages == 0);
        CHECK(!ok || (m == 0 ? stats.raster.sw_clusters == 0 : stats.raster.hw_clusters == 0));
    }
    if (ok) {
        uint32_t differing = 0, twice = 0, holes = 0, covered = 0;
        for (size_t p = 0; p < n; p++) {
            differing += !same_triangle(&vis[0][p], &vis[1][p]);
            covered += vis[0][p].instance != UINT32_MAX;
            twice += (counts[0][p] > 1) + (counts[1][p] > 1);
            uint32_t x = (uint32_t)(p % CRAFT_SIZE), y = (uint32_t)(p / CRAFT_SIZE);
            if (x >= lo[0] && x <= hi[0] && y >= lo[1] && y <= hi[1])
                holes += (counts[0][p] != 1) + (counts[1][p] != 1);
        }
        printf("crafted triangles: %u pixels covered, %u differ between hw and sw, %u covered twice, %u holes\n",
               covered, differing, twice, holes);
        CHECK(covered > 700);
        CHECK(differing == 0);
        CHECK(twice == 0);
        CHECK(holes == 0);
    }
    for (int m = 0; m < 2; m++) {
        free(vis[m]);
        free(counts[m]);
    }
    gdr_renderer_destroy(renderer);
    renderer = NULL;
    gdr_scene_destroy(scene);
    free(c.positions);
    free(c.indices);
}

int main(void)
{
    check_crafted();
    check_demo();
    check_gltf();
    check_lod();
    return test_finish("test_gpu_raster");
}
