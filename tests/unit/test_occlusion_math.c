/* The occlusion test math of src/gpu_shared/occlusion_math.h, against independent references
 * computed in double precision through the projection matrices and the viewport of include/gdr/math.h:
 *  - the screen rectangle contains the projection of points sampled on the sphere, and its bounds
 *    match the exact tangent angles;
 *  - spheres reaching the near plane are not testable;
 *  - the pyramid footprint (level, at most 2x2 texels) covers the exact projection, and its level is
 *    no coarser than the rectangle's longest side calls for;
 *  - the nearest depth is >= the depth of every point of the sphere;
 *  - end to end, on random depth buffers: a sphere declared occluded covers no pixel centre where
 *    the depth buffer is not strictly nearer than the sphere. */
#include <stdlib.h>

#include "gdr/math.h"
#include "gpu_shared/occlusion_math.h"
#include "test_util.h"

#define PI 3.14159265358979323846

typedef struct camera {
    gdr_mat4 projection;
    GdrOcclusionParams params;
    bool infinite;
    float znear, zfar;
} camera;

static double at(const gdr_mat4 *m, int row, int col)
{
    return m->m[col * 4 + row];
}

static camera random_camera(unsigned *rng, uint32_t hzb_width, uint32_t hzb_height)
{
    camera cam;
    float fovy = test_random_range(rng, 15.0f, 120.0f) * (float)PI / 180.0f;
    float aspect = test_random_range(rng, 0.4f, 3.0f);
    cam.znear = test_random_range(rng, 0.01f, 1.0f);
    cam.infinite = test_random(rng) < 0.5f;
    cam.zfar = cam.infinite ? INFINITY : cam.znear * test_random_range(rng, 20.0f, 1e4f);
    cam.projection = cam.infinite ? gdr_perspective_reverse_z_infinite(fovy, aspect, cam.znear)
                                  : gdr_perspective_reverse_z(fovy, aspect, cam.znear, cam.zfar);
    uint32_t largest = hzb_width > hzb_height ? hzb_width : hzb_height, levels = 1;
    while (largest >> levels)
        levels++;
    cam.params = (GdrOcclusionParams){.p00 = (float)at(&cam.projection, 0, 0), .p11 = (float)at(&cam.projection, 1, 1),
                                      .p22 = (float)at(&cam.projection, 2, 2), .p23 = (float)at(&cam.projection, 2, 3),
                                      .znear = cam.znear, .hzb_width = hzb_width, .hzb_height = hzb_height,
                                      .hzb_levels = levels};
    return cam;
}

/* Reference projection of a view-space point: the matrix, the perspective divide and the viewport of
 * gdr_viewport_flip_y, in double; UV = framebuffer position / size. */
static void project(const camera *cam, double x, double y, double z, double *u, double *v, double *depth)
{
    const gdr_mat4 *p = &cam->projection;
    double cx = at(p, 0, 0) * x + at(p, 0, 1) * y + at(p, 0, 2) * z + at(p, 0, 3);
    double cy = at(p, 1, 0) * x + at(p, 1, 1) * y + at(p, 1, 2) * z + at(p, 1, 3);
    double cz = at(p, 2, 0) * x + at(p, 2, 1) * y + at(p, 2, 2) * z + at(p, 2, 3);
    double cw = at(p, 3, 0) * x + at(p, 3, 1) * y + at(p, 3, 2) * z + at(p, 3, 3);
    const double width = 1000.0, height = 1000.0;
    gdr_viewport vp = gdr_viewport_flip_y((float)width, (float)height);
    *u = (vp.x + (cx / cw + 1.0) * 0.5 * vp.width) / width;
    *v = (vp.y + (cy / cw + 1.0) * 0.5 * vp.height) / height;
    *depth = cz / cw;
}

/* Exact slope interval a / -z of the sphere along one axis: the centre's angle +- asin(r / d). */
static void exact_slopes(double ca, double cz, double r, double *lo, double *hi)
{
    double angle = atan2(ca, -cz), half = asin(r / sqrt(ca * ca + cz * cz));
    *lo = tan(angle - half);
    *hi = tan(angle + half);
}

/* A sphere in front of the camera, near or across the frustum's edges, beyond the near plane. */
static void random_sphere(unsigned *rng, const camera *cam, gdr_vec3 *c, float *r)
{
    float distance = cam->znear * test_random_range(rng, 1.5f, 400.0f);
    float slope_x = test_random_range(rng, -1.3f, 1.3f) / (float)at(&cam->projection, 0, 0);
    float slope_y = test_random_range(rng, -1.3f, 1.3f) / (float)at(&cam->projection, 1, 1);
    *c = (gdr_vec3){slope_x * distance, slope_y * distance, -distance};
    *r = (distance - cam->znear) * test_random_range(rng, 0.001f, 0.98f);
}

static void test_orientation(void)
{
    unsigned rng = 7;
    camera cam = random_camera(&rng, 1024, 512);
    GdrSphereRect centre = gdr_sphere_screen_rect((gdr_vec3){0, 0, -10}, 1, cam.znear, cam.params.p00, cam.params.p11);
    CHECK(centre.testable);
    CHECK_NEAR(centre.u0 + centre.u1, 1.0, 1e-6);
    CHECK_NEAR(centre.v0 + centre.v1, 1.0, 1e-6);
    CHECK(centre.u0 < 0.5f && centre.u1 > 0.5f);
    /* +X is right (u grows), +Y is up: the top of the screen, where v is small (row 0). */
    GdrSphereRect right = gdr_sphere_screen_rect((gdr_vec3){3, 0, -10}, 1, cam.znear, cam.params.p00, cam.params.p11);
    GdrSphereRect up = gdr_sphere_screen_rect((gdr_vec3){0, 3, -10}, 1, cam.znear, cam.params.p00, cam.params.p11);
    CHECK(right.u0 > 0.5f && right.v0 < 0.5f && right.v1 > 0.5f);
    CHECK(up.v1 < 0.5f && up.u0 < 0.5f && up.u1 > 0.5f);
}

static void test_near_plane(void)
{
    unsigned rng = 11;
    for (int i = 0; i < 2000; i++) {
        camera cam = random_camera(&rng, 256, 256);
        float r = test_random_range(&rng, 0.001f, 10.0f);
        /* The sphere's nearest point from 3 near distances behind the near plane to 3 beyond it
         * (in front of the eye, containing it, behind the camera). */
        float nearest = -cam.znear + cam.znear * test_random_range(&rng, -3.0f, 3.0f);
        gdr_vec3 c = {test_random_range(&rng, -r, r), test_random_range(&rng, -r, r), nearest - r};
        GdrOcclusionQuery q = gdr_occlusion_query(c, r, cam.params);
        CHECK(q.testable == (c.z + r < -cam.znear));
        if (!q.testable)
            CHECK(q.nearest_depth >= 1.0f); /* never occluded by a pyramid of depths <= 1 */
    }
    /* Touching the near plane counts as reaching it. */
    camera cam = random_camera(&rng, 256, 256);
    CHECK(!gdr_sphere_screen_rect((gdr_vec3){0, 0, -cam.znear - 1.0f}, 1.0f, cam.znear, 1, 1).testable);
    CHECK(gdr_sphere_screen_rect((gdr_vec3){0, 0, -cam.znear - 1.01f}, 1.0f, cam.znear, 1, 1).testable);
}

/* Level-`level` texel of the pyramid holding UV coordinate u (clamped to the screen), in double. */
static int64_t reference_texel(double u, uint32_t size0, int level)
{
    int64_t size = (int64_t)(size0 >> level) > 0 ? (int64_t)(size0 >> level) : 1;
    double at_level = (u < 0 ? 0 : u > 1 ? 1 : u) * (double)size0 / ldexp(1.0, level);
    int64_t texel = (int64_t)floor(at_level);
    return texel < size - 1 ? texel : size - 1;
}

static void test_random_spheres(void)
{
    unsigned rng = 12345;
    const uint32_t sizes[][2] = {{1, 1}, {2, 1}, {1024, 512}, {512, 1024}, {2048, 2048}, {16, 4}, {16384, 8192}};
    int tested = 0, fine_levels = 0;
    for (int i = 0; i < 20000; i++) {
        const uint32_t *size = sizes[i % (int)(sizeof sizes / sizeof sizes[0])];
        camera cam = random_camera(&rng, size[0], size[1]);
        gdr_vec3 c;
        float r;
        random_sphere(&rng, &cam, &c, &r);
        GdrSphereRect rect = gdr_sphere_screen_rect(c, r, cam.znear, cam.params.p00, cam.params.p11);
        GdrOcclusionQuery q = gdr_occlusion_query(c, r, cam.params);
        CHECK(rect.testable && q.testable);
        if (!q.testable)
            continue;
        tested++;

        /* The bounds against the exact tangent angles (float rounding only). */
        double sx0, sx1, sy0, sy1;
        exact_slopes(c.x, c.z, r, &sx0, &sx1);
        exact_slopes(c.y, c.z, r, &sy0, &sy1);
        double u0 = 0.5 + 0.5 * at(&cam.projection, 0, 0) * sx0, u1 = 0.5 + 0.5 * at(&cam.projection, 0, 0) * sx1;
        double v0 = 0.5 - 0.5 * at(&cam.projection, 1, 1) * sy1, v1 = 0.5 - 0.5 * at(&cam.projection, 1, 1) * sy0;
        double tol = 1e-5 * (1.0 + fabs(u0) + fabs(u1) + fabs(v0) + fabs(v1));
        CHECK_NEAR(rect.u0, u0, tol);
        CHECK_NEAR(rect.u1, u1, tol);
        CHECK_NEAR(rect.v0, v0, tol);
        CHECK_NEAR(rect.v1, v1, tol);

        /* The footprint: at most 2x2 texels inside the level, covering the exact bounds. */
        int level = q.level;
        CHECK(level >= 0 && level < (int)cam.params.hzb_levels);
        int64_t lw = (int64_t)(size[0] >> level) > 0 ? (int64_t)(size[0] >> level) : 1;
        int64_t lh = (int64_t)(size[1] >> level) > 0 ? (int64_t)(size[1] >> level) : 1;
        CHECK(q.x0 >= 0 && q.x1 < lw && q.y0 >= 0 && q.y1 < lh);
        CHECK(q.x1 - q.x0 >= 0 && q.x1 - q.x0 <= 1 && q.y1 - q.y0 >= 0 && q.y1 - q.y0 <= 1);
        CHECK(reference_texel(u0, size[0], level) >= q.x0 && reference_texel(u1, size[0], level) <= q.x1);
        CHECK(reference_texel(v0, size[1], level) >= q.y0 && reference_texel(v1, size[1], level) <= q.y1);
        /* ... even grown by 1/16 texel, the most a rasteriser with the minimum 4 sub-pixel bits
         * moves a vertex (a pyramid texel is at least a pixel). */
        double pad_u = 1.0 / 16.0 / size[0], pad_v = 1.0 / 16.0 / size[1];
        CHECK(reference_texel(u0 - pad_u, size[0], level) >= q.x0 && reference_texel(u1 + pad_u, size[0], level) <= q.x1);
        CHECK(reference_texel(v0 - pad_v, size[1], level) >= q.y0 && reference_texel(v1 + pad_v, size[1], level) <= q.y1);
        /* The sample point: the corner shared by two texels, or the centre of a single one. */
        CHECK(q.sample_u * (float)lw == (float)q.x0 + (q.x1 > q.x0 ? 1.0f : 0.5f));
        CHECK(q.sample_v * (float)lh == (float)q.y0 + (q.y1 > q.y0 ? 1.0f : 0.5f));
        /* Not coarser than needed: one level finer, the (padded, clamped) rectangle is longer than
         * a texel, or touches three texels along an axis. */
        if (level > 0) {
            double pad = GDR_HZB_RECT_PAD;
            double w = size[0], h = size[1];
            double xl = fmin(fmax(u0 * w - pad, 0), w), xh = fmin(fmax(u1 * w + pad, 0), w);
            double yl = fmin(fmax(v0 * h - pad, 0), h), yh = fmin(fmax(v1 * h + pad, 0), h);
            double side = fmax(xh - xl, yh - yl) / ldexp(1.0, level - 1);
            bool three = reference_texel(u1 + pad / w, size[0], level - 1) - reference_texel(u0 - pad / w, size[0], level - 1) > 1 ||
                         reference_texel(v1 + pad / h, size[1], level - 1) - reference_texel(v0 - pad / h, size[1], level - 1) > 1;
            CHECK(side > 1.0 - 1e-4 || three);
        } else {
            fine_levels++;
        }

        /* Points on the sphere: inside the rectangle and the footprint, not nearer than the nearest depth. */
        double exact_nearest;
        {
            double u, v;
            project(&cam, 0, 0, (double)c.z + r, &u, &v, &exact_nearest);
        }
        /* Raised by the documented slack, no more (beyond a finite far plane the depth is negative). */
        double slack_bound = 1e-4 * (fabs(exact_nearest) + cam.params.p22);
        CHECK(q.nearest_depth >= exact_nearest && q.nearest_depth <= exact_nearest + slack_bound);
        for (int k = 0; k < 64; k++) {
            double dx, dy, dz, len;
            do {
                dx = 2.0 * test_random(&rng) - 1.0;
                dy = 2.0 * test_random(&rng) - 1.0;
                dz = 2.0 * test_random(&rng) - 1.0;
                len = sqrt(dx * dx + dy * dy + dz * dz);
            } while (len < 1e-3 || len > 1.0);
            double x = c.x + r * dx / len, y = c.y + r * dy / len, z = c.z + r * dz / len;
            double u, v, depth;
            project(&cam, x, y, z, &u, &v, &depth);
            double slack = 1e-5 * (1.0 + fabs(u) + fabs(v));
            CHECK(u >= rect.u0 - slack && u <= rect.u1 + slack && v >= rect.v0 - slack && v <= rect.v1 + slack);
            int64_t tx = reference_texel(u, size[0], level), ty = reference_texel(v, size[1], level);
            CHECK(tx >= q.x0 && tx <= q.x1 && ty >= q.y0 && ty <= q.y1);
            CHECK(q.nearest_depth >= depth);
        }
    }
    CHECK(tested == 20000);
    CHECK(fine_levels > 100); /* the sample reaches small spheres too */
}

/* Depth pixels overlapped by level-0 texel range [t0, t1) of a pyramid of size0 over depth_size pixels. */
static void depth_pixels(uint32_t t0, uint32_t t1, uint32_t size0, uint32_t depth_size, uint32_t *first, uint32_t *end)
{
    *first = (uint32_t)((uint64_t)t0 * depth_size / size0);
    *end = (uint32_t)(((uint64_t)t1 * depth_size + size0 - 1) / size0);
}

/* End to end on the CPU: random depth buffers of mostly near depth with far holes; a sphere declared
 * occluded (by the minimum over its footprint, taken straight from the definition of the pyramid)
 * must have no pixel centre whose ray meets it where the buffer is not nearer than the sphere. */
static void test_end_to_end(void)
{
    unsigned rng = 99;
    const uint32_t sizes[][2] = {{97, 61}, {64, 64}, {33, 120}, {7, 5}, {128, 3}};
    int occluded = 0, visible = 0;
    for (int s = 0; s < 5; s++) {
        uint32_t dw = sizes[s][0], dh = sizes[s][1];
        float *depth = malloc(sizeof(float) * dw * dh);
        for (int trial = 0; trial < 40; trial++) {
            /* Half the trials: random near depths with far holes; half: a flat wall at depth
             * `wall`, with spheres placed so that their nearest depth is within 1% of it. */
            bool wall_trial = trial % 2 == 1;
            float hole_rate = test_random_range(&rng, 0.0f, 0.02f);
            float wall = test_random_range(&rng, 0.05f, 0.9f);
            for (uint32_t i = 0; i < dw * dh; i++)
                depth[i] = test_random(&rng) < hole_rate ? test_random_range(&rng, 0.0f, 0.05f)
                           : wall_trial                  ? wall
                                                         : test_random_range(&rng, 0.6f, 1.0f);
            uint32_t w0 = 1, h0 = 1;
            while (w0 * 2 <= dw)
                w0 *= 2;
            while (h0 * 2 <= dh)
                h0 *= 2;
            camera cam = random_camera(&rng, w0, h0);
            for (int k = 0; k < 300; k++) {
                gdr_vec3 c;
                float r;
                random_sphere(&rng, &cam, &c, &r);
                if (wall_trial) {
                    /* Nearest depth wall * (1 +- 1%): view z of depth d is -P23 / (d + P22). */
                    double target = wall * (1.0 + test_random_range(&rng, -0.01f, 0.01f));
                    double z_nearest = -cam.params.p23 / (target + cam.params.p22);
                    r = (float)(-z_nearest * test_random_range(&rng, 0.001f, 0.3f));
                    float scale = (float)(z_nearest - r) / c.z;
                    c = (gdr_vec3){c.x * scale, c.y * scale, (float)(z_nearest - r)};
                }
                GdrOcclusionQuery q = gdr_occlusion_query(c, r, cam.params);
                if (!q.testable)
                    continue;
                /* The minimum over the footprint, from the definition: level-L texel x covers level-0
                 * texels [x 2^L, (x + 1) 2^L), which cover the depth pixels they overlap. */
                uint32_t px0, px1, py0, py1;
                uint32_t scale = 1u << q.level;
                uint32_t tx1 = (uint32_t)(q.x1 + 1) * scale, ty1 = (uint32_t)(q.y1 + 1) * scale;
                depth_pixels((uint32_t)q.x0 * scale, tx1 < w0 ? tx1 : w0, w0, dw, &px0, &px1);
                depth_pixels((uint32_t)q.y0 * scale, ty1 < h0 ? ty1 : h0, h0, dh, &py0, &py1);
                float footprint_min = INFINITY;
                for (uint32_t y = py0; y < py1; y++)
                    for (uint32_t x = px0; x < px1; x++)
                        footprint_min = fminf(footprint_min, depth[y * dw + x]);
                if (!gdr_hzb_occludes(q.nearest_depth, footprint_min)) {
                    visible++;
                    continue;
                }
                occluded++;
                /* Every pixel centre whose ray meets the sphere: the buffer is strictly nearer there
                 * than the sphere's first intersection along the ray. */
                for (uint32_t y = 0; y < dh; y++)
                    for (uint32_t x = 0; x < dw; x++) {
                        double ndc_x = 2.0 * (x + 0.5) / dw - 1.0, ndc_y = 1.0 - 2.0 * (y + 0.5) / dh;
                        double d[3] = {ndc_x / at(&cam.projection, 0, 0), ndc_y / at(&cam.projection, 1, 1), -1.0};
                        double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                        double dc = d[0] * c.x + d[1] * c.y + d[2] * c.z;
                        double cc = (double)c.x * c.x + (double)c.y * c.y + (double)c.z * c.z;
                        double disc = dc * dc - dd * (cc - (double)r * r);
                        if (disc < 0)
                            continue;
                        double t = (dc - sqrt(disc)) / dd; /* first hit: point t d, view z = -t */
                        double u, v, hit_depth;
                        project(&cam, t * d[0], t * d[1], t * d[2], &u, &v, &hit_depth);
                        if (!(depth[y * dw + x] > hit_depth))
                            fprintf(stderr, "occluded sphere (%g %g %g, r %g) meets pixel (%u, %u) of %ux%u: "
                                            "depth %g, sphere %g\n", c.x, c.y, c.z, r, x, y, dw, dh,
                                    depth[y * dw + x], hit_depth);
                        CHECK(depth[y * dw + x] > hit_depth);
                    }
            }
        }
        free(depth);
    }
    printf("end to end: %d spheres occluded, %d visible\n", occluded, visible);
    CHECK(occluded > 1000 && visible > 1000); /* both outcomes are exercised */
}

static void test_occludes(void)
{
    /* Strictly farther than everything in the footprint. */
    CHECK(!gdr_hzb_occludes(0.5f, 0.5f));
    CHECK(gdr_hzb_occludes(nextafterf(0.5f, 0.0f), 0.5f));
    CHECK(!gdr_hzb_occludes(1.0f, 0.0f));
}

int main(void)
{
    test_occludes();
    test_orientation();
    test_near_plane();
    test_random_spheres();
    test_end_to_end();
    return test_finish("test_occlusion_math");
}
