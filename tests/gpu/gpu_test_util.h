/* Helpers for GPU tests: a validated renderer on the default device (lavapipe in CI) and a CPU
 * reference of the instance culling test. */
#ifndef GDR_GPU_TEST_UTIL_H
#define GDR_GPU_TEST_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/gdr.h"
#include "test_util.h"

static inline gdr_renderer *gpu_test_renderer(uint32_t width, uint32_t height, const gdr_scene *scene)
{
    gdr_error err = {0};
    gdr_renderer *renderer = NULL;
    gdr_renderer_desc desc = {.width = width, .height = height, .validate = true};
    if (gdr_renderer_create(&desc, &renderer, &err) != GDR_OK || gdr_renderer_set_scene(renderer, scene, &err) != GDR_OK) {
        fprintf(stderr, "renderer: %s\n", err.message);
        gdr_renderer_destroy(renderer);
        return NULL;
    }
    return renderer;
}

/* CPU reference of one instance's culling test, with the sphere grown/shrunk by `slack` so that
 * cases within float rounding of the boundary can be told apart: returns +1 visible for sure,
 * -1 culled for sure, 0 too close to call. */
static inline int cpu_instance_visibility(const gdr_scene *scene, uint32_t index, const gdr_camera *camera, float aspect)
{
    const gdr_instance *instance = &scene->instances[index];
    gdr_vec4 b = scene->meshes[instance->mesh].bounds;
    gdr_mat4 view = gdr_view_from_pose(camera->position, camera->rotation);
    gdr_mat4 projection = gdr_perspective_reverse_z_infinite(camera->yfov, aspect, camera->znear);
    gdr_vec4 ijkl = gdr_frustum_symmetric(projection);
    gdr_vec3 world = gdr_mat4_transform_point(instance->transform, (gdr_vec3){b.x, b.y, b.z});
    gdr_vec3 c = gdr_mat4_transform_point(view, world);
    float r = b.w * gdr_mat4_max_axis_scale(instance->transform);
    float slack = 1e-3f * (1.0f + r);
    bool surely_visible = gdr_sphere_in_frustum(ijkl, c, r - slack, camera->znear, INFINITY);
    bool maybe_visible = gdr_sphere_in_frustum(ijkl, c, r + slack, camera->znear, INFINITY);
    return surely_visible ? 1 : maybe_visible ? 0 : -1;
}

/* A camera at `position` turned by `yaw` about +Y, then `pitch` about +X. */
static inline gdr_camera test_look(gdr_vec3 position, float yaw, float pitch, float yfov, float znear)
{
    gdr_quat qy = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, yaw);
    gdr_quat qp = gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, pitch);
    return (gdr_camera){.position = position, .rotation = gdr_quat_mul(qy, qp), .yfov = yfov, .znear = znear};
}

/* qsort order of gdr_visible_meshlet: by instance, then cluster. */
static inline int compare_visible_meshlets(const void *a, const void *b)
{
    const gdr_visible_meshlet *x = a, *y = b;
    if (x->instance != y->instance)
        return x->instance < y->instance ? -1 : 1;
    return x->meshlet < y->meshlet ? -1 : x->meshlet > y->meshlet;
}

static inline int compare_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* The paged caches opened for streamed renderers, closed when the test exits: a streamed renderer
 * reads its cache until it is destroyed. */
#define GPU_TEST_PAGED_CACHES 32
static gdr_paged_cache *gpu_test_paged_caches[GPU_TEST_PAGED_CACHES];

static inline void gpu_test_close_paged_caches(void)
{
    for (int i = 0; i < GPU_TEST_PAGED_CACHES; i++)
        gdr_paged_cache_close(gpu_test_paged_caches[i]), gpu_test_paged_caches[i] = NULL;
}

/* `path` opened as a paged cache for gdr_streaming_desc.cache; NULL, with a message, on failure. */
static inline gdr_paged_cache *gpu_test_paged_cache(const char *path)
{
    static int registered;
    if (!registered)
        registered = atexit(gpu_test_close_paged_caches) == 0;
    for (int i = 0; i < GPU_TEST_PAGED_CACHES; i++) {
        if (gpu_test_paged_caches[i])
            continue;
        gdr_error err = {0};
        if (gdr_paged_cache_open(path, &gpu_test_paged_caches[i], &err) != GDR_OK) {
            fprintf(stderr, "%s: %s\n", path, err.message);
            return NULL;
        }
        return gpu_test_paged_caches[i];
    }
    fprintf(stderr, "%s: more than %d paged caches open\n", path, GPU_TEST_PAGED_CACHES);
    return NULL;
}

#endif
