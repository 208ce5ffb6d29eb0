/* The streaming loop with the GPU in it (docs/STREAMING.md), on the default device (lavapipe in
 * CI), validation on: `unique-field` written with one group a page, a residency pool of a quarter
 * of its pages' bytes and 64 KiB of loads a frame. Each frame the residency (gdr_residency) plans
 * the loads the GPU's requests of the frame before asked for, the loader thread reads them, the
 * page table is updated, and the frame is drawn: every frame's drawn clusters are the CPU's cut
 * over the resident groups (so no hole, no crack), and the frames converge to the image of the
 * scene with every group resident, pixel for pixel. The geometry itself is still uploaded whole:
 * the page pool buffer is not built yet. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "geometry/lod_cut.h"
#include "gpu_test_util.h"
#include "stream/page_loader.h"
#include "stream/residency.h"

#define WIDTH 160
#define HEIGHT 120
#define FRAMES 40
#define VIEWS 3

typedef struct loop {
    const gdr_scene *scene;
    gdr_renderer *renderer;
    gdr_paged_cache *cache;
    gdr_residency *res;
    gdr_page_loader *loader;
    gdr_stream_request *requests; /* the last frame's, read back */
    uint32_t request_count;
    gdr_visible_meshlet *drawn;   /* the last frame's clusters: its page use */
    uint32_t drawn_count, capacity;
} loop;

/* The page table from the residency: resident groups and each node's absent refined count. */
static bool upload_residency(loop *l)
{
    gdr_error err = {0};
    bool ok = true;
    for (uint32_t m = 0; m < l->scene->mesh_count && ok; m++) {
        const gdr_mesh_clusters *c = &l->scene->meshes[m].clusters;
        uint8_t *resident = malloc(c->group_count);
        uint32_t *absent = malloc(sizeof *absent * c->lod_node_count);
        ok = resident && absent;
        for (uint32_t g = 0; ok && g < c->group_count; g++)
            resident[g] = (uint8_t)gdr_residency_group_resident(l->res, m, g);
        if (ok)
            gdr_lod_nodes_count_absent_refined(c, resident, absent);
        ok = ok && gdr_renderer_debug_set_residency(l->renderer, m, resident, absent, &err) == GDR_OK;
        free(resident);
        free(absent);
    }
    if (!ok)
        fprintf(stderr, "residency: %s\n", err.message);
    return ok;
}

/* The last frame's read-back into the residency (page use, requests), this frame's loads through
 * the loader thread, then the page table. */
static bool stream(loop *l, uint32_t frame, uint32_t *loads_out, uint32_t *evictions_out)
{
    for (uint32_t i = 0; frame && i < l->drawn_count; i++) {
        uint32_t mesh = l->scene->instances[l->drawn[i].instance].mesh;
        uint32_t group = l->scene->meshes[mesh].clusters.clusters[l->drawn[i].meshlet].group;
        gdr_residency_mark_used(l->res, frame - 1, mesh, gdr_paged_cache_mesh(l->cache, mesh)->groups[group].page);
    }
    gdr_stream_load loads[256];
    uint32_t count = 0;
    gdr_residency_plan(l->res, frame, l->requests, l->request_count, loads, 256, &count);
    gdr_error err = {0};
    CHECK(gdr_page_loader_submit(l->loader, loads, count, &err) == GDR_OK);
    gdr_page_result result;
    while (gdr_page_loader_collect(l->loader, 1, &result, 1) == 1) {
        CHECK(result.status == GDR_OK);
        gdr_residency_loaded(l->res, result.load.mesh, result.load.page);
        gdr_page_free(&result.page);
    }
    gdr_residency_stats st = gdr_residency_get_stats(l->res);
    CHECK(st.evicted_in_use == 0);
    *loads_out = count;
    *evictions_out += st.evictions;
    return upload_residency(l);
}

/* Draws the frame; checks its clusters against the CPU's resident cut; reads its requests back.
 * *full: the cut is the fully resident one. */
static bool draw(loop *l, const gdr_frame_desc *frame, uint8_t *image, bool *full)
{
    gdr_error err = {0};
    gdr_frame_stats stats;
    gdr_frame_desc f = *frame;
    f.record_visible_meshlets = f.read_back = true;
    gdr_group_request *gpu = malloc(sizeof *gpu * 4096);
    uint32_t count = 0, dropped = 0;
    bool ok = gpu && gdr_renderer_render(l->renderer, &f, 1, &stats, &err) == GDR_OK &&
              gdr_renderer_read_color(l->renderer, image, &err) == GDR_OK &&
              gdr_renderer_read_visible_meshlets(l->renderer, l->drawn, l->capacity, &l->drawn_count, &err) == GDR_OK &&
              gdr_renderer_read_group_requests(l->renderer, gpu, 4096, &count, &dropped, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "render: %s\n", err.message);
    CHECK(ok && stats.validation_messages == 0 && dropped == 0);
    qsort(l->drawn, l->drawn_count, sizeof *l->drawn, compare_visible_meshlets);
    for (uint32_t q = 0; q < count; q++)
        l->requests[q] = (gdr_stream_request){gpu[q].mesh, gpu[q].group, gpu[q].priority};
    l->request_count = count;
    free(gpu);
    gdr_mat4 projection = gdr_perspective_reverse_z_infinite(frame->camera.yfov, (float)WIDTH / HEIGHT,
                                                             frame->camera.znear);
    uint32_t cursor = 0, wrong = 0;
    *full = true;
    for (uint32_t i = 0; ok && i < l->scene->instance_count; i++) {
        uint32_t m = l->scene->instances[i].mesh;
        const gdr_mesh_clusters *c = &l->scene->meshes[m].clusters;
        gdr_lod_view view = {.transform = l->scene->instances[i].transform, .camera_position = frame->camera.position,
                             .projection_y = fabsf(projection.m[5]), .viewport_height = HEIGHT,
                             .znear = frame->camera.znear, .threshold = frame->lod_error_px};
        uint8_t *resident = malloc(c->group_count), *cut = malloc(c->cluster_count), *all = malloc(c->cluster_count);
        for (uint32_t g = 0; resident && g < c->group_count; g++)
            resident[g] = (uint8_t)(!l->res || gdr_residency_group_resident(l->res, m, g));
        if (resident && cut && all) {
            gdr_lod_cut_select_resident(c, &view, resident, cut);
            gdr_lod_cut_select(c, &view, all);
            *full = *full && memcmp(cut, all, c->cluster_count) == 0;
            for (uint32_t k = 0; k < c->cluster_count; k++) {
                bool on_gpu = cursor < l->drawn_count && l->drawn[cursor].instance == i && l->drawn[cursor].meshlet == k;
                cursor += on_gpu;
                wrong += on_gpu != (cut[k] != 0);
            }
        }
        free(resident), free(cut), free(all);
    }
    CHECK(cursor == l->drawn_count && wrong == 0);
    return ok && wrong == 0;
}

static uint64_t pool_bytes(const gdr_paged_cache *cache)
{
    uint64_t total = 0;
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(cache); m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(cache, m)->page_count; p++)
            total += gdr_page_pool_bytes(&gdr_paged_cache_mesh(cache, m)->pages[p]);
    return total;
}

static void run(const gdr_scene *scene, const char *path)
{
    gdr_error err = {0};
    loop l = {.scene = scene, .capacity = 1u << 20};
    l.drawn = malloc(sizeof *l.drawn * l.capacity);
    l.requests = malloc(sizeof *l.requests * 4096);
    uint8_t *image = malloc(WIDTH * HEIGHT * 4), *reference = malloc(VIEWS * WIDTH * HEIGHT * 4);
    l.renderer = gpu_test_renderer(WIDTH, HEIGHT, scene);
    CHECK(l.renderer && l.drawn && l.requests && image && reference &&
          gdr_paged_cache_open(path, &l.cache, &err) == GDR_OK);
    if (!l.cache)
        goto done;
    /* The field from its right, from far, then from its left: the pool holds the pages of one side's
     * cut, so the third view's loads evict the first view's finer pages. */
    static const gdr_vec3 positions[VIEWS] = {{7.0f, 1.5f, -4.0f}, {0.0f, 3.0f, 20.0f}, {-7.0f, 1.5f, -4.0f}};
    static const float yaws[VIEWS] = {1.5708f, 0.0f, -1.5708f};
    gdr_frame_desc frames[VIEWS];
    for (int v = 0; v < VIEWS; v++)
        frames[v] = (gdr_frame_desc){.camera = test_look(positions[v], yaws[v], -0.1f, 1.0f, 0.1f),
                                     .pipeline = GDR_PIPELINE_MESH, .cull = GDR_CULL_OFF, .occlusion = GDR_CULL_OFF,
                                     .lod_error_px = 1.0f};
    bool full = false;
    /* Every group resident (no residency yet): the references. */
    for (int v = 0; v < VIEWS; v++)
        CHECK(draw(&l, &frames[v], reference + (size_t)v * WIDTH * HEIGHT * 4, &full) && full);
    uint64_t total = pool_bytes(l.cache);
    gdr_residency_desc desc = {l.cache, total * 7 / 24, 64u << 10};
    CHECK(gdr_residency_create(&desc, &l.res, &err) == GDR_OK && gdr_page_loader_create(l.cache, &l.loader, &err) == GDR_OK);
    if (!l.loader)
        goto done;
    for (int v = 0; v < VIEWS; v++) {
        uint32_t converged = UINT32_MAX, partial_frames = 0, loads_total = 0, evictions = 0;
        for (uint32_t f = 0; f < FRAMES; f++) {
            uint32_t loads = 0;
            if (!stream(&l, (uint32_t)v * FRAMES + f, &loads, &evictions) || !draw(&l, &frames[v], image, &full))
                break;
            loads_total += loads;
            partial_frames += !full;
            if (!full || memcmp(image, reference + (size_t)v * WIDTH * HEIGHT * 4, WIDTH * HEIGHT * 4) != 0)
                converged = UINT32_MAX;
            else if (converged == UINT32_MAX)
                converged = f;
        }
        gdr_residency_stats st = gdr_residency_get_stats(l.res);
        printf("view %d, pool %llu of %llu bytes (%u slots): %u pages loaded, %u evicted, %u frames not the full cut, "
               "the image equal to the fully resident one from frame %u of %u; last frame %u requests, %u resident "
               "pages\n", v, (unsigned long long)desc.budget_bytes, (unsigned long long)total,
               gdr_residency_slot_count(l.res), loads_total, evictions, partial_frames, converged, FRAMES,
               l.request_count, st.resident_pages);
        CHECK(converged < FRAMES && l.request_count == 0);
        CHECK(v == 1 ? partial_frames == 0 : partial_frames > 0); /* the far view needs no new page */
        CHECK(v < 2 || evictions > 0);
    }
done:
    gdr_page_loader_destroy(l.loader);
    gdr_residency_destroy(l.res);
    gdr_paged_cache_close(l.cache);
    gdr_renderer_destroy(l.renderer);
    free(l.drawn), free(l.requests), free(image), free(reference);
}

int main(void)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load("unique-field:meshes=3,triangles=20000,seed=3", &load, &scene, &err) == GDR_OK);
    char path[256];
    const char *tmp = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/gdr_gpu_streaming_%ld.gdrc", tmp ? tmp : "/tmp", (long)getpid());
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_MIN}; /* a group a page */
    CHECK(scene && gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    if (scene)
        run(scene, path);
    unlink(path);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_streaming");
}
