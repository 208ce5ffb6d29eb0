/* The LOD hierarchy traversal on the GPU: it finds the same clusters as testing every cluster of
 * the DAG (images identical with culling and occlusion on, drawn clusters too without occlusion,
 * random cameras and thresholds) while testing fewer clusters; a deliberately wrong node test changes the image; a
 * traversal level or a task list too small for the frame is reported, never silent. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gpu_test_util.h"
#include "render/renderer_debug.h"

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

static gdr_renderer *make_renderer(const gdr_scene *scene, gdr_renderer_debug debug)
{
    gdr_error err = {0};
    gdr_renderer *r = NULL;
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true};
    if (gdr_renderer_create(&desc, &r, &err) == GDR_OK)
        gdr_renderer_set_debug(r, &debug);
    if (!r || gdr_renderer_set_scene(r, scene, &err) != GDR_OK) {
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
         * differ where nothing shows: a deferred node defers its whole subtree, so the pyramid the
         * late phase tests against differs from the flat frame's.) */
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
    gdr_renderer *bad = make_renderer(scene, (gdr_renderer_debug){.shrink_lod_nodes = true});
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
    gdr_renderer_debug descs[2] = {{.traversal_capacity = 3}, {.task_capacity = 5}};
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

/* A low wall (a box) across the field's first rows: it hides the lower parts of the knots behind
 * it, so that their hierarchies' lower nodes are occluded while their upper nodes are not. */
static bool add_wall(gdr_scene *scene)
{
    gdr_error err = {0};
    gdr_vec3 corners[8];
    for (uint32_t v = 0; v < 8; v++)
        corners[v] = (gdr_vec3){v & 1 ? 1.0f : -1.0f, v & 2 ? 1.0f : -1.0f, v & 4 ? 1.0f : -1.0f};
    const uint32_t faces[36] = {4, 5, 7, 4, 7, 6, 0, 2, 3, 0, 3, 1, 1, 3, 7, 1, 7, 5,
                                0, 4, 6, 0, 6, 2, 2, 6, 7, 2, 7, 3, 0, 1, 5, 0, 5, 4};
    uint32_t mesh = 0;
    gdr_instance wall = {.transform = gdr_mat4_from_trs((gdr_vec3){0.0f, 1.5f, -2.0f}, gdr_quat_identity(),
                                                        (gdr_vec3){3.0f, 1.5f, 0.05f}),
                         .material = GDR_NO_INDEX, .color = {0.6f, 0.6f, 0.6f, 1.0f}};
    bool ok = gdr_scene_add_mesh(scene, "wall", corners, NULL, NULL, 8, faces, 36, &mesh, &err) == GDR_OK;
    wall.mesh = mesh;
    ok = ok && gdr_scene_add_instance(scene, &wall, &err) == GDR_OK &&
         gdr_scene_build_clusters(scene, NULL, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "wall: %s\n", err.message);
    return ok;
}

/* Occlusion culling with the traversal: nodes hidden behind last frame's pyramid are deferred and
 * retested, and where the occluded-node list is too small they are traversed in the early phase
 * (counted as overflow): every image equals the one without occlusion culling. */
static void check_deferred_nodes(gdr_scene *scene)
{
    gdr_renderer *r = add_wall(scene) ? make_renderer(scene, (gdr_renderer_debug){0}) : NULL;
    gdr_renderer *small = r ? make_renderer(scene, (gdr_renderer_debug){.occluded_node_capacity = 2}) : NULL;
    CHECK(r != NULL && small != NULL);
    uint64_t deferred = 0, retested = 0, occluded = 0, overflow = 0;
    uint32_t differing = 0;
    for (int n = 0; n < 4 && small; n++) {
        /* Above and behind the wall, a little higher than the knots behind it, then rising: the
         * second frame tests against the first one's pyramid, which hides nodes that now show. */
        gdr_frame_desc frame = {.camera = test_look((gdr_vec3){0.4f * (float)n - 0.6f, 2.2f, 0.5f}, 0.0f, -0.1f, 1.0f, 0.1f),
                                .pipeline = GDR_PIPELINE_MESH, .lod_error_px = 0.3f, .occlusion = GDR_CULL_ON};
        frame_result on = {0}, listed = {0}, off = {0};
        CHECK(render(r, &frame, 1, &on) && render(small, &frame, 1, &listed));
        release(&on);
        release(&listed);
        frame.camera.position.y += 0.4f * (float)(n + 1);
        CHECK(render(r, &frame, 1, &on) && render(small, &frame, 1, &listed));
        frame.occlusion = GDR_CULL_OFF;
        CHECK(render(r, &frame, 1, &off));
        differing += memcmp(on.image, off.image, WIDTH * HEIGHT * 4) != 0;
        differing += memcmp(listed.image, off.image, WIDTH * HEIGHT * 4) != 0;
        deferred += on.stats.traversal.nodes_early_occluded;
        retested += on.stats.traversal.late_nodes_tested;
        occluded += on.stats.traversal.nodes_occluded;
        overflow += listed.stats.occlusion.overflow;
        CHECK(on.stats.occlusion.overflow == 0 && on.stats.traversal.overflow == 0);
        release(&on);
        release(&listed);
        release(&off);
    }
    printf("occlusion with the traversal: %llu nodes deferred, %llu late visits, %llu occluded; a 2-entry list: "
           "%llu overflow; %u images differ\n", (unsigned long long)deferred, (unsigned long long)retested,
           (unsigned long long)occluded, (unsigned long long)overflow, differing);
    CHECK(differing == 0 && deferred > 0 && retested >= deferred && occluded > 0 && overflow > 0);
    gdr_renderer_destroy(small);
    gdr_renderer_destroy(r);
}

int main(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    CHECK(gdr_scene_load("lod-field:instances=60,triangles=30000,seed=3", NULL, &scene, &err) == GDR_OK);
    gdr_renderer *r = scene ? make_renderer(scene, (gdr_renderer_debug){0}) : NULL;
    if (r) {
        check_same_as_flat(r, 11);
        check_wrong_node_test_is_caught(scene, r);
        check_overflow_reported(scene);
        check_deferred_nodes(scene);
    } else {
        CHECK(false);
    }
    gdr_renderer_destroy(r);
    gdr_scene_destroy(scene);
    return test_finish("test_gpu_lod_traversal");
}
