/* A k-d tree for nearest-point queries (lod_point_tree.h). */
#include "geometry/lod_point_tree.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A node of at most this many points is a leaf: its points are compared one by one. */
#define TREE_LEAF 8u

static float coordinate(const lod_point_tree *t, uint32_t i, int k) { return (&t->points[i].x)[k]; }

/* Points ordered by coordinate k, then by index: a total order, so the split does not depend on
 * how the selection below happens to move equal coordinates. */
static int before(const lod_point_tree *t, uint32_t a, uint32_t b, int k)
{
    float x = coordinate(t, a, k), y = coordinate(t, b, k);
    return x < y || (x == y && a < b);
}

static void swap(uint32_t *a, uint32_t *b)
{
    uint32_t c = *a;
    *a = *b;
    *b = c;
}

/* Reorders order[lo .. hi) so that order[mid] is the point of rank mid - lo along axis k, the ones
 * before it precede it and the ones after follow it (quickselect; the pivots come from a fixed
 * pseudo-random sequence, so the result is the same on every run and no input order makes every
 * pivot a bad one). Expected linear time. */
static void select_median(const lod_point_tree *t, uint32_t lo, uint32_t hi, uint32_t mid, int k, uint32_t *state)
{
    uint32_t *o = t->order;
    while (hi - lo > 1) {
        *state = *state * 1664525u + 1013904223u;
        swap(&o[lo + (*state >> 8) % (hi - lo)], &o[hi - 1]);
        uint32_t pivot = o[hi - 1], store = lo;
        for (uint32_t i = lo; i + 1 < hi; i++)
            if (before(t, o[i], pivot, k))
                swap(&o[i], &o[store++]);
        swap(&o[store], &o[hi - 1]);
        if (store == mid)
            return;
        if (store < mid)
            lo = store + 1;
        else
            hi = store;
    }
}

/* Node i's box (its points' smallest and largest coordinates) and the axis of its largest extent. */
static int node_box(lod_point_tree *t, uint32_t i, uint32_t lo, uint32_t hi)
{
    float *b = t->box[i];
    b[0] = b[1] = b[2] = INFINITY;
    b[3] = b[4] = b[5] = -INFINITY;
    for (uint32_t j = lo; j < hi; j++)
        for (int k = 0; k < 3; k++) {
            float x = coordinate(t, t->order[j], k);
            b[k] = x < b[k] ? x : b[k];
            b[3 + k] = x > b[3 + k] ? x : b[3 + k];
        }
    int axis = 0;
    for (int k = 1; k < 3; k++)
        if (b[3 + k] - b[k] > b[3 + axis] - b[axis])
            axis = k;
    return axis;
}

static void build_node(lod_point_tree *t, uint32_t i, uint32_t lo, uint32_t hi, uint32_t *state)
{
    while (hi - lo > TREE_LEAF) {
        uint32_t mid = lo + (hi - lo) / 2;
        int k = node_box(t, i, lo, hi);
        select_median(t, lo, hi, mid, k, state);
        t->axis[i] = (uint8_t)k;
        t->split[i] = coordinate(t, t->order[mid], k);
        build_node(t, 2 * i, lo, mid, state);
        i = 2 * i + 1; /* the upper half: a loop, so that the recursion is only as deep as the tree */
        lo = mid;
    }
}

/* Grows t's node arrays to `nodes` entries; 0 when out of memory (what was grown is kept). */
static int grow_nodes(lod_point_tree *t, size_t nodes)
{
    float *split = realloc(t->split, nodes * sizeof *split);
    if (split)
        t->split = split;
    float(*box)[6] = realloc(t->box, nodes * sizeof *box);
    if (box)
        t->box = box;
    uint8_t *axis = realloc(t->axis, nodes * sizeof *axis);
    if (axis)
        t->axis = axis;
    if (!split || !box || !axis)
        return 0;
    t->node_cap = nodes;
    return 1;
}

int lod_point_tree_build(lod_point_tree *t, const gdr_vec3 *points, uint32_t n)
{
    t->points = points;
    t->count = n;
    /* A node of more than TREE_LEAF points at depth d holds at most ceil(n / 2^d) of them, so
     * 2^d < n / TREE_LEAF and its index, below 2^(d + 1), is below 2n / TREE_LEAF. */
    size_t nodes = 2 * (size_t)n / TREE_LEAF + 2;
    if (n > t->order_cap) {
        uint32_t *order = realloc(t->order, (size_t)n * sizeof *order);
        if (!order)
            return 0;
        t->order = order;
        t->order_cap = n;
    }
    if (nodes > t->node_cap && !grow_nodes(t, nodes))
        return 0;
    for (uint32_t i = 0; i < n; i++)
        t->order[i] = i;
    uint32_t state = 12345u;
    build_node(t, 1, 0, n, &state);
    return 1;
}

typedef struct tree_query {
    float q[3];
    uint32_t best;
    float best_d2;
} tree_query;

static void visit_leaf(const lod_point_tree *t, uint32_t lo, uint32_t hi, tree_query *s)
{
    for (uint32_t i = lo; i < hi; i++) {
        uint32_t item = t->order[i];
        const gdr_vec3 p = t->points[item];
        float dx = p.x - s->q[0], dy = p.y - s->q[1], dz = p.z - s->q[2]; /* as lod_grid.c's visit_cell */
        float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < s->best_d2 || (d2 == s->best_d2 && item < s->best)) {
            s->best_d2 = d2;
            s->best = item;
        }
    }
}

/* Squared distance from q to node i's box, computed as a point's distance is (visit_leaf): for a point
 * in the box, each axis's difference is at least the box's (rounding is monotonic) and the sum of
 * non-negative squares in the same order no smaller, so a box strictly farther than the best so far
 * holds no point as near, tie included. */
static float box_d2(const lod_point_tree *t, uint32_t i, const float q[3])
{
    const float *b = t->box[i];
    float g[3];
    for (int k = 0; k < 3; k++) {
        float below = b[k] - q[k], above = q[k] - b[3 + k];
        g[k] = below > 0.0f ? below : above > 0.0f ? above : 0.0f;
    }
    return g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
}

/* Node i over order[lo .. hi): skipped when its box is farther than the best so far; its near half
 * first. */
static void visit_node(const lod_point_tree *t, uint32_t i, uint32_t lo, uint32_t hi, tree_query *s)
{
    if (hi - lo <= TREE_LEAF) {
        visit_leaf(t, lo, hi, s);
        return;
    }
    if (box_d2(t, i, s->q) > s->best_d2)
        return;
    uint32_t mid = lo + (hi - lo) / 2;
    if (s->q[t->axis[i]] < t->split[i]) {
        visit_node(t, 2 * i, lo, mid, s);
        visit_node(t, 2 * i + 1, mid, hi, s);
    } else {
        visit_node(t, 2 * i + 1, mid, hi, s);
        visit_node(t, 2 * i, lo, mid, s);
    }
}

uint32_t lod_point_tree_nearest(const lod_point_tree *t, gdr_vec3 point, float *distance_squared)
{
    tree_query s = {{point.x, point.y, point.z}, UINT32_MAX, INFINITY};
    visit_node(t, 1, 0, t->count, &s);
    *distance_squared = s.best_d2;
    return s.best;
}

void lod_point_tree_free(lod_point_tree *t)
{
    free(t->order);
    free(t->split);
    free(t->box);
    free(t->axis);
    memset(t, 0, sizeof *t);
}
