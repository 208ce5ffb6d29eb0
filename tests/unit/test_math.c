/* Math unit tests: each function against an independent computation. */
#include <math.h>
#include <stdlib.h>

#include "gdr/math.h"
#include "test_util.h"

#define PI_F 3.14159265358979f

static gdr_quat random_rotation(unsigned *rng)
{
    gdr_vec3 axis = {test_random_range(rng, -1, 1), test_random_range(rng, -1, 1), test_random_range(rng, -1, 1)};
    if (gdr_vec3_length(axis) < 1e-3f)
        axis = (gdr_vec3){0, 1, 0};
    return gdr_quat_from_axis_angle(axis, test_random_range(rng, -PI_F, PI_F));
}

static void test_matrix_inverse_and_trs(void)
{
    unsigned rng = 12345;
    for (int n = 0; n < 200; n++) {
        gdr_vec3 t = {test_random_range(&rng, -50, 50), test_random_range(&rng, -50, 50), test_random_range(&rng, -50, 50)};
        gdr_vec3 s = {test_random_range(&rng, 0.1f, 4), test_random_range(&rng, 0.1f, 4), test_random_range(&rng, 0.1f, 4)};
        gdr_quat q = random_rotation(&rng);
        gdr_mat4 m = gdr_mat4_from_trs(t, q, s), inv;
        CHECK(gdr_mat4_inverse(m, &inv));
        gdr_mat4 id = gdr_mat4_mul(m, inv);
        for (int i = 0; i < 16; i++)
            CHECK_NEAR(id.m[i], (i % 5 == 0) ? 1.0 : 0.0, 1e-4);
        /* TRS applied to a point equals scale, then quaternion rotation, then translation. */
        gdr_vec3 p = {test_random_range(&rng, -3, 3), test_random_range(&rng, -3, 3), test_random_range(&rng, -3, 3)};
        gdr_vec3 expected = gdr_vec3_add(gdr_quat_rotate(q, (gdr_vec3){p.x * s.x, p.y * s.y, p.z * s.z}), t);
        gdr_vec3 got = gdr_mat4_transform_point(m, p);
        CHECK_NEAR(got.x, expected.x, 1e-3);
        CHECK_NEAR(got.y, expected.y, 1e-3);
        CHECK_NEAR(got.z, expected.z, 1e-3);
        /* The largest axis scale is the largest scale factor, whatever the rotation. */
        CHECK_NEAR(gdr_mat4_max_axis_scale(m), fmaxf(s.x, fmaxf(s.y, s.z)), 1e-4);
    }
    gdr_mat4 singular = {{0}};
    gdr_mat4 untouched = gdr_mat4_identity();
    CHECK(!gdr_mat4_inverse(singular, &untouched));
    CHECK(untouched.m[0] == 1.0f);
    /* Column-major: the translation lives in m[12..14]. */
    gdr_mat4 tr = gdr_mat4_from_trs((gdr_vec3){1, 2, 3}, gdr_quat_identity(), (gdr_vec3){1, 1, 1});
    CHECK(tr.m[12] == 1.0f && tr.m[13] == 2.0f && tr.m[14] == 3.0f);
}

static void test_quaternion_right_handed(void)
{
    /* Right-handed: +90 degrees about +Y takes +X to -Z, and +Z to +X. */
    gdr_quat q = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, 0.5f * PI_F);
    gdr_vec3 x = gdr_quat_rotate(q, (gdr_vec3){1, 0, 0});
    CHECK_NEAR(x.x, 0, 1e-6);
    CHECK_NEAR(x.z, -1, 1e-6);
    gdr_vec3 z = gdr_quat_rotate(q, (gdr_vec3){0, 0, 1});
    CHECK_NEAR(z.x, 1, 1e-6);
    /* Composition: rotating by a*b equals rotating by b then a. */
    unsigned rng = 99;
    for (int n = 0; n < 100; n++) {
        gdr_quat a = random_rotation(&rng), b = random_rotation(&rng);
        gdr_vec3 v = {test_random_range(&rng, -1, 1), test_random_range(&rng, -1, 1), test_random_range(&rng, -1, 1)};
        gdr_vec3 r1 = gdr_quat_rotate(gdr_quat_mul(a, b), v);
        gdr_vec3 r2 = gdr_quat_rotate(a, gdr_quat_rotate(b, v));
        CHECK_NEAR(r1.x, r2.x, 1e-5);
        CHECK_NEAR(r1.y, r2.y, 1e-5);
        CHECK_NEAR(r1.z, r2.z, 1e-5);
        gdr_vec3 r3 = gdr_mat4_transform_point(gdr_mat4_from_quat(a), v);
        gdr_vec3 r4 = gdr_quat_rotate(a, v);
        CHECK_NEAR(r3.x, r4.x, 1e-5);
        CHECK_NEAR(r3.y, r4.y, 1e-5);
        CHECK_NEAR(r3.z, r4.z, 1e-5);
    }
}

static void test_view_matrix(void)
{
    unsigned rng = 7;
    for (int n = 0; n < 100; n++) {
        gdr_vec3 pos = {test_random_range(&rng, -20, 20), test_random_range(&rng, -20, 20), test_random_range(&rng, -20, 20)};
        gdr_quat q = random_rotation(&rng);
        gdr_mat4 view = gdr_view_from_pose(pos, q);
        /* The camera sits at the view-space origin and its forward (-Z rotated by q) stays -Z. */
        gdr_vec3 origin = gdr_mat4_transform_point(view, pos);
        CHECK_NEAR(gdr_vec3_length(origin), 0, 1e-4);
        gdr_vec3 ahead = gdr_vec3_add(pos, gdr_quat_rotate(q, (gdr_vec3){0, 0, -5}));
        gdr_vec3 v = gdr_mat4_transform_point(view, ahead);
        CHECK_NEAR(v.x, 0, 1e-4);
        CHECK_NEAR(v.y, 0, 1e-4);
        CHECK_NEAR(v.z, -5, 1e-4);
        /* It is the inverse of the camera's transform. */
        gdr_mat4 camera = gdr_mat4_from_trs(pos, q, (gdr_vec3){1, 1, 1});
        gdr_mat4 id = gdr_mat4_mul(view, camera);
        for (int i = 0; i < 16; i++)
            CHECK_NEAR(id.m[i], (i % 5 == 0) ? 1.0 : 0.0, 1e-4);
    }
}

static float depth_of(gdr_mat4 proj, float z)
{
    gdr_vec4 clip = gdr_mat4_mul_vec4(proj, (gdr_vec4){0, 0, z, 1});
    return clip.z / clip.w;
}

static void test_projection(void)
{
    float fovy = 1.0f, aspect = 16.0f / 9.0f, zn = 0.1f, zf = 500.0f;
    gdr_mat4 inf = gdr_perspective_reverse_z_infinite(fovy, aspect, zn);
    gdr_mat4 fin = gdr_perspective_reverse_z(fovy, aspect, zn, zf);
    CHECK_NEAR(depth_of(inf, -zn), 1.0, 1e-6);
    CHECK_NEAR(depth_of(inf, -1e9f), 0.0, 1e-6);
    CHECK_NEAR(depth_of(fin, -zn), 1.0, 1e-5);
    CHECK_NEAR(depth_of(fin, -zf), 0.0, 1e-5);
    float previous = 2.0f;
    for (float z = -zn; z > -zf; z *= 1.5f) {
        float d = depth_of(inf, z);
        CHECK(d < previous && d > 0.0f);
        previous = d;
    }
    /* The top edge of the field of view lands on NDC y = +1 (Y up in clip space). */
    float t = tanf(fovy * 0.5f);
    gdr_vec4 top = gdr_mat4_mul_vec4(inf, (gdr_vec4){0, 3.0f * t, -3.0f, 1});
    CHECK_NEAR(top.y / top.w, 1.0, 1e-5);
    gdr_vec4 right = gdr_mat4_mul_vec4(inf, (gdr_vec4){3.0f * t * aspect, 0, -3.0f, 1});
    CHECK_NEAR(right.x / right.w, 1.0, 1e-5);
    /* Vulkan maps y_fb = vp.y + (ndc_y + 1) / 2 * vp.height: with the flip, NDC +1 is row 0. */
    gdr_viewport vp = gdr_viewport_flip_y(640, 480);
    CHECK_NEAR(vp.y + (1.0f + 1.0f) * 0.5f * vp.height, 0.0, 0);
    CHECK_NEAR(vp.y + (-1.0f + 1.0f) * 0.5f * vp.height, 480.0, 0);
}

/* Inward unit normal of the plane through the origin and two frustum corner directions. */
static gdr_vec3 plane_through(gdr_vec3 a, gdr_vec3 b, gdr_vec3 inside)
{
    gdr_vec3 n = gdr_vec3_normalize(gdr_vec3_cross(a, b));
    return gdr_vec3_dot(n, inside) < 0 ? gdr_vec3_scale(n, -1.0f) : n;
}

static void test_frustum(void)
{
    unsigned rng = 2024;
    for (int round = 0; round < 20; round++) {
        float fovy = test_random_range(&rng, 0.3f, 2.5f), aspect = test_random_range(&rng, 0.5f, 3.0f);
        float zn = test_random_range(&rng, 0.01f, 1.0f);
        gdr_mat4 proj = gdr_perspective_reverse_z_infinite(fovy, aspect, zn);
        gdr_vec4 ijkl = gdr_frustum_symmetric(proj);
        /* Independent: the side planes from the frustum's corners at distance 1. */
        float ty = tanf(fovy * 0.5f), tx = ty * aspect;
        gdr_vec3 inside = {0, 0, -1};
        gdr_vec3 c_lb = {-tx, -ty, -1}, c_lt = {-tx, ty, -1}, c_rb = {tx, -ty, -1}, c_rt = {tx, ty, -1};
        gdr_vec3 left = plane_through(c_lb, c_lt, inside), right = plane_through(c_rb, c_rt, inside);
        gdr_vec3 bottom = plane_through(c_lb, c_rb, inside), top = plane_through(c_lt, c_rt, inside);
        CHECK_NEAR(ijkl.x, left.x, 1e-5);
        CHECK_NEAR(ijkl.y, left.z, 1e-5);
        CHECK_NEAR(ijkl.z, bottom.y, 1e-5);
        CHECK_NEAR(ijkl.w, bottom.z, 1e-5);
        gdr_vec3 planes[4] = {left, right, bottom, top};

        for (int n = 0; n < 2000; n++) {
            gdr_vec3 c = {test_random_range(&rng, -30, 30), test_random_range(&rng, -30, 30), test_random_range(&rng, -40, 5)};
            float r = test_random_range(&rng, 0.01f, 5.0f);
            /* Reference: outside if wholly behind one of the four side planes or the near plane. */
            float margin = 1e-3f;
            bool outside = false, near_boundary = false;
            for (int p = 0; p < 4; p++) {
                float d = gdr_vec3_dot(planes[p], c);
                outside |= d < -r;
                near_boundary |= fabsf(d + r) < margin;
            }
            float near_distance = -c.z - zn; /* signed distance beyond the near plane */
            outside |= near_distance < -r;
            near_boundary |= fabsf(near_distance + r) < margin;
            bool visible = gdr_sphere_in_frustum(ijkl, c, r, zn, INFINITY);
            if (!near_boundary)
                CHECK(visible == !outside);
            /* Conservative: a sample point of the sphere inside the clip volume means visible. */
            for (int s = 0; s < 8 && !visible; s++) {
                gdr_vec3 d = {test_random_range(&rng, -1, 1), test_random_range(&rng, -1, 1), test_random_range(&rng, -1, 1)};
                gdr_vec3 p = gdr_vec3_add(c, gdr_vec3_scale(d, r * 0.577f));
                gdr_vec4 clip = gdr_mat4_mul_vec4(proj, (gdr_vec4){p.x, p.y, p.z, 1});
                bool in_clip = clip.w > 0 && fabsf(clip.x) <= clip.w && fabsf(clip.y) <= clip.w &&
                               clip.z >= 0 && clip.z <= clip.w;
                CHECK(!in_clip);
            }
        }
        /* Far plane of the finite variant. */
        CHECK(!gdr_sphere_in_frustum(ijkl, (gdr_vec3){0, 0, -110}, 5, zn, 100));
        CHECK(gdr_sphere_in_frustum(ijkl, (gdr_vec3){0, 0, -104}, 5, zn, 100));
    }
}

static void test_scaled_radius_contains_geometry(void)
{
    unsigned rng = 5;
    for (int n = 0; n < 50; n++) {
        gdr_vec3 s = {test_random_range(&rng, 0.1f, 3), test_random_range(&rng, 0.1f, 3), test_random_range(&rng, 0.1f, 3)};
        gdr_mat4 m = gdr_mat4_from_trs((gdr_vec3){1, 2, 3}, random_rotation(&rng), s);
        gdr_vec3 center = {0.5f, -0.25f, 0.1f};
        float radius = 2.0f;
        gdr_vec3 wc = gdr_mat4_transform_point(m, center);
        float wr = radius * gdr_mat4_max_axis_scale(m);
        for (int k = 0; k < 100; k++) {
            gdr_vec3 d = gdr_vec3_normalize((gdr_vec3){test_random_range(&rng, -1, 1), test_random_range(&rng, -1, 1),
                                                       test_random_range(&rng, -1, 1)});
            gdr_vec3 p = gdr_mat4_transform_point(m, gdr_vec3_add(center, gdr_vec3_scale(d, radius)));
            CHECK(gdr_vec3_length(gdr_vec3_sub(p, wc)) <= wr * 1.0001f);
        }
    }
}

int main(void)
{
    test_matrix_inverse_and_trs();
    test_quaternion_right_handed();
    test_view_matrix();
    test_projection();
    test_frustum();
    test_scaled_radius_contains_geometry();
    return test_finish("test_math");
}
