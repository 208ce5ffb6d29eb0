/* A CPU reference of the shaded view for small scenes: a ray through a pixel centre is intersected
 * with every triangle (double precision), the nearest hit's attributes are interpolated, the
 * material is evaluated with textures sampled at level 0 (the tests look at magnified textures) and
 * shaded with glTF's BRDF, tone mapped and sRGB-encoded, as shared/material.h and shared/shading.h
 * do on the GPU. Written from the formulas, independently of the shaders. */
#ifndef GDR_TEST_MATERIAL_REFERENCE_H
#define GDR_TEST_MATERIAL_REFERENCE_H

#include <math.h>
#include <stdbool.h>

#include "gdr/gdr.h"
#include "gpu_shared/gpu_config.h"

typedef struct ref_vec3 {
    double x, y, z;
} ref_vec3;

static inline ref_vec3 rv(double x, double y, double z) { return (ref_vec3){x, y, z}; }
static inline ref_vec3 rv_from(gdr_vec3 a) { return rv(a.x, a.y, a.z); }
static inline ref_vec3 rv_add(ref_vec3 a, ref_vec3 b) { return rv(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline ref_vec3 rv_sub(ref_vec3 a, ref_vec3 b) { return rv(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline ref_vec3 rv_scale(ref_vec3 a, double s) { return rv(a.x * s, a.y * s, a.z * s); }
static inline double rv_dot(ref_vec3 a, ref_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline ref_vec3 rv_cross(ref_vec3 a, ref_vec3 b)
{
    return rv(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline ref_vec3 rv_normalize(ref_vec3 a) { return rv_scale(a, 1.0 / sqrt(rv_dot(a, a))); }
static inline ref_vec3 rv_mul(ref_vec3 a, ref_vec3 b) { return rv(a.x * b.x, a.y * b.y, a.z * b.z); }

/* The nearest hit of a pixel's ray. */
typedef struct ref_hit {
    bool hit;
    uint32_t instance;
    ref_vec3 p[3];      /* the triangle's world-space corners */
    uint32_t v[3];      /* its vertices (mesh-local indices) */
    double b[3];        /* barycentrics of the hit */
    ref_vec3 position;
} ref_hit;

/* World-space ray of pixel centre (px + 0.5, py + 0.5) of a width x height image seen by camera. */
static inline void ref_pixel_ray(const gdr_camera *camera, uint32_t width, uint32_t height, double px, double py,
                                 ref_vec3 *origin, ref_vec3 *direction)
{
    double aspect = camera->aspect > 0.0f ? camera->aspect : (double)width / height;
    double t = tan(camera->yfov * 0.5);
    double x = (2.0 * (px + 0.5) / width - 1.0) * t * aspect, y = (1.0 - 2.0 * (py + 0.5) / height) * t;
    gdr_vec3 d = gdr_quat_rotate(camera->rotation, (gdr_vec3){(float)x, (float)y, -1.0f});
    *origin = rv_from(camera->position);
    *direction = rv_from(d);
}

static inline ref_hit ref_raycast(const gdr_scene *scene, ref_vec3 o, ref_vec3 d)
{
    ref_hit best = {.hit = false};
    double best_t = INFINITY;
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        const gdr_instance *inst = &scene->instances[i];
        const gdr_mesh *mesh = &scene->meshes[inst->mesh];
        for (uint32_t t = 0; t + 2 < mesh->index_count; t += 3) {
            ref_vec3 p[3];
            for (int k = 0; k < 3; k++)
                p[k] = rv_from(gdr_mat4_transform_point(inst->transform, mesh->positions[mesh->indices[t + k]]));
            ref_vec3 e1 = rv_sub(p[1], p[0]), e2 = rv_sub(p[2], p[0]), q = rv_cross(d, e2);
            double det = rv_dot(e1, q);
            if (fabs(det) < 1e-14)
                continue;
            ref_vec3 s = rv_sub(o, p[0]), r = rv_cross(s, e1);
            double u = rv_dot(s, q) / det, v = rv_dot(d, r) / det, dist = rv_dot(e2, r) / det;
            if (u < 0 || v < 0 || u + v > 1 || dist <= 0 || dist >= best_t)
                continue;
            bool double_sided = inst->material < scene->material_count && scene->materials[inst->material].double_sided;
            if (!double_sided && rv_dot(rv_cross(e1, e2), d) > 0)
                continue; /* the back face of a single-sided material */
            best_t = dist;
            best = (ref_hit){.hit = true, .instance = i, .b = {1 - u - v, u, v}, .position = rv_add(o, rv_scale(d, dist))};
            for (int k = 0; k < 3; k++) {
                best.p[k] = p[k];
                best.v[k] = mesh->indices[t + k];
            }
        }
    }
    return best;
}

static inline double ref_srgb_decode(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static inline double ref_srgb_encode(double c)
{
    c = c < 0 ? 0 : c > 1 ? 1 : c;
    return c <= 0.0031308 ? c * 12.92 : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

/* Vulkan's wrap of an integer texel coordinate. */
static inline int64_t ref_wrap(int64_t i, int64_t size, uint32_t mode)
{
    if (mode == GDR_SAMPLER_WRAP_CLAMP)
        return i < 0 ? 0 : i >= size ? size - 1 : i;
    if (mode == GDR_SAMPLER_WRAP_MIRROR) {
        int64_t m = ((i % (2 * size)) + 2 * size) % (2 * size) - size;
        return (size - 1) - (m >= 0 ? m : -(1 + m));
    }
    return ((i % size) + size) % size;
}

/* Texel (x, y) of level 0: a block-compressed texture's decoded from its block, as the device
 * samples it (gdr_texture_decode_level on that one block). */
static inline void ref_texel(const gdr_texture *t, int64_t x, int64_t y, double out[4])
{
    const uint8_t *c = t->rgba + ((size_t)y * t->width + (size_t)x) * 4;
    uint8_t texels[64];
    if (t->format != GDR_TEXTURE_RGBA8) {
        size_t blocks_x = (t->width + 3) / 4;
        gdr_texture one = {.width = 4, .height = 4, .levels = 1, .format = t->format,
                           .rgba = t->rgba + ((size_t)(y / 4) * blocks_x + (size_t)(x / 4)) * gdr_texture_block_bytes(t->format)};
        gdr_error err;
        if (gdr_texture_decode_level(&one, 0, texels, &err) != GDR_OK)
            memset(texels, 0, sizeof texels);
        c = texels + ((y % 4) * 4 + (x % 4)) * 4;
    }
    for (int k = 0; k < 4; k++)
        out[k] = k < 3 && t->srgb ? ref_srgb_decode(c[k] / 255.0) : c[k] / 255.0;
}

/* The transformed coordinate of reference r at uv. */
static inline void ref_transform_uv(const gdr_texture_ref *r, const double uv[2], double out[2])
{
    double c = cos(r->rotation), s = sin(r->rotation), u = uv[0] * r->scale.x, v = uv[1] * r->scale.y;
    out[0] = r->offset.x + c * u + s * v;
    out[1] = r->offset.y - s * u + c * v;
}

/* Texture reference r at uv, level 0 (magnification filter), linear values. */
static inline void ref_sample(const gdr_scene *scene, const gdr_texture_ref *r, const double uv_in[2], double out[4])
{
    const gdr_texture *t = &scene->textures[r->texture];
    double uv[2];
    ref_transform_uv(r, uv_in, uv);
    uint32_t ws = GDR_SAMPLER_WRAP_S(r->sampler), wt = GDR_SAMPLER_WRAP_T(r->sampler);
    if (r->sampler & GDR_SAMPLER_MAG_NEAREST) {
        ref_texel(t, ref_wrap((int64_t)floor(uv[0] * t->width), t->width, ws),
                  ref_wrap((int64_t)floor(uv[1] * t->height), t->height, wt), out);
        return;
    }
    double x = uv[0] * t->width - 0.5, y = uv[1] * t->height - 0.5, fx = x - floor(x), fy = y - floor(y);
    int64_t x0 = (int64_t)floor(x), y0 = (int64_t)floor(y);
    double c[4][4];
    for (int k = 0; k < 4; k++)
        ref_texel(t, ref_wrap(x0 + (k & 1), t->width, ws), ref_wrap(y0 + (k >> 1), t->height, wt), c[k]);
    for (int k = 0; k < 4; k++)
        out[k] = (c[0][k] * (1 - fx) + c[1][k] * fx) * (1 - fy) + (c[2][k] * (1 - fx) + c[3][k] * fx) * fy;
}

/* The texture's footprint of one pixel at the hit, in texels of reference r (the larger of the
 * two screen directions): below 1 the sampler magnifies and reads level 0. */
static inline double ref_footprint(const gdr_scene *scene, const gdr_texture_ref *r, const double duv_dx[2],
                                   const double duv_dy[2])
{
    const gdr_texture *t = &scene->textures[r->texture];
    double a[2], b[2];
    gdr_texture_ref linear = *r;
    linear.offset = (gdr_vec2){0, 0};
    ref_transform_uv(&linear, duv_dx, a);
    ref_transform_uv(&linear, duv_dy, b);
    double fx = hypot(a[0] * t->width, a[1] * t->height), fy = hypot(b[0] * t->width, b[1] * t->height);
    return fx > fy ? fx : fy;
}

/* glTF's BRDF with gdr's light and ambient (shared/shading.h's constants), tone mapped and encoded. */
static inline void ref_shade(ref_vec3 base, ref_vec3 n, double metallic, double roughness, double occlusion,
                             ref_vec3 emissive, ref_vec3 v, uint8_t out[3])
{
    const double pi = 3.14159265358979;
    ref_vec3 l = rv_normalize(rv(GDR_LIGHT_TOWARDS_X, GDR_LIGHT_TOWARDS_Y, GDR_LIGHT_TOWARDS_Z));
    ref_vec3 c_diff = rv_scale(base, 1 - metallic);
    ref_vec3 f0 = rv_add(rv_scale(rv(0.04, 0.04, 0.04), 1 - metallic), rv_scale(base, metallic));
    double alpha = fmax(roughness * roughness, 1e-3), a2 = alpha * alpha;
    double n_v = fmax(rv_dot(n, v), 1e-4), n_l = fmax(rv_dot(n, l), 0.0);
    ref_vec3 h = rv_normalize(rv_add(l, v));
    double v_h = fmax(rv_dot(v, h), 0.0), n_h = fmax(rv_dot(n, h), 0.0);
    double dd = n_h * n_h * (a2 - 1) + 1, d = a2 / (pi * dd * dd);
    double gl = n_v * sqrt(n_l * n_l * (1 - a2) + a2), gv = n_l * sqrt(n_v * n_v * (1 - a2) + a2);
    double vis = gl + gv > 0 ? 0.5 / (gl + gv) : 0;
    double ambient = (0.18 + 0.17 * (0.5 + 0.5 * n.y)) * occlusion;
    double f0s[3] = {f0.x, f0.y, f0.z}, cd[3] = {c_diff.x, c_diff.y, c_diff.z}, em[3] = {emissive.x, emissive.y, emissive.z};
    double color[3];
    for (int k = 0; k < 3; k++) {
        double fresnel = f0s[k] + (1 - f0s[k]) * pow(1 - v_h, 5);
        double brdf = (1 - fresnel) * cd[k] / pi + fresnel * d * vis;
        color[k] = brdf * 0.7 * pi * n_l + (cd[k] + f0s[k]) * ambient + em[k];
    }
    /* Khronos PBR Neutral. */
    double x = fmin(color[0], fmin(color[1], color[2])), offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    for (int k = 0; k < 3; k++)
        color[k] -= offset;
    double peak = fmax(color[0], fmax(color[1], color[2])), start = 0.76;
    if (peak >= start) {
        double dk = 1 - start, new_peak = 1 - dk * dk / (peak + dk - start);
        double g = 1 - 1 / (0.15 * (peak - new_peak) + 1);
        for (int k = 0; k < 3; k++)
            color[k] = color[k] * new_peak / peak * (1 - g) + new_peak * g;
    }
    for (int k = 0; k < 3; k++)
        out[k] = (uint8_t)lround(ref_srgb_encode(color[k]) * 255.0);
}

/* The interpolated uv of a hit and its change one pixel right and one pixel down (from the hits of
 * those pixels' rays with the same triangle's plane). */
typedef struct ref_point {
    double uv[2], duv_dx[2], duv_dy[2];
    ref_vec3 normal;  /* world space, unit, before the normal map */
    double color[4];  /* vertex colour times instance colour */
} ref_point;

static inline void ref_barycentric_uv(const gdr_mesh *mesh, const ref_hit *h, const double b[3], double uv[2])
{
    uv[0] = uv[1] = 0;
    for (int k = 0; k < 3; k++) {
        uv[0] += b[k] * mesh->uvs[h->v[k]].x;
        uv[1] += b[k] * mesh->uvs[h->v[k]].y;
    }
}

/* Barycentrics of the ray (o, d) on the plane of hit h's triangle. */
static inline void ref_plane_barycentrics(const ref_hit *h, ref_vec3 o, ref_vec3 d, double b[3])
{
    ref_vec3 e1 = rv_sub(h->p[1], h->p[0]), e2 = rv_sub(h->p[2], h->p[0]), q = rv_cross(d, e2);
    double det = rv_dot(e1, q);
    ref_vec3 s = rv_sub(o, h->p[0]), r = rv_cross(s, e1);
    b[1] = rv_dot(s, q) / det;
    b[2] = rv_dot(d, r) / det;
    b[0] = 1 - b[1] - b[2];
}

/* The shaded colour of pixel (px, py), or false when the pixel's ray misses everything or the
 * pixel is not one a test can compare exactly: within one pixel of another triangle's edge, or
 * where a texture of its material is minified (footprint of 0.7 texels or more). */
static inline bool ref_shade_pixel(const gdr_scene *scene, const gdr_camera *camera, uint32_t width, uint32_t height,
                                   uint32_t px, uint32_t py, uint8_t out[3], uint32_t *out_instance)
{
    ref_vec3 o, d, dx, dy;
    ref_pixel_ray(camera, width, height, px, py, &o, &d);
    ref_hit h = ref_raycast(scene, o, d);
    if (!h.hit)
        return false;
    for (int n = 0; n < 4; n++) { /* neighbours on the same triangle */
        ref_vec3 no, nd;
        ref_pixel_ray(camera, width, height, px + (n == 0) - (n == 1), py + (n == 2) - (n == 3), &no, &nd);
        ref_hit nh = ref_raycast(scene, no, nd);
        if (!nh.hit || nh.instance != h.instance || nh.v[0] != h.v[0] || nh.v[1] != h.v[1] || nh.v[2] != h.v[2])
            return false;
    }
    const gdr_instance *inst = &scene->instances[h.instance];
    const gdr_mesh *mesh = &scene->meshes[inst->mesh];
    *out_instance = h.instance;
    gdr_material m = inst->material < scene->material_count ? scene->materials[inst->material] : gdr_material_default();
    if (inst->material >= scene->material_count) {
        m.metallic_factor = 0.0f;
        m.roughness_factor = 0.5f;
    }
    double bx[3], by[3], uvx[2], uvy[2];
    ref_point p;
    ref_barycentric_uv(mesh, &h, h.b, p.uv);
    ref_pixel_ray(camera, width, height, px + 1.0, py, &o, &dx);
    ref_plane_barycentrics(&h, o, dx, bx);
    ref_pixel_ray(camera, width, height, px, py + 1.0, &o, &dy);
    ref_plane_barycentrics(&h, o, dy, by);
    ref_barycentric_uv(mesh, &h, bx, uvx);
    ref_barycentric_uv(mesh, &h, by, uvy);
    for (int k = 0; k < 2; k++) {
        p.duv_dx[k] = uvx[k] - p.uv[k];
        p.duv_dy[k] = uvy[k] - p.uv[k];
    }
    const gdr_texture_ref *refs[5] = {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture,
                                      &m.occlusion_texture, &m.emissive_texture};
    double texel[5][4];
    for (int k = 0; k < 5; k++) {
        texel[k][0] = texel[k][1] = texel[k][2] = texel[k][3] = 1.0;
        if (refs[k]->texture == GDR_NO_INDEX)
            continue;
        if (ref_footprint(scene, refs[k], p.duv_dx, p.duv_dy) >= 0.7)
            return false;
        ref_sample(scene, refs[k], p.uv, texel[k]);
        if (refs[k]->sampler & GDR_SAMPLER_MAG_NEAREST) { /* not within a pixel of a texel edge */
            double a[2], b2[2], c[2];
            const gdr_texture *t = &scene->textures[refs[k]->texture];
            ref_transform_uv(refs[k], p.uv, a);
            ref_transform_uv(refs[k], uvx, b2);
            ref_transform_uv(refs[k], uvy, c);
            double span[2] = {fabs(b2[0] - a[0]) + fabs(c[0] - a[0]), fabs(b2[1] - a[1]) + fabs(c[1] - a[1])};
            double fu = a[0] * t->width - floor(a[0] * t->width), fv = a[1] * t->height - floor(a[1] * t->height);
            if (fu < span[0] * t->width || fu > 1 - span[0] * t->width || fv < span[1] * t->height ||
                fv > 1 - span[1] * t->height)
                return false;
        }
    }
    /* Vertex colour, normal. */
    double vc[4] = {0, 0, 0, 0};
    ref_vec3 n = rv(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        gdr_vec4 c = mesh->colors ? mesh->colors[h.v[k]] : (gdr_vec4){1, 1, 1, 1};
        const float *cf = &c.x;
        for (int j = 0; j < 4; j++)
            vc[j] += h.b[k] * cf[j];
        gdr_vec3 nk = mesh->normals[h.v[k]];
        gdr_mat4 mt = inst->transform; /* the cofactor of the upper 3x3 (columns) */
        ref_vec3 c0 = rv(mt.m[0], mt.m[1], mt.m[2]), c1 = rv(mt.m[4], mt.m[5], mt.m[6]), c2 = rv(mt.m[8], mt.m[9], mt.m[10]);
        ref_vec3 cof = rv_add(rv_add(rv_scale(rv_cross(c1, c2), nk.x), rv_scale(rv_cross(c2, c0), nk.y)),
                              rv_scale(rv_cross(c0, c1), nk.z));
        n = rv_add(n, rv_scale(cof, h.b[k]));
    }
    n = rv_normalize(n);
    if (m.double_sided && rv_dot(rv_cross(rv_sub(h.p[1], h.p[0]), rv_sub(h.p[2], h.p[0])), rv_sub(o, h.position)) < 0)
        n = rv_scale(n, -1); /* a back face, shaded with the normal reversed */
    const float *ic = &inst->color.x, *bc = &m.base_color.x;
    ref_vec3 base = rv(bc[0] * ic[0] * vc[0] * texel[0][0], bc[1] * ic[1] * vc[1] * texel[0][1],
                       bc[2] * ic[2] * vc[2] * texel[0][2]);
    if (m.normal_texture.texture != GDR_NO_INDEX) {
        double uv0[2], uv1[2], uv2[2];
        for (int k = 0; k < 2; k++) {
            uv0[k] = k ? mesh->uvs[h.v[0]].y : mesh->uvs[h.v[0]].x;
            uv1[k] = (k ? mesh->uvs[h.v[1]].y : mesh->uvs[h.v[1]].x) - uv0[k];
            uv2[k] = (k ? mesh->uvs[h.v[2]].y : mesh->uvs[h.v[2]].x) - uv0[k];
        }
        ref_vec3 e1 = rv_sub(h.p[1], h.p[0]), e2 = rv_sub(h.p[2], h.p[0]);
        double r = uv1[0] * uv2[1] - uv2[0] * uv1[1];
        ref_vec3 dp_du = rv_scale(rv_sub(rv_scale(e1, uv2[1]), rv_scale(e2, uv1[1])), 1 / r);
        ref_vec3 dp_dv = rv_scale(rv_sub(rv_scale(e2, uv1[0]), rv_scale(e1, uv2[0])), 1 / r);
        ref_vec3 t = rv_normalize(rv_sub(dp_du, rv_scale(n, rv_dot(n, dp_du))));
        ref_vec3 b = rv_cross(n, t);
        if (rv_dot(b, dp_dv) > 0)
            b = rv_scale(b, -1);
        double tx = texel[2][0] * 2 - 1, ty = texel[2][1] * 2 - 1; /* z rebuilt from x and y, as the shaders do */
        double x = tx * m.normal_scale, y = ty * m.normal_scale, z = sqrt(fmax(1 - tx * tx - ty * ty, 0));
        n = rv_normalize(rv_add(rv_add(rv_scale(t, x), rv_scale(b, y)), rv_scale(n, z)));
    }
    double metallic = fmin(fmax(m.metallic_factor * texel[1][2], 0), 1);
    double roughness = fmin(fmax(m.roughness_factor * texel[1][1], 0), 1);
    double occlusion = 1 + m.occlusion_strength * (texel[3][0] - 1);
    ref_vec3 emissive = rv(m.emissive.x * texel[4][0], m.emissive.y * texel[4][1], m.emissive.z * texel[4][2]);
    ref_vec3 v = rv_normalize(rv_sub(rv_from(camera->position), h.position));
    ref_shade(base, n, metallic, roughness, occlusion, emissive, v, out);
    return true;
}

#endif
