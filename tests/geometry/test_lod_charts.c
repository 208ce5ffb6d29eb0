/* The coarse end of a mesh cut into many small uv charts (as DamagedHelmet's 424): simplified to
 * fewer triangles than charts, the simplifier must give some corners the uv of another chart, and
 * the slide the group states is the largest over its triangles (each charged at most its longest
 * edge: the texels it spoils lie inside it). So which crossings it takes decides the group's error:
 * the slide stated must stay within 1.75 times the mean edge of the simplified sheet (1.48x). Before
 * the collapses' cost weighed a slide as the group states it (the largest a triangle is charged,
 * capped by its size), crossings were ordered by how far apart the charts lie in the atlas, which
 * says nothing of the triangle they spoil, and long triangles spanning charts set the slide (3.3x
 * the mean edge here); and before a collapse that stretches a triangle an earlier one slid was
 * charged the slide it raises (the cap grows with the triangle), slivers charged while short and
 * stretched later at no cost set it (2.08x). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geometry/lod_simplify.h"
#include "point_distance.h"
#include "test_util.h"

#define QUADS 48
#define CHART 3 /* quads per chart side: 256 charts */
#define POSITIONS ((QUADS + 1) * (QUADS + 1))
#define TRIANGLES (QUADS * QUADS * 2)

/* A gently rolling unit sheet (the geometric costs are not all zero), its grid's positions. */
static void sheet_positions(float *positions)
{
    for (uint32_t y = 0; y <= QUADS; y++)
        for (uint32_t x = 0; x <= QUADS; x++) {
            float *p = positions + (y * (QUADS + 1) + x) * 3;
            p[0] = (float)x / QUADS;
            p[1] = (float)y / QUADS;
            p[2] = 0.08f * sinf(5.0f * p[0]) * cosf(4.0f * p[1]);
        }
}

/* The wedge of position p in chart c, made on first use: its uv is the position's xy (the chart maps
 * at the surface's scale) moved to the chart's place in the atlas, charts scattered up to 20 units
 * apart. Returns the wedge. */
static uint32_t chart_wedge(uint32_t p, uint32_t c, const float *positions, uint32_t *slot, uint32_t *count,
                            uint32_t *vertex_position, gdr_vec2 *uvs, gdr_vec3 *normals)
{
    uint32_t *w = &slot[(size_t)p * 4 + (c & 3u)];
    if (*w != UINT32_MAX)
        return *w;
    *w = (*count)++;
    const float *q = positions + p * 3;
    vertex_position[*w] = p;
    uvs[*w] = (gdr_vec2){20.0f * test_hash_unit(c) + q[0], 20.0f * test_hash_unit(c + 7777u) + q[1]};
    normals[*w] = (gdr_vec3){0.0f, 0.0f, 1.0f};
    return *w;
}

/* The same sheet under a texture of blocks of colour: the simplifier skips the lookups of slides
 * that cannot raise the largest of a move's (lod_simplify.c, corner_attribute_error); with every
 * slide looked up (in->every_slide) it must keep the same triangles, collapses and slide. */
static void check_texture_lookups_skipped(lod_simplify_input *in, lod_simplify_scratch *scratch)
{
    enum { SIZE = 64 };
    static uint8_t rgba[SIZE * SIZE * 4];
    static uint32_t skipped[TRIANGLES * 3], every[TRIANGLES * 3];
    for (uint32_t i = 0; i < SIZE * SIZE; i++) {
        uint32_t block = (i / SIZE / 8) * 8 + i % SIZE / 8;
        for (int k = 0; k < 4; k++)
            rgba[i * 4 + (uint32_t)k] = (uint8_t)(255.0f * test_hash_unit(block * 4u + (uint32_t)k));
    }
    lod_texture_pyramid pyramid;
    CHECK(lod_texture_pyramid_build(&pyramid, rgba, SIZE, SIZE));
    lod_texture_use use = {.pyramid = &pyramid, .m = {{0.05, 0}, {0, 0.05}}, .channels = 0x7, .weight = 1.0};
    lod_texture_set set = {&use, 1};
    lod_simplify_result a, b;
    in->texture = &set;
    in->every_slide = 0;
    CHECK_MSG(lod_simplify(scratch, in, skipped, &a), "out of memory");
    in->every_slide = 1;
    CHECK_MSG(lod_simplify(scratch, in, every, &b), "out of memory");
    in->texture = NULL;
    in->every_slide = 0;
    printf("test_lod_charts: under a texture %zu triangles, %u collapses, slide %.4f; every slide looked up: %zu, "
           "%u, %.4f\n", a.index_count / 3, a.collapses, (double)a.slide, b.index_count / 3, b.collapses,
           (double)b.slide);
    CHECK_MSG(a.index_count == b.index_count && a.collapses == b.collapses && a.slide == b.slide &&
                  memcmp(skipped, every, a.index_count * sizeof *skipped) == 0,
              "skipping the lookups that cannot count changed the simplified triangles");
    lod_texture_pyramid_free(&pyramid);
}

int main(void)
{
    static float positions[POSITIONS * 3];
    static uint32_t indices[TRIANGLES * 3], vertex_position[POSITIONS * 4], vertex_source[POSITIONS * 4],
        slot[POSITIONS * 4], out[TRIANGLES * 3];
    static gdr_vec2 uvs[POSITIONS * 4];
    static gdr_vec3 normals[POSITIONS * 4];
    static uint8_t locked[POSITIONS];
    sheet_positions(positions);
    for (uint32_t i = 0; i < POSITIONS * 4; i++)
        slot[i] = UINT32_MAX, vertex_source[i] = i;
    /* the (at most 4) charts around a position differ in the parity of their column or row, which
     * the two lowest bits of a chart's id hold: its wedge's slot among the position's 4 */
    uint32_t count = 0, k = 0;
    for (uint32_t y = 0; y < QUADS; y++)
        for (uint32_t x = 0; x < QUADS; x++) {
            uint32_t cx = x / CHART, cy = y / CHART, c = (cy * (QUADS / CHART) + cx) * 4 + (cy & 1u) * 2 + (cx & 1u);
            uint32_t p00 = y * (QUADS + 1) + x, p10 = p00 + 1, p01 = p00 + QUADS + 1, p11 = p01 + 1;
            uint32_t tris[6] = {p00, p10, p11, p00, p11, p01};
            for (int j = 0; j < 6; j++)
                indices[k++] = chart_wedge(tris[j], c, positions, slot, &count, vertex_position, uvs, normals);
        }
    lod_simplify_input in = {.indices = indices, .index_count = TRIANGLES * 3, .vertex_count = count,
                             .vertex_position = vertex_position, .vertex_source = vertex_source, .uvs = uvs,
                             .normals = normals, .position_count = POSITIONS, .positions = positions,
                             .locked = locked, .target_index_count = TRIANGLES * 3 / 16};
    lod_simplify_scratch scratch = {0};
    lod_simplify_result result;
    CHECK_MSG(lod_simplify(&scratch, &in, out, &result), "out of memory");
    size_t kept = result.index_count / 3;
    double sum = 0.0;
    for (size_t t = 0; t < kept; t++)
        for (int j = 0; j < 3; j++)
            sum += packed_edge_length(positions, vertex_position[out[t * 3 + (size_t)j]],
                                      vertex_position[out[t * 3 + (size_t)(j + 1) % 3]]);
    double mean = kept ? sum / (3.0 * (double)kept) : 0.0;
    printf("test_lod_charts: %u triangles in %u charts -> %zu, slide %.4f, mean edge %.4f (%.2fx)\n", TRIANGLES,
           (QUADS / CHART) * (QUADS / CHART), kept, (double)result.slide, mean, (double)result.slide / mean);
    CHECK_MSG(kept <= (size_t)TRIANGLES / 8, "simplified to %zu of %u triangles only", kept, TRIANGLES);
    CHECK_MSG(result.slide > 0.0f, "no slide stated, though charts had to be crossed");
    CHECK_MSG(result.slide <= 1.75 * mean, "slide %g is above 1.75 times the mean edge %g", (double)result.slide, mean);
    check_texture_lookups_skipped(&in, &scratch);
    lod_simplify_scratch_free(&scratch);
    return test_finish("test_lod_charts");
}
