/* gdr math: vectors, quaternions, column-major 4x4 matrices, projection and frustum tests.
 *
 * Conventions (seeds 000 and 001):
 *  - right-handed space; the camera looks down -Z, +X right, +Y up;
 *  - matrices are column-major: m[column * 4 + row], vectors are columns (p' = M p);
 *  - reverse-Z: the near plane maps to depth 1, infinity (or the far plane) to depth 0;
 *  - Vulkan's framebuffer Y points down: we flip with a negative viewport height instead of
 *    negating P[1][1], so clip space keeps +Y up (gdr_viewport_flip_y).
 */
#ifndef GDR_MATH_H
#define GDR_MATH_H

#include <stdbool.h>

#include "gdr/core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct gdr_vec2 { float x, y; } gdr_vec2;
typedef struct gdr_vec3 { float x, y, z; } gdr_vec3;
typedef struct gdr_vec4 { float x, y, z, w; } gdr_vec4;
typedef struct gdr_quat { float x, y, z, w; } gdr_quat; /* w is the scalar part */
typedef struct gdr_mat4 { float m[16]; } gdr_mat4;      /* m[column * 4 + row] */

/* --- vectors --- */
GDR_API gdr_vec3 gdr_vec3_make(float x, float y, float z);
GDR_API gdr_vec3 gdr_vec3_add(gdr_vec3 a, gdr_vec3 b);
GDR_API gdr_vec3 gdr_vec3_sub(gdr_vec3 a, gdr_vec3 b);
GDR_API gdr_vec3 gdr_vec3_scale(gdr_vec3 a, float s);
GDR_API float gdr_vec3_dot(gdr_vec3 a, gdr_vec3 b);
GDR_API gdr_vec3 gdr_vec3_cross(gdr_vec3 a, gdr_vec3 b);
GDR_API float gdr_vec3_length(gdr_vec3 a);
GDR_API gdr_vec3 gdr_vec3_normalize(gdr_vec3 a); /* returns a unchanged if its length is 0 */

/* --- quaternions (unit quaternions represent rotations) --- */
GDR_API gdr_quat gdr_quat_identity(void);
GDR_API gdr_quat gdr_quat_from_axis_angle(gdr_vec3 axis, float radians);
GDR_API gdr_quat gdr_quat_mul(gdr_quat a, gdr_quat b); /* rotation b, then a */
GDR_API gdr_quat gdr_quat_normalize(gdr_quat q);
GDR_API gdr_vec3 gdr_quat_rotate(gdr_quat q, gdr_vec3 v);

/* --- matrices --- */
GDR_API gdr_mat4 gdr_mat4_identity(void);
GDR_API gdr_mat4 gdr_mat4_mul(gdr_mat4 a, gdr_mat4 b); /* a * b */
GDR_API gdr_mat4 gdr_mat4_transpose(gdr_mat4 a);
/* General inverse; returns false (and leaves *out untouched) for a singular matrix. */
GDR_API bool gdr_mat4_inverse(gdr_mat4 a, gdr_mat4 *out);
GDR_API gdr_vec4 gdr_mat4_mul_vec4(gdr_mat4 a, gdr_vec4 v);
GDR_API gdr_vec3 gdr_mat4_transform_point(gdr_mat4 a, gdr_vec3 p); /* w = 1, no divide */
GDR_API gdr_mat4 gdr_mat4_from_quat(gdr_quat q);
/* T * R * S: scale, then rotate, then translate. */
GDR_API gdr_mat4 gdr_mat4_from_trs(gdr_vec3 translation, gdr_quat rotation, gdr_vec3 scale);
/* Largest length of the three basis columns: the factor by which a bounding sphere's radius
 * must grow so the sphere still contains the transformed geometry. */
GDR_API float gdr_mat4_max_axis_scale(gdr_mat4 a);

/* --- camera --- */
/* View matrix of a camera at `position` with orientation `rotation`; with the identity rotation
 * the camera looks down -Z. It is the inverse of the camera's rigid transform. */
GDR_API gdr_mat4 gdr_view_from_pose(gdr_vec3 position, gdr_quat rotation);
/* Reverse-Z infinite perspective: f = 1/tan(fovy/2); P = [f/a 0 0 0; 0 f 0 0; 0 0 0 zn; 0 0 -1 0]. */
GDR_API gdr_mat4 gdr_perspective_reverse_z_infinite(float fovy_radians, float aspect, float znear);
/* Reverse-Z finite perspective: P[2][2] = zn/(zf-zn), P[2][3] = zf*zn/(zf-zn) (row, column). */
GDR_API gdr_mat4 gdr_perspective_reverse_z(float fovy_radians, float aspect, float znear, float zfar);
/* Reverse-Z orthographic of half extents xmag, ymag: P = [1/xmag 0 0 0; 0 1/ymag 0 0;
 * 0 0 1/(zf-zn) zf/(zf-zn); 0 0 0 1] (depth 1 at the near plane, 0 at the far one; w = 1). */
GDR_API gdr_mat4 gdr_orthographic_reverse_z(float xmag, float ymag, float znear, float zfar);

/* A viewport in framebuffer pixels, as VkViewport takes it. */
typedef struct gdr_viewport { float x, y, width, height; } gdr_viewport;
/* Vulkan viewport for a width x height target with +Y up in clip space: y = height,
 * height = -height (needs Vulkan 1.1 / VK_KHR_maintenance1). */
GDR_API gdr_viewport gdr_viewport_flip_y(float width, float height);

/* --- frustum culling (seed 001) --- */
/* Symmetric frustum coefficients (i, j, k, l) of a symmetric projection: the left/right planes
 * are i*x -+ ... written as i*|x| + j*z = 0, the bottom/top planes k*|y| + l*z = 0, taken from the
 * normalised Gribb-Hartmann planes row3 + row0 (left) and row3 + row1 (bottom). */
GDR_API gdr_vec4 gdr_frustum_symmetric(gdr_mat4 projection);
/* True unless the sphere (view-space centre, radius) lies entirely outside the frustum given by
 * the symmetric coefficients, the near plane at z = -znear and the far plane at z = -zfar
 * (pass INFINITY for the infinite projection). Conservative: may keep a sphere near a corner. */
GDR_API bool gdr_sphere_in_frustum(gdr_vec4 ijkl, gdr_vec3 center_view, float radius, float znear,
                                   float zfar);

#ifdef __cplusplus
}
#endif
#endif
