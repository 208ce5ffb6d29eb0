/* The LOD cut on the GPU, on the default device (lavapipe in CI), validation on:
 *  - the clusters the task shaders select equal the CPU reference cut (geometry/lod_cut.h) for many
 *    cameras, thresholds and instance transforms, and the discrete depth cut exactly;
 *  - no cracks: a closed dense mesh rendered at several thresholds shows no background inside the
 *    silhouette of its full-detail render (a rim of 2 px plus the threshold is ignored: the
 *    silhouette itself may move by up to the threshold);
 *  - the image approaches full detail as the threshold falls (PSNR reported), and the triangles
 *    drawn fall with distance;
 *  - a field of far instances, one to a few pixels across, draws a few triangles each, from the
 *    root chain (no hierarchy traversal), with the same pixels whether culling is on or off. */
#include <math.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "geometry/lod_cut.h"
#include "gpu_test_util.h"
#include "procedural/procedural_meshes.h"

#define WIDTH 256
#define HEIGHT 160
#define PI_F 3.14159265f

static gdr_renderer *renderer;
static uint8_t *image_full, *image_lod;

/* The cluster cut against its CPU reference: the point level below the root, which the instance
 * cull draws instead of the clusters of an instance within a pixel, is off here
 * (test_gpu_point_level checks it). */
static bool render(const gdr_frame_desc *frame, uint8_t *pixels, gdr_frame_stats *stats)
{
    gdr_error err = {0};
    gdr_frame_desc clusters_only = *frame;
    clusters_only.point_level = GDR_CULL_OFF;
    if (gdr_renderer_render(renderer, &clusters_only, 1, stats, &err) != GDR_OK ||
        (pixels && gdr_renderer_read_color(renderer, pixels, &err) != GDR_OK)) {
        fprintf(stderr, "render: %s\n", err.message);
        return false;
    }
    return true;
}

/* A scene of `count` instances of one closed dense mesh (an icosphere blob subdivided `levels`
 * times), in a row going away from the origin along -Z, with varied rotations and scales. */
static gdr_scene *blob_scene(uint32_t levels, uint32_t count)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    uint32_t mesh = 0;
    if (gdr_scene_create(&scene, &err) != GDR_OK || gdr_procedural_blob(scene, levels, &mesh, &err) != GDR_OK) {
        fprintf(stderr, "blob scene: %s\n", err.message);
        gdr_scene_destroy(scene);
        return NULL;
    }
    unsigned rng = 77;
    for (uint32_t i = 0; i < count; i++) {
        float scale = count == 1 ? 1.0f : test_random_range(&rng, 0.5f, 2.0f);
        gdr_quat q = gdr_quat_from_axis_angle(gdr_vec3_normalize((gdr_vec3){test_random_range(&rng, -1, 1), 1.0f,
                                                                             test_random_range(&rng, -1, 1)}),
                                              test_random_range(&rng, -PI_F, PI_F));
        gdr_vec3 position = count == 1 ? (gdr_vec3){0, 0, 0}
                                       : (gdr_vec3){test_random_range(&rng, -6, 6), test_random_range(&rng, -2, 2),
                                                    -3.0f - 4.0f * (float)i};
        gdr_instance instance = {.transform = gdr_mat4_from_trs(position, q, (gdr_vec3){scale, scale, scale}),
                                 .mesh = mesh, .material = GDR_NO_INDEX, .color = {0.8f, 0.7f, 0.5f, 1.0f}};
        if (gdr_scene_add_instance(scene, &instance, &err) != GDR_OK) {
            fprintf(stderr, "blob scene: %s\n", err.message);
            gdr_scene_destroy(scene);
            return NULL;
        }
    }
    gdr_lod_options options = {.no_progress = true};
    if (gdr_scene_build_lod(scene, &options, NULL, &err) != GDR_OK) {
        fprintf(stderr, "blob scene: %s\n", err.message);
        gdr_scene_destroy(scene);
        return NULL;
    }
    return scene;
}

/* Within float rounding of the threshold: the GPU may decide either way. */
static bool near_threshold(const gdr_mesh_clusters *c, uint32_t group, const gdr_lod_view *view)
{
    if (group == GDR_NO_INDEX || isinf(c->groups[group].error))
        return false;
    const float *m = view->transform.m;
    float e = gdr_lod_group_projected_error(c->groups[group].sphere, c->groups[group].error,
                                            (gdr_vec3){m[0], m[1], m[2]}, (gdr_vec3){m[4], m[5], m[6]},
                                            (gdr_vec3){m[8], m[9], m[10]}, (gdr_vec3){m[12], m[13], m[14]},
                                            view->camera_position, view->znear, gdr_lod_projection_scale(view));
    return fabsf(e - view->threshold) <= 1e-4f * view->threshold;
}

/* Renders `frame` (culling off: the LOD cut alone decides) and compares the clusters drawn with
 * the CPU reference cut of every instance. Returns the clusters drawn. */
static uint32_t check_cut(const gdr_scene *scene, const gdr_frame_desc *frame, const char *what)
{
    gdr_frame_stats stats;
    gdr_error err = {0};
    if (!render(frame, NULL, &stats)) {
        CHECK(false);
        return 0;
    }
    uint64_t capacity = 1;
    for (uint32_t i = 0; i < scene->instance_count; i++)
        capacity += scene->meshes[scene->instances[i].mesh].clusters.cluster_count;
    gdr_visible_meshlet *drawn = malloc(sizeof *drawn * capacity);
    uint32_t count = 0;
    CHECK(drawn && gdr_renderer_read_visible_meshlets(renderer, drawn, (uint32_t)capacity, &count, &err) == GDR_OK);
    if (!drawn)
        return 0;
    qsort(drawn, count, sizeof *drawn, compare_visible_meshlets);
    CHECK(stats.lod.applied == (frame->lod_fixed_depth ? frame->lod_depth > 0 : frame->lod_error_px > 0.0f));
    CHECK(count == stats.meshlets_visible);
    CHECK(stats.lod.meshlets_culled + stats.meshlets_visible == stats.meshlets_tested);
    uint64_t per_depth_clusters = 0, per_depth_triangles = 0;
    for (uint32_t d = 0; d < GDR_LOD_STATS_DEPTH_COUNT; d++) {
        per_depth_clusters += stats.lod.clusters_per_depth[d];
        per_depth_triangles += stats.lod.triangles_per_depth[d];
    }
    CHECK(per_depth_clusters == stats.meshlets_visible);
    CHECK(per_depth_triangles == stats.triangles); /* culling off: every triangle of a drawn cluster */

    gdr_mat4 projection = gdr_perspective_reverse_z_infinite(frame->camera.yfov, (float)WIDTH / HEIGHT,
                                                             frame->camera.znear);
    uint32_t cursor = 0, undecided = 0, wrong = 0, selected_total = 0;
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        const gdr_mesh_clusters *c = &scene->meshes[scene->instances[i].mesh].clusters;
        gdr_lod_view view = {.transform = scene->instances[i].transform, .camera_position = frame->camera.position,
                             .projection_y = fabsf(projection.m[5]), .viewport_height = HEIGHT,
                             .znear = frame->camera.znear, .threshold = frame->lod_error_px};
        uint8_t *selected = malloc(c->cluster_count ? c->cluster_count : 1);
        if (!selected)
            break;
        if (frame->lod_fixed_depth)
            gdr_lod_cut_select_depth(c, frame->lod_depth, selected);
        else
            gdr_lod_cut_select(c, &view, selected);
        for (uint32_t k = 0; k < c->cluster_count; k++) {
            bool gpu = cursor < count && drawn[cursor].instance == i && drawn[cursor].meshlet == k;
            cursor += gpu;
            selected_total += selected[k];
            bool unsure = !frame->lod_fixed_depth && (near_threshold(c, c->clusters[k].group, &view) ||
                                                      near_threshold(c, c->clusters[k].refined_group, &view));
            if (gpu != (selected[k] != 0)) {
                undecided += unsure;
                wrong += !unsure;
                if (!unsure && wrong <= 3)
                    fprintf(stderr, "%s: instance %u cluster %u: GPU %s, CPU reference %s\n", what, i, k,
                            gpu ? "drawn" : "not drawn", selected[k] ? "drawn" : "not drawn");
            }
        }
        free(selected);
    }
    CHECK(cursor == count); /* nothing drawn outside the clusters of the instances */
    CHECK(wrong == 0);
    if (wrong || undecided)
        fprintf(stderr, "%s: %u clusters differ from the reference, %u within rounding of the threshold\n", what, wrong,
                undecided);
    free(drawn);
    (void)selected_total;
    return count;
}

static void check_cuts(void)
{
    gdr_error err = {0};
    gdr_scene *scenes[2] = {blob_scene(4, 24), NULL};
    CHECK(gdr_scene_load("demo:instances=150,seed=11", NULL, &scenes[1], &err) == GDR_OK);
    const char *names[2] = {"blob row", "demo"};
    for (int s = 0; s < 2; s++) {
        gdr_scene *scene = scenes[s];
        renderer = scene ? gpu_test_renderer(WIDTH, HEIGHT, scene) : NULL;
        if (!renderer) {
            CHECK(false);
            gdr_scene_destroy(scene);
            continue;
        }
        unsigned rng = 99 + (unsigned)s;
        char what[96];
        const float thresholds[4] = {0.3f, 1.0f, 4.0f, 25.0f};
        for (int n = 0; n < 8; n++) {
            gdr_camera camera = test_look((gdr_vec3){test_random_range(&rng, -20, 20), test_random_range(&rng, 0.5f, 15),
                                                test_random_range(&rng, -20, 30)},
                                     test_random_range(&rng, -PI_F, PI_F), test_random_range(&rng, -0.8f, 0.3f),
                                     test_random_range(&rng, 0.4f, 1.4f), test_random_range(&rng, 0.05f, 0.5f));
            gdr_frame_desc frame = {.camera = camera, .cull = GDR_CULL_OFF, .pipeline = GDR_PIPELINE_MESH,
                                    .record_visible_meshlets = true, .lod_error_px = thresholds[n % 4]};
            snprintf(what, sizeof what, "%s camera %d threshold %g", names[s], n, (double)frame.lod_error_px);
            check_cut(scene, &frame, what);
            frame.lod_fixed_depth = true; /* the discrete cut, exactly */
            frame.lod_depth = (uint32_t)n % 5;
            snprintf(what, sizeof what, "%s camera %d depth %u", names[s], n, frame.lod_depth);
            check_cut(scene, &frame, what);
        }
        /* Far away: every instance takes the root shortcut, which draws the root groups. */
        gdr_frame_desc far = {.camera = test_look((gdr_vec3){0, 0, 4000}, 0, 0, 0.8f, 0.1f), .cull = GDR_CULL_OFF,
                              .pipeline = GDR_PIPELINE_MESH, .record_visible_meshlets = true, .lod_error_px = 1.0f};
        snprintf(what, sizeof what, "%s far away", names[s]);
        check_cut(scene, &far, what);
        /* The indirect pipeline draws full detail and says the cut was not applied. */
        gdr_frame_stats stats;
        gdr_frame_desc indirect = {.camera = far.camera, .pipeline = GDR_PIPELINE_INDIRECT, .lod_error_px = 1.0f};
        CHECK(render(&indirect, NULL, &stats) && !stats.lod.applied);
        gdr_renderer_destroy(renderer);
        renderer = NULL;
        gdr_scene_destroy(scene);
    }
}

static bool is_background(const uint8_t *image, size_t p, const uint8_t *background)
{
    return memcmp(image + 4 * p, background, 4) == 0;
}

/* Pixels inside the full-detail silhouette, `rim` pixels in from its edge, that show background. */
static uint32_t holes(const uint8_t *full, const uint8_t *lod, int rim)
{
    const uint8_t *background = full; /* the top-left corner: the blob is framed away from it */
    uint32_t n = 0;
    for (int y = rim; y < HEIGHT - rim; y++)
        for (int x = rim; x < WIDTH - rim; x++) {
            if (!is_background(lod, (size_t)y * WIDTH + x, background))
                continue;
            bool inside = true;
            for (int dy = -rim; dy <= rim && inside; dy++)
                for (int dx = -rim; dx <= rim && inside; dx++)
                    inside = !is_background(full, (size_t)(y + dy) * WIDTH + (x + dx), background);
            n += inside;
        }
    return n;
}

static double psnr(const uint8_t *a, const uint8_t *b)
{
    double sum = 0.0;
    for (size_t p = 0; p < (size_t)WIDTH * HEIGHT; p++)
        for (int k = 0; k < 3; k++) {
            double d = (double)a[4 * p + k] - (double)b[4 * p + k];
            sum += d * d;
        }
    double mse = sum / ((double)WIDTH * HEIGHT * 3);
    return mse > 0.0 ? 10.0 * log10(255.0 * 255.0 / mse) : INFINITY;
}

static void check_cracks_and_quality(void)
{
    gdr_scene *scene = blob_scene(6, 1);
    renderer = scene ? gpu_test_renderer(WIDTH, HEIGHT, scene) : NULL;
    if (!renderer) {
        CHECK(false);
        gdr_scene_destroy(scene);
        return;
    }
    const float distances[3] = {2.6f, 5.0f, 12.0f};
    const float thresholds[6] = {8.0f, 4.0f, 2.0f, 1.0f, 0.5f, 0.25f};
    for (int d = 0; d < 3; d++) {
        gdr_camera camera = test_look((gdr_vec3){0.3f, 0.4f, distances[d]}, 0.0f, 0.0f, 0.9f, 0.05f);
        gdr_frame_desc frame = {.camera = camera, .read_back = true, .pipeline = GDR_PIPELINE_MESH};
        gdr_frame_stats stats;
        CHECK(render(&frame, image_full, &stats));
        uint64_t full_triangles = stats.triangles;
        double previous = 0.0;
        printf("blob at distance %.1f: full detail %llu triangles;", (double)distances[d],
               (unsigned long long)full_triangles);
        for (int t = 0; t < 6; t++) {
            frame.lod_error_px = thresholds[t];
            CHECK(render(&frame, image_lod, &stats));
            int rim = 2 + (int)ceilf(thresholds[t]);
            uint32_t crack_pixels = holes(image_full, image_lod, rim);
            if (crack_pixels)
                fprintf(stderr, "blob at %.1f, threshold %g: %u background pixels inside the silhouette\n",
                        (double)distances[d], (double)thresholds[t], crack_pixels);
            CHECK(crack_pixels == 0);
            double q = psnr(image_full, image_lod);
            printf(" %g px: %.1f dB, %llu triangles;", (double)thresholds[t], q, (unsigned long long)stats.triangles);
            /* Closer to full detail as the threshold falls (a little slack for pixels that flip). */
            CHECK(t == 0 || q >= previous - 0.5);
            if (thresholds[t] == 1.0f)
                CHECK(q >= 30.0);
            previous = q;
        }
        printf("\n");
    }
    /* Triangles drawn fall with distance. */
    uint64_t previous = UINT64_MAX, first = 0, last = 0;
    printf("triangles drawn at 1 px by distance:");
    for (int d = 0; d < 7; d++) {
        float distance = 3.0f * (float)(1 << d);
        gdr_frame_desc frame = {.camera = test_look((gdr_vec3){0, 0, distance}, 0, 0, 0.9f, 0.05f), .cull = GDR_CULL_OFF,
                                .pipeline = GDR_PIPELINE_MESH, .lod_error_px = 1.0f};
        gdr_frame_stats stats;
        CHECK(render(&frame, NULL, &stats));
        printf(" %g: %llu", (double)distance, (unsigned long long)stats.triangles);
        CHECK(stats.triangles <= previous);
        previous = stats.triangles;
        first = d == 0 ? stats.triangles : first;
        last = stats.triangles;
    }
    printf("\n");
    CHECK(last * 8 < first);
    gdr_renderer_destroy(renderer);
    renderer = NULL;
    gdr_scene_destroy(scene);
}

/* A field of `count` instances of one blob (icosphere subdivided `levels` times) in front of the
 * camera at the origin looking down -Z, at distances where each projects to `from` .. `to` pixels
 * across (log-uniform), at 1 px scale p_scale (pixels per unit at distance 1). */
static gdr_scene *far_field_scene(uint32_t levels, uint32_t count, float from, float to, float p_scale)
{
    gdr_scene *scene = blob_scene(levels, 0);
    if (!scene)
        return NULL;
    gdr_error err = {0};
    float radius = scene->meshes[0].bounds.w;
    unsigned rng = 5;
    for (uint32_t i = 0; i < count; i++) {
        float pixels = from * powf(to / from, test_random(&rng));
        float distance = 2.0f * radius * p_scale / pixels;
        gdr_vec3 dir = gdr_vec3_normalize((gdr_vec3){test_random_range(&rng, -0.5f, 0.5f),
                                                      test_random_range(&rng, -0.3f, 0.3f), -1.0f});
        gdr_quat q = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, test_random_range(&rng, -PI_F, PI_F));
        gdr_instance instance = {.transform = gdr_mat4_from_trs(gdr_vec3_scale(dir, distance), q, (gdr_vec3){1, 1, 1}),
                                 .mesh = 0, .material = GDR_NO_INDEX, .color = {0.8f, 0.7f, 0.5f, 1.0f}};
        if (gdr_scene_add_instance(scene, &instance, &err) != GDR_OK) {
            fprintf(stderr, "far field: %s\n", err.message);
            gdr_scene_destroy(scene);
            return NULL;
        }
    }
    return scene;
}

/* The bounding sphere of instance i, projected: its diameter in pixels. */
static float projected_diameter(const gdr_scene *scene, uint32_t i, const gdr_camera *camera, float p_scale)
{
    const gdr_instance *instance = &scene->instances[i];
    gdr_vec4 b = scene->meshes[instance->mesh].bounds;
    gdr_vec3 centre = gdr_mat4_transform_point(instance->transform, (gdr_vec3){b.x, b.y, b.z});
    return 2.0f * b.w * p_scale / gdr_vec3_length(gdr_vec3_sub(centre, camera->position));
}

/* Far instances cost a few triangles: the DAG goes on below one cluster, and the instance cull
 * takes the cut from the root chain without traversing the hierarchy; the GPU cut equals the CPU
 * reference at every level of the chain, and culling and occlusion culling change no pixel. */
static void check_far_field(void)
{
    gdr_camera camera = test_look((gdr_vec3){0, 0, 0}, 0.0f, 0.0f, 0.9f, 0.1f);
    gdr_mat4 projection = gdr_perspective_reverse_z_infinite(camera.yfov, (float)WIDTH / HEIGHT, camera.znear);
    float p_scale = fabsf(projection.m[5]) * 0.5f * HEIGHT;
    gdr_scene *scene = far_field_scene(6, 300, 0.5f, 6.0f, p_scale);
    renderer = scene ? gpu_test_renderer(WIDTH, HEIGHT, scene) : NULL;
    if (!renderer) {
        CHECK(false);
        gdr_scene_destroy(scene);
        return;
    }
    const gdr_mesh_clusters *c = &scene->meshes[0].clusters;
    uint32_t root_triangles = c->clusters[c->groups[c->group_count - 1].first_cluster].triangle_count;
    printf("far field: blob of %u triangles, DAG depth %u, root of %u triangles\n", scene->meshes[0].index_count / 3,
           c->dag_depth, root_triangles);
    CHECK(c->groups[c->group_count - 1].cluster_count == 1 && root_triangles <= GDR_LOD_DEFAULT_ROOT_TRIANGLES);
    const float thresholds[3] = {0.5f, 1.0f, 2.0f};
    char what[64];
    for (int t = 0; t < 3; t++) {
        gdr_frame_desc frame = {.camera = camera, .cull = GDR_CULL_OFF, .pipeline = GDR_PIPELINE_MESH,
                                .record_visible_meshlets = true, .lod_error_px = thresholds[t]};
        snprintf(what, sizeof what, "far field threshold %g", (double)thresholds[t]);
        check_cut(scene, &frame, what);
    }
    /* At 1 px: triangles per instance, from the clusters drawn. */
    gdr_frame_desc frame = {.camera = camera, .pipeline = GDR_PIPELINE_MESH, .record_visible_meshlets = true,
                            .lod_error_px = 1.0f, .read_back = true};
    gdr_frame_stats stats;
    gdr_error err = {0};
    uint32_t capacity = scene->instance_count * c->cluster_count, count = 0;
    gdr_visible_meshlet *drawn = malloc(sizeof *drawn * capacity);
    uint32_t *triangles = calloc(scene->instance_count, sizeof *triangles);
    CHECK(drawn && triangles && render(&frame, image_lod, &stats) &&
          gdr_renderer_read_visible_meshlets(renderer, drawn, capacity, &count, &err) == GDR_OK);
    for (uint32_t k = 0; drawn && triangles && k < count; k++)
        triangles[drawn[k].instance] += c->clusters[drawn[k].meshlet].triangle_count;
    uint32_t small = 0, worst_small = 0;
    uint64_t total = 0;
    for (uint32_t i = 0; triangles && i < scene->instance_count; i++) {
        total += triangles[i];
        if (projected_diameter(scene, i, &camera, p_scale) <= 2.0f) {
            small++;
            worst_small = triangles[i] > worst_small ? triangles[i] : worst_small;
        }
    }
    printf("far field at 1 px: %u instances, %.1f triangles each on average; %u of them at most 2 px across draw "
           "at most %u triangles; %llu hierarchy nodes tested\n",
           scene->instance_count, (double)total / scene->instance_count, small, worst_small,
           (unsigned long long)stats.traversal.nodes_tested);
    CHECK(small > 50 && worst_small <= 8);
    CHECK(total <= 16ull * scene->instance_count);
    /* Every instance's cut lies on the root chain: none is left to the traversal. */
    CHECK(stats.traversal.nodes_tested == 0);
    /* Culling (frustum, cone, occlusion) is conservative for the small clusters: the same pixels. */
    frame.cull = GDR_CULL_OFF;
    frame.record_visible_meshlets = false;
    CHECK(render(&frame, image_full, NULL));
    CHECK(memcmp(image_full, image_lod, (size_t)WIDTH * HEIGHT * 4) == 0);
    frame.cull = GDR_CULL_ON;
    frame.occlusion = GDR_CULL_ON;
    CHECK(render(&frame, NULL, NULL) && render(&frame, image_lod, NULL));
    CHECK(memcmp(image_full, image_lod, (size_t)WIDTH * HEIGHT * 4) == 0);
    free(drawn);
    free(triangles);
    gdr_renderer_destroy(renderer);
    renderer = NULL;
    gdr_scene_destroy(scene);
}

int main(void)
{
    image_full = malloc(WIDTH * HEIGHT * 4);
    image_lod = malloc(WIDTH * HEIGHT * 4);
    check_far_field();
    check_cuts();
    check_cracks_and_quality();
    free(image_full);
    free(image_lod);
    return test_finish("test_gpu_lod");
}
