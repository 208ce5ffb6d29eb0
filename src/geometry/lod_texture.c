/* What the texture shows where it slides (lod_texture.h): per texture, the minimum and maximum of
 * each channel over cells of texels, in a pyramid, so that the largest change a box of uvs can show
 * is found from at most 4 x 4 cells of one level. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geometry/lod_texture.h"

/* Pyramid level 0 cells are this many texels a side: a sixteenth of the texels' memory for each of
 * the minimum and the maximum, and a box is at most this much wider than asked. */
#define LOD_TEXTURE_CELL 4u
#define ALL_CHANNELS 0xfu

/* --- one texture's pyramid ------------------------------------------------------------------------ */

static uint32_t cells_of(uint32_t n, uint32_t per) { return (n + per - 1) / per; }

/* Each channel's minimum into lo and maximum into hi over n RGBA values `stride` bytes apart, with
 * lo and hi as they were (kept in locals: the compiler need not reload them past the stores). */
static void span_range(const uint8_t *v, uint32_t n, size_t stride, uint8_t *lo, uint8_t *hi)
{
    uint8_t l0 = lo[0], l1 = lo[1], l2 = lo[2], l3 = lo[3], h0 = hi[0], h1 = hi[1], h2 = hi[2], h3 = hi[3];
    for (uint32_t i = 0; i < n; i++, v += stride) {
        l0 = v[0] < l0 ? v[0] : l0, l1 = v[1] < l1 ? v[1] : l1, l2 = v[2] < l2 ? v[2] : l2, l3 = v[3] < l3 ? v[3] : l3;
        h0 = v[0] > h0 ? v[0] : h0, h1 = v[1] > h1 ? v[1] : h1, h2 = v[2] > h2 ? v[2] : h2, h3 = v[3] > h3 ? v[3] : h3;
    }
    lo[0] = l0, lo[1] = l1, lo[2] = l2, lo[3] = l3, hi[0] = h0, hi[1] = h1, hi[2] = h2, hi[3] = h3;
}

/* Level 0: each cell's channels over its texels. */
static void first_level(lod_texture_pyramid *p, const uint8_t *rgba)
{
    uint32_t w = cells_of(p->width, LOD_TEXTURE_CELL), h = cells_of(p->height, LOD_TEXTURE_CELL);
    for (uint32_t cy = 0; cy < h; cy++)
        for (uint32_t cx = 0; cx < w; cx++) {
            uint8_t lo[4] = {255, 255, 255, 255}, hi[4] = {0, 0, 0, 0};
            uint32_t x0 = cx * LOD_TEXTURE_CELL, y0 = cy * LOD_TEXTURE_CELL;
            uint32_t nx = p->width - x0 < LOD_TEXTURE_CELL ? p->width - x0 : LOD_TEXTURE_CELL;
            uint32_t y1 = y0 + LOD_TEXTURE_CELL < p->height ? y0 + LOD_TEXTURE_CELL : p->height;
            for (uint32_t y = y0; y < y1; y++)
                span_range(rgba + ((size_t)y * p->width + x0) * 4, nx, 4, lo, hi);
            memcpy(p->lo[0] + ((size_t)cy * w + cx) * 4, lo, 4);
            memcpy(p->hi[0] + ((size_t)cy * w + cx) * 4, hi, 4);
        }
}

/* Level l from level l - 1: each cell over the (up to) 2 x 2 cells it covers. */
static void next_level(lod_texture_pyramid *p, uint32_t l)
{
    uint32_t w = p->level_width[l], h = p->level_height[l], pw = p->level_width[l - 1], ph = p->level_height[l - 1];
    for (uint32_t cy = 0; cy < h; cy++)
        for (uint32_t cx = 0; cx < w; cx++) {
            uint8_t lo[4] = {255, 255, 255, 255}, hi[4] = {0, 0, 0, 0};
            for (uint32_t y = cy * 2; y < cy * 2 + 2 && y < ph; y++)
                for (uint32_t x = cx * 2; x < cx * 2 + 2 && x < pw; x++) {
                    const uint8_t *a = p->lo[l - 1] + ((size_t)y * pw + x) * 4, *b = p->hi[l - 1] + ((size_t)y * pw + x) * 4;
                    for (int k = 0; k < 4; k++) {
                        lo[k] = a[k] < lo[k] ? a[k] : lo[k];
                        hi[k] = b[k] > hi[k] ? b[k] : hi[k];
                    }
                }
            memcpy(p->lo[l] + ((size_t)cy * w + cx) * 4, lo, 4);
            memcpy(p->hi[l] + ((size_t)cy * w + cx) * 4, hi, 4);
        }
}

int lod_texture_pyramid_build(lod_texture_pyramid *p, const uint8_t *rgba, uint32_t width, uint32_t height)
{
    *p = (lod_texture_pyramid){.width = width, .height = height};
    uint32_t w = cells_of(width, LOD_TEXTURE_CELL), h = cells_of(height, LOD_TEXTURE_CELL), levels = 1;
    while (w > 1 || h > 1)
        w = cells_of(w, 2), h = cells_of(h, 2), levels++;
    p->level_width = malloc(levels * sizeof *p->level_width);
    p->level_height = malloc(levels * sizeof *p->level_height);
    p->lo = calloc(levels, sizeof *p->lo);
    p->hi = calloc(levels, sizeof *p->hi);
    p->levels = levels;
    if (!p->level_width || !p->level_height || !p->lo || !p->hi) {
        lod_texture_pyramid_free(p);
        return 0;
    }
    w = cells_of(width, LOD_TEXTURE_CELL), h = cells_of(height, LOD_TEXTURE_CELL);
    for (uint32_t l = 0; l < levels; l++) {
        p->level_width[l] = w, p->level_height[l] = h;
        p->lo[l] = malloc((size_t)w * h * 4);
        p->hi[l] = malloc((size_t)w * h * 4);
        if (!p->lo[l] || !p->hi[l]) {
            lod_texture_pyramid_free(p);
            return 0;
        }
        w = cells_of(w, 2), h = cells_of(h, 2);
    }
    first_level(p, rgba);
    for (uint32_t l = 1; l < levels; l++)
        next_level(p, l);
    return 1;
}

void lod_texture_pyramid_free(lod_texture_pyramid *p)
{
    for (uint32_t l = 0; l < p->levels; l++) {
        if (p->lo)
            free(p->lo[l]);
        if (p->hi)
            free(p->hi[l]);
    }
    free(p->lo);
    free(p->hi);
    free(p->level_width);
    free(p->level_height);
    memset(p, 0, sizeof *p);
}

/* --- a box's change -------------------------------------------------------------------------------- */

/* The texels [lo, hi] (inclusive, lo <= hi, hi - lo < size) of one axis under a wrap mode, as at
 * most two ranges within [0, size): returns how many. */
static int wrap_range(int64_t lo, int64_t hi, int64_t size, uint32_t mode, int64_t out[2][2])
{
    if (mode == GDR_SAMPLER_WRAP_CLAMP) {
        out[0][0] = lo < 0 ? 0 : lo >= size ? size - 1 : lo;
        out[0][1] = hi < 0 ? 0 : hi >= size ? size - 1 : hi;
        return 1;
    }
    int64_t period = mode == GDR_SAMPLER_WRAP_MIRROR ? 2 * size : size;
    int64_t a = lo % period;
    a += a < 0 ? period : 0;
    int64_t b = a + (hi - lo), n = 0;
    for (int64_t start = 0; start <= b; start += size) { /* the pieces in [0, size), [size, 2 size), ... */
        int64_t p0 = a > start ? a : start, p1 = b < start + size - 1 ? b : start + size - 1;
        if (p0 > p1)
            continue;
        int64_t k = start / size; /* the piece's period: odd ones mirrored */
        if (mode == GDR_SAMPLER_WRAP_MIRROR && k % 2 == 1)
            out[n][0] = start + size - 1 - p1, out[n][1] = start + size - 1 - p0;
        else
            out[n][0] = p0 - start, out[n][1] = p1 - start;
        n++;
    }
    return (int)n;
}

/* The texels a bilinear sample reads over [u0, u1] of an axis of `size` texels, as ranges within the
 * texture (wrap_range); the whole axis when the box spans it or is not finite. */
static int axis_ranges(double u0, double u1, uint32_t size, uint32_t mode, int64_t out[2][2])
{
    double x0 = floor(u0 * size - 0.5), x1 = floor(u1 * size - 0.5) + 1.0;
    if (!(x0 >= -1e12 && x1 <= 1e12) || x1 - x0 + 1.0 >= size) {
        out[0][0] = 0, out[0][1] = (int64_t)size - 1;
        return 1;
    }
    return wrap_range((int64_t)x0, (int64_t)x1, size, mode, out);
}

/* Each channel's minimum and maximum over the texels [x0, x1] x [y0, y1] (within the texture),
 * widened to whole cells of the level where the range spans at most 4 x 4 cells, into lo and hi
 * as they were. */
static void range_of(const lod_texture_pyramid *p, const int64_t x[2], const int64_t y[2], uint8_t lo[4], uint8_t hi[4])
{
    uint64_t cx0 = (uint64_t)x[0] / LOD_TEXTURE_CELL, cx1 = (uint64_t)x[1] / LOD_TEXTURE_CELL;
    uint64_t cy0 = (uint64_t)y[0] / LOD_TEXTURE_CELL, cy1 = (uint64_t)y[1] / LOD_TEXTURE_CELL;
    uint32_t l = 0;
    while (l + 1 < p->levels && ((cx1 >> l) - (cx0 >> l) > 3 || (cy1 >> l) - (cy0 >> l) > 3))
        l++;
    uint32_t w = p->level_width[l];
    uint8_t l0 = lo[0], l1 = lo[1], l2 = lo[2], l3 = lo[3], h0 = hi[0], h1 = hi[1], h2 = hi[2], h3 = hi[3];
    for (uint64_t cy = cy0 >> l; cy <= (cy1 >> l) && cy < p->level_height[l]; cy++)
        for (uint64_t cx = cx0 >> l; cx <= (cx1 >> l) && cx < w; cx++) {
            const uint8_t *a = p->lo[l] + (cy * w + cx) * 4, *b = p->hi[l] + (cy * w + cx) * 4;
            l0 = a[0] < l0 ? a[0] : l0, l1 = a[1] < l1 ? a[1] : l1, l2 = a[2] < l2 ? a[2] : l2, l3 = a[3] < l3 ? a[3] : l3;
            h0 = b[0] > h0 ? b[0] : h0, h1 = b[1] > h1 ? b[1] : h1, h2 = b[2] > h2 ? b[2] : h2, h3 = b[3] > h3 ? b[3] : h3;
        }
    lo[0] = l0, lo[1] = l1, lo[2] = l2, lo[3] = l3, hi[0] = h0, hi[1] = h1, hi[2] = h2, hi[3] = h3;
}

/* One use's change over the box of the uvs, in [0, 1] before its weight. */
static double use_variation(const lod_texture_use *u, const double (*uv)[2], uint32_t count)
{
    const lod_texture_pyramid *p = u->pyramid;
    if (!p || !p->levels)
        return 1.0;
    double box[2][2] = {{INFINITY, -INFINITY}, {INFINITY, -INFINITY}};
    for (uint32_t i = 0; i < count; i++)
        for (int a = 0; a < 2; a++) {
            double t = u->offset[a] + u->m[a][0] * uv[i][0] + u->m[a][1] * uv[i][1];
            box[a][0] = t < box[a][0] ? t : box[a][0];
            box[a][1] = t > box[a][1] ? t : box[a][1];
        }
    int64_t xs[2][2], ys[2][2];
    int nx = axis_ranges(box[0][0], box[0][1], p->width, GDR_SAMPLER_WRAP_S(u->sampler), xs);
    int ny = axis_ranges(box[1][0], box[1][1], p->height, GDR_SAMPLER_WRAP_T(u->sampler), ys);
    uint8_t lo[4] = {255, 255, 255, 255}, hi[4] = {0, 0, 0, 0};
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++)
            range_of(p, xs[i], ys[j], lo, hi);
    int largest = 0;
    for (int k = 0; k < 4; k++)
        if ((u->channels >> k & 1u) && hi[k] >= lo[k] && hi[k] - lo[k] > largest)
            largest = hi[k] - lo[k];
    return largest / 255.0;
}

double lod_texture_variation(const lod_texture_set *set, const double (*uv)[2], uint32_t count)
{
    if (!set)
        return 1.0;
    double largest = 0.0;
    for (uint32_t i = 0; i < set->count && largest < 1.0; i++) {
        const lod_texture_use *u = &set->uses[i];
        /* A use's change is at most its weight (use_variation is at most 1): one whose weight is no
         * more than the largest so far cannot raise it, and is not measured. */
        if (u->weight > largest) {
            double v = use_variation(u, uv, count) * u->weight;
            largest = v > largest ? v : largest;
        }
    }
    return largest < 1.0 ? largest : 1.0;
}

/* --- a scene's textures ------------------------------------------------------------------------------ */

typedef struct mesh_material {
    uint32_t mesh, material;
} mesh_material;

static int compare_pairs(const void *a, const void *b)
{
    const mesh_material *x = a, *y = b;
    if (x->mesh != y->mesh)
        return x->mesh < y->mesh ? -1 : 1;
    return x->material < y->material ? -1 : x->material > y->material;
}

/* The distinct (mesh, material) pairs of the instances of textured meshes, sorted; *count of them.
 * NULL when out of memory. */
static mesh_material *gather_pairs(const gdr_scene *scene, const uint8_t *textured, size_t *count)
{
    mesh_material *pairs = malloc((scene->instance_count ? scene->instance_count : 1) * sizeof *pairs);
    if (!pairs)
        return NULL;
    size_t n = 0;
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        const gdr_instance *in = &scene->instances[i];
        if (in->mesh < scene->mesh_count && textured[in->mesh] && in->material < scene->material_count)
            pairs[n++] = (mesh_material){in->mesh, in->material};
    }
    qsort(pairs, n, sizeof *pairs, compare_pairs);
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (k == 0 || compare_pairs(&pairs[k - 1], &pairs[i]) != 0)
            pairs[k++] = pairs[i];
    *count = k;
    return pairs;
}

static double largest3(double a, double b, double c) { return fmax(a, fmax(b, c)); }
/* A factor as a weight: not below 0, NaN as 1 (any change). */
static double as_weight(double w) { return w >= 0.0 ? w : (w < 0.0 ? 0.0 : 1.0); }

/* A material's texture references with the channels its shading reads and the factor it multiplies
 * them by; returns how many it has. */
static uint32_t material_refs(const gdr_material *m, const gdr_texture_ref *refs[5], uint32_t channels[5],
                              double weights[5])
{
    int alpha = m->alpha_mode != GDR_ALPHA_OPAQUE;
    const gdr_texture_ref *all[5] = {&m->base_color_texture, &m->metallic_roughness_texture, &m->normal_texture,
                                     &m->occlusion_texture, &m->emissive_texture};
    const uint32_t reads[5] = {alpha ? 0xfu : 0x7u, 0x6u, 0x3u, 0x1u, 0x7u}; /* RGB(A), GB, RG (z is rebuilt), R, RGB */
    const double factors[5] = {
        fmax(largest3(m->base_color.x, m->base_color.y, m->base_color.z), alpha ? m->base_color.w : 0.0),
        fmax(m->metallic_factor, m->roughness_factor), fmax(fabs(m->normal_scale), 1.0), m->occlusion_strength,
        largest3(m->emissive.x, m->emissive.y, m->emissive.z)};
    uint32_t n = 0;
    for (int k = 0; k < 5; k++)
        if (all[k]->texture != GDR_NO_INDEX) {
            refs[n] = all[k], channels[n] = reads[k], weights[n] = as_weight(factors[k]);
            n++;
        }
    return n;
}

/* The pyramid of texture t, built the first time a use needs it; NULL where none can be (not RGBA8,
 * no texels, out of range). *failed on running out of memory. */
static const lod_texture_pyramid *pyramid_for(const gdr_scene *scene, lod_scene_textures *out, uint32_t t, int *failed)
{
    if (t >= scene->texture_count)
        return NULL;
    const gdr_texture *tex = &scene->textures[t];
    if (tex->format != GDR_TEXTURE_RGBA8 || !tex->rgba || !tex->width || !tex->height)
        return NULL;
    lod_texture_pyramid *p = &out->pyramids[t];
    if (!p->levels && !lod_texture_pyramid_build(p, tex->rgba, tex->width, tex->height))
        *failed = 1;
    return p->levels ? p : NULL;
}

/* One texture reference as a use (its transform as a matrix). */
static lod_texture_use make_use(const gdr_texture_ref *ref, const lod_texture_pyramid *p, uint32_t channels, double weight)
{
    double c = cos(ref->rotation), s = sin(ref->rotation);
    return (lod_texture_use){.pyramid = p, .sampler = ref->sampler, .offset = {ref->offset.x, ref->offset.y},
                             .m = {{c * ref->scale.x, s * ref->scale.y}, {-s * ref->scale.x, c * ref->scale.y}},
                             .channels = channels, .weight = weight};
}

/* The uses of the sorted pairs, into out->uses, and each mesh's set over them. */
static int fill_uses(const gdr_scene *scene, const mesh_material *pairs, size_t count, lod_scene_textures *out)
{
    int failed = 0;
    size_t n = 0;
    for (size_t i = 0; i < count && !failed; i++) {
        const gdr_texture_ref *refs[5];
        uint32_t channels[5];
        double weights[5];
        uint32_t k = material_refs(&scene->materials[pairs[i].material], refs, channels, weights);
        lod_texture_set *set = &out->sets[pairs[i].mesh];
        if (!set->count)
            set->uses = out->uses + n;
        for (uint32_t j = 0; j < k; j++)
            out->uses[n++] = make_use(refs[j], pyramid_for(scene, out, refs[j]->texture, &failed), channels[j], weights[j]);
        set->count += k;
    }
    return !failed;
}

gdr_status lod_scene_textures_build(const gdr_scene *scene, const uint8_t *textured, lod_scene_textures *out,
                                    gdr_error *err)
{
    *out = (lod_scene_textures){0};
    size_t count = 0;
    mesh_material *pairs = gather_pairs(scene, textured, &count);
    out->pyramids = calloc(scene->texture_count ? scene->texture_count : 1, sizeof *out->pyramids);
    out->pyramid_count = scene->texture_count;
    out->uses = malloc((count ? count : 1) * 5 * sizeof *out->uses);
    out->sets = calloc(scene->mesh_count ? scene->mesh_count : 1, sizeof *out->sets);
    out->mesh_count = scene->mesh_count;
    int ok = pairs && out->pyramids && out->uses && out->sets && fill_uses(scene, pairs, count, out);
    free(pairs);
    if (ok)
        return GDR_OK;
    lod_scene_textures_free(out);
    return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "LOD DAG: out of memory for the textures' ranges");
}

void lod_scene_textures_free(lod_scene_textures *t)
{
    for (uint32_t i = 0; t->pyramids && i < t->pyramid_count; i++)
        lod_texture_pyramid_free(&t->pyramids[i]);
    free(t->pyramids);
    free(t->uses);
    free(t->sets);
    *t = (lod_scene_textures){0};
}
