#include <math.h>

#include "gdr/math.h"

gdr_quat gdr_quat_identity(void) { return (gdr_quat){0.0f, 0.0f, 0.0f, 1.0f}; }

gdr_quat gdr_quat_from_axis_angle(gdr_vec3 axis, float radians)
{
    gdr_vec3 n = gdr_vec3_normalize(axis);
    float s = sinf(radians * 0.5f);
    return (gdr_quat){n.x * s, n.y * s, n.z * s, cosf(radians * 0.5f)};
}

gdr_quat gdr_quat_mul(gdr_quat a, gdr_quat b)
{
    return (gdr_quat){
        a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
        a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
        a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
        a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
    };
}

gdr_quat gdr_quat_normalize(gdr_quat q)
{
    float length = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    if (length == 0.0f)
        return gdr_quat_identity();
    float inv = 1.0f / length;
    return (gdr_quat){q.x * inv, q.y * inv, q.z * inv, q.w * inv};
}

gdr_vec3 gdr_quat_rotate(gdr_quat q, gdr_vec3 v)
{
    /* v' = v + 2w (u x v) + 2 u x (u x v), u = (x, y, z) */
    gdr_vec3 u = {q.x, q.y, q.z};
    gdr_vec3 t = gdr_vec3_scale(gdr_vec3_cross(u, v), 2.0f);
    return gdr_vec3_add(gdr_vec3_add(v, gdr_vec3_scale(t, q.w)), gdr_vec3_cross(u, t));
}
