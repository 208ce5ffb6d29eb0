/* A default camera for scenes that bring none: it frames every instance's bounding sphere. */
#include <math.h>

#include "gdr/scene.h"

gdr_camera gdr_scene_framing_camera(const gdr_scene *scene)
{
    gdr_vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        const gdr_instance *instance = &scene->instances[i];
        gdr_vec4 b = scene->meshes[instance->mesh].bounds;
        gdr_vec3 c = gdr_mat4_transform_point(instance->transform, (gdr_vec3){b.x, b.y, b.z});
        float r = b.w * gdr_mat4_max_axis_scale(instance->transform);
        lo = (gdr_vec3){fminf(lo.x, c.x - r), fminf(lo.y, c.y - r), fminf(lo.z, c.z - r)};
        hi = (gdr_vec3){fmaxf(hi.x, c.x + r), fmaxf(hi.y, c.y + r), fmaxf(hi.z, c.z + r)};
    }
    gdr_vec3 center = {0, 0, 0};
    float radius = 1.0f;
    if (scene->instance_count > 0) {
        center = gdr_vec3_scale(gdr_vec3_add(lo, hi), 0.5f);
        radius = fmaxf(0.5f * gdr_vec3_length(gdr_vec3_sub(hi, lo)), 1e-3f);
    }
    /* Look at the centre from the front (+Z), a little above, far enough that the sphere fits a
     * 45-degree vertical field of view. */
    const float yfov = 45.0f * 3.14159265f / 180.0f, pitch = -0.35f;
    float distance = radius / sinf(0.5f * yfov) * 1.05f;
    gdr_quat rotation = gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, pitch);
    gdr_vec3 back = gdr_quat_rotate(rotation, (gdr_vec3){0, 0, distance});
    gdr_camera camera = {.name = "framing", .position = gdr_vec3_add(center, back), .rotation = rotation,
                         .yfov = yfov, .znear = fmaxf(distance - radius, distance * 1e-3f) * 0.5f,
                         .zfar = 0.0f, .aspect = 0.0f};
    if (camera.znear > 0.1f)
        camera.znear = 0.1f;
    return camera;
}
