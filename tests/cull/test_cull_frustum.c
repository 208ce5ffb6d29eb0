/* Frustum planes, sphere and box tests against brute-force checks: clip-space classification
 * of sampled points, and box corners against each plane. */
#include <stdlib.h>

#include "gdr/cull.h"
#include "test_util.h"

static gdr_mat4 random_view_projection(unsigned *rng, bool infinite, gdr_mat4 *view_out)
{
    gdr_vec3 axis = {test_random_range(rng, -1, 1), test_random_range(rng, -1, 1), test_random_range(rng, -1, 1)};
    if (gdr_vec3_length(axis) < 1e-3f)
        axis = (gdr_vec3){0, 1, 0};
    gdr_quat q = gdr_quat_from_axis_angle(gdr_vec3_normalize(axis), test_random_range(rng, -3.1f, 3.1f));
    gdr_vec3 pos = {test_random_range(rng, -50, 50), test_random_range(rng, -50, 50), test_random_range(rng, -50, 50)};
    gdr_mat4 view = gdr_view_from_pose(pos, q);
    float fov = test_random_range(rng, 0.3f, 2.0f), aspect = test_random_range(rng, 0.5f, 2.5f);
    float znear = test_random_range(rng, 0.05f, 2.0f);
    gdr_mat4 proj = infinite ? gdr_perspective_reverse_z_infinite(fov, aspect, znear)
                             : gdr_perspective_reverse_z(fov, aspect, znear, znear + test_random_range(rng, 10, 200));
    if (view_out)
        *view_out = view;
    return gdr_mat4_mul(proj, view);
}

/* Clip-space inside test of a world point, with a relative tolerance: 1 inside, -1 outside,
 * 0 too close to call. */
static int point_inside(gdr_mat4 vp, gdr_vec3 p)
{
    gdr_vec4 c = gdr_mat4_mul_vec4(vp, (gdr_vec4){p.x, p.y, p.z, 1.0f});
    double w = c.w, tol = 1e-4 * (fabs(c.w) + fabs(c.x) + fabs(c.y) + fabs(c.z)) + 1e-6;
    double margins[6] = {w + c.x, w - c.x, w + c.y, w - c.y, c.z, w - c.z};
    int result = 1;
    for (int i = 0; i < 6; i++) {
        if (margins[i] < -tol)
            return -1;
        if (margins[i] < tol)
            result = 0;
    }
    return result;
}

static double plane_distance(gdr_vec4 p, gdr_vec3 x) { return (double)p.x * x.x + (double)p.y * x.y + (double)p.z * x.z + p.w; }

static void test_planes(unsigned *rng)
{
    for (int cam = 0; cam < 200; cam++) {
        bool infinite = cam & 1;
        gdr_mat4 view;
        gdr_mat4 vp = random_view_projection(rng, infinite, &view);
        gdr_frustum f = gdr_frustum_from_matrix(vp);
        CHECK(f.plane_count == (infinite ? 5u : 6u));
        for (uint32_t i = 0; i < f.plane_count; i++) {
            gdr_vec4 p = f.planes[i];
            CHECK_NEAR(sqrt((double)p.x * p.x + (double)p.y * p.y + (double)p.z * p.z), 1.0, 1e-5);
        }
        gdr_mat4 inv_view;
        CHECK(gdr_mat4_inverse(view, &inv_view));
        gdr_vec3 eye = {inv_view.m[12], inv_view.m[13], inv_view.m[14]};
        for (int s = 0; s < 300; s++) {
            gdr_vec3 p = {eye.x + test_random_range(rng, -60, 60), eye.y + test_random_range(rng, -60, 60),
                          eye.z + test_random_range(rng, -60, 60)};
            int inside = point_inside(vp, p);
            double min_dist = INFINITY;
            for (uint32_t i = 0; i < f.plane_count; i++)
                min_dist = fmin(min_dist, plane_distance(f.planes[i], p));
            if (inside == 1)
                CHECK(min_dist > -1e-3);
            if (inside == -1)
                CHECK(min_dist < 1e-3);
            /* the point as a zero-radius sphere / zero-size box */
            gdr_cull_outcome so = gdr_frustum_test_sphere(&f, p, 0.0f);
            gdr_cull_outcome bo = gdr_frustum_test_box(&f, p, (gdr_vec3){0, 0, 0});
            CHECK(so == bo);
            if (inside == 1)
                CHECK(so == GDR_CULL_INSIDE);
            if (inside == -1)
                CHECK(so == GDR_CULL_OUTSIDE);
        }
    }
}

/* Spheres: OUTSIDE means no sampled point of the sphere is inside the frustum; INSIDE means every
 * sampled point is; and the outcome matches the per-plane definition computed in double. */
static void test_spheres(unsigned *rng)
{
    int counts[3] = {0};
    for (int cam = 0; cam < 60; cam++) {
        gdr_mat4 view;
        gdr_mat4 vp = random_view_projection(rng, cam & 1, &view);
        gdr_frustum f = gdr_frustum_from_matrix(vp);
        gdr_mat4 inv_view;
        gdr_mat4_inverse(view, &inv_view);
        gdr_vec3 eye = {inv_view.m[12], inv_view.m[13], inv_view.m[14]};
        for (int s = 0; s < 200; s++) {
            gdr_vec3 c = {eye.x + test_random_range(rng, -40, 40), eye.y + test_random_range(rng, -40, 40),
                          eye.z + test_random_range(rng, -40, 40)};
            float r = test_random_range(rng, 0.0f, 15.0f);
            gdr_cull_outcome o = gdr_frustum_test_sphere(&f, c, r);
            counts[o]++;
            bool tie = false, outside = false, partly = false;
            for (uint32_t i = 0; i < f.plane_count; i++) {
                double d = plane_distance(f.planes[i], c);
                if (fabs(d + r) < 1e-3 || fabs(d - r) < 1e-3)
                    tie = true;
                outside |= d < -r;
                partly |= d < r;
            }
            if (!tie)
                CHECK(o == (outside ? GDR_CULL_OUTSIDE : partly ? GDR_CULL_INTERSECTS : GDR_CULL_INSIDE));
            for (int k = 0; k < 40; k++) {
                gdr_vec3 dir = {test_random_range(rng, -1, 1), test_random_range(rng, -1, 1), test_random_range(rng, -1, 1)};
                if (gdr_vec3_length(dir) > 1.0f)
                    continue;
                gdr_vec3 p = gdr_vec3_add(c, gdr_vec3_scale(dir, r));
                int inside = point_inside(vp, p);
                if (o == GDR_CULL_OUTSIDE)
                    CHECK(inside != 1);
                if (o == GDR_CULL_INSIDE)
                    CHECK(inside != -1);
            }
        }
    }
    printf("spheres: outside %d, intersecting %d, inside %d\n", counts[0], counts[1], counts[2]);
    CHECK(counts[0] > 100 && counts[1] > 100 && counts[2] > 100);
}

/* Boxes: the |n|.extent form equals the corner test: OUTSIDE iff all eight corners are outside one
 * plane; INSIDE iff every corner is inside every plane. */
static void test_boxes(unsigned *rng)
{
    int counts[3] = {0};
    for (int cam = 0; cam < 60; cam++) {
        gdr_mat4 view;
        gdr_mat4 vp = random_view_projection(rng, cam & 1, &view);
        gdr_frustum f = gdr_frustum_from_matrix(vp);
        gdr_mat4 inv_view;
        gdr_mat4_inverse(view, &inv_view);
        gdr_vec3 eye = {inv_view.m[12], inv_view.m[13], inv_view.m[14]};
        for (int s = 0; s < 200; s++) {
            gdr_vec3 c = {eye.x + test_random_range(rng, -40, 40), eye.y + test_random_range(rng, -40, 40),
                          eye.z + test_random_range(rng, -40, 40)};
            gdr_vec3 e = {test_random_range(rng, 0, 10), test_random_range(rng, 0, 10), test_random_range(rng, 0, 10)};
            gdr_cull_outcome o = gdr_frustum_test_box(&f, c, e);
            counts[o]++;
            bool tie = false, outside = false, all_inside = true;
            for (uint32_t i = 0; i < f.plane_count; i++) {
                double lo = INFINITY, hi = -INFINITY;
                for (int k = 0; k < 8; k++) {
                    gdr_vec3 corner = {c.x + ((k & 1) ? e.x : -e.x), c.y + ((k & 2) ? e.y : -e.y),
                                       c.z + ((k & 4) ? e.z : -e.z)};
                    double d = plane_distance(f.planes[i], corner);
                    lo = fmin(lo, d);
                    hi = fmax(hi, d);
                }
                if (fabs(lo) < 1e-3 || fabs(hi) < 1e-3)
                    tie = true;
                outside |= hi < 0.0;
                all_inside &= lo >= 0.0;
            }
            if (!tie)
                CHECK(o == (outside ? GDR_CULL_OUTSIDE : all_inside ? GDR_CULL_INSIDE : GDR_CULL_INTERSECTS));
            /* sampled points of a culled box are never inside the frustum */
            for (int k = 0; k < 30 && o == GDR_CULL_OUTSIDE; k++) {
                gdr_vec3 p = {c.x + e.x * test_random_range(rng, -1, 1), c.y + e.y * test_random_range(rng, -1, 1),
                              c.z + e.z * test_random_range(rng, -1, 1)};
                CHECK(point_inside(vp, p) != 1);
            }
        }
    }
    printf("boxes: outside %d, intersecting %d, inside %d\n", counts[0], counts[1], counts[2]);
    CHECK(counts[0] > 100 && counts[1] > 100 && counts[2] > 100);
}

static void test_plane_box(unsigned *rng)
{
    for (int s = 0; s < 2000; s++) {
        gdr_vec4 plane = {test_random_range(rng, -2, 2), test_random_range(rng, -2, 2), test_random_range(rng, -2, 2),
                          test_random_range(rng, -5, 5)};
        gdr_vec3 c = {test_random_range(rng, -5, 5), test_random_range(rng, -5, 5), test_random_range(rng, -5, 5)};
        gdr_vec3 e = {test_random_range(rng, 0, 2), test_random_range(rng, 0, 2), test_random_range(rng, 0, 2)};
        double lo = INFINITY, hi = -INFINITY;
        for (int k = 0; k < 8; k++) {
            gdr_vec3 corner = {c.x + ((k & 1) ? e.x : -e.x), c.y + ((k & 2) ? e.y : -e.y), c.z + ((k & 4) ? e.z : -e.z)};
            double d = plane_distance(plane, corner);
            lo = fmin(lo, d);
            hi = fmax(hi, d);
        }
        if (fabs(lo) < 1e-4 || fabs(hi) < 1e-4)
            continue;
        gdr_cull_outcome o = gdr_plane_test_box(plane, c, e);
        CHECK(o == (hi < 0 ? GDR_CULL_OUTSIDE : lo >= 0 ? GDR_CULL_INSIDE : GDR_CULL_INTERSECTS));
    }
    CHECK(gdr_plane_test_box((gdr_vec4){0, 0, 0, 1}, (gdr_vec3){0, 0, 0}, (gdr_vec3){1, 1, 1}) == GDR_CULL_INSIDE);
    CHECK(gdr_plane_test_box((gdr_vec4){0, 0, 0, -1}, (gdr_vec3){0, 0, 0}, (gdr_vec3){1, 1, 1}) == GDR_CULL_OUTSIDE);
}

int main(void)
{
    unsigned rng = 12345;
    test_planes(&rng);
    test_spheres(&rng);
    test_boxes(&rng);
    test_plane_box(&rng);
    return test_finish("test_cull_frustum");
}
