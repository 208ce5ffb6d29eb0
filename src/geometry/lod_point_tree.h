/* A k-d tree over a point set for nearest-point queries: what a point grid (lod_grid.h) falls back
 * to where its cells would be crowded, as when the points lie on a curve (a fan's rim) rather than
 * a surface. Its answers are the grid's: the exact nearest point, the lowest index on ties. */
#ifndef GDR_GEOMETRY_LOD_POINT_TREE_H
#define GDR_GEOMETRY_LOD_POINT_TREE_H

#include <stddef.h>
#include <stdint.h>

#include "gdr/math.h"

typedef struct lod_point_tree {
    const gdr_vec3 *points; /* not owned */
    uint32_t count;
    /* The points' indices, split in halves recursively: node 1 (the root) holds order[0 .. count),
     * node i of order[lo .. hi) splits at mid = lo + (hi - lo) / 2 along axis[i], at split[i]
     * (its child 2i holds order[lo .. mid), at most split, 2i + 1 order[mid .. hi), at least);
     * box[i]: the smallest and largest coordinate of its points along each axis. Only nodes of more
     * than the leaf size are stored (indices below 2 count / leaf size + 2). */
    uint32_t *order;
    float *split;
    float (*box)[6];
    uint8_t *axis;
    size_t order_cap, node_cap;
} lod_point_tree;

/* Indexes points[0 .. n), n > 0 (kept by pointer until the next build; the arrays are kept between
 * builds). Returns 0 when out of memory. */
int lod_point_tree_build(lod_point_tree *t, const gdr_vec3 *points, uint32_t n);
/* The index of the point nearest to `point` (the lowest index on ties) and its squared distance,
 * computed as lod_grid_nearest computes it. */
uint32_t lod_point_tree_nearest(const lod_point_tree *t, gdr_vec3 point, float *distance_squared);
void lod_point_tree_free(lod_point_tree *t);

#endif
