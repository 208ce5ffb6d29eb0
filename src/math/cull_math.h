/* Culling tests shared by the CPU (src/math, tests) and the GPU (culling shaders): one definition.
 * Seed 001 / seed 000, with the sign of the near-plane test written for a camera looking down -Z. */
#ifndef GDR_CULL_MATH_H
#define GDR_CULL_MATH_H

#include "math/glsl_c_bridge.h"

/* Sphere (view-space centre c, radius r) against the symmetric frustum (i, j, k, l):
 *   left/right:  j*z >= |i*x| - r      bottom/top:  l*z >= |k*y| - r
 *   near:        c.z - r <= -znear     (some part of the sphere is beyond the near plane)
 *   far:         c.z + r >= -zfar      (zfar = +inf for the infinite projection)  */
GDR_SHARED_FN bool gdr_sphere_visible(gdr_vec4 ijkl, gdr_vec3 c, float r, float znear, float zfar)
{
    bool visible = (c.z - r <= -znear) && (c.z + r >= -zfar);
    visible = visible && (ijkl.y * c.z >= gdr_abs(ijkl.x * c.x) - r);
    visible = visible && (ijkl.w * c.z >= gdr_abs(ijkl.z * c.y) - r);
    return visible;
}

/* The same with the side planes moved out by offset (x, y): j*z + offset.x >= |i*x| - r and
 * l*z + offset.y >= |k*y| - r. An orthographic view's box is (i, j, k, l) = (1, 0, 1, 0) with
 * offset (xmag, ymag); a perspective frustum's offset is (0, 0), gdr_sphere_visible. */
GDR_SHARED_FN bool gdr_sphere_visible_offset(gdr_vec4 ijkl, gdr_vec2 offset, gdr_vec3 c, float r, float znear,
                                             float zfar)
{
    bool visible = (c.z - r <= -znear) && (c.z + r >= -zfar);
    visible = visible && (ijkl.y * c.z + offset.x >= gdr_abs(ijkl.x * c.x) - r);
    visible = visible && (ijkl.w * c.z + offset.y >= gdr_abs(ijkl.z * c.y) - r);
    return visible;
}

/* Largest length of a transform's three basis columns: how much a bounding sphere's radius must
 * grow under that transform (seed 001: the radius is scaled by the largest axis scale). */
GDR_SHARED_FN float gdr_max_axis_scale(gdr_vec3 c0, gdr_vec3 c1, gdr_vec3 c2)
{
    float s0 = c0.x * c0.x + c0.y * c0.y + c0.z * c0.z;
    float s1 = c1.x * c1.x + c1.y * c1.y + c1.z * c1.z;
    float s2 = c2.x * c2.x + c2.y * c2.y + c2.z * c2.z;
    return gdr_sqrt(gdr_max(s0, gdr_max(s1, s2)));
}

/* Cluster normal cone (meshoptimizer's meshopt_Bounds, with apex), everything in mesh space: every
 * triangle of the cluster faces away from a camera at p when dot(normalize(apex - p), axis) >= cutoff.
 * The test holds in mesh space for any invertible transform with a positive determinant (back-facing
 * is preserved), so the camera is brought into mesh space rather than the cone into world space. */
GDR_SHARED_FN bool gdr_cone_backfacing(gdr_vec3 apex, gdr_vec3 axis, float cutoff, gdr_vec3 camera)
{
    float dx = apex.x - camera.x, dy = apex.y - camera.y, dz = apex.z - camera.z;
    float d = dx * axis.x + dy * axis.y + dz * axis.z;
    return d >= cutoff * gdr_sqrt(dx * dx + dy * dy + dz * dz);
}

#endif
