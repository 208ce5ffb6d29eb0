/* Level-0 meshlets made spatially compact (meshlet_split.c): meshoptimizer 0.18's builder, once no
 * triangle next to a meshlet is free, takes the nearest free triangle however far, and such a
 * meshlet spans two far-apart places. This cuts the farthest of those jumps. */
#ifndef GDR_GEOMETRY_MESHLET_SPLIT_H
#define GDR_GEOMETRY_MESHLET_SPLIT_H

#include <stddef.h>
#include <stdint.h>

#include <meshoptimizer.h>

/* Meshlets in meshoptimizer's layout: `meshlets[count]`, their local vertex lists in `vertices`
 * and their 4-byte-aligned triangle bytes in `triangles` (meshoptimizer's packing). */
typedef struct meshlet_arrays {
    struct meshopt_Meshlet *meshlets;
    size_t count;
    uint32_t *vertices;
    uint8_t *triangles;
} meshlet_arrays;

/* Replaces every meshlet of `a` whose triangles lie in parts far apart (meshlet_split.c says when)
 * by one meshlet per part, in its place and in the order of each part's first triangle; triangles
 * keep their order and corners, each part lists its vertices in first-use order, the padding
 * stays zero. Positions are float triples indexed by the meshlets' vertices. Where something is
 * cut, the arrays are replaced (the old ones freed); where nothing is, `a` is left as it is.
 * Returns 0, or -1 when out of memory (`a` then unchanged). The result depends only on `a` and the
 * positions. */
int gdr_meshlets_split_far_parts(meshlet_arrays *a, const float *positions);

#endif
