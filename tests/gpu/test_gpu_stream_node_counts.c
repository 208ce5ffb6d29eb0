/* The streamed scene's LOD node counts on the GPU, updated per changed group (docs/STREAMING.md,
 * "Node counts"), on the default device (lavapipe in CI), validation on. `unique-field` written
 * with one group a page streams into a pool of a quarter of what its views need, the threshold held
 * (so that pages come and go in most frames), along a path near the field and back out. After every
 * frame, for every mesh, the node counts the GPU holds equal gdr_lod_nodes_count_absent_refined
 * over the page table the GPU holds (a node whose count changed and was not updated or not
 * uploaded fails it). Every frame's node updates stay within the changed groups' paths (at most the
 * largest path sum of one group per changed group), the words uploaded within those updates, and
 * over the run the words uploaded are a small part of what recomputing every changed mesh uploaded
 * (the code before: the whole mesh's counts for each mesh whose residency changed). */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "geometry/lod_cut.h"
#include "gpu_test_util.h"
#include "render/renderer_debug.h"
#include "stream/residency.h"

#define WIDTH 160
#define HEIGHT 120
#define FRAMES 60
#define SLOTS 40 /* the pinned pages (one per mesh) and 28 more: the views need several times that */

static gdr_frame_desc path_frame(uint32_t f)
{
    /* Along the front row, near, then out to the far side. */
    float t = (float)f / FRAMES;
    gdr_vec3 at = {-4.0f + 8.0f * t, 1.5f, f < FRAMES / 2 ? 3.0f : 3.0f + 40.0f * (t - 0.5f)};
    return (gdr_frame_desc){.camera = test_look(at, 0.0f, -0.1f, 1.0f, 0.1f), .pipeline = GDR_PIPELINE_MESH,
                            .cull = GDR_CULL_OFF, .occlusion = GDR_CULL_OFF, .lod_error_px = 0.5f,
                            .read_back = true};
}

/* The most node updates one group's change can make in `c`: for each leaf holding a cluster made
 * from the group, the leaf's depth plus one. */
static uint32_t largest_group_updates(const gdr_mesh_clusters *c)
{
    uint32_t *depth = calloc(c->lod_node_count + 1, sizeof *depth), *sum = calloc(c->group_count + 1, sizeof *sum);
    uint32_t largest = 0;
    for (uint32_t n = 0; depth && sum && n < c->lod_node_count; n++) {
        const gdr_lod_node *node = &c->lod_nodes[n];
        if (!(node->flags & GDR_LOD_NODE_LEAF)) {
            for (uint32_t k = 0; k < node->count; k++)
                depth[node->first + k] = depth[n] + 1;
            continue;
        }
        uint32_t last = GDR_NO_INDEX; /* a leaf counts once per group */
        for (uint32_t i = node->first; i < node->first + node->count; i++) {
            uint32_t r = c->clusters[i].refined_group;
            if (r != GDR_NO_INDEX && r != last)
                sum[r] += depth[n] + 1, last = r;
        }
    }
    for (uint32_t g = 0; sum && g < c->group_count; g++)
        largest = sum[g] > largest ? sum[g] : largest;
    free(depth), free(sum);
    return largest;
}

/* The GPU's counts of mesh m against the whole recomputation over the GPU's page table. Returns
 * whether its page table differs from `before` (updated). */
static bool check_mesh(gdr_renderer *r, const gdr_mesh_clusters *c, uint32_t m, uint8_t *before, uint32_t *wrong)
{
    gdr_error err = {0};
    uint8_t *resident = malloc(c->group_count + 1);
    uint32_t *gpu = malloc(sizeof *gpu * (c->lod_node_count + 1)), *full = malloc(sizeof *full * (c->lod_node_count + 1));
    bool ok = resident && gpu && full && gdr_renderer_read_residency(r, m, resident, &err) == GDR_OK &&
              gdr_renderer_debug_read_node_counts(r, m, gpu, &err) == GDR_OK;
    CHECK(ok);
    bool changed = false;
    if (ok) {
        gdr_lod_nodes_count_absent_refined(c, resident, full);
        for (uint32_t n = 0; n < c->lod_node_count; n++)
            *wrong += gpu[n] != full[n];
        changed = memcmp(before, resident, c->group_count) != 0;
        memcpy(before, resident, c->group_count);
    }
    free(resident), free(gpu), free(full);
    return changed;
}

static void run(const gdr_scene *scene, const char *path, uint64_t slot_bytes)
{
    gdr_error err = {0};
    gdr_renderer *r = NULL;
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true};
    gdr_streaming_desc stream = {.cache = gpu_test_paged_cache(path), .geometry_budget_bytes = SLOTS * slot_bytes,
                                 .upload_budget_bytes = 256u << 10, .wait_for_loads = true, .fixed_lod_error = true};
    CHECK(gdr_renderer_create(&desc, &r, &err) == GDR_OK &&
          gdr_renderer_set_scene_streamed(r, scene, &stream, &err) == GDR_OK);
    uint8_t **before = calloc(scene->mesh_count, sizeof *before);
    uint32_t largest = 0;
    for (uint32_t m = 0; before && m < scene->mesh_count; m++) {
        const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
        before[m] = calloc(c->group_count + 1, 1); /* every group absent before the first frame */
        uint32_t u = largest_group_updates(c);
        largest = u > largest ? u : largest;
    }
    uint64_t words = 0, whole = 0, updates = 0, changed_groups = 0, uploads = 0, evictions = 0;
    uint32_t wrong = 0, over = 0, frames = 0;
    gdr_frame_stats stats = {0};
    for (uint32_t f = 0; r && before && f < FRAMES; f++, frames++) {
        gdr_frame_desc frame = path_frame(f);
        if (gdr_renderer_render(r, &frame, 1, &stats, &err) != GDR_OK || stats.validation_messages) {
            fprintf(stderr, "frame %u: %s\n", f, err.message);
            CHECK(!"render");
            break;
        }
        const gdr_streaming_stats *s = &stats.streaming;
        for (uint32_t m = 0; m < scene->mesh_count; m++)
            if (check_mesh(r, &scene->meshes[m].clusters, m, before[m], &wrong) && f > 0)
                whole += scene->meshes[m].clusters.lod_node_count;
        over += s->node_updates > (uint64_t)s->node_groups_changed * largest || s->node_words_uploaded > s->node_updates;
        if (f > 0) /* the first frame's counts come with the pinned pages: every node */
            words += s->node_words_uploaded;
        updates += s->node_updates, changed_groups += s->node_groups_changed;
        uploads += s->uploads, evictions += s->evictions;
    }
    printf("%u frames: %llu uploads, %llu evictions, %llu group changes, %llu node updates (at most %u per group), "
           "%llu count words uploaded after the first frame against %llu for recomputing each changed mesh; "
           "%u counts wrong\n", frames, (unsigned long long)uploads, (unsigned long long)evictions,
           (unsigned long long)changed_groups, (unsigned long long)updates, largest, (unsigned long long)words,
           (unsigned long long)whole, wrong);
    CHECK(frames == FRAMES && wrong == 0 && over == 0);
    CHECK(uploads > 2 * SLOTS && evictions > SLOTS); /* pages came and went */
    CHECK(4 * words < whole);
    for (uint32_t m = 0; before && m < scene->mesh_count; m++)
        free(before[m]);
    free(before);
    gdr_renderer_destroy(r);
}

int main(void)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load("unique-field:meshes=12,triangles=20000,seed=3", &load, &scene, &err) == GDR_OK);
    char path[256];
    const char *tmp = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/gdr_gpu_stream_node_counts_%ld.gdrc", tmp ? tmp : "/tmp", (long)getpid());
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_MIN}; /* a group a page */
    CHECK(scene && gdr_scene_quantize_vertices(scene, &err) == GDR_OK);
    CHECK(scene && gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    gdr_paged_cache *cache = scene ? gpu_test_paged_cache(path) : NULL;
    uint64_t slot = 0;
    for (uint32_t m = 0; cache && m < gdr_paged_cache_mesh_count(cache); m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(cache, m)->page_count; p++) {
            uint64_t bytes = gdr_page_pool_bytes(&gdr_paged_cache_mesh(cache, m)->pages[p]);
            slot = bytes > slot ? bytes : slot;
        }
    slot = (slot + 255) & ~(uint64_t)255;
    if (cache)
        run(scene, path, slot);
    gpu_test_close_paged_caches();
    unlink(path);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_stream_node_counts");
}
