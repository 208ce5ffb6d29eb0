/* A cut that fits the pool (docs/STREAMING.md) on the default device (lavapipe in CI), validation
 * on: `unique-field` written with one group a page, seen from near at a fine threshold, streamed
 * into pools of a half, a quarter and an eighth of the pages that view's full cut needs. In every
 * frame the drawn clusters are the CPU's cut over the groups the renderer reports resident, at the
 * threshold the frame reports it drew with (exactly one cluster on every DAG path: no hole, no
 * crack), and no group the latest read-back cut drew leaves. Within SETTLE_FRAMES frames the
 * resident set is stable: no load, upload, eviction or request and the threshold unchanged for
 * STABLE_FRAMES frames in a row; the settled image is within MIN_PSNR dB of the full-detail image.
 * The camera then moves back to a view the pool holds: the threshold returns to the one asked for and the
 * image becomes the full-detail image of that view, byte for byte. With the threshold held fixed
 * (the behaviour before the cut fitted the pool) the same pool never settles. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "geometry/lod_cut.h"
#include "gpu_test_util.h"
#include "stream/residency.h"

#define WIDTH 160
#define HEIGHT 120
#define SETTLE_FRAMES 90
#define STABLE_FRAMES 30
#define BACK_FRAMES 40
#define UPLOAD_BUDGET (256u << 10)
#define MIN_PSNR 28.0

/* Near the front row, a fine threshold: many pages; and from far, where few pages do. */
static gdr_frame_desc near_frame(void)
{
    return (gdr_frame_desc){.camera = test_look((gdr_vec3){-1.5f, 1.5f, 3.0f}, 0.0f, -0.1f, 1.0f, 0.1f),
                            .pipeline = GDR_PIPELINE_MESH, .cull = GDR_CULL_OFF, .occlusion = GDR_CULL_OFF,
                            .lod_error_px = 0.5f, .record_visible_meshlets = true, .read_back = true};
}

static gdr_frame_desc far_frame(void)
{
    gdr_frame_desc frame = near_frame();
    frame.camera = test_look((gdr_vec3){0.0f, 3.0f, 24.0f}, 0.0f, -0.1f, 1.0f, 0.1f);
    frame.lod_error_px = 2.0f;
    return frame;
}

static gdr_lod_view lod_view(const gdr_scene *scene, uint32_t instance, const gdr_frame_desc *frame, float threshold)
{
    gdr_mat4 projection = gdr_perspective_reverse_z_infinite(frame->camera.yfov, (float)WIDTH / HEIGHT,
                                                             frame->camera.znear);
    return (gdr_lod_view){.transform = scene->instances[instance].transform, .camera_position = frame->camera.position,
                          .projection_y = fabsf(projection.m[5]), .viewport_height = HEIGHT,
                          .znear = frame->camera.znear, .threshold = threshold};
}

/* The pages the full cut of `frame` needs (its groups' pages and their ancestors'), the pinned
 * pages among them. */
static uint32_t pages_needed(const gdr_scene *scene, gdr_paged_cache *cache, const gdr_frame_desc *frame)
{
    uint32_t needed = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
        const gdr_paged_mesh *pm = gdr_paged_cache_mesh(cache, m);
        uint8_t *cut = malloc(c->cluster_count), *page = calloc(pm->page_count, 1), *group = calloc(c->group_count, 1);
        for (uint32_t i = 0; cut && group && i < scene->instance_count; i++) {
            if (scene->instances[i].mesh != m)
                continue;
            gdr_lod_view view = lod_view(scene, i, frame, frame->lod_error_px);
            gdr_lod_cut_select(c, &view, cut);
            for (uint32_t k = 0; k < c->cluster_count; k++)
                group[c->clusters[k].group] |= cut[k];
        }
        for (uint32_t pass = 0; group && pass <= c->dag_depth; pass++)
            for (uint32_t g = 0; g < c->group_count; g++)
                for (uint32_t e = 0; group[g] && e < pm->groups[g].parent_count; e++)
                    group[pm->parents[pm->groups[g].parent_first + e]] = 1;
        for (uint32_t g = 0; page && group && g < c->group_count; g++)
            if (group[g] && !page[pm->groups[g].page])
                page[pm->groups[g].page] = 1, needed++;
        needed += page && !page[0]; /* the coarsest page is pinned: always resident */
        free(cut), free(page), free(group);
    }
    return needed;
}

/* Per group of every mesh: drawn two frames before, resident in the frame before and now. */
typedef struct history {
    size_t *base;
    uint8_t *drawn[2], *resident_before, *resident;
    uint32_t evicted_in_use;
} history;

static void history_init(const gdr_scene *scene, history *h)
{
    h->base = malloc(sizeof *h->base * (scene->mesh_count + 1));
    for (uint32_t m = 0; h->base && m <= scene->mesh_count; m++)
        h->base[m] = m ? h->base[m - 1] + scene->meshes[m - 1].clusters.group_count : 0;
    size_t groups = h->base ? h->base[scene->mesh_count] + 1 : 1;
    h->drawn[0] = calloc(groups, 1), h->drawn[1] = calloc(groups, 1);
    h->resident_before = calloc(groups, 1), h->resident = calloc(groups, 1);
    h->evicted_in_use = 0;
}

static void history_free(history *h)
{
    free(h->base), free(h->drawn[0]), free(h->drawn[1]), free(h->resident_before), free(h->resident);
}

/* One frame: the drawn clusters against the CPU's cut over the resident groups at the threshold the
 * frame drew with; the groups the frame two before drew that were resident and left. */
static bool draw(const gdr_scene *scene, gdr_renderer *r, const gdr_frame_desc *frame, uint8_t *image,
                 gdr_frame_stats *stats, history *h, bool *full)
{
    gdr_error err = {0};
    uint32_t capacity = 1u << 20, count = 0, cursor = 0, wrong = 0;
    gdr_visible_meshlet *drawn = malloc(sizeof *drawn * capacity);
    bool ok = drawn && h->base && gdr_renderer_render(r, frame, 1, stats, &err) == GDR_OK &&
              gdr_renderer_read_color(r, image, &err) == GDR_OK &&
              gdr_renderer_read_visible_meshlets(r, drawn, capacity, &count, &err) == GDR_OK;
    CHECK(ok && stats->validation_messages == 0);
    if (!ok) {
        fprintf(stderr, "render: %s\n", err.message);
        free(drawn);
        return false;
    }
    qsort(drawn, count, sizeof *drawn, compare_visible_meshlets);
    uint8_t *swap = h->resident_before;
    h->resident_before = h->resident, h->resident = swap;
    for (uint32_t m = 0; m < scene->mesh_count; m++)
        ok = ok && gdr_renderer_read_residency(r, m, h->resident + h->base[m], &err) == GDR_OK;
    uint8_t *older = h->drawn[0];
    for (size_t g = 0; g < h->base[scene->mesh_count]; g++) {
        h->evicted_in_use += older[g] && h->resident_before[g] && !h->resident[g];
        older[g] = 0;
    }
    *full = true;
    for (uint32_t i = 0; ok && i < scene->instance_count; i++) {
        uint32_t m = scene->instances[i].mesh;
        const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
        gdr_lod_view view = lod_view(scene, i, frame, stats->streaming.lod_error_px);
        uint8_t *cut = malloc(c->cluster_count), *all = malloc(c->cluster_count);
        if (!cut || !all) {
            wrong++;
        } else {
            gdr_lod_cut_select_resident(c, &view, h->resident + h->base[m], cut);
            view.threshold = frame->lod_error_px;
            gdr_lod_cut_select(c, &view, all);
            *full = *full && memcmp(cut, all, c->cluster_count) == 0;
            for (uint32_t k = 0; k < c->cluster_count; k++) {
                bool on_gpu = cursor < count && drawn[cursor].instance == i && drawn[cursor].meshlet == k;
                cursor += on_gpu;
                wrong += on_gpu != (cut[k] != 0);
                if (on_gpu)
                    older[h->base[m] + c->clusters[k].group] = 1;
            }
        }
        free(cut), free(all);
    }
    h->drawn[0] = h->drawn[1], h->drawn[1] = older;
    free(drawn);
    CHECK(ok && cursor == count && wrong == 0);
    CHECK(stats->streaming.evicted_in_use == 0 && stats->streaming.requests_dropped == 0);
    CHECK(stats->streaming.upload_bytes <= UPLOAD_BUDGET || stats->streaming.uploads == 1);
    return ok && wrong == 0 && cursor == count;
}

static double psnr(const uint8_t *a, const uint8_t *b)
{
    double sum = 0.0;
    for (size_t i = 0; i < (size_t)WIDTH * HEIGHT * 4; i++)
        if (i % 4 != 3)
            sum += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    double mse = sum / ((double)WIDTH * HEIGHT * 3);
    return mse == 0.0 ? INFINITY : 10.0 * log10(255.0 * 255.0 / mse);
}

static gdr_renderer *streamed(const gdr_scene *scene, const char *path, uint64_t budget, bool fixed)
{
    gdr_error err = {0};
    gdr_renderer *r = NULL;
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true};
    gdr_streaming_desc stream = {.cache = gpu_test_paged_cache(path), .geometry_budget_bytes = budget,
                                 .upload_budget_bytes = UPLOAD_BUDGET, .wait_for_loads = true,
                                 .fixed_lod_error = fixed};
    if (gdr_renderer_create(&desc, &r, &err) != GDR_OK ||
        gdr_renderer_set_scene_streamed(r, scene, &stream, &err) != GDR_OK) {
        fprintf(stderr, "streamed renderer: %s\n", err.message);
        gdr_renderer_destroy(r);
        return NULL;
    }
    return r;
}

/* The near view in a pool of `slots`: the frame from which STABLE_FRAMES frames in a row changed
 * nothing (UINT32_MAX: none within SETTLE_FRAMES), its image into `image`. */
static uint32_t settle(const gdr_scene *scene, gdr_renderer *r, uint8_t *image, gdr_frame_stats *stats, history *h,
                       uint32_t *partial)
{
    gdr_frame_desc frame = near_frame();
    uint32_t quiet = 0, settled = UINT32_MAX;
    float threshold = -1.0f;
    bool full;
    for (uint32_t f = 0; f < SETTLE_FRAMES + STABLE_FRAMES && draw(scene, r, &frame, image, stats, h, &full); f++) {
        const gdr_streaming_stats *s = &stats->streaming;
        bool still = s->loads == 0 && s->uploads == 0 && s->evictions == 0 && s->requests == 0 && s->pending == 0 &&
                     s->lod_error_px == threshold;
        threshold = s->lod_error_px;
        quiet = still ? quiet + 1 : 0;
        *partial += !full;
        if (getenv("GDR_TEST_VERBOSE"))
            printf("  frame %u: threshold %g, %u wanted / %u slots, %u requests, %u loads, %u evictions, settled %u\n",
                   f, (double)s->lod_error_px, s->wanted_pages, s->slot_count, s->requests, s->loads, s->evictions,
                   s->settled_frames);
        if (quiet == STABLE_FRAMES) {
            settled = f + 1 - STABLE_FRAMES;
            break;
        }
    }
    return settled;
}

/* Back to the far view, which the pool holds: the threshold asked for and the full image again. */
static void move_back(const gdr_scene *scene, gdr_renderer *r, const uint8_t *far_reference, history *h)
{
    gdr_frame_desc frame = far_frame();
    uint8_t *image = malloc(WIDTH * HEIGHT * 4);
    gdr_frame_stats stats = {0};
    uint32_t same_from = UINT32_MAX;
    bool full = false;
    for (uint32_t f = 0; image && f < BACK_FRAMES && draw(scene, r, &frame, image, &stats, h, &full); f++) {
        bool same = full && stats.streaming.lod_error_px == frame.lod_error_px &&
                    memcmp(image, far_reference, WIDTH * HEIGHT * 4) == 0;
        same_from = !same ? UINT32_MAX : same_from == UINT32_MAX ? f : same_from;
    }
    printf("  back to the far view: threshold %g (asked %g), the full-detail image from frame %u of %u\n",
           (double)stats.streaming.lod_error_px, (double)frame.lod_error_px, same_from, BACK_FRAMES);
    CHECK(same_from < BACK_FRAMES && stats.streaming.lod_error_scale == 1.0f);
    free(image);
}

static void pool_fraction(const gdr_scene *scene, const char *path, uint32_t needed, uint32_t pinned, uint64_t slot,
                          uint32_t divisor, const uint8_t *near_reference, const uint8_t *far_reference)
{
    /* A fraction of the pages beyond the pinned ones, which every pool holds. */
    uint32_t slots = pinned + (needed - pinned) / divisor;
    gdr_renderer *r = streamed(scene, path, (uint64_t)slots * slot, false);
    CHECK(r != NULL);
    uint8_t *image = malloc(WIDTH * HEIGHT * 4);
    gdr_frame_stats stats = {0};
    history h;
    history_init(scene, &h);
    uint32_t partial = 0, settled = r && image ? settle(scene, r, image, &stats, &h, &partial) : UINT32_MAX;
    const gdr_streaming_stats *s = &stats.streaming;
    double quality = image ? psnr(image, near_reference) : 0.0;
    printf("pool 1/%u of the view's %u pages (%u slots, %u pinned): settled from frame %u (stable %u frames), "
           "threshold %g (x %g, %u changes), %u pages wanted, %llu uploads and %llu evictions in all, PSNR %.2f dB "
           "against full detail\n", divisor, needed, s->slot_count, pinned, settled, s->settled_frames,
           (double)s->lod_error_px, (double)s->lod_error_scale, s->lod_error_changes, s->wanted_pages,
           (unsigned long long)s->uploads_total, (unsigned long long)s->evictions_total, quality);
    CHECK(settled < SETTLE_FRAMES && s->settled_frames >= STABLE_FRAMES);
    CHECK(s->wanted_pages <= s->slot_count && s->lod_error_scale > 1.0f);
    CHECK(quality >= MIN_PSNR);
    if (r && image)
        move_back(scene, r, far_reference, &h);
    CHECK(h.evicted_in_use == 0);
    history_free(&h);
    free(image);
    gdr_renderer_destroy(r);
}

/* The same pool with the threshold held: pages drawn two frames ago are evicted and reloaded, and the
 * resident set never settles. */
static void fixed_threshold(const gdr_scene *scene, const char *path, uint32_t needed, uint32_t pinned, uint64_t slot)
{
    uint32_t slots = pinned + (needed - pinned) / 4;
    gdr_renderer *r = streamed(scene, path, (uint64_t)slots * slot, true);
    uint8_t *image = malloc(WIDTH * HEIGHT * 4);
    gdr_frame_stats stats = {0};
    history h;
    history_init(scene, &h);
    uint32_t partial = 0, settled = r && image ? settle(scene, r, image, &stats, &h, &partial) : 0;
    printf("threshold held, pool 1/4: settled from frame %u, %llu uploads and %llu evictions in %u frames\n", settled,
           (unsigned long long)stats.streaming.uploads_total, (unsigned long long)stats.streaming.evictions_total,
           SETTLE_FRAMES + STABLE_FRAMES);
    CHECK(r && settled == UINT32_MAX && stats.streaming.evictions_total > stats.streaming.slot_count);
    history_free(&h);
    free(image);
    gdr_renderer_destroy(r);
}

static void run(const gdr_scene *scene, const char *path)
{
    uint8_t *near_reference = malloc(WIDTH * HEIGHT * 4), *far_reference = malloc(WIDTH * HEIGHT * 4);
    gdr_renderer *whole = gpu_test_renderer(WIDTH, HEIGHT, scene);
    gdr_error err = {0};
    gdr_frame_stats stats;
    gdr_frame_desc frames[2] = {near_frame(), far_frame()};
    uint8_t *images[2] = {near_reference, far_reference};
    for (int i = 0; i < 2; i++)
        CHECK(whole && images[i] && gdr_renderer_render(whole, &frames[i], 1, &stats, &err) == GDR_OK &&
              gdr_renderer_read_color(whole, images[i], &err) == GDR_OK);
    gdr_renderer_destroy(whole);
    gdr_paged_cache *cache = gpu_test_paged_cache(path);
    CHECK(cache != NULL);
    uint32_t pinned = scene->mesh_count, needed = cache ? pages_needed(scene, cache, &frames[0]) : 0;
    uint32_t far_needed = cache ? pages_needed(scene, cache, &frames[1]) : 0;
    uint64_t slot = 0;
    for (uint32_t m = 0; cache && m < gdr_paged_cache_mesh_count(cache); m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(cache, m)->page_count; p++) {
            uint64_t bytes = gdr_page_pool_bytes(&gdr_paged_cache_mesh(cache, m)->pages[p]);
            slot = bytes > slot ? bytes : slot;
        }
    slot = (slot + 255) & ~(uint64_t)255;
    printf("the near view needs %u pages, the far one %u (%u pinned)\n", needed, far_needed, pinned);
    /* Each pool must hold the far view (the camera moves back to it) and be below the near one's. */
    CHECK(far_needed <= pinned + (needed - pinned) / 8);
    for (uint32_t divisor = 2; cache && divisor <= 8; divisor *= 2)
        pool_fraction(scene, path, needed, pinned, slot, divisor, near_reference, far_reference);
    if (cache)
        fixed_threshold(scene, path, needed, pinned, slot);
    free(near_reference), free(far_reference);
}

int main(void)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load("unique-field:meshes=12,triangles=20000,seed=3", &load, &scene, &err) == GDR_OK);
    char path[256];
    const char *tmp = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/gdr_gpu_streaming_pressure_%ld.gdrc", tmp ? tmp : "/tmp", (long)getpid());
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_MIN}; /* a group a page */
    CHECK(scene && gdr_scene_quantize_vertices(scene, &err) == GDR_OK);
    CHECK(scene && gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    if (scene)
        run(scene, path);
    gpu_test_close_paged_caches();
    unlink(path);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_streaming_pressure");
}
