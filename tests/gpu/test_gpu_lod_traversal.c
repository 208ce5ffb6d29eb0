/* The LOD hierarchy traversal on the GPU: it finds the same clusters as testing every cluster of
 * the DAG (images identical with culling and occlusion on, drawn clusters too without occlusion,
 * random cameras and thresholds) while testing fewer clusters; a deliberately wrong node test changes the image; a
 * traversal level or a task list too small for the frame is reported, never silent. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gpu_test_util.h"

#define WIDTH 192
#define HEIGHT 128

typedef struct frame_result {
    gdr_frame_stats stats;
    uint8_t *image;
    gdr_visible_meshlet *clusters;
    uint32_t cluster_count;
} frame_result;

static bool render(gdr_renderer *r, const gdr_frame_desc *frame, uint32_t frames, frame_result *out)
{
    gdr_error err = {0};
    gdr_frame_desc f = *frame;
    f.read_back = true;
    f.record_visible_meshlets = true;
    size_t capacity = 1u << 20;
    out->clusters = malloc(sizeof *out->clusters * capacity);
    out->image = malloc(WIDTH * HEIGHT * 4);
    bool ok = out->clusters && out->image && gdr_renderer_render(r, &f, frames, &out->stats, &err) == GDR_OK &&
              gdr_renderer_read_color(r, out->image, &err) == GDR_OK &&
              gdr_renderer_read_visible_meshlets(r, out->clusters, (uint32_t)capacity, &out->cluster_count, &err) ==
                  GDR_OK;
    if (!ok)
        fprintf(stderr, "render: %s\n", err.message);
    else
        qsort(out->clusters, out->cluster_count, sizeof *out->clusters, compare_visible_meshlets);
    return ok && out->stats.validation_messages == 0;
}

static void release(frame_result *r)
{
    free(r->image);
    free(r->clusters);
}

static bool same_clusters(const frame_result *a, const frame_result *b)
{
    return a->cluster_count == b->cluster_count &&
           memcmp(a->clusters, b->clusters, sizeof *a->clusters * a->cluster_count) == 0;
}

static gdr_renderer *make_renderer(const gdr_scene *scene, gdr_renderer_desc desc)
{
    gdr_error err = {0};
    gdr_renderer *r = NULL;
    desc.width = WIDTH;
    desc.height = HEIGHT;
    desc.validate = true;
    if (gdr_renderer_create(&desc, &r, &err) != GDR_OK || gdr_renderer_set_scene(r, scene, &err) != GDR_OK) {
        fprintf(stderr, "renderer: %s\n", err.message);
        gdr_renderer_destroy(r);
        return NULL;
    }
    return r;
}

static gdr_frame_desc random_frame(unsigned *rng)
{
    static const float thresholds[4] = {0.5f, 1.0f, 3.0f, 12.0f};
    /* Around the scene's camera, which looks down the field from behind its first row. */
    gdr_camera camera = test_look((gdr_vec3){test_random_range(rng, -3, 3), test_random_range(rng, 1, 6),
                                             test_random_range(rng, -4, 3)},
                                  test_random_range(rng, -0.6f, 0.6f), test_random_range(rng, -0.5f, 0.0f),
                                  test_random_range(rng, 0.6f, 1.2f), 0.1f);
    return (gdr_frame_desc){.camera = camera, .pipeline = GDR_PIPELINE_MESH,
                            .lod_error_px = thresholds[(unsigned)test_random_range(rng, 0, 3.99f)]};
}

/* Hierarchical and flat: the same image and clusters for random views, occlusion on and off. */
static void check_same_as_flat(gdr_renderer *r, unsigned seed)
{
    unsigned rng = seed;
    uint64_t tested_hierarchy = 0, tested_flat = 0, nodes = 0;
    for (int n = 0; n < 6; n++) {
        gdr_frame_desc frame = random_frame(&rng);
        frame.occlusion = n % 2 ? GDR_CULL_OFF : GDR_CULL_ON;
        frame_result hierarchy = {0}, flat = {0};
        CHECK(render(r, &frame, 2, &hierarchy));
        frame.lod_hierarchy = GDR_CULL_OFF;
        CHECK(render(r, &frame, 2, &flat));
        CHECK(hierarchy.stats.traversal.applied && !flat.stats.traversal.applied);
        CHECK(memcmp(hierarchy.image, flat.image, WIDTH * HEIGHT * 4) == 0);
        /* Without occlusion culling the same clusters too. (With it, which clusters were drawn can
         * differ where nothing shows: the traversal leaves the history bits of clusters below a
         * skipped node as they were, so a cluster hidden since may still be drawn early.) */
        if (frame.occlusion == GDR_CULL_OFF) {
            CHECK(same_clusters(&hierarchy, &flat));
            CHECK(hierarchy.stats.triangles == flat.stats.triangles);
        }
        CHECK(hierarchy.stats.traversal.overflow == 0 && hierarchy.stats.task_overflow == 0);
        tested_hierarchy += hierarchy.stats.meshlets_tested;
        tested_flat += flat.stats.meshlets_tested;
        nodes += hierarchy.stats.traversal.nodes_tested;
        release(&hierarchy);
        release(&flat);
    }
    printf("6 views: clusters tested %llu (hierarchy, plus %llu nodes) against %llu (flat)\n",
           (unsigned long long)tested_hierarchy, (unsigned long long)nodes, (unsigned long long)tested_flat);
    CHECK(nodes > 0 && tested_hierarchy + nodes < tested_flat);
}

/* A node test that is not conservative (shrunken spheres) loses clusters: the image tests see it. */
static void check_wrong_node_test_is_caught(const gdr_scene *scene, gdr_renderer *good)
{
    gdr_renderer *bad = make_renderer(scene, (gdr_renderer_desc){.debug_shrink_lod_nodes = true});
    CHECK(bad != NULL);
    unsigned rng = 5;
    uint32_t differing = 0;
    for (int n = 0; n < 4 && bad; n++) {
        gdr_frame_desc frame = random_frame(&rng);
        frame_result a = {0}, b = {0};
        CHECK(render(good, &frame, 1, &a) && render(bad, &frame, 1, &b));
        differing += memcmp(a.image, b.image, WIDTH * HEIGHT * 4) != 0;
        release(&a);
        release(&b);
    }
    printf("shrunken node spheres: %u of 4 images differ\n", differing);
    CHECK(differing > 0);
    gdr_renderer_destroy(bad);
}

/* Queues too small for the frame: the statistics say how much did not fit. */
static void check_overflow_reported(const gdr_scene *scene)
{
    gdr_renderer_desc descs[2] = {{.debug_traversal_capacity = 3}, {.debug_task_capacity = 5}};
    for (int i = 0; i < 2; i++) {
        gdr_renderer *r = make_renderer(scene, descs[i]);
        CHECK(r != NULL);
        if (!r)
            continue;
        unsigned rng = 17;
        frame_result result = {0};
        gdr_frame_desc frame = random_frame(&rng);
        frame.camera = test_look((gdr_vec3){0, 4.5f, 1}, 0, -0.3f, 1.05f, 0.1f);
        frame.lod_error_px = 1.0f;
        CHECK(render(r, &frame, 1, &result));
        printf("%s capacity: traversal overflow %u, task overflow %u\n", i ? "task" : "traversal",
               result.stats.traversal.overflow, result.stats.task_overflow);
        CHECK(i == 0 ? result.stats.traversal.overflow > 0 : result.stats.task_overflow > 0);
        release(&result);
        gdr_renderer_destroy(r);
    }
}

int main(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    CHECK(gdr_scene_load("lod-field:instances=60,triangles=30000,seed=3", NULL, &scene, &err) == GDR_OK);
    gdr_renderer *r = scene ? make_renderer(scene, (gdr_renderer_desc){0}) : NULL;
    if (r) {
        check_same_as_flat(r, 11);
        check_wrong_node_test_is_caught(scene, r);
        check_overflow_reported(scene);
    } else {
        CHECK(false);
    }
    gdr_renderer_destroy(r);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_lod_traversal");
}
