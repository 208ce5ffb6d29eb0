/* Distances between triangle surfaces for the LOD quality benchmark: a uniform grid over a
 * triangle list answers "distance from a point to the nearest triangle", and the symmetric
 * Hausdorff distance between two surfaces is estimated from dense samples of both. */
#ifndef GDR_BENCH_SURFACE_DISTANCE_H
#define GDR_BENCH_SURFACE_DISTANCE_H

#include <stddef.h>
#include <stdint.h>

#include "gdr/math.h"

/* A triangle surface: corner k of triangle t is positions[indices[3t + k]]. */
typedef struct surface {
    const gdr_vec3 *positions;
    uint32_t vertex_count;
    const uint32_t *indices;
    size_t triangle_count;
} surface;

typedef struct triangle_grid triangle_grid;

triangle_grid *triangle_grid_create(surface s);
void triangle_grid_destroy(triangle_grid *g);
/* Distance from p to the nearest triangle. */
double triangle_grid_distance(const triangle_grid *g, gdr_vec3 p);
/* The same, also naming the nearest triangle (index into the surface's triangles; UINT32_MAX for an
 * empty surface) and, where barycentric is not NULL, the coordinates of its point nearest to p. */
double triangle_grid_nearest(const triangle_grid *g, gdr_vec3 p, uint32_t *nearest, double barycentric[3]);

/* The largest distance from samples of `from` to the surface indexed by `to`. Samples: every vertex
 * used, every centroid, and on triangles longer than `spacing` a barycentric grid of about that
 * spacing (at most 8 steps an edge). */
double surface_one_sided(surface from, const triangle_grid *to, double spacing);

/* Surface area. */
double surface_area(surface s);

#endif
