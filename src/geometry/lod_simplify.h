/* Simplifying one group of a LOD DAG step: half-edge collapses over positions, ordered by a
 * quadric (geometric) error plus the error of the attributes (uv, normal) that the moved corners
 * take from the wedges of the position they move onto. Every output corner is an input vertex;
 * all wedges of a position move together, so seams stay closed in position. docs/GEOMETRY.md
 * ("Simplification across seams") explains the choices. */
#ifndef GDR_GEOMETRY_LOD_SIMPLIFY_H
#define GDR_GEOMETRY_LOD_SIMPLIFY_H

#include <stddef.h>
#include <stdint.h>

#include "gdr/math.h"
#include "geometry/lod_texture.h"

/* A group's triangles over local vertices (wedges); each wedge lies at one local position. */
typedef struct lod_simplify_input {
    const uint32_t *indices; /* index_count wedge ids, a triangle list */
    size_t index_count;
    uint32_t vertex_count;
    const uint32_t *vertex_position; /* wedge -> position */
    const uint32_t *vertex_source;   /* wedge -> mesh vertex, for its uv and normal */
    const gdr_vec2 *uvs;             /* mesh arrays */
    const gdr_vec3 *normals;
    uint32_t position_count;
    const float *positions; /* 3 per position */
    const uint8_t *locked;  /* per position: never moves */
    size_t target_index_count;
    double normal_weight;   /* the normal term's weight (lod_simplify.c); 0: the default, NORMAL_WEIGHT */
    const lod_texture_set *texture; /* what the uvs sample, to weigh a slide by the change the texture shows
                                       under it (lod_texture.h); NULL: unknown, a slide counts whole */
    int every_slide; /* for tests: look the texture up for every slide, also where it cannot count
                        (the output is the same) */
} lod_simplify_input;

typedef struct lod_simplify_result {
    size_t index_count;  /* triangles kept, written as wedge ids */
    uint32_t collapses;
    float slide;         /* the largest texture slide of an output triangle: charged to it by a collapse
                            that moved one of its corners, times the largest change the texture shows
                            under it (0 to 1), at most its longest edge (mesh units) */
} lod_simplify_result;

/* A position's cheapest collapse as last evaluated (the heap holds at most one per position). */
typedef struct lod_simplify_heap_item {
    float cost;
    uint32_t position;
} lod_simplify_heap_item;

/* One corner of the fan of the position being evaluated: its triangle's affine frame (p0 at the
 * corner, edges e1 and e2, their Gram matrix), the uv and normal at the corner and their changes
 * along e1 and e2, the area and the surface-to-uv area ratio (0: no uv field), and where the
 * triangle survives the collapse evaluated, its uv and normal at the target's position. */
typedef struct lod_simplify_corner {
    double p0[3], e1[3], e2[3], g11, g12, g22, inv_det, area, uv_scale;
    double t0[2], t1[2], t2[2], n0[3], n1[3], n2[3];
    double uv_at_q[2], normal_at_q[3]; /* the uv and normal extrapolated to the target evaluated */
    double edge2_at_q;                 /* the squared longest edge of the triangle moved to the target */
    uint32_t wedge, other[2]; /* the corner's wedge, the positions of the triangle's other corners */
    int holds_b;              /* the triangle holds the position evaluated as target */
} lod_simplify_corner;

/* Scratch reused from group to group (one per worker). */
typedef struct lod_simplify_scratch {
    uint32_t *tri;   /* corner -> wedge (mutated as positions move) */
    size_t tri_cap;
    uint32_t *next;  /* corner -> next corner at the same position, UINT32_MAX at the end */
    size_t next_cap;
    uint8_t *alive;  /* per triangle */
    size_t alive_cap;
    uint32_t *head;  /* position -> first corner */
    size_t head_cap;
    double *quadric; /* 10 per position */
    size_t quadric_cap;
    uint8_t *flags;  /* per position: removed, border, in the heap */
    size_t flags_cap;
    uint32_t *mark;  /* per position: the token of the last walk that met it */
    size_t mark_cap;
    uint32_t *pass;  /* per position: the last pass that moved a position onto it */
    size_t pass_cap;
    uint32_t token;
    lod_simplify_heap_item *heap;
    size_t heap_cap, heap_count;
    /* one evaluation: the moving position's corners, neighbours, wedges, the target's wedges, and
     * per wedge the wedge it takes */
    uint32_t *fan, *fan_b, *neighbours, *near, *wedges, *wedges_b, *choice;
    size_t fan_cap, fan_b_cap, neighbours_cap, near_cap, wedges_cap, wedges_b_cap, choice_cap;
    float *costs;
    size_t costs_cap;
    /* per neighbour of the position evaluated: the geometric part of its cost, whether costs holds
     * the whole cost (else the geometric part), whether the order has taken it */
    double *geometry;
    size_t geometry_cap;
    uint8_t *exact, *taken;
    size_t exact_cap, taken_cap;
    uint32_t *edge_count; /* per neighbour: the fan's triangles that hold it */
    size_t edge_count_cap;
    uint32_t *slot;       /* per position: its index among the neighbours gathered (with mark) */
    size_t slot_cap;
    /* per triangle: the largest texture slide (mesh length) a collapse charged to it, moving one of its
     * corners onto another position's wedge */
    float *tri_slide;
    size_t tri_slide_cap;
    lod_simplify_corner *info; /* per corner of the fan evaluated */
    size_t info_cap;
} lod_simplify_scratch;

/* Simplifies towards target_index_count; writes the kept triangles (wedge ids, in input order) to
 * out (index_count entries). Returns 0 when out of memory. */
int lod_simplify(lod_simplify_scratch *s, const lod_simplify_input *in, uint32_t *out, lod_simplify_result *res);
void lod_simplify_scratch_free(lod_simplify_scratch *s);

#endif
