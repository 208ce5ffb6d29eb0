#include <math.h>

#include "gdr/math.h"

#define AT(a, row, col) ((a).m[(col) * 4 + (row)])

gdr_mat4 gdr_view_from_pose(gdr_vec3 position, gdr_quat rotation)
{
    /* The camera's transform is rigid (R, p); its inverse is (R^T, -R^T p). */
    gdr_mat4 r = gdr_mat4_transpose(gdr_mat4_from_quat(gdr_quat_normalize(rotation)));
    gdr_vec3 t = gdr_mat4_transform_point(r, position);
    AT(r, 0, 3) = -t.x;
    AT(r, 1, 3) = -t.y;
    AT(r, 2, 3) = -t.z;
    return r;
}

static gdr_mat4 perspective_base(float fovy_radians, float aspect)
{
    float f = 1.0f / tanf(fovy_radians * 0.5f);
    gdr_mat4 p = {{0}};
    AT(p, 0, 0) = f / aspect;
    AT(p, 1, 1) = f;
    AT(p, 3, 2) = -1.0f;
    return p;
}

gdr_mat4 gdr_perspective_reverse_z_infinite(float fovy_radians, float aspect, float znear)
{
    gdr_mat4 p = perspective_base(fovy_radians, aspect);
    AT(p, 2, 3) = znear;
    return p;
}

gdr_mat4 gdr_perspective_reverse_z(float fovy_radians, float aspect, float znear, float zfar)
{
    gdr_mat4 p = perspective_base(fovy_radians, aspect);
    AT(p, 2, 2) = znear / (zfar - znear);
    AT(p, 2, 3) = zfar * znear / (zfar - znear);
    return p;
}

gdr_mat4 gdr_orthographic_reverse_z(float xmag, float ymag, float znear, float zfar)
{
    gdr_mat4 p = {{0}};
    AT(p, 0, 0) = 1.0f / xmag;
    AT(p, 1, 1) = 1.0f / ymag;
    AT(p, 2, 2) = 1.0f / (zfar - znear);
    AT(p, 2, 3) = zfar / (zfar - znear);
    AT(p, 3, 3) = 1.0f;
    return p;
}

gdr_viewport gdr_viewport_flip_y(float width, float height)
{
    return (gdr_viewport){0.0f, height, width, -height};
}
