/* The LOD cut on the CPU: the reference the GPU selection is checked against (issue 5).
 *
 * The first part is written so that GLSL can compile it too (plain float expressions through
 * src/shaders/shared/glsl_c_bridge.h): move it under src/shaders/shared when a shader needs it.
 * The rule itself is documented in gdr/geometry.h ("The cut"). */
#ifndef GDR_GEOMETRY_LOD_CUT_H
#define GDR_GEOMETRY_LOD_CUT_H

#include "shaders/shared/cull_math.h"
#include "shaders/shared/glsl_c_bridge.h"

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

#ifndef GDR_GLSL
#include <stdint.h>

#include "gdr/geometry.h"
#include "gdr/math.h"

/* One view of one mesh instance. */
typedef struct gdr_lod_view {
    gdr_mat4 transform;       /* mesh space -> world space */
    gdr_vec3 camera_position; /* world space */
    float projection_y;       /* P[1][1] of the projection (1 / tan(fovy / 2)) */
    float viewport_height;    /* pixels */
    float znear;              /* > 0 */
    float threshold;          /* pixels, finite; 0 draws level 0 */
} gdr_lod_view;

/* projection_y * 0.5 * viewport_height. */
float gdr_lod_projection_scale(const gdr_lod_view *view);

/* Whether group `group` passes for `view`: its projected error is <= threshold. The threshold
 * must be finite: the root's projected error is INFINITY and never passes. */
bool gdr_lod_group_passes(const gdr_mesh_clusters *clusters, uint32_t group, const gdr_lod_view *view);

/* The cut: selected[i] = 1 for each cluster i the rule draws, else 0 (cluster_count bytes).
 * Returns the number of clusters selected. */
uint32_t gdr_lod_cut_select(const gdr_mesh_clusters *clusters, const gdr_lod_view *view, uint8_t *selected);

/* The discrete debug cut at DAG depth N (gdr/geometry.h): the same rule with
 * passes(g) = (depth(g) < depth and g is not the root). */
uint32_t gdr_lod_cut_select_depth(const gdr_mesh_clusters *clusters, uint32_t depth, uint8_t *selected);
#endif

#endif
