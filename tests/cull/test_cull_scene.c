/* gdr_cull_execute (octree and brute force, any thread count, any task size) against a direct
 * per-object reference of the documented rules, for random scenes and cameras. */
#include <stdlib.h>
#include <string.h>

#include "gdr/thread_pool.h"
#include "gdr/cull.h"
#include "test_util.h"

static gdr_cull_object random_object(unsigned *rng, float world)
{
    gdr_cull_object o = {0};
    float u = test_random(rng);
    float size = u < 0.7f ? test_random_range(rng, 0.05f, 2.0f) : u < 0.95f ? test_random_range(rng, 2, 20)
                                                                            : test_random_range(rng, 20, 120);
    o.center = (gdr_vec3){test_random_range(rng, -world, world), test_random_range(rng, -world * 0.3f, world * 0.3f),
                          test_random_range(rng, -world, world)};
    o.extent = (gdr_vec3){size * test_random_range(rng, 0.1f, 1), size * test_random_range(rng, 0.1f, 1),
                          size * test_random_range(rng, 0.1f, 1)};
    o.radius = gdr_vec3_length(o.extent) * test_random_range(rng, 0.8f, 1.0f);
    float f = test_random(rng);
    if (f < 0.03f)
        o.flags |= GDR_CULL_OBJECT_HIDDEN;
    else if (f < 0.05f)
        o.flags |= GDR_CULL_OBJECT_ALWAYS_VISIBLE;
    else if (f < 0.06f)
        o.flags |= GDR_CULL_OBJECT_HIDDEN | GDR_CULL_OBJECT_ALWAYS_VISIBLE;
    float g = test_random(rng);
    if (g < 0.01f)
        o.radius = -1.0f; /* invalid */
    else if (g < 0.02f)
        o.extent.y = NAN;
    else if (g < 0.03f)
        o.radius = 0.0f, o.extent = (gdr_vec3){0, 0, 0}; /* empty */
    else if (g < 0.04f)
        o.extent = (gdr_vec3){0, 0, 0}; /* a sphere with a point box: still valid */
    if (test_random(rng) < 0.4f)
        o.max_draw_distance = test_random_range(rng, 10, 150);
    if (test_random(rng) < 0.2f)
        o.min_draw_distance = test_random_range(rng, 1, 40);
    if (test_random(rng) < 0.2f)
        o.min_screen_size = test_random_range(rng, 0.001f, 0.1f);
    if (test_random(rng) < 0.1f)
        o.max_screen_size = test_random_range(rng, 0.1f, 1.0f);
    return o;
}

static bool object_valid(const gdr_cull_object *o)
{
    if (!isfinite(o->center.x) || !isfinite(o->center.y) || !isfinite(o->center.z) || !isfinite(o->radius) ||
        !isfinite(o->extent.x) || !isfinite(o->extent.y) || !isfinite(o->extent.z))
        return false;
    if (o->radius < 0 || o->extent.x < 0 || o->extent.y < 0 || o->extent.z < 0)
        return false;
    return o->radius > 0 || o->extent.x > 0 || o->extent.y > 0 || o->extent.z > 0;
}

/* The rules of include/gdr/cull.h, written out one object at a time. */
static bool reference(const gdr_cull_object *o, const gdr_cull_view *v, const gdr_frustum *f, gdr_vec3 eye,
                      bool *fading, bool *clipping)
{
    *fading = *clipping = false;
    if (o->flags & GDR_CULL_OBJECT_HIDDEN)
        return false;
    if (o->flags & GDR_CULL_OBJECT_ALWAYS_VISIBLE)
        return true;
    if (!object_valid(o))
        return false;
    if (!v->skip_frustum && (gdr_frustum_test_sphere(f, o->center, o->radius) == GDR_CULL_OUTSIDE ||
                             gdr_frustum_test_box(f, o->center, o->extent) == GDR_CULL_OUTSIDE))
        return false;
    gdr_vec3 d = gdr_vec3_sub(o->center, eye);
    float dist = sqrtf(d.x * d.x + d.y * d.y + d.z * d.z);
    float closest = v->distance_to_sphere_edge ? fmaxf(dist - o->radius, 0.0f) : dist;
    float farthest = v->distance_to_sphere_edge ? dist + o->radius : dist;
    float scale = v->distance_scale > 0 ? v->distance_scale : 1.0f;
    if (o->max_draw_distance > 0 && closest > o->max_draw_distance * scale)
        return false;
    if (o->min_draw_distance > 0 && farthest < o->min_draw_distance * scale)
        return false;
    bool fade = v->fade_range > 0 &&
                ((o->max_draw_distance > 0 && closest > o->max_draw_distance * scale - v->fade_range) ||
                 (o->min_draw_distance > 0 && farthest < o->min_draw_distance * scale + v->fade_range));
    float screen_scale = v->screen_scale > 0 ? v->screen_scale : fmaxf(fabsf(v->projection.m[0]), fabsf(v->projection.m[5]));
    float size = dist <= o->radius ? INFINITY : screen_scale * o->radius / dist;
    if (o->min_screen_size > 0 && size < o->min_screen_size)
        return false;
    if (v->min_screen_size > 0 && size < v->min_screen_size)
        return false;
    if (o->max_screen_size > 0 && size >= o->max_screen_size)
        return false;
    if (v->clip_plane.x != 0 || v->clip_plane.y != 0 || v->clip_plane.z != 0) {
        gdr_cull_outcome c = gdr_plane_test_box(v->clip_plane, o->center, o->extent);
        if (c == GDR_CULL_OUTSIDE)
            return false;
        *clipping = c == GDR_CULL_INTERSECTS;
    }
    *fading = fade;
    return true;
}

static gdr_cull_view random_view(unsigned *rng, float world, int config)
{
    gdr_cull_view v = {0};
    gdr_vec3 axis = gdr_vec3_normalize((gdr_vec3){test_random_range(rng, -1, 1), test_random_range(rng, -1, 1),
                                                  test_random_range(rng, -1, 1)});
    gdr_quat q = gdr_quat_from_axis_angle(axis, test_random_range(rng, -3.1f, 3.1f));
    float reach = test_random(rng) < 0.8f ? world : world * 3;
    gdr_vec3 pos = {test_random_range(rng, -reach, reach), test_random_range(rng, -reach, reach) * 0.3f,
                    test_random_range(rng, -reach, reach)};
    v.view = gdr_view_from_pose(pos, q);
    float fov = test_random_range(rng, 0.4f, 1.8f), aspect = test_random_range(rng, 0.7f, 2.2f);
    v.projection = (config & 1) ? gdr_perspective_reverse_z_infinite(fov, aspect, 0.1f)
                                : gdr_perspective_reverse_z(fov, aspect, 0.1f, test_random_range(rng, 20, 400));
    if (config & 2) {
        v.distance_scale = test_random(rng) < 0.5f ? 0.0f : test_random_range(rng, 0.5f, 2.0f);
        v.fade_range = test_random_range(rng, 0, 10);
        v.distance_to_sphere_edge = test_random(rng) < 0.5f;
    }
    if (config & 4) {
        v.min_screen_size = test_random_range(rng, 0, 0.05f);
        if (test_random(rng) < 0.3f)
            v.screen_scale = test_random_range(rng, 0.5f, 3.0f);
    }
    if (config & 8) {
        gdr_vec3 n = gdr_vec3_normalize((gdr_vec3){test_random_range(rng, -1, 1), test_random_range(rng, -1, 1),
                                                   test_random_range(rng, -1, 1)});
        float s = test_random_range(rng, 0.2f, 3.0f); /* need not be normalised */
        v.clip_plane = (gdr_vec4){n.x * s, n.y * s, n.z * s, test_random_range(rng, -world, world) * s};
    }
    if (config & 16)
        v.skip_frustum = true;
    return v;
}

typedef struct outputs {
    uint32_t *visible, *fading, *clipping;
} outputs;

static outputs outputs_alloc(uint32_t words)
{
    outputs o = {malloc(words * 4 + 4), malloc(words * 4 + 4), malloc(words * 4 + 4)};
    return o;
}

static void outputs_free(outputs *o)
{
    free(o->visible);
    free(o->fading);
    free(o->clipping);
}

static uint64_t checks_run;

static void compare_scene(const gdr_cull_scene *scene, const gdr_cull_object *objects, uint32_t count, unsigned *rng,
                          gdr_thread_pool **pools, uint32_t pool_count, uint32_t cameras, float world)
{
    uint32_t words = gdr_cull_word_count(count);
    outputs ref = outputs_alloc(words), got = outputs_alloc(words);
    uint64_t visible_total = 0, fading_total = 0, clipping_total = 0, inside_nodes = 0;
    for (uint32_t cam = 0; cam < cameras; cam++) {
        int config = (int)((cam * 11 + 3) % 32);
        gdr_cull_view v = random_view(rng, world, config);
        gdr_mat4 inv;
        CHECK(gdr_mat4_inverse(v.view, &inv));
        gdr_vec3 eye = {inv.m[12], inv.m[13], inv.m[14]};
        gdr_frustum f = gdr_frustum_from_matrix(gdr_mat4_mul(v.projection, v.view));
        memset(ref.visible, 0, words * 4);
        memset(ref.fading, 0, words * 4);
        memset(ref.clipping, 0, words * 4);
        uint32_t ref_visible = 0;
        for (uint32_t i = 0; i < count; i++) {
            bool fade, clip;
            if (reference(&objects[i], &v, &f, eye, &fade, &clip)) {
                ref.visible[i / 32] |= 1u << (i % 32);
                ref.fading[i / 32] |= (uint32_t)fade << (i % 32);
                ref.clipping[i / 32] |= (uint32_t)clip << (i % 32);
                ref_visible++;
            }
        }
        visible_total += ref_visible;
        for (uint32_t w = 0; w < words; w++) {
            fading_total += (uint64_t)__builtin_popcount(ref.fading[w]);
            clipping_total += (uint64_t)__builtin_popcount(ref.clipping[w]);
        }
        /* every pool, octree and brute force, a few task sizes */
        gdr_cull_stats first_octree = {0};
        for (uint32_t p = 0; p < pool_count; p++) {
            for (int brute = 0; brute < 2; brute++) {
                uint32_t task_words[] = {0, 1, 3};
                uint32_t tw = task_words[(cam + p + (uint32_t)brute) % 3];
                gdr_cull_view vv = v;
                vv.brute_force = brute;
                vv.words_per_task = tw;
                memset(got.visible, 0xAB, words * 4);
                memset(got.fading, 0xAB, words * 4);
                memset(got.clipping, 0xAB, words * 4);
                gdr_cull_result result = {got.visible, got.fading, got.clipping};
                gdr_cull_stats stats;
                gdr_error err;
                CHECK(gdr_cull_execute(scene, &vv, pools[p], &result, &stats, &err) == GDR_OK);
                bool same = memcmp(ref.visible, got.visible, words * 4) == 0 &&
                            memcmp(ref.fading, got.fading, words * 4) == 0 &&
                            memcmp(ref.clipping, got.clipping, words * 4) == 0;
                CHECK(same);
                if (!same) {
                    for (uint32_t i = 0; i < count; i++) {
                        bool a = gdr_cull_bit(ref.visible, i), b = gdr_cull_bit(got.visible, i);
                        if (a != b || gdr_cull_bit(ref.fading, i) != gdr_cull_bit(got.fading, i) ||
                            gdr_cull_bit(ref.clipping, i) != gdr_cull_bit(got.clipping, i)) {
                            fprintf(stderr, "  camera %u config %d pool %u brute %d: object %u ref %d got %d\n", cam,
                                    config, p, brute, i, a, b);
                            break;
                        }
                    }
                    return;
                }
                CHECK(stats.visible == ref_visible);
                CHECK(stats.visible + stats.hidden + stats.invalid + stats.frustum + stats.precomputed +
                          stats.distance + stats.screen_size + stats.clip_plane ==
                      count);
                if (!brute) {
                    /* the octree pass (run as tasks over subtrees) does the same work on any pool */
                    if (p == 0)
                        first_octree = stats;
                    CHECK(stats.nodes_tested == first_octree.nodes_tested &&
                          stats.nodes_inside == first_octree.nodes_inside &&
                          stats.objects_tested == first_octree.objects_tested);
                    inside_nodes += stats.nodes_inside;
                    if (count >= 1000 && !v.skip_frustum)
                        CHECK(stats.objects_tested < count); /* the octree spared some tests */
                }
                checks_run++;
            }
        }
    }
    printf("  %u objects, %u cameras: visible %.1f%%, fading %llu, needs clipping %llu, inside nodes %llu\n", count,
           cameras, 100.0 * (double)visible_total / ((double)count * cameras), (unsigned long long)fading_total,
           (unsigned long long)clipping_total, (unsigned long long)inside_nodes);
    if (count >= 1000) { /* the random cases must exercise every rule */
        CHECK(visible_total > 0);
        CHECK(fading_total > 0);
        CHECK(clipping_total > 0);
        CHECK(inside_nodes > 0);
    }
    outputs_free(&ref);
    outputs_free(&got);
}

int main(void)
{
    unsigned rng = 777;
    uint32_t thread_counts[] = {1, 2, 3, 8};
    gdr_thread_pool *pools[5] = {NULL};
    gdr_error err;
    for (int i = 0; i < 4; i++)
        CHECK(gdr_thread_pool_create(thread_counts[i], &pools[i + 1], &err) == GDR_OK);

    uint32_t sizes[] = {1, 31, 33, 1000, 20000, 100000};
    for (size_t s = 0; s < sizeof(sizes) / sizeof(sizes[0]); s++) {
        uint32_t count = sizes[s];
        float world = 100.0f;
        gdr_cull_object *objects = malloc(count * sizeof(*objects));
        for (uint32_t i = 0; i < count; i++)
            objects[i] = random_object(&rng, world);
        gdr_cull_scene_desc desc = {objects, count, 0, s % 2 ? 4 : 0};
        gdr_cull_scene *scene;
        CHECK(gdr_cull_scene_create(&desc, &scene, &err) == GDR_OK);
        printf("scene %u objects: %u octree nodes\n", count, gdr_cull_scene_node_count(scene));
        uint32_t cameras = count >= 100000 ? 12 : count >= 20000 ? 40 : 96;
        compare_scene(scene, objects, count, &rng, pools, 5, cameras, world);

        /* move a third of the objects (some far outside the root), re-flag others, compare again */
        for (uint32_t i = 0; i < count; i += 3) {
            gdr_cull_object o = random_object(&rng, i % 2 ? world : world * 2.5f);
            CHECK(gdr_cull_scene_update(scene, i, 1, &o, &err) == GDR_OK);
            objects[i] = o;
        }
        for (uint32_t i = 1; i < count; i += 7) {
            gdr_cull_object o = objects[i];
            o.flags ^= GDR_CULL_OBJECT_HIDDEN;
            CHECK(gdr_cull_scene_update(scene, i, 1, &o, &err) == GDR_OK);
            objects[i] = o;
        }
        compare_scene(scene, objects, count, &rng, pools, 5, cameras / 2, world);
        CHECK(gdr_cull_scene_update(scene, count, 1, objects, &err) == GDR_ERROR_INVALID_ARGUMENT);
        gdr_cull_scene_destroy(scene);
        free(objects);
    }

    /* an empty scene and a view with a singular matrix */
    gdr_cull_scene_desc empty = {0};
    gdr_cull_scene *scene;
    CHECK(gdr_cull_scene_create(&empty, &scene, &err) == GDR_OK);
    uint32_t word = 0;
    gdr_cull_view v = {0};
    gdr_cull_result result = {&word, NULL, NULL};
    CHECK(gdr_cull_execute(scene, &v, NULL, &result, NULL, &err) == GDR_ERROR_INVALID_ARGUMENT);
    v.view = gdr_mat4_identity();
    v.projection = gdr_perspective_reverse_z_infinite(1.0f, 1.0f, 0.1f);
    CHECK(gdr_cull_execute(scene, &v, NULL, &result, NULL, &err) == GDR_OK);
    gdr_cull_scene_destroy(scene);

    for (int i = 1; i < 5; i++)
        gdr_thread_pool_destroy(pools[i]);
    printf("%llu culling runs compared\n", (unsigned long long)checks_run);
    return test_finish("test_cull_scene");
}
