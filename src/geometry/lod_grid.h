/* A uniform grid over a point set, for nearest-point queries while measuring a group's deviation
 * (lod_error.c). About two points per cell; the arrays are kept between builds. */
#ifndef GDR_GEOMETRY_LOD_GRID_H
#define GDR_GEOMETRY_LOD_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "gdr/math.h"
#include "geometry/lod_point_tree.h"

typedef struct lod_grid {
    const gdr_vec3 *points; /* not owned */
    uint32_t count;
    float lo[3];
    float cell, inv_cell;
    uint32_t dim[3];
    float top[3]; /* dim - 1 as floats, to which a coordinate's cell is clamped (computed once) */
    uint32_t *start, *items; /* cell c holds items[start[c] .. start[c + 1]) */
    size_t start_cap, items_cap;
    lod_point_tree tree; /* what answers instead where the cells would be crowded (use_tree) */
    int use_tree;
} lod_grid;

/* Indexes points[0 .. n), n > 0 (kept by pointer until the next build), in at most
 * cells_per_point * n + 64 cells (fewer cells: less memory, more points a query looks at). Where
 * those cells would be crowded (points on a curve: lod_grid.c), a k-d tree is built instead, with
 * the same answers. Returns 0 when out of memory. */
int lod_grid_build(lod_grid *g, const gdr_vec3 *points, uint32_t n, double cells_per_point);
/* The index of the point nearest to `point` (the lowest index on ties) and its squared distance. */
uint32_t lod_grid_nearest(const lod_grid *g, gdr_vec3 point, float *distance_squared);
void lod_grid_free(lod_grid *g);

/* Cells x0 .. x1 of row (y, z) that triangle t crosses: kept from the counting pass of a build to
 * its storing pass for the triangles that are clipped (lod_grid.c). */
typedef struct lod_grid_run {
    uint32_t t;
    uint16_t x0, x1, y, z;
} lod_grid_run;

/* A uniform grid over triangles (corner k of triangle t: positions[3 * corners[3t + k]] .. + 3),
 * each listed in the cells it crosses (a small one: in every cell of its bounding box). */
typedef struct lod_triangle_grid {
    const float *positions; /* not owned */
    const uint32_t *corners;
    float lo[3];
    float cell, inv_cell;
    uint32_t dim[3];
    float top[3]; /* dim - 1 as floats, to which a coordinate's cell is clamped (computed once) */
    uint32_t count; /* triangles */
    uint32_t cell_limit; /* a query looks at up to this many triangles of a cell (set by the build;
                            a caller with few queries may lift it: exact, see lod_grid.c) */
    uint32_t *start, *items;
    size_t start_cap, items_cap;
    lod_grid_run *runs; /* scratch of a build, kept between builds */
    size_t run_count, run_next, runs_cap;
} lod_triangle_grid;

int lod_triangle_grid_build(lod_triangle_grid *g, const float *positions, const uint32_t *corners, uint32_t n);
/* The triangle nearest to `point` and its squared distance (computed by `distance`). */
typedef float lod_point_triangle_fn(gdr_vec3 p, gdr_vec3 a, gdr_vec3 b, gdr_vec3 c);
uint32_t lod_triangle_grid_nearest(const lod_triangle_grid *g, gdr_vec3 point, lod_point_triangle_fn *distance,
                                   float *distance_squared);
void lod_triangle_grid_free(lod_triangle_grid *g);

#endif
