/* The LOD cut's per-group math (issue 5), compiled by C (the CPU reference, src/geometry/lod_cut.c)
 * and GLSL (meshlet.task, drawcull) alike. The rule is documented in gdr/geometry.h ("The cut"). */
#ifndef GDR_LOD_MATH_H
#define GDR_LOD_MATH_H

#include "cull_math.h"
#include "glsl_c_bridge.h"

/* Projected error in pixels of a group whose world-space sphere has centre `centre` and radius
 * `radius` and whose world-space error is `error`, seen from `camera`:
 *   error / max(distance(camera, centre) - radius, znear) * projection_scale,
 * projection_scale = P[1][1] * 0.5 * viewport height in pixels. An error of INFINITY (the root)
 * gives INFINITY. */
GDR_SHARED_FN float gdr_lod_projected_error(gdr_vec3 centre, float radius, float error, gdr_vec3 camera, float znear,
                                            float projection_scale)
{
    float dx = centre.x - camera.x, dy = centre.y - camera.y, dz = centre.z - camera.z;
    float distance = gdr_sqrt(dx * dx + dy * dy + dz * dz);
    return error / gdr_max(distance - radius, znear) * projection_scale;
}

/* The same for a mesh-space group sphere (centre xyz, radius w) and error under an instance
 * transform given by its columns c0..c3 (mesh -> world): the centre goes through the transform,
 * radius and error grow by its largest axis scale. */
GDR_SHARED_FN float gdr_lod_group_projected_error(gdr_vec4 sphere, float error, gdr_vec3 c0, gdr_vec3 c1, gdr_vec3 c2,
                                                  gdr_vec3 c3, gdr_vec3 camera, float znear, float projection_scale)
{
    float scale = gdr_max_axis_scale(c0, c1, c2);
    gdr_vec3 centre;
    centre.x = c0.x * sphere.x + c1.x * sphere.y + c2.x * sphere.z + c3.x;
    centre.y = c0.y * sphere.x + c1.y * sphere.y + c2.y * sphere.z + c3.y;
    centre.z = c0.z * sphere.x + c1.z * sphere.y + c2.z * sphere.z + c3.z;
    return gdr_lod_projected_error(centre, sphere.w * scale, error * scale, camera, znear, projection_scale);
}

/* The cut rule for one cluster, given whether the group it was made from passes (true for
 * level 0) and whether the group it is part of passes (false without a group):
 * passes(g) = projected error of g <= threshold. */
GDR_SHARED_FN bool gdr_lod_cluster_drawn(bool refined_group_passes, bool group_passes)
{
    return refined_group_passes && !group_passes;
}

#endif
