/* Geometry streaming on the CPU, frame by frame, as the GPU loop runs it (docs/STREAMING.md): a
 * unique-field scene whose pages are about ten times the pool; each frame the cut restricted to the
 * resident groups (gdr_lod_cut_select_resident) is the image, the groups the full cut needs but
 * finds absent are the requests, the pages of the drawn clusters the page use, both read back one
 * frame late; the residency plans loads within the pool and the upload budget, the loader thread
 * reads and decodes them. Checked at every frame of a camera path and of a still camera: the cut
 * is exact (one cluster on every DAG path: no hole, no crack), the pool never exceeds the budget,
 * each frame's loads stay within the upload budget (requests beyond it wait), eviction never
 * takes a pinned page, a page the latest cut used or one with a resident child; a still camera
 * converges to the full cut within a bounded number of frames; a damaged page is refused by name,
 * stays absent and the cut stays exact; two runs give the same frames, the second with the
 * residency's page graph made on threads. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geometry/lod_cut.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "gdr/thread_pool.h"
#include "stream/page_loader.h"
#include "stream/residency.h"
#include "test_util.h"

#define PATH_FRAMES 40
#define STILL_FRAMES 30

/* Every path from a level-0 cluster to the root holds exactly one selected cluster (clusters are
 * ordered by group and groups by depth, so the clusters made from a group come later). */
static int cut_is_exact(const gdr_mesh_clusters *mc, const uint8_t *selected)
{
    uint32_t n = mc->cluster_count;
    uint32_t *lo = malloc(sizeof *lo * n), *hi = malloc(sizeof *hi * n);
    uint32_t *succ_lo = malloc(sizeof *succ_lo * mc->group_count), *succ_hi = malloc(sizeof *succ_hi * mc->group_count);
    for (uint32_t g = 0; g < mc->group_count; g++)
        succ_lo[g] = UINT32_MAX, succ_hi[g] = 0;
    int ok = 1;
    for (uint32_t i = n; i-- > 0;) {
        const gdr_cluster *c = &mc->clusters[i];
        uint32_t g = c->group;
        uint32_t min = succ_lo[g] == UINT32_MAX ? 0 : succ_lo[g], max = succ_lo[g] == UINT32_MAX ? 0 : succ_hi[g];
        lo[i] = min + selected[i];
        hi[i] = max + selected[i];
        if (c->refined_group != GDR_NO_INDEX) {
            uint32_t r = c->refined_group;
            succ_lo[r] = lo[i] < succ_lo[r] ? lo[i] : succ_lo[r];
            succ_hi[r] = hi[i] > succ_hi[r] ? hi[i] : succ_hi[r];
        }
    }
    for (uint32_t i = 0; i < mc->level0_cluster_count && ok; i++)
        ok = lo[i] == 1 && hi[i] == 1;
    free(lo), free(hi), free(succ_lo), free(succ_hi);
    return ok;
}

typedef struct sim {
    const gdr_scene *scene;
    gdr_paged_cache *cache;
    gdr_residency *res;
    gdr_page_loader *loader;
    uint64_t budget, upload_budget;
    gdr_stream_request *requests; /* last frame's, read back now */
    uint32_t request_count;
    uint8_t **used;               /* last frame's page use, per mesh */
    uint64_t trace;               /* a hash of every frame's numbers: runs compare it */
    uint32_t deferred_frames, failed_pages, max_loads, evictions;
    int exact, full;              /* this frame: the cut was exact; it equals the full cut */
    int same_walk;                /* every frame: the traversal's cut is the flat one */
    gdr_lod_traversal_stats traversal;
} sim;

static gdr_lod_view view_of(const gdr_scene *scene, uint32_t instance, gdr_vec3 camera)
{
    return (gdr_lod_view){.transform = scene->instances[instance].transform, .camera_position = camera,
                          .projection_y = 1.0f / tanf(0.5f), .viewport_height = 120.0f, .znear = 0.1f,
                          .threshold = 1.0f};
}

static uint64_t mix(uint64_t h, uint64_t v) { return (h ^ v) * 1099511628211ull; }

/* One mesh's frame: its cut, checks, this frame's requests and page use. */
static void frame_mesh(sim *s, uint32_t m, gdr_vec3 camera, gdr_stream_request *next, uint32_t *next_count)
{
    const gdr_mesh_clusters *mc = &s->scene->meshes[m].clusters;
    const gdr_paged_mesh *pm = gdr_paged_cache_mesh(s->cache, m);
    uint8_t *resident = malloc(mc->group_count), *cut = malloc(mc->cluster_count), *full = malloc(mc->cluster_count);
    for (uint32_t g = 0; g < mc->group_count; g++)
        resident[g] = (uint8_t)gdr_residency_group_resident(s->res, m, g);
    gdr_lod_view view = view_of(s->scene, m, camera); /* instance m draws mesh m */
    gdr_lod_cut_select_resident(mc, &view, resident, cut);
    gdr_lod_cut_select(mc, &view, full);
    /* The traversal's cut over the same resident groups (what the GPU runs): the same bytes. */
    uint32_t *absent = malloc(sizeof *absent * mc->lod_node_count);
    uint8_t *walked = malloc(mc->cluster_count);
    gdr_lod_nodes_count_absent_refined(mc, resident, absent);
    gdr_lod_cut_select_hierarchical_resident(mc, &view, resident, absent, walked, &s->traversal);
    s->same_walk &= memcmp(walked, cut, mc->cluster_count) == 0;
    free(absent), free(walked);
    s->exact &= cut_is_exact(mc, cut);
    s->full &= memcmp(cut, full, mc->cluster_count) == 0;
    memset(s->used[m], 0, pm->page_count);
    for (uint32_t c = 0; c < mc->cluster_count; c++) {
        uint32_t g = mc->clusters[c].group;
        if (cut[c])
            s->used[m][pm->groups[g].page] = 1;
        if (full[c] && !resident[g]) {
            float distance = gdr_vec3_length(gdr_vec3_sub(camera, (gdr_vec3){view.transform.m[12],
                                                                              view.transform.m[13],
                                                                              view.transform.m[14]}));
            next[(*next_count)++] = (gdr_stream_request){m, g, 1.0f / (1.0f + distance)};
        }
        s->trace = mix(s->trace, cut[c]);
    }
    free(resident), free(cut), free(full);
}

/* The loads of this frame through the loader thread; damaged pages are refused by name. */
static void load_pages(sim *s, const gdr_stream_load *loads, uint32_t count)
{
    gdr_error err = {0};
    CHECK(gdr_page_loader_submit(s->loader, loads, count, &err) == GDR_OK);
    gdr_page_result result;
    while (gdr_page_loader_collect(s->loader, 1, &result, 1) == 1) {
        if (result.status == GDR_OK) {
            gdr_residency_loaded(s->res, result.load.mesh, result.load.page);
            gdr_page_free(&result.page);
        } else {
            CHECK_STATUS(result.error, GDR_ERROR_CORRUPT);
            CHECK_NAMES(result.error, " page ");
            if (s->failed_pages++ == 0)
                printf("refused: %s\n", result.error.message);
            gdr_residency_failed(s->res, result.load.mesh, result.load.page);
        }
    }
}

static void run_frame(sim *s, uint32_t frame, gdr_vec3 camera)
{
    /* Last frame's read-back: page use, then requests. */
    uint32_t latest = frame ? frame - 1 : 0;
    for (uint32_t m = 0; frame && m < s->scene->mesh_count; m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(s->cache, m)->page_count; p++)
            if (s->used[m][p])
                gdr_residency_mark_used(s->res, latest, m, p);
    gdr_stream_load loads[256];
    uint32_t count = 0;
    gdr_residency_plan(s->res, frame, s->requests, s->request_count, loads, 256, &count);
    gdr_residency_stats st = gdr_residency_get_stats(s->res);
    CHECK(st.resident_bytes <= s->budget && st.evicted_in_use == 0);
    if (frame > 0)
        CHECK(st.loads <= 1 || st.load_bytes <= s->upload_budget);
    /* The latest cut's pages and the pinned ones are all still there (planned or resident). */
    for (uint32_t m = 0; m < s->scene->mesh_count; m++)
        for (uint32_t p = 0; frame && p < gdr_paged_cache_mesh(s->cache, m)->page_count; p++)
            if (s->used[m][p] || p == 0)
                CHECK(gdr_residency_page_slot(s->res, m, p) != UINT32_MAX);
    s->deferred_frames += st.deferred > 0;
    s->evictions += st.evictions;
    s->max_loads = count > s->max_loads ? count : s->max_loads;
    load_pages(s, loads, count);
    s->trace = mix(mix(mix(s->trace, st.loads), st.evictions), st.resident_pages);
    /* This frame: its cut from what is resident now; its requests for the next frame. */
    s->exact = s->full = 1;
    uint32_t next_count = 0;
    gdr_stream_request *next = malloc(sizeof *next * 65536);
    for (uint32_t m = 0; m < s->scene->mesh_count; m++)
        frame_mesh(s, m, camera, next, &next_count);
    CHECK(s->exact);
    free(s->requests);
    s->requests = next;
    s->request_count = next_count;
}

/* The camera path: from near the first row out beyond the field, back to 4 m from it, then still. */
static gdr_vec3 camera_at(uint32_t frame)
{
    float t = frame < PATH_FRAMES ? (float)frame / PATH_FRAMES : 1.0f;
    gdr_vec3 near = {-1.5f, 2.0f, 0.0f}, far = {4.0f, 3.0f, 16.0f}, end = {0.0f, 2.5f, 8.0f};
    return t < 0.5f ? gdr_vec3_add(near, gdr_vec3_scale(gdr_vec3_sub(far, near), 2.0f * t))
                    : gdr_vec3_add(far, gdr_vec3_scale(gdr_vec3_sub(end, far), 2.0f * t - 1.0f));
}

/* Runs the path and the still camera; returns the trace. converged_at: the first frame from which
 * the cut equals the full cut (UINT32_MAX: never). */
static uint64_t simulate(const gdr_scene *scene, const char *path, uint64_t budget, uint64_t upload_budget,
                         gdr_thread_pool *pool, uint32_t *converged_at, uint32_t *failed_pages,
                         uint32_t *deferred_frames)
{
    sim s = {.scene = scene, .budget = budget, .upload_budget = upload_budget, .trace = 14695981039346656037ull,
             .same_walk = 1};
    gdr_error err = {0};
    CHECK(gdr_paged_cache_open(path, &s.cache, &err) == GDR_OK);
    gdr_residency_desc desc = {s.cache, budget, upload_budget, pool};
    CHECK(s.cache && gdr_residency_create(&desc, &s.res, &err) == GDR_OK);
    if (!s.res)
        fprintf(stderr, "%s\n", err.message);
    CHECK(s.res && gdr_page_loader_create(s.cache, 3, &s.loader, &err) == GDR_OK);
    s.used = calloc(scene->mesh_count, sizeof *s.used);
    for (uint32_t m = 0; s.cache && m < scene->mesh_count; m++)
        s.used[m] = calloc(gdr_paged_cache_mesh(s.cache, m)->page_count, 1);
    *converged_at = UINT32_MAX;
    for (uint32_t f = 0; s.loader && f < PATH_FRAMES + STILL_FRAMES; f++) {
        run_frame(&s, f, camera_at(f));
        if (!s.full)
            *converged_at = UINT32_MAX;
        else if (*converged_at == UINT32_MAX)
            *converged_at = f;
    }
    gdr_residency_stats st = s.res ? gdr_residency_get_stats(s.res) : (gdr_residency_stats){0};
    printf("last frame: %u requests, %u resident pages of %u slots, %u deferred; %u evictions in all\n",
           s.request_count, st.resident_pages, s.res ? gdr_residency_slot_count(s.res) : 0, st.deferred,
           s.evictions);
    /* The path needs more than the pool holds; with a damaged page the groups past it never load
     * and the rest may fit. */
    CHECK(s.evictions > 0 || s.failed_pages > 0);
    CHECK(s.same_walk);
    printf("traversal: %llu nodes and %llu clusters tested\n", (unsigned long long)s.traversal.nodes_tested,
           (unsigned long long)s.traversal.clusters_tested);
    *failed_pages = s.failed_pages;
    *deferred_frames = s.deferred_frames;
    gdr_page_loader_destroy(s.loader);
    gdr_residency_destroy(s.res);
    for (uint32_t m = 0; m < scene->mesh_count; m++)
        free(s.used[m]);
    free(s.used);
    free(s.requests);
    gdr_paged_cache_close(s.cache);
    return s.trace;
}

static uint64_t total_pool_bytes(const char *path, uint32_t *pages)
{
    gdr_paged_cache *pc = NULL;
    gdr_error err = {0};
    uint64_t total = 0;
    *pages = 0;
    if (gdr_paged_cache_open(path, &pc, &err) != GDR_OK)
        return 0;
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(pc); m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(pc, m)->page_count; p++)
            total += gdr_page_pool_bytes(&gdr_paged_cache_mesh(pc, m)->pages[p]), (*pages)++;
    gdr_paged_cache_close(pc);
    return total;
}

/* A copy of the cache with one byte of page `page` of mesh `mesh` flipped. */
static void write_damaged(const char *path, const char *damaged, uint32_t mesh, uint32_t page)
{
    gdr_paged_cache *pc = NULL;
    gdr_error err = {0};
    CHECK(gdr_paged_cache_open(path, &pc, &err) == GDR_OK);
    if (!pc)
        return;
    const gdr_page_info *pi = &gdr_paged_cache_mesh(pc, mesh)->pages[page];
    FILE *in = fopen(path, "rb"), *out = fopen(damaged, "wb");
    int ch;
    for (uint64_t at = 0; in && out && (ch = fgetc(in)) != EOF; at++)
        fputc(at == pi->offset + pi->stored_size / 3 ? ch ^ 0x40 : ch, out);
    if (in)
        fclose(in);
    if (out)
        fclose(out);
    gdr_paged_cache_close(pc);
}

/* Whether a group of page `page` was made, through any number of steps, from a group of page `of`. */
static int depends_on(const gdr_paged_mesh *pm, uint32_t page, uint32_t of)
{
    uint32_t *stack = malloc(sizeof *stack * (pm->parent_count + pm->group_count + 1)), top = 0;
    uint8_t *seen = calloc(pm->group_count, 1);
    int found = 0;
    for (uint32_t k = pm->pages[page].first; k < pm->pages[page].first + pm->pages[page].group_count; k++)
        stack[top++] = pm->page_groups[k];
    while (top > 0 && !found) {
        const gdr_page_group *g = &pm->groups[stack[--top]];
        found = g->page == of;
        for (uint32_t e = g->parent_first; e < g->parent_first + g->parent_count; e++)
            if (!seen[pm->parents[e]]) {
                seen[pm->parents[e]] = 1;
                stack[top++] = pm->parents[e];
            }
    }
    free(stack), free(seen);
    return found;
}

/* A pool of the pinned pages and the closure of the finest page a: a page the latest cut used is
 * never evicted for another (the request waits), and is evicted once a later cut no longer uses it. */
static void check_eviction_rules(const char *path)
{
    gdr_paged_cache *pc = NULL;
    gdr_residency *res = NULL;
    gdr_error err = {0};
    CHECK(gdr_paged_cache_open(path, &pc, &err) == GDR_OK);
    if (!pc)
        return;
    const gdr_paged_mesh *pm = gdr_paged_cache_mesh(pc, 0);
    uint32_t a = pm->page_count - 1, closure = 1, b = UINT32_MAX;
    for (uint32_t p = 1; p < a; p++)
        closure += depends_on(pm, a, p);
    for (uint32_t p = a; p-- > 1 && b == UINT32_MAX;)
        if (!depends_on(pm, a, p))
            b = p;
    CHECK(b != UINT32_MAX);
    gdr_residency_desc desc = {pc, 1ull << 40, 0};
    CHECK(gdr_residency_create(&desc, &res, &err) == GDR_OK);
    desc.budget_bytes = (uint64_t)(gdr_paged_cache_mesh_count(pc) + closure) * gdr_residency_slot_bytes(res);
    gdr_residency_destroy(res);
    CHECK(gdr_residency_create(&desc, &res, &err) == GDR_OK);
    if (!res || b == UINT32_MAX)
        return;
    gdr_stream_load loads[256];
    uint32_t count = 0;
    gdr_residency_plan(res, 0, NULL, 0, loads, 256, &count); /* the pinned pages */
    CHECK(count == gdr_paged_cache_mesh_count(pc));
    for (uint32_t i = 0; i < count; i++)
        gdr_residency_loaded(res, loads[i].mesh, loads[i].page);
    gdr_stream_request ra = {0, pm->page_groups[pm->pages[a].first], 1.0f};
    gdr_stream_request rb = {0, pm->page_groups[pm->pages[b].first], 2.0f};
    gdr_residency_plan(res, 1, &ra, 1, loads, 256, &count);
    CHECK(count == closure && loads[count - 1].page == a);
    for (uint32_t i = 0; i < count; i++) {
        gdr_residency_loaded(res, 0, loads[i].page);
        gdr_residency_mark_used(res, 1, 0, loads[i].page); /* frame 1's cut drew them all */
    }
    gdr_residency_plan(res, 2, &rb, 1, loads, 256, &count);
    gdr_residency_stats st = gdr_residency_get_stats(res);
    CHECK(count == 0 && st.deferred == 1 && st.evictions == 0);
    CHECK(gdr_residency_page_slot(res, 0, a) != UINT32_MAX);
    gdr_residency_mark_used(res, 2, 0, 0); /* frame 2's cut: page 0 only */
    gdr_residency_plan(res, 3, &rb, 1, loads, 256, &count);
    st = gdr_residency_get_stats(res);
    CHECK(count >= 1 && st.evictions >= 1 && st.evicted_in_use == 0);
    CHECK(gdr_residency_page_slot(res, 0, a) == UINT32_MAX && gdr_residency_page_slot(res, 0, 0) != UINT32_MAX);
    gdr_residency_destroy(res);
    gdr_paged_cache_close(pc);
}

int main(void)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load("unique-field:meshes=4,triangles=40000,seed=3", &load, &scene, &err) == GDR_OK);
    if (!scene)
        return test_finish("test_streaming");
    char path[1024], damaged[1100];
    snprintf(path, sizeof path, "%s/streaming.gdrc", GDR_IO_TEST_TMP);
    snprintf(damaged, sizeof damaged, "%s/streaming_damaged.gdrc", GDR_IO_TEST_TMP);
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_MIN}; /* a group a page */
    CHECK(gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    uint32_t pages = 0;
    uint64_t total = total_pool_bytes(path, &pages), budget = total / 10, upload = 64u << 10;
    printf("%u pages: %llu bytes in the pool when all resident; budget %llu, upload budget %llu a frame\n", pages,
           (unsigned long long)total, (unsigned long long)budget, (unsigned long long)upload);

    uint32_t converged, failed, deferred;
    uint64_t trace = simulate(scene, path, budget, upload, NULL, &converged, &failed, &deferred);
    printf("converged at frame %u (camera still from frame %u); %u frames deferred requests\n", converged,
           PATH_FRAMES, deferred);
    CHECK(converged < PATH_FRAMES + STILL_FRAMES / 2);
    CHECK(failed == 0 && deferred > 0);
    /* The same frames again, the residency's page graph made on four threads. */
    uint32_t converged2, failed2, deferred2;
    gdr_thread_pool *pool = NULL;
    CHECK(gdr_thread_pool_create(4, &pool, &err) == GDR_OK);
    CHECK(simulate(scene, path, budget, upload, pool, &converged2, &failed2, &deferred2) == trace);
    CHECK(converged2 == converged);
    gdr_thread_pool_destroy(pool);

    check_eviction_rules(path);

    /* A budget too small for the coarsest pages is refused, naming the sizes. */
    gdr_paged_cache *pc = NULL;
    gdr_residency *res = NULL;
    CHECK(gdr_paged_cache_open(path, &pc, &err) == GDR_OK);
    gdr_residency_desc tiny = {pc, 1000, 0};
    CHECK_FAILS(gdr_residency_create(&tiny, &res, &err), err, GDR_ERROR_CAPACITY);
    CHECK(res == NULL);
    gdr_paged_cache_close(pc);

    /* A damaged page of the nearest mesh: refused, its groups stay absent, every cut stays exact. */
    write_damaged(path, damaged, 0, 2);
    simulate(scene, damaged, budget, upload, NULL, &converged, &failed, &deferred);
    CHECK(failed == 1 && converged == UINT32_MAX);
    remove(damaged);
    remove(path);
    gdr_scene_destroy(scene);
    return test_finish("test_streaming");
}
