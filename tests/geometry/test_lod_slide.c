/* The texture slide the seam-crossing simplifier states for a group: on a flat grid where every
 * triangle is its own uv chart (no corner has a partner across an edge, so every collapse gives some
 * corner the uv of another chart), the slide stated is positive and at most the longest edge of an
 * output triangle that carries a charged wedge: a slide spoils only the texels inside the triangles
 * that carry it. The slides charged here are far above the triangles (the charts lie up to 1,000 uv
 * units apart), so a slide stated without that bound fails the test. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "geometry/lod_simplify.h"
#include "point_distance.h"
#include "test_util.h"

#define QUADS 12
#define POSITIONS ((QUADS + 1) * (QUADS + 1))
#define TRIANGLES (QUADS * QUADS * 2)

int main(void)
{
    static float positions[POSITIONS * 3];
    static uint32_t indices[TRIANGLES * 3], vertex_position[TRIANGLES * 3], vertex_source[TRIANGLES * 3],
        out[TRIANGLES * 3];
    static gdr_vec2 uvs[TRIANGLES * 3];
    static gdr_vec3 normals[TRIANGLES * 3];
    static uint8_t locked[POSITIONS];
    for (uint32_t y = 0; y <= QUADS; y++)
        for (uint32_t x = 0; x <= QUADS; x++) {
            float *p = positions + (y * (QUADS + 1) + x) * 3;
            p[0] = (float)x / QUADS;
            p[1] = (float)y / QUADS;
            p[2] = 0.0f;
        }
    /* Each triangle's three corners are wedges of their own, in a chart of its own: the uvs of a
     * triangle map it at the same scale as the surface, placed far apart in uv space. */
    uint32_t w = 0;
    for (uint32_t y = 0; y < QUADS; y++)
        for (uint32_t x = 0; x < QUADS; x++) {
            uint32_t p00 = y * (QUADS + 1) + x, p10 = p00 + 1, p01 = p00 + QUADS + 1, p11 = p01 + 1;
            uint32_t tris[2][3] = {{p00, p10, p11}, {p00, p11, p01}};
            for (int t = 0; t < 2; t++) {
                float ox = 1000.0f * test_hash_unit(w), oy = 1000.0f * test_hash_unit(w + 7777u);
                for (int k = 0; k < 3; k++, w++) {
                    const float *p = positions + tris[t][k] * 3;
                    indices[w] = w;
                    vertex_position[w] = tris[t][k];
                    vertex_source[w] = w;
                    uvs[w] = (gdr_vec2){ox + p[0], oy + p[1]};
                    normals[w] = (gdr_vec3){0.0f, 0.0f, 1.0f};
                }
            }
        }
    lod_simplify_input in = {.indices = indices, .index_count = TRIANGLES * 3, .vertex_count = TRIANGLES * 3,
                             .vertex_position = vertex_position, .vertex_source = vertex_source, .uvs = uvs,
                             .normals = normals, .position_count = POSITIONS, .positions = positions,
                             .locked = locked, .target_index_count = TRIANGLES * 3 / 4};
    lod_simplify_scratch scratch = {0};
    lod_simplify_result result;
    CHECK_MSG(lod_simplify(&scratch, &in, out, &result), "out of memory");
    size_t kept = result.index_count / 3;
    CHECK_MSG(kept < TRIANGLES / 2, "simplified %zu of %u triangles only", kept, TRIANGLES);
    float longest = 0.0f;
    for (size_t t = 0; t < kept; t++)
        for (int k = 0; k < 3; k++) {
            float e = packed_edge_length(positions, vertex_position[out[t * 3 + (size_t)k]],
                                         vertex_position[out[t * 3 + (size_t)(k + 1) % 3]]);
            longest = e > longest ? e : longest;
        }
    CHECK_MSG(result.slide > 0.0f, "no slide stated, though every collapse crossed charts");
    CHECK_MSG(result.slide <= longest, "slide %g is above the longest output edge %g", (double)result.slide,
          (double)longest);
    printf("test_lod_slide: %u -> %zu triangles, slide %.4f, longest output edge %.4f\n", TRIANGLES, kept,
           (double)result.slide, (double)longest);
    lod_simplify_scratch_free(&scratch);
    return test_finish("test_lod_slide");
}
