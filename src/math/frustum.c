#include <math.h>

#include "gdr/math.h"
#include "math/cull_math.h"

gdr_vec4 gdr_frustum_symmetric(gdr_mat4 projection)
{
    /* Gribb-Hartmann: plane = row3 + row0 (left), row3 + row1 (bottom). Row r of a
     * column-major matrix is (m[r], m[4 + r], m[8 + r], m[12 + r]). */
    const float *m = projection.m;
    gdr_vec3 left = {m[3] + m[0], m[7] + m[4], m[11] + m[8]};
    gdr_vec3 bottom = {m[3] + m[1], m[7] + m[5], m[11] + m[9]};
    float left_length = gdr_vec3_length(left);
    float bottom_length = gdr_vec3_length(bottom);
    return (gdr_vec4){left.x / left_length, left.z / left_length, bottom.y / bottom_length,
                      bottom.z / bottom_length};
}

bool gdr_sphere_in_frustum(gdr_vec4 ijkl, gdr_vec3 center_view, float radius, float znear, float zfar)
{
    return gdr_sphere_visible(ijkl, center_view, radius, znear, zfar);
}
