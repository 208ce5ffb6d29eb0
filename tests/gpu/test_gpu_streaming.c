/* Streaming in the renderer (docs/STREAMING.md) on the default device (lavapipe in CI), validation
 * on: `unique-field` written with one group a page, drawn at 1 px by a renderer whose page pool holds
 * one slot more than the view that needs most, fewer than the three views' pages together (the sets
 * computed, not only their sizes) and at most a tenth of the pages' bytes, and copies at most 256 KiB
 * a frame. The scene (20 meshes of 40,000 triangles) is chosen so that those premises hold, and
 * the test checks them. Along still views and a path, every
 * frame's drawn clusters are the CPU's cut over the groups the renderer reports resident (exactly
 * one cluster on every DAG path: no hole, no crack), the pool stays within the budget, each frame's
 * uploads within theirs, no page in use is evicted, and each still view converges to the image of
 * the scene uploaded whole, pixel for pixel. A budget large enough for everything gives that image
 * with no eviction; a page damaged on disk is refused by name and its group stays absent while the
 * frames go on with coarser geometry, and so are the pages of a file cut short while it streams.
 * The scene is quantized (as gdr build --pages writes it) and the small pool streams it as read
 * for streaming, without its geometry. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "geometry/lod_cut.h"
#include "gpu_test_util.h"
#include "render/renderer_debug.h"
#include "stream/residency.h"
#include "io/io_internal.h"
#include "io/loaders.h"

#define WIDTH 160
#define HEIGHT 120
#define FRAMES 40
#define VIEWS 3
#define UPLOAD_BUDGET (256u << 10)

typedef struct frame_check {
    bool full;          /* the cut is the fully resident one */
    uint32_t drawn;     /* clusters */
    uint32_t absent;    /* groups absent in the frame */
    /* Per group of every mesh (mesh m's from the sum of the earlier meshes' counts): drawn in the
     * frame two before this one and in the one before, resident in the one before and in this one.
     * A frame plans its evictions with the cut of the frame two before it (the latest it has read
     * back): a group drawn then and resident in the frame before must not have left. */
    uint8_t *drawn_before[2], *resident_before, *resident;
    uint32_t evicted_in_use;
} frame_check;

static void history_init(const gdr_scene *scene, frame_check *check)
{
    size_t groups = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++)
        groups += scene->meshes[m].clusters.group_count;
    *check = (frame_check){.drawn_before = {calloc(groups + 1, 1), calloc(groups + 1, 1)},
                           .resident_before = calloc(groups + 1, 1), .resident = calloc(groups + 1, 1)};
}

static void history_free(frame_check *check)
{
    free(check->drawn_before[0]), free(check->drawn_before[1]), free(check->resident_before), free(check->resident);
}

static gdr_frame_desc view_frame(int v)
{
    /* The field from far, then nearer its left and its right columns
     * (the field: 4 columns 3 apart, the front row at z = -4). */
    static const gdr_vec3 positions[VIEWS] = {{0.0f, 3.0f, 20.0f}, {-4.5f, 2.0f, 8.0f}, {4.5f, 2.0f, 8.0f}};
    static const float yaws[VIEWS] = {0.0f, 0.0f, 0.0f};
    return (gdr_frame_desc){.camera = test_look(positions[v], yaws[v], -0.1f, 1.0f, 0.1f),
                            .pipeline = GDR_PIPELINE_MESH, .cull = GDR_CULL_OFF, .occlusion = GDR_CULL_OFF,
                            .lod_error_px = 1.0f, .record_visible_meshlets = true, .read_back = true};
}

/* The pages of every mesh numbered one after another: mesh m's from base[m], base[mesh_count] in
 * all. NULL where the allocation fails. */
static uint32_t *page_bases(const gdr_paged_cache *cache)
{
    uint32_t meshes = gdr_paged_cache_mesh_count(cache);
    uint32_t *base = malloc(sizeof *base * (meshes + 1));
    for (uint32_t m = 0; base && m <= meshes; m++)
        base[m] = m ? base[m - 1] + gdr_paged_cache_mesh(cache, m - 1)->page_count : 0;
    return base;
}

/* The pool slots a view's full cut needs, marked in `set` (indexed as page_bases numbers the pages):
 * the pages of the groups its clusters belong to, and the pages of those groups' ancestors (the
 * closure). Returns how many it marked that were not marked before. */
static uint32_t mark_view_pages(const gdr_scene *scene, const gdr_paged_cache *cache, const uint32_t *base,
                                const gdr_frame_desc *frame, uint8_t *set)
{
    gdr_mat4 projection = gdr_perspective_reverse_z_infinite(frame->camera.yfov, (float)WIDTH / HEIGHT,
                                                             frame->camera.znear);
    uint32_t added = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
        const gdr_paged_mesh *pm = gdr_paged_cache_mesh(cache, m);
        uint8_t *cut = malloc(c->cluster_count), *group = calloc(c->group_count, 1);
        for (uint32_t i = 0; cut && group && i < scene->instance_count; i++) {
            if (scene->instances[i].mesh != m)
                continue;
            gdr_lod_view view = {.transform = scene->instances[i].transform, .camera_position = frame->camera.position,
                                 .projection_y = fabsf(projection.m[5]), .viewport_height = HEIGHT,
                                 .znear = frame->camera.znear, .threshold = frame->lod_error_px};
            gdr_lod_cut_select(c, &view, cut);
            for (uint32_t k = 0; k < c->cluster_count; k++)
                if (cut[k])
                    group[c->clusters[k].group] = 1;
        }
        /* Parents are deeper groups: walking from the finest depth up closes the set. */
        for (uint32_t pass = 0; group && pass <= c->dag_depth; pass++)
            for (uint32_t g = 0; g < c->group_count; g++)
                for (uint32_t e = 0; group[g] && e < pm->groups[g].parent_count; e++)
                    group[pm->parents[pm->groups[g].parent_first + e]] = 1;
        for (uint32_t g = 0; group && g < c->group_count; g++)
            if (group[g] && !set[base[m] + pm->groups[g].page]) {
                set[base[m] + pm->groups[g].page] = 1;
                added++;
            }
        free(cut), free(group);
    }
    return added;
}

/* The pool's slots: one more than the view that needs most, provided the three views' pages
 * together need more than that (so the still views must evict) and the pool is at most a tenth of
 * the pages' bytes. 0 where the scene does not meet those premises. */
static uint32_t pool_slots(const gdr_scene *scene, const char *path, uint64_t slot, uint64_t total)
{
    gdr_paged_cache *cache = NULL;
    gdr_error err = {0};
    if (gdr_paged_cache_open(path, &cache, &err) != GDR_OK)
        return 0;
    uint32_t *base = page_bases(cache);
    uint32_t pages = base ? base[gdr_paged_cache_mesh_count(cache)] : 0;
    uint8_t *all = calloc(pages + 1, 1), *one = calloc(pages + 1, 1);
    uint32_t most = 0, together = 0;
    for (int v = 0; base && all && one && v < VIEWS; v++) {
        gdr_frame_desc frame = view_frame(v);
        memset(one, 0, pages);
        uint32_t needed = mark_view_pages(scene, cache, base, &frame, one);
        for (uint32_t p = 0; p < pages; p++)
            together += one[p] && !all[p], all[p] |= one[p];
        printf("view %d needs %u slots\n", v, needed);
        most = needed > most ? needed : most;
    }
    printf("the three views together need %u slots of %u pages; the pool has %u\n", together, pages, most + 1);
    free(all), free(one), free(base);
    gdr_paged_cache_close(cache);
    CHECK(most + 1 < together && (most + 1) * slot <= total / 10);
    return most + 1 < together && (most + 1) * slot <= total / 10 ? most + 1 : 0;
}

/* One frame: its image, and its drawn clusters against the CPU's cut over the groups the renderer
 * reports resident for that frame. */
static bool draw(const gdr_scene *scene, gdr_renderer *r, const gdr_frame_desc *frame, uint8_t *image,
                 gdr_frame_stats *stats, frame_check *out)
{
    gdr_error err = {0};
    uint32_t capacity = 1u << 20, count = 0;
    gdr_visible_meshlet *drawn = malloc(sizeof *drawn * capacity);
    bool ok = drawn && gdr_renderer_render(r, frame, 1, stats, &err) == GDR_OK &&
              gdr_renderer_read_color(r, image, &err) == GDR_OK &&
              gdr_renderer_read_visible_meshlets(r, drawn, capacity, &count, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "render: %s\n", err.message);
    CHECK(ok && stats->validation_messages == 0);
    if (!ok) {
        free(drawn);
        return false;
    }
    qsort(drawn, count, sizeof *drawn, compare_visible_meshlets);
    gdr_mat4 projection = gdr_perspective_reverse_z_infinite(frame->camera.yfov, (float)WIDTH / HEIGHT,
                                                             frame->camera.znear);
    uint32_t cursor = 0, wrong = 0;
    /* The threshold the frame drew with: the pool may have raised it (a cut that fits the pool). */
    float threshold = stats->streaming.enabled ? stats->streaming.lod_error_px : frame->lod_error_px;
    if (threshold != frame->lod_error_px)
        printf("frame drawn at threshold %g (x %g), %u pages wanted, %u slots\n", (double)threshold,
               (double)stats->streaming.lod_error_scale, stats->streaming.wanted_pages, stats->streaming.slot_count);
    out->full = true, out->drawn = count, out->absent = 0;
    size_t *base = malloc(sizeof *base * (scene->mesh_count + 1));
    for (uint32_t m = 0; base && m <= scene->mesh_count; m++)
        base[m] = m ? base[m - 1] + scene->meshes[m - 1].clusters.group_count : 0;
    uint8_t *swap = out->resident_before;
    out->resident_before = out->resident;
    out->resident = swap;
    for (uint32_t m = 0; base && out->resident && m < scene->mesh_count; m++)
        ok = ok && gdr_renderer_read_residency(r, m, out->resident + base[m], &err) == GDR_OK;
    uint8_t *older = out->drawn_before[0];
    for (size_t g = 0; base && older && g < base[scene->mesh_count]; g++) {
        out->evicted_in_use += older[g] && out->resident_before[g] && !out->resident[g];
        older[g] = 0;
    }
    for (uint32_t i = 0; ok && base && older && i < scene->instance_count; i++) {
        uint32_t m = scene->instances[i].mesh;
        const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
        gdr_lod_view view = {.transform = scene->instances[i].transform, .camera_position = frame->camera.position,
                             .projection_y = fabsf(projection.m[5]), .viewport_height = HEIGHT,
                             .znear = frame->camera.znear, .threshold = threshold};
        uint8_t *resident = out->resident + base[m], *cut = malloc(c->cluster_count), *all = malloc(c->cluster_count);
        if (cut && all) {
            for (uint32_t g = 0; g < c->group_count; g++)
                out->absent += !resident[g];
            gdr_lod_cut_select_resident(c, &view, resident, cut);
            gdr_lod_cut_select(c, &view, all);
            out->full = out->full && memcmp(cut, all, c->cluster_count) == 0;
            for (uint32_t k = 0; k < c->cluster_count; k++) {
                bool on_gpu = cursor < count && drawn[cursor].instance == i && drawn[cursor].meshlet == k;
                cursor += on_gpu;
                wrong += on_gpu != (cut[k] != 0);
                if (on_gpu)
                    older[base[m] + c->clusters[k].group] = 1;
            }
        } else {
            wrong++;
        }
        free(cut), free(all);
    }
    /* This frame's drawn groups become the newer history entry. */
    out->drawn_before[0] = out->drawn_before[1];
    out->drawn_before[1] = older;
    free(base);
    free(drawn);
    CHECK(cursor == count && wrong == 0);
    return wrong == 0 && cursor == count;
}

/* The frame's streaming figures against the budgets and the eviction rule. */
static void check_budgets(const gdr_frame_stats *stats, uint64_t budget)
{
    const gdr_streaming_stats *s = &stats->streaming;
    CHECK(s->enabled && s->pool_bytes <= budget && s->resident_bytes <= s->pool_bytes);
    CHECK(s->upload_bytes <= UPLOAD_BUDGET || s->uploads == 1);
    CHECK(s->evicted_in_use == 0);
    CHECK(stats->streaming.requests_dropped == 0);
}

/* Twenty frames of `frame` from a renderer whose cache was damaged: each within the budgets, each
 * cut checked against the history (started here; the caller frees it), the last one's figures in
 * *stats. Stops at the first frame that fails. */
static void draw_after_damage(const gdr_scene *scene, gdr_renderer *r, const gdr_frame_desc *frame, uint64_t budget,
                              gdr_frame_stats *stats, frame_check *check)
{
    uint8_t *image = malloc(WIDTH * HEIGHT * 4);
    history_init(scene, check);
    for (uint32_t i = 0; r && image && i < 20 && draw(scene, r, frame, image, stats, check); i++)
        check_budgets(stats, budget);
    free(image);
}

/* The pool bytes of every page together; *slot receives a slot's size (the largest page's, rounded
 * up to 256 bytes as the residency does). */
static uint64_t pool_bytes(const char *path, uint64_t *slot)
{
    gdr_paged_cache *cache = NULL;
    gdr_error err = {0};
    uint64_t total = 0, largest = 0;
    if (gdr_paged_cache_open(path, &cache, &err) != GDR_OK)
        return 0;
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(cache); m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(cache, m)->page_count; p++) {
            uint64_t bytes = gdr_page_pool_bytes(&gdr_paged_cache_mesh(cache, m)->pages[p]);
            total += bytes;
            largest = bytes > largest ? bytes : largest;
        }
    gdr_paged_cache_close(cache);
    *slot = (largest + 255) & ~(uint64_t)255;
    return total;
}

/* A renderer streaming `scene` from the cache at `path` within `budget` bytes. The records of the
 * clusters of absent groups are poisoned (renderer_debug.h): a shader reading one would draw it, and
 * the drawn clusters would differ from the CPU's cut. */
static gdr_renderer *streamed_renderer(const gdr_scene *scene, const char *path, uint64_t budget)
{
    gdr_error err = {0};
    gdr_renderer *r = NULL;
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true};
    gdr_streaming_desc stream = {.cache = gpu_test_paged_cache(path), .geometry_budget_bytes = budget,
                                 .upload_budget_bytes = UPLOAD_BUDGET, .wait_for_loads = true};
    if (gdr_renderer_create(&desc, &r, &err) == GDR_OK)
        gdr_renderer_set_debug(r, &(gdr_renderer_debug){.poison_absent_records = true});
    if (!r || gdr_renderer_set_scene_streamed(r, scene, &stream, &err) != GDR_OK) {
        fprintf(stderr, "streamed renderer: %s\n", err.message);
        gdr_renderer_destroy(r);
        return NULL;
    }
    return r;
}

/* Still views one after another, FRAMES frames each: every frame checked, each view converging to
 * its reference image. Returns the evictions. */
static uint64_t still_views(const gdr_scene *scene, gdr_renderer *r, uint64_t budget, const uint8_t *reference,
                            const char *what)
{
    uint8_t *image = malloc(WIDTH * HEIGHT * 4);
    gdr_frame_stats stats = {0};
    frame_check check;
    history_init(scene, &check);
    for (int v = 0; image && v < VIEWS; v++) {
        gdr_frame_desc frame = view_frame(v);
        uint32_t converged = UINT32_MAX, partial = 0;
        for (uint32_t f = 0; f < FRAMES && draw(scene, r, &frame, image, &stats, &check); f++) {
            check_budgets(&stats, budget);
            partial += !check.full;
            bool same = check.full && memcmp(image, reference + (size_t)v * WIDTH * HEIGHT * 4, WIDTH * HEIGHT * 4) == 0;
            converged = !same ? UINT32_MAX : converged == UINT32_MAX ? f : converged;
        }
        printf("%s, view %d: pool %llu bytes (%u slots), %llu pages uploaded and %llu evicted so far, %u frames "
               "not the full cut, the image the whole upload's from frame %u of %u; last frame %u requests, %u "
               "resident pages, %u groups absent\n", what, v, (unsigned long long)stats.streaming.pool_bytes,
               stats.streaming.slot_count, (unsigned long long)stats.streaming.uploads_total,
               (unsigned long long)stats.streaming.evictions_total, partial, converged, FRAMES,
               stats.streaming.requests, stats.streaming.resident_pages, check.absent);
        CHECK(converged < FRAMES && stats.streaming.requests == 0);
    }
    CHECK(check.evicted_in_use == 0);
    history_free(&check);
    free(image);
    return stats.streaming.evictions_total;
}

/* A camera path once around the field, looking at it: every frame checked. */
static void camera_path(const gdr_scene *scene, gdr_renderer *r, uint64_t budget)
{
    uint8_t *image = malloc(WIDTH * HEIGHT * 4);
    gdr_frame_stats stats = {0};
    frame_check check;
    history_init(scene, &check);
    uint32_t partial = 0;
    for (uint32_t f = 0; image && f < 30; f++) {
        float t = (float)f / 29.0f, angle = 6.2832f * t;
        gdr_frame_desc frame = view_frame(0);
        frame.camera = test_look((gdr_vec3){14.0f * sinf(angle), 2.5f, -7.0f + 14.0f * cosf(angle)}, angle, -0.1f,
                                 1.0f, 0.1f);
        if (!draw(scene, r, &frame, image, &stats, &check))
            break;
        check_budgets(&stats, budget);
        partial += !check.full;
        if (getenv("GDR_TEST_VERBOSE"))
            printf("path frame %u: %u drawn, %u requests (%u distinct), %u loads, %u uploads, %u evictions, %u deferred, "
                   "%u groups used, %u resident\n", f, check.drawn, stats.streaming.requests,
                   stats.streaming.distinct_requests, stats.streaming.loads, stats.streaming.uploads,
                   stats.streaming.evictions, stats.streaming.deferred, stats.streaming.groups_used,
                   stats.streaming.resident_pages);
    }
    printf("path: 30 frames around the field, %u not the full cut, %llu pages uploaded and %llu evicted in all\n",
           partial, (unsigned long long)stats.streaming.uploads_total,
           (unsigned long long)stats.streaming.evictions_total);
    CHECK(check.evicted_in_use == 0 && stats.streaming.evictions_total > 0);
    history_free(&check);
    free(image);
}

/* The finest group of mesh m that a frame's full cut draws (over all of the mesh's instances), or
 * UINT32_MAX where it draws none. */
static uint32_t finest_drawn_group(const gdr_scene *scene, uint32_t m, const gdr_frame_desc *frame)
{
    gdr_mat4 projection = gdr_perspective_reverse_z_infinite(frame->camera.yfov, (float)WIDTH / HEIGHT,
                                                             frame->camera.znear);
    const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
    uint8_t *cut = malloc(c->cluster_count);
    uint32_t group = UINT32_MAX;
    for (uint32_t i = 0; cut && i < scene->instance_count; i++) {
        if (scene->instances[i].mesh != m)
            continue;
        gdr_lod_view view = {.transform = scene->instances[i].transform, .camera_position = frame->camera.position,
                             .projection_y = fabsf(projection.m[5]), .viewport_height = HEIGHT,
                             .znear = frame->camera.znear, .threshold = frame->lod_error_px};
        gdr_lod_cut_select(c, &view, cut);
        for (uint32_t k = 0; k < c->cluster_count; k++)
            if (cut[k] && (group == UINT32_MAX || c->groups[c->clusters[k].group].depth < c->groups[group].depth))
                group = c->clusters[k].group;
    }
    free(cut);
    return group;
}

/* A byte of a page view 0's full cut needs flipped on disk (the page of the finest group view 0
 * draws of the first mesh where that page is not the pinned page 0): refused by name, its group
 * stays absent, every frame's cut stays exact. */
static void damaged_page(const gdr_scene *scene, const gdr_scene *paged, const char *path, uint64_t budget)
{
    gdr_paged_cache *cache = NULL;
    gdr_error err = {0};
    CHECK(gdr_paged_cache_open(path, &cache, &err) == GDR_OK);
    if (!cache)
        return;
    gdr_frame_desc frame = view_frame(0);
    uint32_t mesh = 0, group = UINT32_MAX, page = 0;
    for (uint32_t m = 0; page == 0 && m < scene->mesh_count; m++) {
        mesh = m;
        group = finest_drawn_group(scene, m, &frame);
        page = group == UINT32_MAX ? 0 : gdr_paged_cache_mesh(cache, m)->groups[group].page;
    }
    const gdr_paged_mesh *pm = gdr_paged_cache_mesh(cache, mesh);
    const gdr_mesh_clusters *c = &scene->meshes[mesh].clusters;
    uint64_t offset = pm->pages[page].offset + pm->pages[page].stored_size / 2;
    gdr_paged_cache_close(cache);
    CHECK(group != UINT32_MAX && page != 0);
    if (group == UINT32_MAX || page == 0)
        return;
    FILE *f = fopen(path, "r+b");
    int byte = EOF;
    if (f && fseek(f, (long)offset, SEEK_SET) == 0 && (byte = fgetc(f)) != EOF && fseek(f, (long)offset, SEEK_SET) == 0)
        fputc(byte ^ 0x5a, f);
    CHECK(f && byte != EOF);
    if (f)
        fclose(f);

    gdr_renderer *r = streamed_renderer(paged, path, budget);
    CHECK(r != NULL);
    uint8_t *resident = malloc(c->group_count);
    gdr_frame_stats stats = {0};
    frame_check check;
    draw_after_damage(scene, r, &frame, budget, &stats, &check);
    char expected[64];
    snprintf(expected, sizeof expected, "mesh %u page %u", mesh, page);
    printf("damaged page %u of mesh %u (group %u): %u refused, \"%s\"\n", page, mesh, group,
           stats.streaming.pages_refused, stats.streaming.refused);
    CHECK(stats.streaming.pages_refused >= 1 && strstr(stats.streaming.refused, path) &&
          strstr(stats.streaming.refused, expected));
    CHECK(r && resident && gdr_renderer_read_residency(r, mesh, resident, &err) == GDR_OK && !resident[group]);
    CHECK(!check.full && check.drawn > 0 && check.evicted_in_use == 0);
    history_free(&check);
    free(resident);
    gdr_renderer_destroy(r);
}

/* The bytes of the file at `path` (*size of them), or NULL. */
static uint8_t *read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    uint8_t *data = NULL;
    long n = f && fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    if (n > 0 && fseek(f, 0, SEEK_SET) == 0 && (data = malloc((size_t)n)) && fread(data, 1, (size_t)n, f) != (size_t)n) {
        free(data);
        data = NULL;
    }
    if (f)
        fclose(f);
    *size = data ? (size_t)n : 0;
    return data;
}

/* The table entry of section `id` in a cache's bytes (docs/CACHE_FORMAT.md: 32-byte entries at 64). */
static uint8_t *section_entry(uint8_t *data, const char *id)
{
    uint32_t count;
    memcpy(&count, data + 16, 4);
    for (uint32_t i = 0; i < count; i++)
        if (memcmp(data + 64 + 32 * (size_t)i, id, 4) == 0)
            return data + 64 + 32 * (size_t)i;
    return NULL;
}

/* Section 'CLGR' of the cache `from` written over that of `to`, of the same size, with every checksum
 * made right: `to`'s pages with `from`'s account of the clusters' refined groups. */
static int splice_groups(const char *from, const char *to)
{
    size_t a_size = 0, b_size = 0;
    uint8_t *a = read_file(from, &a_size), *b = read_file(to, &b_size);
    uint8_t *ea = a ? section_entry(a, "CLGR") : NULL, *eb = b ? section_entry(b, "CLGR") : NULL;
    uint64_t a_at = 0, b_at = 0, a_bytes = 0, b_bytes = 0;
    if (ea && eb) {
        memcpy(&a_at, ea + 8, 8), memcpy(&a_bytes, ea + 16, 8);
        memcpy(&b_at, eb + 8, 8), memcpy(&b_bytes, eb + 16, 8);
    }
    int ok = ea && eb && a_bytes == b_bytes && memcmp(a + a_at, b + b_at, a_bytes) != 0;
    if (ok) {
        memcpy(b + b_at, a + a_at, a_bytes);
        uint64_t h = gdr_io_hash(b + b_at, b_bytes);
        memcpy(eb + 24, &h, 8);
        uint32_t count;
        memcpy(&count, b + 16, 4);
        h = gdr_io_hash(b + 64, 32 * (size_t)count);
        memcpy(b + 32, &h, 8);
        h = gdr_io_hash(b, 40);
        memcpy(b + 40, &h, 8);
        FILE *f = fopen(to, "wb");
        ok = f && fwrite(b, 1, b_size, f) == b_size;
        if (f)
            fclose(f);
    }
    free(a), free(b);
    return ok;
}

/* A group of mesh m that view 0's cut loads (a parent of the finest group it draws, made from it)
 * outside page 0, with a refined group that at least two of its clusters were made from: *cluster
 * the first of them. UINT32_MAX when there is none. */
static uint32_t group_with_shared_refinement(const gdr_scene *scene, gdr_paged_cache *cache, uint32_t m,
                                             uint32_t *cluster)
{
    gdr_frame_desc frame = view_frame(0);
    const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
    const gdr_paged_mesh *pm = gdr_paged_cache_mesh(cache, m);
    uint32_t finest = finest_drawn_group(scene, m, &frame);
    if (finest == UINT32_MAX)
        return UINT32_MAX;
    for (uint32_t e = 0; e < pm->groups[finest].parent_count; e++) {
        uint32_t p = pm->parents[pm->groups[finest].parent_first + e];
        const gdr_cluster_group *g = &c->groups[p];
        for (uint32_t i = g->first_cluster; pm->groups[p].page != 0 && i < g->first_cluster + g->cluster_count; i++)
            for (uint32_t j = i + 1; j < g->first_cluster + g->cluster_count; j++)
                if (c->clusters[i].refined_group != GDR_NO_INDEX &&
                    c->clusters[i].refined_group == c->clusters[j].refined_group) {
                    *cluster = i;
                    return p;
                }
    }
    return UINT32_MAX;
}

static gdr_scene *read_for_streaming(const char *path);

/* The cluster records of a streamed scene live in the record pool: room for the largest page's
 * records beside each pool slot, so they follow the pool, not the scene (before, a record per
 * cluster of the scene). The statistics also time the set-up's steps. */
static void check_record_pool(const gdr_scene *scene, gdr_renderer *r, const char *path)
{
    gdr_paged_cache *cache = NULL;
    gdr_error err = {0};
    uint32_t largest = 0;
    uint64_t clusters = 0;
    CHECK(gdr_paged_cache_open(path, &cache, &err) == GDR_OK);
    for (uint32_t m = 0; cache && m < gdr_paged_cache_mesh_count(cache); m++) {
        const gdr_paged_mesh *pm = gdr_paged_cache_mesh(cache, m);
        for (uint32_t p = 0; p < pm->page_count; p++)
            largest = pm->pages[p].cluster_count > largest ? pm->pages[p].cluster_count : largest;
        clusters += scene->meshes[m].clusters.cluster_count;
    }
    gdr_paged_cache_close(cache);
    gdr_frame_desc frame = view_frame(0);
    gdr_frame_stats stats = {0};
    CHECK(gdr_renderer_render(r, &frame, 1, &stats, &err) == GDR_OK);
    const gdr_streaming_stats *st = &stats.streaming;
    printf("record pool: %llu bytes for %u slots of %u records (the scene's %llu clusters: %llu bytes)\n",
           (unsigned long long)st->cluster_record_bytes, st->slot_count, largest, (unsigned long long)clusters,
           (unsigned long long)(clusters * 128u)); /* 128 bytes a record (GdrGpuMeshlet) */
    CHECK(st->cluster_record_bytes == (uint64_t)st->slot_count * largest * 128u);
    CHECK(st->cluster_record_bytes < clusters * 128u);
    /* The set-up's steps were timed, each a part of what it took. */
    printf("set-up: open %.2f ms, scene %.2f ms, node counts %.2f ms, first pages %.2f ms\n", st->setup_open_ms,
           st->setup_scene_ms, st->setup_node_counts_ms, st->setup_first_pages_ms);
    CHECK(st->setup_open_ms > 0.0 && st->setup_scene_ms > 0.0 && st->setup_node_counts_ms > 0.0 &&
          st->setup_first_pages_ms > 0.0 && st->setup_first_pages_ms < 60e3);
}

/* A page whose records disagree with the file's account of its clusters ('CLGR'), every checksum
 * right: one cluster of a group view 0 loads written as made from nothing in the pages alone. The
 * page is refused naming the file, the mesh and the page; the frames go on drawing exact cuts. */
static void damaged_records(gdr_scene *scene, const char *path, uint64_t budget)
{
    gdr_paged_cache *cache = NULL;
    gdr_error err = {0};
    CHECK(gdr_paged_cache_open(path, &cache, &err) == GDR_OK);
    uint32_t mesh = 0, group = UINT32_MAX, cluster = 0, page = 0;
    for (uint32_t m = 0; cache && group == UINT32_MAX && m < scene->mesh_count; m++) {
        mesh = m;
        group = group_with_shared_refinement(scene, cache, m, &cluster);
        page = group == UINT32_MAX ? 0 : gdr_paged_cache_mesh(cache, m)->groups[group].page;
    }
    gdr_paged_cache_close(cache);
    CHECK(group != UINT32_MAX && page != 0);
    if (group == UINT32_MAX)
        return;
    char copy[300];
    snprintf(copy, sizeof copy, "%s.records.gdrc", path);
    gdr_cluster *k = &scene->meshes[mesh].clusters.clusters[cluster];
    uint32_t refined = k->refined_group;
    k->refined_group = GDR_NO_INDEX;
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_MIN};
    CHECK(gdr_cache_write(copy, scene, &write, &err) == GDR_OK);
    k->refined_group = refined;
    CHECK(splice_groups(path, copy));

    gdr_scene *paged = read_for_streaming(copy);
    gdr_renderer *r = paged ? streamed_renderer(paged, copy, budget) : NULL;
    CHECK(r != NULL);
    gdr_frame_desc frame = view_frame(0);
    gdr_frame_stats stats = {0};
    frame_check check;
    draw_after_damage(scene, r, &frame, budget, &stats, &check);
    char expected[64];
    snprintf(expected, sizeof expected, "mesh %u page %u: ", mesh, page);
    printf("damaged records in page %u of mesh %u (group %u, cluster %u): %u refused, \"%s\"\n", page, mesh, group,
           cluster, stats.streaming.pages_refused, stats.streaming.refused);
    CHECK(stats.streaming.pages_refused >= 1 && strstr(stats.streaming.refused, copy) &&
          strstr(stats.streaming.refused, expected) && strstr(stats.streaming.refused, "refined groups"));
    CHECK(check.drawn > 0 && check.evicted_in_use == 0);
    history_free(&check);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(paged);
    unlink(copy);
}

/* The file cut short while the renderer streams from it (after the open, before the views load
 * their pages): the pages past the end are refused, naming the file and the page, and the frames go
 * on drawing the exact cut over what is resident. Works on a copy of the cache. */
static void truncated_while_streaming(const gdr_scene *scene, const gdr_scene *paged, const char *path,
                                      uint64_t budget)
{
    char copy[300];
    snprintf(copy, sizeof copy, "%s.cut.gdrc", path);
    FILE *in = fopen(path, "rb"), *out = fopen(copy, "wb");
    char buffer[65536];
    size_t n;
    while (in && out && (n = fread(buffer, 1, sizeof buffer, in)) > 0)
        CHECK(fwrite(buffer, 1, n, out) == n);
    long size = out ? ftell(out) : 0;
    if (in)
        fclose(in);
    if (out)
        fclose(out);
    gdr_renderer *r = streamed_renderer(paged, copy, budget);
    CHECK(r != NULL && size > 0);
    /* The last pages hold the finest groups: half of the page data goes. */
    CHECK(r && truncate(copy, size - size / 8) == 0);
    gdr_frame_stats stats = {0};
    frame_check check;
    gdr_frame_desc frame = view_frame(1);
    draw_after_damage(scene, r, &frame, budget, &stats, &check);
    printf("file cut short while streaming: %u pages refused, \"%s\"\n", stats.streaming.pages_refused,
           stats.streaming.refused);
    CHECK(stats.streaming.pages_refused >= 1 && strstr(stats.streaming.refused, copy) &&
          strstr(stats.streaming.refused, " page "));
    CHECK(check.drawn > 0 && check.evicted_in_use == 0);
    history_free(&check);
    gdr_renderer_destroy(r);
    unlink(copy);
}

/* The cache read for streaming: what the open reads (a small share of the file), and a scene that
 * the whole-upload path and the cache writer refuse. */
static gdr_scene *read_for_streaming(const char *path)
{
    gdr_scene *paged = NULL;
    gdr_error err = {0};
    uint64_t bytes_read = 0, file_size = 0;
    FILE *f = fopen(path, "rb");
    if (f && fseek(f, 0, SEEK_END) == 0)
        file_size = (uint64_t)ftell(f);
    if (f)
        fclose(f);
    CHECK(gdr_cache_read_for_streaming(path, NULL, &paged, NULL, &bytes_read, &err) == GDR_OK && paged &&
          paged->geometry_in_pages && paged->meshes[0].positions == NULL && paged->meshes[0].clusters.triangles == NULL);
    /* No cluster record is read (the pages hold them): the scene has none, and the bytes read are
     * fewer than its records alone would take (72 bytes a cluster in CLDT). */
    uint64_t clusters = 0, with_records = 0;
    for (uint32_t m = 0; paged && m < paged->mesh_count; m++) {
        clusters += paged->meshes[m].clusters.cluster_count;
        with_records += paged->meshes[m].clusters.clusters != NULL;
    }
    printf("read for streaming: %llu of the file's %llu bytes, %llu clusters, %llu meshes with their records\n",
           (unsigned long long)bytes_read, (unsigned long long)file_size, (unsigned long long)clusters,
           (unsigned long long)with_records);
    CHECK(bytes_read > 0 && bytes_read < file_size / 8);
    CHECK(clusters > 0 && with_records == 0 && bytes_read < 72 * clusters);
    gdr_renderer *whole = NULL;
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true};
    CHECK(paged && gdr_renderer_create(&desc, &whole, &err) == GDR_OK);
    if (paged && whole)
        CHECK_FAILS(gdr_renderer_set_scene(whole, paged, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    gdr_renderer_destroy(whole);
    char copy[300];
    snprintf(copy, sizeof copy, "%s.copy", path);
    CHECK(paged && gdr_cache_write(copy, paged, NULL, &err) == GDR_ERROR_INVALID_ARGUMENT && access(copy, F_OK) != 0);
    return paged;
}

static void run(gdr_scene *scene, const char *path)
{
    uint8_t *reference = malloc(VIEWS * WIDTH * HEIGHT * 4);
    gdr_renderer *whole = gpu_test_renderer(WIDTH, HEIGHT, scene);
    CHECK(whole && reference);
    gdr_frame_stats stats;
    frame_check check;
    history_init(scene, &check);
    for (int v = 0; whole && reference && v < VIEWS; v++) {
        gdr_frame_desc frame = view_frame(v);
        CHECK(draw(scene, whole, &frame, reference + (size_t)v * WIDTH * HEIGHT * 4, &stats, &check) && check.full);
    }
    history_free(&check);
    gdr_renderer_destroy(whole);

    /* A pool one slot larger than the view that needs most (at most a tenth of the pages): each view
     * fits, the three together do not (pool_slots checks both), so the still views evict. */
    uint64_t slot = 0, total = pool_bytes(path, &slot);
    uint64_t budget = pool_slots(scene, path, slot, total) * slot;
    /* The small pool streams a scene read without its geometry; the run with room for everything streams
     * the whole scene. */
    gdr_scene *paged = read_for_streaming(path);
    gdr_renderer *r = paged && budget ? streamed_renderer(paged, path, budget) : NULL;
    CHECK(r && total > 0 && budget > 0);
    if (r && reference) {
        uint64_t evictions = still_views(scene, r, budget, reference, "small pool");
        CHECK(evictions > 0); /* the views need more than the pool holds */
        camera_path(scene, r, budget);
        check_record_pool(scene, r, path);
    }
    gdr_renderer_destroy(r);

    /* Room for everything: the same images, nothing evicted; the scene read without its records too. */
    r = streamed_renderer(scene, path, 2 * total);
    CHECK(r != NULL);
    if (r && reference)
        CHECK(still_views(scene, r, 2 * total, reference, "everything") == 0);
    gdr_renderer_destroy(r);
    r = paged ? streamed_renderer(paged, path, 2 * total) : NULL;
    CHECK(r != NULL);
    if (r && reference)
        CHECK(still_views(scene, r, 2 * total, reference, "everything, without the records") == 0);
    gdr_renderer_destroy(r);

    /* A budget below the coarsest pages is refused. */
    gdr_renderer *small = NULL;
    gdr_error err = {0};
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true};
    gdr_streaming_desc tiny = {.cache = gpu_test_paged_cache(path), .geometry_budget_bytes = 1024};
    CHECK(gdr_renderer_create(&desc, &small, &err) == GDR_OK &&
          gdr_renderer_set_scene_streamed(small, scene, &tiny, &err) == GDR_ERROR_CAPACITY);
    printf("a 1 KiB budget: %s\n", err.message);
    gdr_renderer_destroy(small);

    if (paged && budget)
        damaged_records(scene, path, budget);
    if (paged && budget)
        truncated_while_streaming(scene, paged, path, budget);
    if (paged && budget)
        damaged_page(scene, paged, path, budget);
    gdr_scene_destroy(paged);
    free(reference);
}

int main(void)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load("unique-field:meshes=20,triangles=40000,seed=3", &load, &scene, &err) == GDR_OK);
    char path[256];
    const char *tmp = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/gdr_gpu_streaming_%ld.gdrc", tmp ? tmp : "/tmp", (long)getpid());
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_MIN}; /* a group a page */
    /* Quantized, as gdr build --pages writes it: the pages decode to the scene's own vertices. */
    CHECK(scene && gdr_scene_quantize_vertices(scene, &err) == GDR_OK);
    CHECK(scene && gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    if (scene)
        run(scene, path);
    unlink(path);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_streaming");
}
