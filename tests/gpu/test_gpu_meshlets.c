/* The meshlet pipeline and the CPU-driven pipeline on the default device
 * (lavapipe in CI), validation on:
 *  - culling at every level (instances, clusters by frustum and cone, triangles) never changes the
 *    image, for random cameras, cameras inside meshes and grazing views;
 *  - the clusters the task shaders let through equal a CPU reference of the same tests;
 *  - the mesh pipeline draws the image of the indirect pipeline, up to a few pixels (see
 *    MAX_PATH_DIFFERENCE); the CPU-driven pipeline draws exactly the same image;
 *  - a device without mesh shaders falls back to the indirect pipeline and says why. */
#include <math.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gpu_test_util.h"
#include "math/cull_math.h"

#define WIDTH 192
#define HEIGHT 108
#define PI_F 3.14159265f
/* lavapipe's mesh-shader and vertex paths rasterise the same triangles from the same clip
 * coordinates, but clip large triangles crossing the near plane on different code paths, so a
 * pixel on a clipped edge (in practice: where the huge ground triangles meet the horizon) can
 * flip between two triangles. A handful at most; anything systematic would be hundreds. */
#define MAX_PATH_DIFFERENCE 8

static gdr_renderer *renderer;
static uint8_t *image_a, *image_b;

static bool render(const gdr_frame_desc *frame, uint8_t *pixels, gdr_frame_stats *stats)
{
    gdr_error err = {0};
    if (gdr_renderer_render(renderer, frame, 1, stats, &err) != GDR_OK ||
        gdr_renderer_read_color(renderer, pixels, &err) != GDR_OK) {
        fprintf(stderr, "render: %s\n", err.message);
        return false;
    }
    return true;
}

static uint32_t differing_pixels(const uint8_t *a, const uint8_t *b)
{
    uint32_t n = 0;
    for (size_t p = 0; p < (size_t)WIDTH * HEIGHT; p++)
        n += memcmp(a + 4 * p, b + 4 * p, 4) != 0;
    return n;
}

/* CPU reference of one cluster of one instance: +1 surely visible, -1 surely culled, 0 too close
 * to call (within float rounding of a boundary). */
static int cpu_cluster_visibility(const gdr_scene *scene, uint32_t index, uint32_t cluster, const gdr_camera *camera)
{
    const gdr_instance *instance = &scene->instances[index];
    const gdr_cluster *c = &scene->meshes[instance->mesh].clusters.clusters[cluster];
    gdr_mat4 view = gdr_view_from_pose(camera->position, camera->rotation);
    gdr_mat4 projection = gdr_perspective_reverse_z_infinite(camera->yfov, (float)WIDTH / HEIGHT, camera->znear);
    gdr_vec4 ijkl = gdr_frustum_symmetric(projection);
    gdr_vec3 center = gdr_mat4_transform_point(view, gdr_mat4_transform_point(instance->transform,
                                                                              (gdr_vec3){c->sphere.x, c->sphere.y, c->sphere.z}));
    float r = c->sphere.w * gdr_mat4_max_axis_scale(instance->transform);
    float slack = 1e-3f * (1.0f + r);
    bool surely_in = gdr_sphere_visible(ijkl, center, r - slack, camera->znear, INFINITY);
    bool maybe_in = gdr_sphere_visible(ijkl, center, r + slack, camera->znear, INFINITY);
    if (!maybe_in)
        return -1;
    gdr_mat4 inverse;
    if (!gdr_mat4_inverse(instance->transform, &inverse))
        return 0;
    gdr_vec3 eye = gdr_mat4_transform_point(inverse, camera->position);
    /* The cone test with the cutoff nudged both ways. */
    bool surely_back = gdr_cone_backfacing(c->cone_apex, c->cone_axis, c->cone_cutoff + 1e-4f, eye);
    bool maybe_back = gdr_cone_backfacing(c->cone_apex, c->cone_axis, c->cone_cutoff - 1e-4f, eye);
    if (surely_back)
        return -1;
    return surely_in && !maybe_back ? 1 : 0;
}

/* Pixels whose winner depends on rounding alone: they change in the indirect pipeline when the
 * camera moves by a millionth of its distance from the origin (far below a pixel on screen).
 * Overlapping coincident surfaces (CAD models are full of them) z-fight in a speckle pattern set
 * by the rounding of every vertex transform; the mesh pipeline does the same arithmetic with other
 * instructions (lavapipe compiles the mesh stage on its own), so its speckles differ too. */
static uint32_t tie_pixels(const gdr_camera *camera)
{
    gdr_frame_desc frame = {.camera = *camera, .read_back = true, .pipeline = GDR_PIPELINE_INDIRECT};
    gdr_frame_stats stats;
    bool ok = render(&frame, image_a, &stats);
    float shift = 1e-6f * (1.0f + gdr_vec3_length(camera->position));
    frame.camera.position.x += shift;
    frame.camera.position.y += shift;
    ok = ok && render(&frame, image_b, &stats);
    return ok ? differing_pixels(image_a, image_b) : 0;
}

/* Checks one camera on `scene`; `what` names it in failure messages. */
static void check_camera(const gdr_scene *scene, const gdr_camera *camera, const char *what)
{
    uint32_t ties = tie_pixels(camera);
    gdr_error err = {0};
    gdr_frame_stats culled, all;
    gdr_frame_desc frame = {.camera = *camera, .cull = GDR_CULL_ON, .read_back = true, .pipeline = GDR_PIPELINE_MESH,
                            .record_visible_meshlets = true};
    if (!render(&frame, image_a, &culled)) {
        CHECK(false);
        return;
    }
    /* The clusters drawn against the CPU reference. */
    uint64_t capacity = culled.meshlets_total ? culled.meshlets_total : 1;
    gdr_visible_meshlet *drawn = malloc(sizeof *drawn * capacity);
    uint32_t count = 0;
    CHECK(drawn && gdr_renderer_read_visible_meshlets(renderer, drawn, (uint32_t)capacity, &count, &err) == GDR_OK);
    qsort(drawn, count, sizeof *drawn, compare_visible_meshlets);
    CHECK(count == culled.meshlets_visible);
    CHECK(culled.meshlets_frustum_culled + culled.meshlets_cone_culled + culled.meshlets_visible == culled.meshlets_tested);
    CHECK(culled.task_overflow == 0);
    uint32_t cursor = 0, undecided = 0, wrong = 0, total = 0;
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        int instance = cpu_instance_visibility(scene, i, camera, (float)WIDTH / HEIGHT);
        const gdr_mesh_clusters *clusters = &scene->meshes[scene->instances[i].mesh].clusters;
        for (uint32_t k = 0; k < clusters->level0_cluster_count; k++, total++) {
            bool gpu = cursor < count && drawn[cursor].instance == i && drawn[cursor].meshlet == k;
            cursor += gpu;
            int cpu = instance < 0 ? -1 : cpu_cluster_visibility(scene, i, k, camera);
            if (instance == 0 && cpu > 0)
                cpu = 0;
            if (cpu == 0)
                undecided++;
            else if ((cpu > 0) != gpu && wrong++ < 5)
                fprintf(stderr, "%s: instance %u cluster %u: GPU says %s, CPU reference says %s\n", what, i, k,
                        gpu ? "drawn" : "culled", cpu > 0 ? "visible" : "culled");
        }
    }
    CHECK(cursor == count); /* nothing drawn twice or out of range */
    CHECK(wrong == 0);
    CHECK(undecided <= total / 100 + 2);
    free(drawn);

    /* Culling off at every level: the same picture. */
    frame.cull = GDR_CULL_OFF;
    frame.record_visible_meshlets = false;
    if (!render(&frame, image_b, &all)) {
        CHECK(false);
        return;
    }
    CHECK(all.meshlets_visible == all.meshlets_total);
    uint32_t differing = differing_pixels(image_a, image_b);
    if (differing) {
        fprintf(stderr, "%s: culling changed %u pixels\n", what, differing);
        CHECK(false);
    }
    /* The indirect pipeline: the same picture up to a few pixels. */
    frame.cull = GDR_CULL_ON;
    frame.pipeline = GDR_PIPELINE_INDIRECT;
    if (!render(&frame, image_b, &all)) {
        CHECK(false);
        return;
    }
    differing = differing_pixels(image_a, image_b);
    if (differing > MAX_PATH_DIFFERENCE + 2 * ties) {
        fprintf(stderr, "%s: mesh and indirect pipelines differ in %u pixels (decided by depth rounding: %u)\n", what,
                differing, ties);
        CHECK(false);
    } else if (ties) {
        printf("%s: mesh vs indirect %u pixels; pixels decided by depth rounding %u\n", what, differing, ties);
    }
    /* The CPU-driven pipeline: exactly the indirect pipeline's picture. */
    frame.pipeline = GDR_PIPELINE_CPU;
    if (!render(&frame, image_a, &all)) {
        CHECK(false);
        return;
    }
    differing = differing_pixels(image_a, image_b);
    if (differing) {
        fprintf(stderr, "%s: CPU-driven and indirect pipelines differ in %u pixels\n", what, differing);
        CHECK(false);
    }
}

static void check_demo(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    CHECK(gdr_scene_load("demo:instances=144,seed=5", NULL, &scene, &err) == GDR_OK);
    CHECK(scene && gdr_scene_build_clusters(scene, NULL, &err) == GDR_OK);
    renderer = scene ? gpu_test_renderer(WIDTH, HEIGHT, scene) : NULL;
    if (!renderer) {
        CHECK(false);
        gdr_scene_destroy(scene);
        return;
    }
    char what[64];
    unsigned rng = 4242;
    for (int n = 0; n < 16; n++) { /* anywhere, any direction */
        gdr_camera camera = test_look((gdr_vec3){test_random_range(&rng, -30, 30), test_random_range(&rng, 0.3f, 20),
                                            test_random_range(&rng, -30, 30)},
                                 test_random_range(&rng, -PI_F, PI_F), test_random_range(&rng, -1.2f, 0.3f),
                                 test_random_range(&rng, 0.4f, 1.6f), test_random_range(&rng, 0.05f, 1.0f));
        snprintf(what, sizeof what, "demo random camera %d", n);
        check_camera(scene, &camera, what);
    }
    for (int n = 0; n < 6; n++) { /* inside an instance's mesh, looking out */
        const gdr_instance *instance = &scene->instances[(n * 37) % scene->instance_count];
        gdr_vec4 b = scene->meshes[instance->mesh].bounds;
        gdr_vec3 center = gdr_mat4_transform_point(instance->transform, (gdr_vec3){b.x, b.y, b.z});
        gdr_camera camera = test_look(center, (float)n * 1.1f, -0.2f, 1.2f, 0.02f);
        snprintf(what, sizeof what, "demo camera inside instance %u", (n * 37) % scene->instance_count);
        check_camera(scene, &camera, what);
    }
    for (int n = 0; n < 6; n++) { /* grazing: just above the ground, and skimming past a mesh's side */
        const gdr_instance *instance = &scene->instances[(n * 53 + 7) % scene->instance_count];
        gdr_vec4 b = scene->meshes[instance->mesh].bounds;
        gdr_vec3 center = gdr_mat4_transform_point(instance->transform, (gdr_vec3){b.x, b.y, b.z});
        float r = b.w * gdr_mat4_max_axis_scale(instance->transform);
        gdr_camera camera = n < 2 ? test_look((gdr_vec3){center.x, 0.02f, center.z}, (float)n * 2.0f, 0.0f, 0.9f, 0.01f)
                                  : test_look((gdr_vec3){center.x + r * 1.01f, center.y, center.z + 3.0f * r}, 0.0f,
                                         0.0f, 0.5f, 0.05f);
        snprintf(what, sizeof what, "demo grazing camera %d", n);
        check_camera(scene, &camera, what);
    }
    gdr_renderer_destroy(renderer);
    renderer = NULL;

    /* No mesh shaders: the default falls back to the indirect pipeline and says why; asking for
     * the mesh pipeline is a clear error; the picture is the same. */
    gdr_renderer_desc desc = {.width = WIDTH, .height = HEIGHT, .validate = true, .disable_mesh_shaders = true};
    CHECK(gdr_renderer_create(&desc, &renderer, &err) == GDR_OK);
    CHECK(renderer && gdr_renderer_set_scene(renderer, scene, &err) == GDR_OK);
    if (renderer) {
        const char *why = NULL;
        CHECK(!gdr_renderer_has_mesh_pipeline(renderer, &why) && why && why[0]);
        gdr_frame_desc frame = {.camera = scene->cameras[0], .read_back = true};
        gdr_frame_stats stats;
        CHECK(render(&frame, image_a, &stats));
        CHECK(stats.pipeline == GDR_PIPELINE_INDIRECT && strstr(stats.pipeline_reason, "no mesh pipeline"));
        CHECK(stats.instances_visible > 0 && stats.validation_messages == 0);
        frame.pipeline = GDR_PIPELINE_MESH;
        CHECK_FAILS(gdr_renderer_render(renderer, &frame, 1, &stats, &err), err, GDR_ERROR_UNSUPPORTED);
        gdr_renderer_destroy(renderer);
        renderer = NULL;
    }
    gdr_scene_destroy(scene);
}

static void check_gltf(void)
{
    const char *path = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_load_options options = {.no_cache = 1, .no_progress = 1};
    if (gdr_scene_load(path, &options, &scene, &err) != GDR_OK) {
        fprintf(stderr, "%s: %s\n", path, err.message);
        CHECK(false);
        return;
    }
    CHECK(gdr_scene_build_clusters(scene, NULL, &err) == GDR_OK);
    renderer = gpu_test_renderer(WIDTH, HEIGHT, scene);
    if (!renderer) {
        CHECK(false);
        gdr_scene_destroy(scene);
        return;
    }
    /* The model's bounds from its instances' spheres. */
    gdr_vec3 center = {0, 0, 0};
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        gdr_vec4 b = scene->meshes[scene->instances[i].mesh].bounds;
        center = gdr_vec3_add(center, gdr_mat4_transform_point(scene->instances[i].transform, (gdr_vec3){b.x, b.y, b.z}));
    }
    center = gdr_vec3_scale(center, 1.0f / (float)(scene->instance_count ? scene->instance_count : 1));
    float radius = 0.0f;
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        gdr_vec4 b = scene->meshes[scene->instances[i].mesh].bounds;
        gdr_vec3 c = gdr_mat4_transform_point(scene->instances[i].transform, (gdr_vec3){b.x, b.y, b.z});
        float r = gdr_vec3_length(gdr_vec3_sub(c, center)) + b.w * gdr_mat4_max_axis_scale(scene->instances[i].transform);
        radius = r > radius ? r : radius;
    }
    char what[64];
    const float distances[6] = {2.2f, 1.4f, 0.9f, 0.5f, 0.25f, 0.05f}; /* in bounding radii: the last are inside */
    for (int n = 0; n < 6; n++) {
        float yaw = (float)n * 1.3f, pitch = -0.35f + 0.15f * (float)n;
        gdr_vec3 back = {sinf(yaw) * cosf(pitch), -sinf(pitch), cosf(yaw) * cosf(pitch)}; /* camera +Z in world */
        gdr_vec3 position = gdr_vec3_add(center, gdr_vec3_scale(back, distances[n] * radius));
        gdr_camera camera = test_look(position, yaw, pitch, 1.0f, 0.002f * radius);
        snprintf(what, sizeof what, "2CylinderEngine camera %d", n);
        check_camera(scene, &camera, what);
    }
    gdr_renderer_destroy(renderer);
    renderer = NULL;
    gdr_scene_destroy(scene);
}

int main(void)
{
    image_a = malloc(WIDTH * HEIGHT * 4);
    image_b = malloc(WIDTH * HEIGHT * 4);
    check_demo();
    check_gltf();
    free(image_a);
    free(image_b);
    return test_finish("test_gpu_meshlets");
}
