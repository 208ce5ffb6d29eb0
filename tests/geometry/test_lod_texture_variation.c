/* A texture slide weighed by what the texture shows where it slides (lod_texture.c,
 * lod_simplify.c): the largest change of a box of uvs, against brute force over the texels a
 * bilinear sample reads (every wrap mode, texture transforms, sizes that are no multiple of the
 * pyramid's cells); and the DAG of a charted torus, whose collapses slide the texture within and
 * across charts: under a texture of one colour no group charges a slide (white-box, the build's
 * observer), under a texture whose every texel differs from its neighbours fully the DAG is the one
 * built knowing no texture (a slide counts whole), and gdr_scene_build_lod finds the mesh's texture
 * through its material, transform included. Before the weight, the scene's DAG was the same under
 * any texture. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "gdr/scene.h"
#include "geometry/lod_internal.h"
#include "geometry/lod_texture.h"
#include "charted_torus.h"
#include "test_util.h"

#define TORUS_SEGMENTS 96u
#define TORUS_SIDES 32u
#define TEX 64u        /* test textures are TEX x TEX */
#define HALF_EDGE 56u  /* the half texture: one colour below this column, a checker from it on */

static uint32_t rng_state = 12345u;
static uint32_t rng(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return rng_state >> 8;
}
static double uniform(double lo, double hi) { return lo + (hi - lo) * (rng() & 0xffffff) / (double)0x1000000; }

/* --- the box's change against brute force ------------------------------------------------------------ */

/* A texel index of an axis under a wrap mode. */
static int64_t wrap_index(int64_t i, int64_t size, uint32_t mode)
{
    if (mode == GDR_SAMPLER_WRAP_CLAMP)
        return i < 0 ? 0 : i >= size ? size - 1 : i;
    int64_t period = mode == GDR_SAMPLER_WRAP_MIRROR ? 2 * size : size, m = i % period;
    m += m < 0 ? period : 0;
    return m < size ? m : 2 * size - 1 - m;
}

/* The largest change of the channels over every texel a bilinear sample of the box reads. */
static double brute_variation(const uint8_t *rgba, uint32_t w, uint32_t h, const lod_texture_use *u,
                              const double (*uv)[2], uint32_t count)
{
    double box[2][2] = {{INFINITY, -INFINITY}, {INFINITY, -INFINITY}};
    for (uint32_t i = 0; i < count; i++)
        for (int a = 0; a < 2; a++) {
            double t = u->offset[a] + u->m[a][0] * uv[i][0] + u->m[a][1] * uv[i][1];
            box[a][0] = fmin(box[a][0], t), box[a][1] = fmax(box[a][1], t);
        }
    int64_t x0 = (int64_t)floor(box[0][0] * w - 0.5), x1 = (int64_t)floor(box[0][1] * w - 0.5) + 1;
    int64_t y0 = (int64_t)floor(box[1][0] * h - 0.5), y1 = (int64_t)floor(box[1][1] * h - 0.5) + 1;
    if (x1 - x0 >= (int64_t)w)
        x0 = 0, x1 = w - 1;
    if (y1 - y0 >= (int64_t)h)
        y0 = 0, y1 = h - 1;
    int lo[4] = {255, 255, 255, 255}, hi[4] = {0, 0, 0, 0};
    for (int64_t y = y0; y <= y1; y++)
        for (int64_t x = x0; x <= x1; x++) {
            int64_t tx = wrap_index(x, w, GDR_SAMPLER_WRAP_S(u->sampler)), ty = wrap_index(y, h, GDR_SAMPLER_WRAP_T(u->sampler));
            const uint8_t *t = rgba + ((size_t)ty * w + (size_t)tx) * 4;
            for (int k = 0; k < 4; k++)
                lo[k] = t[k] < lo[k] ? t[k] : lo[k], hi[k] = t[k] > hi[k] ? t[k] : hi[k];
        }
    int largest = 0;
    for (int k = 0; k < 4; k++)
        if ((u->channels >> k & 1u) && hi[k] - lo[k] > largest)
            largest = hi[k] - lo[k];
    return largest / 255.0;
}

/* A texture of flat patches (so that small boxes often see no change) with a few lone texels. */
static uint8_t *patchy_texture(uint32_t w, uint32_t h)
{
    uint8_t *t = malloc((size_t)w * h * 4);
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++)
            for (int k = 0; k < 4; k++)
                t[((size_t)y * w + x) * 4 + k] = (uint8_t)(40 * ((x / 9 + y / 7 + (uint32_t)k) % 3));
    for (int i = 0; i < 12; i++)
        t[((size_t)(rng() % h) * w + rng() % w) * 4 + rng() % 4] = (uint8_t)(rng() & 255);
    return t;
}

/* Random boxes of random sizes, wrap modes and transforms: the pyramid's change is never below the
 * texels' (it bounds what the image can show), and a box within one flat patch shows none. */
static void check_against_brute_force(uint32_t w, uint32_t h)
{
    uint8_t *rgba = patchy_texture(w, h);
    lod_texture_pyramid p;
    CHECK(lod_texture_pyramid_build(&p, rgba, w, h));
    uint32_t below = 0, tried = 0, exact_zero = 0;
    for (int i = 0; i < 4000; i++) {
        double rot = i % 3 ? 0.0 : uniform(-3.2, 3.2), sx = i % 5 ? 1.0 : uniform(-2.0, 2.0), sy = i % 5 ? 1.0 : uniform(-2.0, 2.0);
        lod_texture_use u = {.pyramid = &p, .sampler = (uint32_t)(rng() % 3) | (uint32_t)(rng() % 3) << 2,
                             .offset = {i % 2 ? uniform(-1.5, 1.5) : 0.0, i % 2 ? uniform(-1.5, 1.5) : 0.0},
                             .m = {{cos(rot) * sx, sin(rot) * sy}, {-sin(rot) * sx, cos(rot) * sy}},
                             .channels = 1u + rng() % 15u, .weight = 1.0};
        lod_texture_set set = {&u, 1};
        double size = i % 4 == 0 ? uniform(0.0, 1.5) : uniform(0.0, 0.1), uv[3][2];
        double cu = uniform(-3.0, 3.0), cv = uniform(-3.0, 3.0);
        for (int k = 0; k < 3; k++)
            uv[k][0] = cu + uniform(0.0, size), uv[k][1] = cv + uniform(0.0, size);
        double got = lod_texture_variation(&set, (const double(*)[2])uv, 3);
        double want = brute_variation(rgba, w, h, &u, (const double(*)[2])uv, 3);
        tried++;
        if (got < want - 1e-12) {
            if (below < 5)
                fprintf(stderr, "  box at (%g, %g) size %g sampler %u: %g below the texels' %g\n", cu, cv, size,
                        u.sampler, got, want);
            below++;
        }
        exact_zero += want == 0.0 && got == 0.0;
    }
    printf("test_lod_texture_variation: %u x %u: %u boxes, %u below brute force, %u flat found flat\n", w, h, tried,
           below, exact_zero);
    CHECK_MSG(below == 0, "%u boxes' change below the texels they read", below);
    CHECK_MSG(exact_zero > 0, "no box found flat: the pyramid is too coarse to tell flat regions");
    lod_texture_pyramid_free(&p);
    free(rgba);
}

/* A texture of one colour shows no change; a one-texel checker shows the full change in every box;
 * the factor weighs it, capped at 1; no set means any change. */
static void check_simple_textures(void)
{
    uint8_t flat[TEX * TEX * 4], checker[TEX * TEX * 4];
    for (uint32_t i = 0; i < TEX * TEX; i++) {
        memset(flat + i * 4, 128, 4);
        memset(checker + i * 4, (i % TEX + i / TEX) % 2 ? 255 : 0, 4);
    }
    lod_texture_pyramid pf, pc;
    CHECK(lod_texture_pyramid_build(&pf, flat, TEX, TEX) && lod_texture_pyramid_build(&pc, checker, TEX, TEX));
    lod_texture_use u[2] = {{.pyramid = &pf, .m = {{1, 0}, {0, 1}}, .channels = 0xf, .weight = 1.0},
                            {.pyramid = &pc, .m = {{1, 0}, {0, 1}}, .channels = 0xf, .weight = 0.25}};
    const double uv[2][2] = {{0.3, 0.3}, {0.3001, 0.3}};
    lod_texture_set one = {u, 1}, both = {u, 2};
    CHECK(lod_texture_variation(&one, uv, 2) == 0.0);
    CHECK(lod_texture_variation(&both, uv, 2) == 0.25);
    u[1].weight = 3.0;
    CHECK(lod_texture_variation(&both, uv, 2) == 1.0);
    CHECK(lod_texture_variation(NULL, uv, 2) == 1.0);
    lod_texture_pyramid_free(&pf);
    lod_texture_pyramid_free(&pc);
}

/* Several uses of one set, weights in any order (some equal, some 0, some above 1): the set's change
 * is exactly the largest of its uses' weighed changes, each measured alone, capped at 1. Guards
 * lod_texture_variation's skipping of a use whose weight cannot raise the largest so far. */
static void check_set_is_largest_use(void)
{
    uint8_t *rgba[3] = {patchy_texture(37, 21), patchy_texture(64, 64), patchy_texture(5, 130)};
    const uint32_t w[3] = {37, 64, 5}, h[3] = {21, 64, 130};
    lod_texture_pyramid p[3];
    for (int k = 0; k < 3; k++)
        CHECK(lod_texture_pyramid_build(&p[k], rgba[k], w[k], h[k]));
    static const double weights[] = {0.0, 0.1, 0.25, 0.25, 0.5, 0.9, 1.0, 1.5};
    uint32_t mismatched = 0, raised = 0;
    for (int i = 0; i < 3000; i++) {
        lod_texture_use u[5];
        uint32_t count = 1u + rng() % 5u;
        for (uint32_t k = 0; k < count; k++)
            u[k] = (lod_texture_use){.pyramid = &p[rng() % 3], .sampler = (uint32_t)(rng() % 3),
                                     .m = {{1, 0}, {0, 1}}, .channels = 1u + rng() % 15u,
                                     .weight = weights[rng() % (sizeof weights / sizeof weights[0])]};
        double size = i % 4 == 0 ? uniform(0.0, 1.0) : uniform(0.0, 0.1), uv[3][2];
        double cu = uniform(-2.0, 2.0), cv = uniform(-2.0, 2.0);
        for (int k = 0; k < 3; k++)
            uv[k][0] = cu + uniform(0.0, size), uv[k][1] = cv + uniform(0.0, size);
        double want = 0.0;
        for (uint32_t k = 0; k < count; k++) {
            lod_texture_set alone = {&u[k], 1};
            double v = lod_texture_variation(&alone, (const double(*)[2])uv, 3);
            raised += k > 0 && v > want;
            want = v > want ? v : want;
        }
        lod_texture_set set = {u, count};
        mismatched += lod_texture_variation(&set, (const double(*)[2])uv, 3) != want;
    }
    printf("test_lod_texture_variation: 3000 sets of up to 5 uses, %u where a later use raised the largest, %u "
           "mismatched\n", raised, mismatched);
    CHECK_MSG(mismatched == 0, "%u sets' change is not their largest use's", mismatched);
    CHECK_MSG(raised > 0, "no set where a later use mattered: the check is empty");
    for (int k = 0; k < 3; k++) {
        lod_texture_pyramid_free(&p[k]);
        free(rgba[k]);
    }
}

/* --- the DAG ------------------------------------------------------------------------------------------ */

typedef struct slide_count {
    uint32_t groups, with_slide;
} slide_count;

static void observe_step(void *user, const lod_build *b, const lod_step_view *v)
{
    (void)b;
    slide_count *k = user;
    for (uint32_t g = 0; g < v->groups; g++)
        if (v->results[g].formed) {
            k->groups++;
            k->with_slide += v->results[g].slide > 0.0f;
        }
}

/* RGBA8 TEX x TEX: one colour (kind 0), a one-texel checker of black and white (1), or one colour
 * below column HALF_EDGE and the checker from it on (2). */
static void fill_texture(uint8_t *t, int kind)
{
    for (uint32_t y = 0; y < TEX; y++)
        for (uint32_t x = 0; x < TEX; x++) {
            int flat = kind == 0 || (kind == 2 && x < HALF_EDGE);
            memset(t + ((size_t)y * TEX + x) * 4, flat ? 128 : (x + y) % 2 ? 255 : 0, 4);
        }
}

/* A scene of the charted torus (one instance), its material sampling a base-colour texture of
 * `kind` through a transform of scale `scale` (below 1: offset by 0.05 and clamped, so that the uvs
 * of the atlas, [0, 1], and their continuations past it, down to -1.1 on coarse triangles that span
 * charts, land in the half's flat columns). */
static gdr_scene *torus_scene(int kind, float scale)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    charted_torus_check(gdr_scene_create(&s, &err), &err, "scene");
    uint32_t mesh = add_charted_torus(s, TORUS_SEGMENTS, TORUS_SIDES), tex, mat;
    uint8_t *texels = malloc(TEX * TEX * 4);
    fill_texture(texels, kind);
    charted_torus_check(gdr_scene_add_texture(s, "t", TEX, TEX, texels, 1, &tex, &err), &err, "texture");
    free(texels);
    gdr_material m = gdr_material_default();
    m.base_color_texture.texture = tex;
    m.base_color_texture.scale = (gdr_vec2){scale, scale};
    if (scale < 1.0f) {
        m.base_color_texture.offset = (gdr_vec2){0.05f, 0.05f};
        m.base_color_texture.sampler = GDR_SAMPLER_WRAP_CLAMP | GDR_SAMPLER_WRAP_CLAMP << 2;
    }
    charted_torus_check(gdr_scene_add_material(s, &m, &mat, &err), &err, "material");
    gdr_instance in = {.transform = gdr_mat4_identity(), .mesh = mesh, .material = mat, .color = {1, 1, 1, 1}};
    charted_torus_check(gdr_scene_add_instance(s, &in, &err), &err, "instance");
    return s;
}

/* The torus's DAG built white-box with a texture of `kind` (-1: none known); counts the groups'
 * slides. */
static gdr_scene *observed_torus(int kind, slide_count *k)
{
    gdr_scene *s = torus_scene(kind < 0 ? 0 : kind, 1.0f);
    gdr_error err = {0};
    gdr_mesh *m = &s->meshes[0];
    uint8_t texels[TEX * TEX * 4];
    fill_texture(texels, kind < 0 ? 0 : kind);
    lod_texture_pyramid p;
    CHECK(lod_texture_pyramid_build(&p, texels, TEX, TEX));
    lod_texture_use u = {.pyramid = &p, .m = {{1, 0}, {0, 1}}, .channels = 0x7, .weight = 1.0};
    lod_texture_set set = {&u, 1};
    lod_observer obs = {observe_step, k};
    gdr_lod_options o = {.thread_count = 2, .no_progress = 1};
    charted_torus_check(gdr_scene_build_clusters(s, NULL, &err), &err, "meshlets");
    charted_torus_check(gdr_lod_build_textured(m, &o, kind < 0 ? NULL : &set, &obs, NULL, &err), &err, "DAG");
    lod_texture_pyramid_free(&p);
    return s;
}

/* Whether two meshes' DAGs are the same: clusters, their triangles, groups and their errors. */
static int same_dag(const gdr_mesh *a, const gdr_mesh *b)
{
    const gdr_mesh_clusters *x = &a->clusters, *y = &b->clusters;
    if (x->cluster_count != y->cluster_count || x->group_count != y->group_count ||
        x->triangle_byte_count != y->triangle_byte_count || x->vertex_count != y->vertex_count)
        return 0;
    for (uint32_t g = 0; g < x->group_count; g++)
        if (x->groups[g].error != y->groups[g].error || x->groups[g].depth != y->groups[g].depth)
            return 0;
    return memcmp(x->vertices, y->vertices, x->vertex_count * sizeof *x->vertices) == 0 &&
           memcmp(x->triangles, y->triangles, x->triangle_byte_count) == 0;
}

static gdr_scene *scene_built(int kind, float scale)
{
    gdr_scene *s = torus_scene(kind, scale);
    gdr_error err = {0};
    charted_torus_check(gdr_scene_build_lod(s, &(gdr_lod_options){.thread_count = 2, .no_progress = 1}, NULL, &err),
                        &err, "scene DAG");
    return s;
}

static void check_dags(void)
{
    slide_count unknown = {0}, flat = {0}, checker = {0};
    gdr_scene *su = observed_torus(-1, &unknown), *sf = observed_torus(0, &flat), *sc = observed_torus(1, &checker);
    printf("test_lod_texture_variation: torus %u x %u: groups with a slide: %u of %u (no texture known), %u of %u "
           "(one colour), %u of %u (checker)\n",
           TORUS_SEGMENTS, TORUS_SIDES, unknown.with_slide, unknown.groups, flat.with_slide, flat.groups,
           checker.with_slide, checker.groups);
    CHECK_MSG(unknown.with_slide > 0, "no group charged a slide: the torus does not test it");
    CHECK_MSG(flat.with_slide == 0, "%u groups charged a slide under a texture of one colour", flat.with_slide);
    CHECK_MSG(same_dag(&sc->meshes[0], &su->meshes[0]), "a full-contrast texture changed the DAG");
    CHECK_MSG(!same_dag(&sf->meshes[0], &su->meshes[0]), "a texture of one colour left the DAG as it was");

    /* through the scene: the material's texture, and its transform (scale 0.2 keeps the uvs within the
     * half's flat columns, scale 1 reaches its checker) */
    gdr_scene *scene_flat = scene_built(0, 1.0f), *scene_half_in = scene_built(2, 0.2f);
    gdr_scene *scene_half = scene_built(2, 1.0f), *scene_checker = scene_built(1, 1.0f);
    CHECK_MSG(same_dag(&scene_flat->meshes[0], &sf->meshes[0]), "the scene's DAG under one colour is not the white-box one");
    CHECK_MSG(same_dag(&scene_half_in->meshes[0], &sf->meshes[0]),
              "uvs scaled into the flat half: the DAG is not the one under one colour");
    CHECK_MSG(!same_dag(&scene_half->meshes[0], &sf->meshes[0]), "uvs reaching the checker half: slides ignored");
    CHECK_MSG(same_dag(&scene_checker->meshes[0], &su->meshes[0]), "the scene's DAG under a checker is not the whole-slide one");
    gdr_scene_destroy(scene_flat), gdr_scene_destroy(scene_half_in), gdr_scene_destroy(scene_half);
    gdr_scene_destroy(scene_checker), gdr_scene_destroy(su), gdr_scene_destroy(sf), gdr_scene_destroy(sc);
}

int main(void)
{
    check_simple_textures();
    check_against_brute_force(37, 21);
    check_against_brute_force(64, 64);
    check_against_brute_force(5, 130);
    check_set_is_largest_use();
    check_dags();
    return test_finish("test_lod_texture_variation");
}
