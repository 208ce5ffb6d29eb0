/* The LOD cut's per-group math, compiled by C (the CPU reference, src/geometry/lod_cut.c)
 * and GLSL (meshlet.task, drawcull) alike. The rule is documented in gdr/geometry.h ("The cut"). */
#ifndef GDR_LOD_MATH_H
#define GDR_LOD_MATH_H

#include "math/cull_math.h"
#include "math/glsl_c_bridge.h"

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

/* An upper bound on how much a transform's linear part (columns c0..c2) can stretch a distance:
 * its spectral norm, bounded by Gershgorin's circle theorem on the Gram matrix of the columns.
 * At least the largest axis scale; equal to it for rotation times scale (orthogonal columns), and
 * still a bound under shear, which nested glTF transforms produce. */
GDR_SHARED_FN float gdr_lod_transform_stretch(gdr_vec3 c0, gdr_vec3 c1, gdr_vec3 c2)
{
    float g00 = c0.x * c0.x + c0.y * c0.y + c0.z * c0.z;
    float g11 = c1.x * c1.x + c1.y * c1.y + c1.z * c1.z;
    float g22 = c2.x * c2.x + c2.y * c2.y + c2.z * c2.z;
    float g01 = gdr_abs(c0.x * c1.x + c0.y * c1.y + c0.z * c1.z);
    float g02 = gdr_abs(c0.x * c2.x + c0.y * c2.y + c0.z * c2.z);
    float g12 = gdr_abs(c1.x * c2.x + c1.y * c2.y + c1.z * c2.z);
    float row = gdr_max(g00 + g01 + g02, gdr_max(g11 + g01 + g12, g22 + g02 + g12));
    return gdr_sqrt(row);
}

/* Relative slack of the hierarchy's node test: covers the float rounding of the group tests it
 * stands for (docs/GEOMETRY.md, "LOD hierarchy"). */
#define GDR_LOD_NODE_SLACK (1.0f / 65536.0f)

/* Whether a node of the LOD hierarchy (gdr/geometry.h) may hold a cluster of the cut, for an
 * instance transform given by its columns c0..c3 (mesh -> world); false only when no cluster
 * below it is drawn by gdr_lod_cluster_drawn with the group tests of gdr_lod_group_projected_error
 * (computed in float, as the cluster tests compute them). `sphere` contains every group, refined
 * group and cluster sphere below; max_error bounds their groups' errors from above and
 * min_refined_error their refined groups' errors from below (0: a cluster below has none).
 * Skipped when
 *   every group below passes:  max_error * s / max(d - r, znear) * projection_scale <= threshold, or
 *   no refined group passes:   min_refined_error * s / max(d + r, znear) * projection_scale > threshold,
 * s the largest axis scale (as the group tests use), d the distance to the transformed centre, r
 * the radius times gdr_lod_transform_stretch, d -+ r widened by a bound on the rounding of the
 * group tests' own distances, and the quotients by GDR_LOD_NODE_SLACK. */
GDR_SHARED_FN bool gdr_lod_node_may_draw(gdr_vec4 sphere, float max_error, float min_refined_error, gdr_vec3 c0,
                                         gdr_vec3 c1, gdr_vec3 c2, gdr_vec3 c3, gdr_vec3 camera, float znear,
                                         float projection_scale, float threshold)
{
    float scale = gdr_max_axis_scale(c0, c1, c2);     /* what the group tests scale errors by */
    float stretch = gdr_lod_transform_stretch(c0, c1, c2); /* how far a group centre can move */
    gdr_vec3 centre;
    centre.x = c0.x * sphere.x + c1.x * sphere.y + c2.x * sphere.z + c3.x;
    centre.y = c0.y * sphere.x + c1.y * sphere.y + c2.y * sphere.z + c3.y;
    centre.z = c0.z * sphere.x + c1.z * sphere.y + c2.z * sphere.z + c3.z;
    float dx = centre.x - camera.x, dy = centre.y - camera.y, dz = centre.z - camera.z;
    float distance = gdr_sqrt(dx * dx + dy * dy + dz * dz);
    float radius = sphere.w * stretch;
    /* Every magnitude the group tests below round: the camera, the translation, and the
     * transformed centres (within stretch * (|centre| + 2 r) of the translation). */
    float magnitude = gdr_abs(camera.x) + gdr_abs(camera.y) + gdr_abs(camera.z);
    magnitude += gdr_abs(c3.x) + gdr_abs(c3.y) + gdr_abs(c3.z);
    magnitude += stretch * (gdr_abs(sphere.x) + gdr_abs(sphere.y) + gdr_abs(sphere.z) + 2.0f * sphere.w);
    float rounding = GDR_LOD_NODE_SLACK * magnitude;
    float nearest = gdr_max(distance - radius - rounding, znear);
    float farthest = gdr_max(distance + radius + rounding, znear);
    float upper = max_error * scale / nearest * projection_scale * (1.0f + GDR_LOD_NODE_SLACK);
    float lower = min_refined_error * scale / farthest * projection_scale * (1.0f - GDR_LOD_NODE_SLACK);
    bool every_group_passes = upper <= threshold;
    bool no_refined_group_passes = min_refined_error > 0.0f && lower > threshold;
    return !every_group_passes && !no_refined_group_passes;
}

#endif
