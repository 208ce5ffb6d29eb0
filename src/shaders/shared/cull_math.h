/* Culling tests shared by the CPU (src/math, tests) and the GPU (culling shaders): one definition.
 * Seed 001 / seed 000, with the sign of the near-plane test written for a camera looking down -Z. */
#ifndef GDR_CULL_MATH_H
#define GDR_CULL_MATH_H

#include "glsl_c_bridge.h"

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

#endif
