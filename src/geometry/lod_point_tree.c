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

/* The axis of order[lo .. hi)'s largest extent. */
static int widest_axis(const lod_point_tree *t, uint32_t lo, uint32_t hi)
{
    float a[3] = {INFINITY, INFINITY, INFINITY}, b[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = lo; i < hi; i++)
        for (int k = 0; k < 3; k++) {
            float x = coordinate(t, t->order[i], k);
            a[k] = x < a[k] ? x : a[k];
            b[k] = x > b[k] ? x : b[k];
        }
    int axis = 0;
    for (int k = 1; k < 3; k++)
        if (b[k] - a[k] > b[axis] - a[axis])
            axis = k;
    return axis;
}

static void build_node(lod_point_tree *t, uint32_t lo, uint32_t hi, uint32_t *state)
{
    while (hi - lo > TREE_LEAF) {
        uint32_t mid = lo + (hi - lo) / 2;
        int k = widest_axis(t, lo, hi);
        select_median(t, lo, hi, mid, k, state);
        t->axis[mid] = (uint8_t)k;
        t->split[mid] = coordinate(t, t->order[mid], k);
        build_node(t, lo, mid, state);
        lo = mid; /* the upper half: a loop, so that the recursion is only as deep as the tree */
    }
}

int lod_point_tree_build(lod_point_tree *t, const gdr_vec3 *points, uint32_t n)
{
    t->points = points;
    t->count = n;
    if (n > t->cap) {
        uint32_t *order = realloc(t->order, (size_t)n * sizeof *order);
        if (order)
            t->order = order;
        float *split = realloc(t->split, (size_t)n * sizeof *split);
        if (split)
            t->split = split;
        uint8_t *axis = realloc(t->axis, (size_t)n * sizeof *axis);
        if (axis)
            t->axis = axis;
        if (!order || !split || !axis)
            return 0;
        t->cap = n;
    }
    for (uint32_t i = 0; i < n; i++)
        t->order[i] = i;
    uint32_t state = 12345u;
    build_node(t, 0, n, &state);
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

/* The near half first, then the far one unless the splitting plane is farther than the best so far.
 * A point beyond the plane is at least as far along that axis as the plane (rounding is monotonic),
 * and its squared distance, a sum of non-negative squares, at least that axis's square: skipping
 * only where the plane's square is strictly larger keeps every tie, so the lowest index wins. */
static void visit_node(const lod_point_tree *t, uint32_t lo, uint32_t hi, tree_query *s)
{
    if (hi - lo <= TREE_LEAF) {
        visit_leaf(t, lo, hi, s);
        return;
    }
    uint32_t mid = lo + (hi - lo) / 2;
    float gap = s->q[t->axis[mid]] - t->split[mid];
    if (gap < 0.0f) {
        visit_node(t, lo, mid, s);
        if (!(gap * gap > s->best_d2))
            visit_node(t, mid, hi, s);
    } else {
        visit_node(t, mid, hi, s);
        if (!(gap * gap > s->best_d2))
            visit_node(t, lo, mid, s);
    }
}

uint32_t lod_point_tree_nearest(const lod_point_tree *t, gdr_vec3 point, float *distance_squared)
{
    tree_query s = {{point.x, point.y, point.z}, UINT32_MAX, INFINITY};
    visit_node(t, 0, t->count, &s);
    *distance_squared = s.best_d2;
    return s.best;
}

void lod_point_tree_free(lod_point_tree *t)
{
    free(t->order);
    free(t->split);
    free(t->axis);
    memset(t, 0, sizeof *t);
}
