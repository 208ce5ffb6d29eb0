#include <math.h>
#include <string.h>

#include "gdr/math.h"
#include "math/cull_math.h"

#define AT(a, row, col) ((a).m[(col) * 4 + (row)])

gdr_mat4 gdr_mat4_identity(void)
{
    gdr_mat4 r = {{0}};
    AT(r, 0, 0) = AT(r, 1, 1) = AT(r, 2, 2) = AT(r, 3, 3) = 1.0f;
    return r;
}

gdr_mat4 gdr_mat4_mul(gdr_mat4 a, gdr_mat4 b)
{
    gdr_mat4 r;
    for (int col = 0; col < 4; col++)
        for (int row = 0; row < 4; row++) {
            float sum = 0.0f;
            for (int k = 0; k < 4; k++)
                sum += AT(a, row, k) * AT(b, k, col);
            AT(r, row, col) = sum;
        }
    return r;
}

gdr_mat4 gdr_mat4_transpose(gdr_mat4 a)
{
    gdr_mat4 r;
    for (int col = 0; col < 4; col++)
        for (int row = 0; row < 4; row++)
            AT(r, row, col) = AT(a, col, row);
    return r;
}

bool gdr_mat4_inverse(gdr_mat4 a, gdr_mat4 *out)
{
    /* Gauss-Jordan elimination with partial pivoting, in double precision. */
    double w[4][8];
    for (int row = 0; row < 4; row++)
        for (int col = 0; col < 4; col++) {
            w[row][col] = AT(a, row, col);
            w[row][col + 4] = row == col ? 1.0 : 0.0;
        }
    for (int col = 0; col < 4; col++) {
        int pivot = col;
        for (int row = col + 1; row < 4; row++)
            if (fabs(w[row][col]) > fabs(w[pivot][col]))
                pivot = row;
        if (fabs(w[pivot][col]) < 1e-30)
            return false;
        if (pivot != col) {
            double tmp[8];
            memcpy(tmp, w[col], sizeof tmp);
            memcpy(w[col], w[pivot], sizeof tmp);
            memcpy(w[pivot], tmp, sizeof tmp);
        }
        double inv = 1.0 / w[col][col];
        for (int k = 0; k < 8; k++)
            w[col][k] *= inv;
        for (int row = 0; row < 4; row++) {
            if (row == col)
                continue;
            double factor = w[row][col];
            for (int k = 0; k < 8; k++)
                w[row][k] -= factor * w[col][k];
        }
    }
    for (int row = 0; row < 4; row++)
        for (int col = 0; col < 4; col++)
            AT(*out, row, col) = (float)w[row][col + 4];
    return true;
}

gdr_vec4 gdr_mat4_mul_vec4(gdr_mat4 a, gdr_vec4 v)
{
    float in[4] = {v.x, v.y, v.z, v.w}, o[4];
    for (int row = 0; row < 4; row++)
        o[row] = AT(a, row, 0) * in[0] + AT(a, row, 1) * in[1] + AT(a, row, 2) * in[2] +
                 AT(a, row, 3) * in[3];
    return (gdr_vec4){o[0], o[1], o[2], o[3]};
}

gdr_vec3 gdr_mat4_transform_point(gdr_mat4 a, gdr_vec3 p)
{
    gdr_vec4 r = gdr_mat4_mul_vec4(a, (gdr_vec4){p.x, p.y, p.z, 1.0f});
    return (gdr_vec3){r.x, r.y, r.z};
}

gdr_mat4 gdr_mat4_from_quat(gdr_quat q)
{
    float xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
    float xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
    float wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
    gdr_mat4 r = gdr_mat4_identity();
    AT(r, 0, 0) = 1.0f - 2.0f * (yy + zz);
    AT(r, 0, 1) = 2.0f * (xy - wz);
    AT(r, 0, 2) = 2.0f * (xz + wy);
    AT(r, 1, 0) = 2.0f * (xy + wz);
    AT(r, 1, 1) = 1.0f - 2.0f * (xx + zz);
    AT(r, 1, 2) = 2.0f * (yz - wx);
    AT(r, 2, 0) = 2.0f * (xz - wy);
    AT(r, 2, 1) = 2.0f * (yz + wx);
    AT(r, 2, 2) = 1.0f - 2.0f * (xx + yy);
    return r;
}

gdr_mat4 gdr_mat4_from_trs(gdr_vec3 translation, gdr_quat rotation, gdr_vec3 scale)
{
    gdr_mat4 r = gdr_mat4_from_quat(rotation);
    float s[3] = {scale.x, scale.y, scale.z};
    for (int col = 0; col < 3; col++)
        for (int row = 0; row < 3; row++)
            AT(r, row, col) *= s[col];
    AT(r, 0, 3) = translation.x;
    AT(r, 1, 3) = translation.y;
    AT(r, 2, 3) = translation.z;
    return r;
}

float gdr_mat4_max_axis_scale(gdr_mat4 a)
{
    return gdr_max_axis_scale((gdr_vec3){a.m[0], a.m[1], a.m[2]}, (gdr_vec3){a.m[4], a.m[5], a.m[6]},
                              (gdr_vec3){a.m[8], a.m[9], a.m[10]});
}
