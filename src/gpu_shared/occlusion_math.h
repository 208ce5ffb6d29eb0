/* Occlusion culling against the depth pyramid (HZB), shared by the CPU (tests, references) and the
 * GPU (culling shaders): one definition. docs/OCCLUSION.md derives every step.
 *
 * Conventions: view space is right-handed and the camera looks down -Z; the projection is
 * gdr_perspective_reverse_z_infinite or gdr_perspective_reverse_z (include/gdr/math.h), so depth is
 * (P22 z + P23) / -z: 1 at the near plane, 0 at infinity (or the far plane); the viewport flips Y
 * (gdr_viewport_flip_y), so NDC +Y is the top row of the framebuffer. Screen positions are given
 * in UV: u = (1 + x_ndc) / 2 to the right, v = (1 - y_ndc) / 2 downwards, (0, 0) the top-left
 * corner of the top-left pixel, (1, 1) the bottom-right corner of the bottom-right one. That is
 * also the depth pyramid's UV: level-0 texel (x, y) of a W x H pyramid covers
 * [x/W, (x+1)/W) x [y/H, (y+1)/H).
 *
 * Use (the texture fetch stays with the caller):
 *     GdrOcclusionQuery q = gdr_occlusion_query(view_center, radius, params);
 *     if (q.testable) {
 *         float farthest = textureLod(hzb_min_sampler, vec2(q.sample_u, q.sample_v), float(q.level)).x;
 *         visible = !gdr_hzb_occludes(q.nearest_depth, farthest);
 *     }
 * where hzb_min_sampler is the pyramid's all-levels view with its min-reduction sampler
 * (src/render/hzb.h); that one fetch returns the minimum of texels [x0, x1] x [y0, y1] of
 * `level`. Without such a sampler, take the minimum of texelFetch over those (at most 4) texels. */
#ifndef GDR_OCCLUSION_MATH_H
#define GDR_OCCLUSION_MATH_H

#include "math/glsl_c_bridge.h"

#ifdef GDR_GLSL
#define gdr_occ_floor floor
#define gdr_occ_ceil ceil
#define gdr_occ_log2 log2
#define gdr_occ_ldexp ldexp
#define gdr_occ_fmin min
#define gdr_occ_fmax max
#define GDR_OCC_INT(x) int(x)
#define GDR_OCC_UINT(x) uint(x)
#define GDR_OCC_FLOAT(x) float(x)
#else
#define gdr_occ_floor floorf
#define gdr_occ_ceil ceilf
#define gdr_occ_log2 log2f
#define gdr_occ_ldexp ldexpf
#define gdr_occ_fmin fminf
#define gdr_occ_fmax fmaxf
#define GDR_OCC_INT(x) ((gdr_int)(x))
#define GDR_OCC_UINT(x) ((gdr_uint)(x))
#define GDR_OCC_FLOAT(x) ((float)(x))
#endif

/* The rectangle is grown by this many level-0 pyramid texels on every side before texels are
 * chosen. A pyramid texel is at least one depth pixel wide, so this is at least 1/8 pixel: more
 * than the rasteriser's snapping of vertices to its sub-pixel grid (Vulkan guarantees at least 4
 * sub-pixel bits, so a vertex moves by at most 1/16 pixel) plus the float rounding of the
 * projection, either of which could otherwise let geometry cover a pixel centre just outside the
 * exact rectangle. */
#define GDR_HZB_RECT_PAD (1.0f / 8.0f)
/* The nearest depth d is raised by this times (|d| + P22): the sphere's geometry is rasterised
 * with a different sequence of float operations (model-view-projection in the vertex shader, depth
 * interpolation) than the one that transforms its bounding sphere, so a surface touching the
 * sphere's nearest point may land a few ULPs nearer than the computed value; with a finite far
 * plane, -P22 - P23 / z cancels near the far plane and those ULPs are ULPs of P22, not of d.
 * 2^-16 is far above those ULPs and changes no real culling decision. */
#define GDR_HZB_DEPTH_SLACK (1.0f / 65536.0f)

/* Levels of the depth pyramid one dispatch of depthreduce.comp.glsl writes (one 16x16 tile of the
 * first, reduced in shared memory to 1x1 of the fifth). */
#define GDR_HZB_LEVELS_PER_DISPATCH 5

/* Push constants of depthreduce.comp.glsl (the pyramid build, src/render/hzb.c). */
GDR_STRUCT_BEGIN(GdrDepthReducePush)
    gdr_uint source_width;      /* the depth buffer (level 0) or the level before the first written */
    gdr_uint source_height;
    gdr_uint destination_width; /* the first level this dispatch writes */
    gdr_uint destination_height;
    gdr_uint from_depth;        /* 1: level 0 from the depth buffer (footprint loop); 0: 2x2 from the previous level */
    gdr_uint level_count;       /* levels written: 1 .. GDR_HZB_LEVELS_PER_DISPATCH */
    /* Level 0: 0 to read the depth image; else the address of a visibility buffer (64 bits per pixel,
     * rows top first, source_width wide, the depth's float bits in the high word) to read instead. */
    gdr_uint64 visibility_buffer;
GDR_STRUCT_END(GdrDepthReducePush)

/* What the occlusion test needs to know about the camera and the pyramid. */
GDR_STRUCT_BEGIN(GdrOcclusionParams)
    float p00;   /* projection P[0][0] = f / aspect (row, column) */
    float p11;   /* P[1][1] = f (not negated: the viewport flips Y) */
    float p22;   /* P[2][2]: 0 for the infinite projection, zn / (zf - zn) for the finite one */
    float p23;   /* P[2][3]: zn for the infinite projection, zf zn / (zf - zn) for the finite one */
    float znear; /* the near plane is z = -znear */
    gdr_uint hzb_width;  /* level-0 size of the pyramid (powers of two) */
    gdr_uint hzb_height;
    gdr_uint hzb_levels; /* down to 1x1: floor(log2(max(width, height))) + 1 */
GDR_STRUCT_END(GdrOcclusionParams)

/* A sphere's screen rectangle in UV (u0 <= u1, v0 <= v1; not clamped to the screen). */
GDR_STRUCT_BEGIN(GdrSphereRect)
    float u0;
    float v0;
    float u1;
    float v1;
    bool testable; /* false: the sphere reaches the near plane (or the eye); it must pass */
GDR_STRUCT_END(GdrSphereRect)

/* Where to read the pyramid: texels [x0, x1] x [y0, y1] of `level`, x1 - x0 and y1 - y0 in {0, 1}. */
GDR_STRUCT_BEGIN(GdrHzbFootprint)
    gdr_int level;
    gdr_int x0;
    gdr_int y0;
    gdr_int x1;
    gdr_int y1;
    float sample_u; /* one bilinear fetch with a min-reduction sampler here covers exactly those texels */
    float sample_v;
GDR_STRUCT_END(GdrHzbFootprint)

GDR_STRUCT_BEGIN(GdrOcclusionQuery)
    bool testable;       /* false: treat the sphere as visible without reading the pyramid */
    gdr_int level;       /* the footprint (GdrHzbFootprint) */
    gdr_int x0;
    gdr_int y0;
    gdr_int x1;
    gdr_int y1;
    float sample_u;
    float sample_v;
    float nearest_depth; /* reverse-Z depth of the sphere's nearest point, raised by GDR_HZB_DEPTH_SLACK; 1 if not testable */
GDR_STRUCT_END(GdrOcclusionQuery)

GDR_SHARED_FN gdr_int gdr_occ_min_int(gdr_int a, gdr_int b)
{
    return a < b ? a : b;
}

GDR_SHARED_FN float gdr_occ_clamp(float x, float lo, float hi)
{
    return gdr_occ_fmin(gdr_occ_fmax(x, lo), hi);
}

/* One bound of the sphere's projection along one screen axis, as the slope a / -z, from the 2D
 * problem in the (a, z) plane (a = x or y): the planes through the eye that contain the other
 * screen axis and touch the sphere are, in that plane, the two lines through the eye tangent to the
 * circle of centre (ca, cz) and radius r (Mara & McGuire 2013). With t = sqrt(ca^2 + cz^2 - r^2)
 * the tangent length, the tangent points are, up to a positive scale, the centre rotated by
 * +-asin(r / |c|): (t ca - s r cz, t cz + s r ca) for s = +1 and s = -1. Needs the whole circle at
 * z < 0, which makes the denominator (-z of the tangent point) positive. */
GDR_SHARED_FN float gdr_occ_tangent_slope(float ca, float cz, float r, float t, float s)
{
    return (t * ca - s * r * cz) / -(t * cz + s * r * ca);
}

/* Sphere (view-space centre c, radius r) -> its screen rectangle in UV. Spheres that reach the
 * near plane (any point with z >= -znear) are not testable: the rectangle is then the whole screen. */
GDR_SHARED_FN GdrSphereRect gdr_sphere_screen_rect(gdr_vec3 c, float r, float znear, float p00, float p11)
{
    GdrSphereRect rect;
    rect.testable = c.z + r < -znear;
    rect.u0 = 0.0f;
    rect.v0 = 0.0f;
    rect.u1 = 1.0f;
    rect.v1 = 1.0f;
    if (!rect.testable)
        return rect;
    float czr2 = c.z * c.z - r * r; /* > 0: |c.z| > r + znear */
    float tx = gdr_sqrt(c.x * c.x + czr2);
    float ty = gdr_sqrt(c.y * c.y + czr2);
    float sx0 = gdr_occ_tangent_slope(c.x, c.z, r, tx, 1.0f);
    float sx1 = gdr_occ_tangent_slope(c.x, c.z, r, tx, -1.0f);
    float sy0 = gdr_occ_tangent_slope(c.y, c.z, r, ty, 1.0f);
    float sy1 = gdr_occ_tangent_slope(c.y, c.z, r, ty, -1.0f);
    /* x_ndc = P00 x / -z, u = (1 + x_ndc) / 2; y_ndc = P11 y / -z, v = (1 - y_ndc) / 2. */
    rect.u0 = 0.5f + 0.5f * p00 * gdr_occ_fmin(sx0, sx1);
    rect.u1 = 0.5f + 0.5f * p00 * gdr_occ_fmax(sx0, sx1);
    rect.v0 = 0.5f - 0.5f * p11 * gdr_occ_fmax(sy0, sy1);
    rect.v1 = 0.5f - 0.5f * p11 * gdr_occ_fmin(sy0, sy1);
    return rect;
}

/* Size of pyramid level `level` along an axis whose level-0 size is size0. */
GDR_SHARED_FN gdr_int gdr_hzb_level_size(gdr_uint size0, gdr_int level)
{
    gdr_int size = GDR_OCC_INT(size0 >> GDR_OCC_UINT(level));
    return size > 0 ? size : 1;
}

/* The texel of `level` holding level-0 coordinate `at` (in [0, size0]; size0 itself goes to the
 * last texel). Level-`level` texel i covers level-0 texels [i 2^level, (i + 1) 2^level). */
GDR_SHARED_FN gdr_int gdr_occ_texel(float at, gdr_int level, gdr_uint size0)
{
    return gdr_occ_min_int(GDR_OCC_INT(gdr_occ_floor(gdr_occ_ldexp(at, -level))), gdr_hzb_level_size(size0, level) - 1);
}

/* The pyramid level and its (at most) 2x2 texels that cover the rectangle, grown by
 * GDR_HZB_RECT_PAD and clamped to the screen. The level is ceil(log2(longest side in level-0
 * texels)), so the rectangle is at most one texel wide there and so touches at most two texels per
 * axis; a level further up is taken if rounding left it touching three. */
GDR_SHARED_FN GdrHzbFootprint gdr_hzb_footprint(GdrSphereRect rect, gdr_uint hzb_width, gdr_uint hzb_height,
                                                gdr_uint hzb_levels)
{
    float w = GDR_OCC_FLOAT(hzb_width);
    float h = GDR_OCC_FLOAT(hzb_height);
    float x_lo = gdr_occ_clamp(rect.u0 * w - GDR_HZB_RECT_PAD, 0.0f, w);
    float x_hi = gdr_occ_clamp(rect.u1 * w + GDR_HZB_RECT_PAD, 0.0f, w);
    float y_lo = gdr_occ_clamp(rect.v0 * h - GDR_HZB_RECT_PAD, 0.0f, h);
    float y_hi = gdr_occ_clamp(rect.v1 * h + GDR_HZB_RECT_PAD, 0.0f, h);
    float side = gdr_occ_fmax(gdr_occ_fmax(x_hi - x_lo, y_hi - y_lo), 1.0f);
    gdr_int last = GDR_OCC_INT(hzb_levels) - 1;
    GdrHzbFootprint f;
    f.level = gdr_occ_min_int(GDR_OCC_INT(gdr_occ_ceil(gdr_occ_log2(side))), last);
    f.x0 = gdr_occ_texel(x_lo, f.level, hzb_width);
    f.x1 = gdr_occ_texel(x_hi, f.level, hzb_width);
    f.y0 = gdr_occ_texel(y_lo, f.level, hzb_height);
    f.y1 = gdr_occ_texel(y_hi, f.level, hzb_height);
    while (f.level < last && (f.x1 - f.x0 > 1 || f.y1 - f.y0 > 1)) {
        f.level += 1;
        f.x0 = gdr_occ_texel(x_lo, f.level, hzb_width);
        f.x1 = gdr_occ_texel(x_hi, f.level, hzb_width);
        f.y0 = gdr_occ_texel(y_lo, f.level, hzb_height);
        f.y1 = gdr_occ_texel(y_hi, f.level, hzb_height);
    }
    /* A bilinear fetch at the corner shared by two texels weights both by 1/2; at a texel's centre
     * it weights the neighbour by exactly 0, and a min-reduction sampler ignores zero weights.
     * Level sizes are powers of two, so these coordinates are exact. */
    float lw = GDR_OCC_FLOAT(gdr_hzb_level_size(hzb_width, f.level));
    float lh = GDR_OCC_FLOAT(gdr_hzb_level_size(hzb_height, f.level));
    f.sample_u = (GDR_OCC_FLOAT(f.x0) + (f.x1 > f.x0 ? 1.0f : 0.5f)) / lw;
    f.sample_v = (GDR_OCC_FLOAT(f.y0) + (f.y1 > f.y0 ? 1.0f : 0.5f)) / lh;
    return f;
}

/* Reverse-Z depth of the sphere's nearest point, z = c.z + r (depth grows towards the eye, for
 * both projections: d(z) = -P22 - P23 / z increases with z for z < 0), raised by
 * GDR_HZB_DEPTH_SLACK. Needs c.z + r < 0. Negative beyond a finite far plane. */
GDR_SHARED_FN float gdr_sphere_nearest_depth(gdr_vec3 c, float r, float p22, float p23)
{
    float depth = -p22 - p23 / (c.z + r);
    return depth + GDR_HZB_DEPTH_SLACK * (gdr_abs(depth) + p22);
}

/* The pyramid holds, per texel, the farthest (smallest reverse-Z) depth beneath it: the sphere is
 * hidden only when even its nearest point is strictly farther than all of that. */
GDR_SHARED_FN bool gdr_hzb_occludes(float nearest_depth, float pyramid_min)
{
    return nearest_depth < pyramid_min;
}

/* All of the above for one sphere. */
GDR_SHARED_FN GdrOcclusionQuery gdr_occlusion_query(gdr_vec3 c, float r, GdrOcclusionParams p)
{
    GdrSphereRect rect = gdr_sphere_screen_rect(c, r, p.znear, p.p00, p.p11);
    GdrHzbFootprint f = gdr_hzb_footprint(rect, p.hzb_width, p.hzb_height, p.hzb_levels);
    GdrOcclusionQuery q;
    q.testable = rect.testable;
    q.level = f.level;
    q.x0 = f.x0;
    q.y0 = f.y0;
    q.x1 = f.x1;
    q.y1 = f.y1;
    q.sample_u = f.sample_u;
    q.sample_v = f.sample_v;
    q.nearest_depth = rect.testable ? gdr_sphere_nearest_depth(c, r, p.p22, p.p23) : 1.0f;
    return q;
}

#endif
