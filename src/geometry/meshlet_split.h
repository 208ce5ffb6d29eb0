/* Level-0 meshlets made spatially compact (meshlet_split.c): meshoptimizer 0.18's builder, once no
 * triangle next to a meshlet is free, takes the nearest free triangle however far, and one such
 * meshlet spans two far-apart places. This splits those meshlets at the jump. */
#ifndef GDR_GEOMETRY_MESHLET_SPLIT_H
#define GDR_GEOMETRY_MESHLET_SPLIT_H

#include <stddef.h>
#include <stdint.h>

#include <meshoptimizer.h>

/* Meshlets in meshoptimizer's layout: `meshlets[count]`, their local vertex lists in `vertices`
 * and their 4-byte-aligned triangle bytes in `triangles`. */
typedef struct meshlet_arrays {
    struct meshopt_Meshlet *meshlets;
    size_t count;
    uint32_t *vertices;
    uint8_t *triangles;
} meshlet_arrays;

/* Splits every meshlet of `a` whose triangles form parts lying farther apart than the chunk's
 * median meshlet size (half the diagonal of its bounding box) into one meshlet per part, in place
 * of the original and in the order of each part's first triangle; triangles keep their order and
 * corners, each part lists its vertices in first-use order. Positions are float triples indexed by
 * the meshlets' vertices. Returns 0, or -1 when out of memory (`a` then unchanged). Where nothing
 * splits, `a` is left as it is. */
int gdr_meshlets_split_far_parts(meshlet_arrays *a, const float *positions, uint32_t max_vertices,
                                 uint32_t max_triangles);

#endif
