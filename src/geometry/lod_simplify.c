/* Simplifying one group's triangles by half-edge collapses over positions (lod_simplify.h).
 *
 * A position a moves onto a neighbouring position b: every triangle holding both disappears, every
 * other triangle around a takes, in place of its corner at a (a wedge wa), a wedge of b. That is
 * the wedge wb that shares a triangle along the edge a-b with wa where there is one (the attribute
 * field continues across the collapsed edge), else the wedge of b that best continues wa's field:
 * wa's surviving triangles' affine uv and normal, extrapolated to b's position, compared with each
 * wedge of b. The cost of a collapse is the mean squared distance of a's Garland-Heckbert quadric
 * at b plus the normals' error averaged over a's fan plus the largest texture slide it charges a
 * triangle, weighed by the change the texture shows where it slides (lod_texture.h) and at most the
 * triangle's longest edge (all squared lengths). A heap keeps each
 * position's cheapest collapse as last evaluated; a popped position is evaluated again and moves
 * only if it is still no dearer than the next one (lazy re-evaluation). Collapses run in passes: a
 * position moved onto waits for the next pass, and a pass ends past 1.5 x the cost that would
 * reach the target, so collapses spread over the group instead of piling onto a few positions.
 * Single-threaded per group, ties broken by position index: the result does not depend on the
 * thread count. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geometry/lod_internal.h"
#include "geometry/lod_simplify.h"

#define NONE UINT32_MAX
#define FLAG_REMOVED 1u
#define FLAG_BORDER 2u /* on an open border (or a non-manifold edge): moves only along a border edge */
#define FLAG_QUEUED 4u
/* Weight of an open border's edge plane, per squared edge length: keeps borders in place against
 * the area-weighted planes of the surface. */
#define BORDER_WEIGHT 4.0
/* The largest texture slide of a collapse (mesh length times the change the texture shows under it,
 * capped by the triangle's longest edge) costs its square times this, as a squared distance does: the slide enters the group's error as
 * the deviation does. A normal's change costs as a length of |delta n| times the square root of its
 * triangle's area (a surface tilted by that angle over the triangle's size), squared, times
 * NORMAL_WEIGHT, averaged over the fan by area. Chosen by measurement (docs/GEOMETRY.md). */
#define UV_WEIGHT 1.0
#define NORMAL_WEIGHT 0.5
/* A triangle may turn by at most about 75 degrees in one collapse. */
#define MIN_NORMAL_COS 0.25

typedef struct run {
    lod_simplify_scratch *s;
    uint32_t pass;    /* a position moved onto in this pass neither moves nor is moved onto again */
    const lod_simplify_input *in;
    size_t triangles; /* alive */
    int failed;       /* out of memory */
    /* The position and target of the last whole cost computed (settle_cost): s->info and s->choice
     * still describe that move, so collapse() need not compute it again. NONE: none since the last
     * evaluation began. */
    uint32_t settled_a, settled_b;
} run;

static inline uint32_t wedge_position(const run *r, uint32_t w) { return r->in->vertex_position[w]; }
static inline uint32_t corner_position(const run *r, uint32_t c) { return wedge_position(r, r->s->tri[c]); }
/* The corner j steps on from corner c in its triangle (j < 3), with one division rather than two. */
static inline uint32_t corner_after(uint32_t c, uint32_t j)
{
    uint32_t k = c % 3, m = k + j;
    return c - k + (m >= 3 ? m - 3 : m);
}

static inline void load(const run *r, uint32_t p, double out[3])
{
    const float *f = r->in->positions + (size_t)p * 3;
    out[0] = f[0], out[1] = f[1], out[2] = f[2];
}

static inline void sub(const double a[3], const double b[3], double o[3])
{
    o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2];
}
static inline double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
/* fmax and fmin (a NaN gives way to the other value) without libm's call: the same results. */
static inline double max2(double x, double y) { return x > y || y != y ? x : y; }
static inline double min2(double x, double y) { return x < y || y != y ? x : y; }
static inline void cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}

/* --- quadrics: a2 ab ac ad b2 bc bd c2 cd d2 of w (n.x + d)^2, and the sum of the weights w ------------ */
#define QUADRIC_SIZE 11

static inline void quadric_add_plane(double *q, const double n[3], double d, double w)
{
    q[0] += w * n[0] * n[0], q[1] += w * n[0] * n[1], q[2] += w * n[0] * n[2], q[3] += w * n[0] * d;
    q[4] += w * n[1] * n[1], q[5] += w * n[1] * n[2], q[6] += w * n[1] * d;
    q[7] += w * n[2] * n[2], q[8] += w * n[2] * d, q[9] += w * d * d, q[10] += w;
}

static double quadric_eval(const double *q, const double x[3])
{
    double e = q[0] * x[0] * x[0] + q[4] * x[1] * x[1] + q[7] * x[2] * x[2] + q[9];
    e += 2.0 * (q[1] * x[0] * x[1] + q[2] * x[0] * x[2] + q[5] * x[1] * x[2]);
    e += 2.0 * (q[3] * x[0] + q[6] * x[1] + q[8] * x[2]);
    return e > 0.0 ? e : 0.0;
}

/* --- the heap ------------------------------------------------------------------------------------ */

static int heap_less(const lod_simplify_heap_item *a, const lod_simplify_heap_item *b)
{
    return a->cost < b->cost || (a->cost == b->cost && a->position < b->position);
}

static void heap_push(lod_simplify_scratch *s, float cost, uint32_t position)
{
    size_t i = s->heap_count++;
    lod_simplify_heap_item item = {cost, position};
    while (i > 0 && heap_less(&item, &s->heap[(i - 1) / 2])) {
        s->heap[i] = s->heap[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    s->heap[i] = item;
}

static lod_simplify_heap_item heap_pop(lod_simplify_scratch *s)
{
    lod_simplify_heap_item top = s->heap[0], last = s->heap[--s->heap_count];
    size_t i = 0, n = s->heap_count;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && heap_less(&s->heap[c + 1], &s->heap[c]))
            c++;
        if (!heap_less(&s->heap[c], &last))
            break;
        s->heap[i] = s->heap[c];
        i = c;
    }
    if (n)
        s->heap[i] = last;
    return top;
}

/* --- the corners around a position ---------------------------------------------------------------- */

/* Room for evaluating a fan of n corners: its frames, and its at most 2n neighbours with their
 * costs. Sized by the largest fan met rather than the group's corners: a position's fan is a few
 * triangles. Returns 0 (and marks the run failed) when out of memory. */
static int reserve_fan(run *r, uint32_t n)
{
    lod_simplify_scratch *s = r->s;
    size_t m = (size_t)n * 2;
    int ok = LOD_RESERVE(s, info, n) && LOD_RESERVE(s, neighbours, m) && LOD_RESERVE(s, near, m) &&
             LOD_RESERVE(s, costs, m) && LOD_RESERVE(s, geometry, m) && LOD_RESERVE(s, exact, m) &&
             LOD_RESERVE(s, taken, m) && LOD_RESERVE(s, edge_count, m);
    r->failed |= !ok;
    return ok;
}

/* Gathers the corners of p's live triangles into s->fan (dropping dead ones from p's list). */
static uint32_t gather_fan(run *r, uint32_t p, uint32_t *fan)
{
    lod_simplify_scratch *s = r->s;
    uint32_t n = 0, *link = &s->head[p];
    while (*link != NONE) {
        uint32_t c = *link;
        if (!s->alive[c / 3]) {
            *link = s->next[c];
            continue;
        }
        fan[n++] = c;
        link = &s->next[c];
    }
    return n;
}

static int triangle_holds(const run *r, uint32_t t, uint32_t p)
{
    return corner_position(r, t * 3) == p || corner_position(r, t * 3 + 1) == p || corner_position(r, t * 3 + 2) == p;
}

/* The distinct neighbours of the position whose fan is given, marked with a fresh token. */
static uint32_t gather_neighbours(run *r, const uint32_t *fan, uint32_t n, uint32_t *out, uint32_t *token)
{
    lod_simplify_scratch *s = r->s;
    uint32_t k = 0, t = ++s->token;
    if (n)
        s->mark[corner_position(r, fan[0])] = t; /* not its own neighbour (a degenerate triangle) */
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = fan[i];
        for (uint32_t j = 1; j < 3; j++) {
            uint32_t q = corner_position(r, corner_after(c, j));
            if (s->mark[q] != t) {
                s->mark[q] = t;
                out[k++] = q;
            }
        }
    }
    *token = t;
    return k;
}

/* gather_neighbours for a position a's evaluation: also counts, per neighbour, the triangles of the
 * fan that hold it (each triangle once), into s->edge_count. */
static uint32_t gather_candidates(run *r, uint32_t a, const uint32_t *fan, uint32_t n, uint32_t *out)
{
    lod_simplify_scratch *s = r->s;
    uint32_t k = 0, t = ++s->token;
    s->mark[a] = t; /* not its own neighbour (a degenerate triangle) */
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = fan[i];
        uint32_t x = corner_position(r, corner_after(c, 1)), y = corner_position(r, corner_after(c, 2));
        for (uint32_t j = 0; j < 2; j++) {
            uint32_t q = j ? y : x;
            if (q == a || (j && y == x))
                continue;
            if (s->mark[q] != t) {
                s->mark[q] = t;
                s->slot[q] = k;
                s->edge_count[k] = 0;
                out[k++] = q;
            }
            s->edge_count[s->slot[q]]++;
        }
    }
    return k;
}

static uint32_t gather_wedges(run *r, const uint32_t *fan, uint32_t n, uint32_t *out)
{
    uint32_t k = 0;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t w = r->s->tri[fan[i]], j = 0;
        while (j < k && out[j] != w)
            j++;
        if (j == k)
            out[k++] = w;
    }
    return k;
}

/* --- the attribute error ---------------------------------------------------------------------------- */

/* Fills s->info for the fan of a position (its corners' triangles: their affine frames and
 * attribute gradients, computed once for every collapse evaluated from it); returns its area. */
static double prepare_fan(run *r, const uint32_t *fan, uint32_t n)
{
    const lod_simplify_input *in = r->in;
    double total = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        lod_simplify_corner *f = &r->s->info[i];
        uint32_t c = fan[i], w[3];
        double p[3][3];
        for (uint32_t j = 0; j < 3; j++) {
            w[j] = r->s->tri[corner_after(c, j)];
            load(r, wedge_position(r, w[j]), p[j]);
        }
        f->wedge = w[0];
        f->other[0] = wedge_position(r, w[1]), f->other[1] = wedge_position(r, w[2]);
        memcpy(f->p0, p[0], sizeof f->p0);
        sub(p[1], p[0], f->e1), sub(p[2], p[0], f->e2);
        f->g11 = dot(f->e1, f->e1), f->g12 = dot(f->e1, f->e2), f->g22 = dot(f->e2, f->e2);
        double det = f->g11 * f->g22 - f->g12 * f->g12;
        f->area = det > 0.0 ? 0.5 * sqrt(det) : 0.0;
        total += f->area;
        f->inv_det = det > 1e-12 * f->g11 * f->g22 ? 1.0 / det : 0.0; /* 0: degenerate, no field */
        const uint32_t m0 = in->vertex_source[w[0]], m1 = in->vertex_source[w[1]], m2 = in->vertex_source[w[2]];
        f->uv_scale = 0.0;
        if (in->uvs) {
            const gdr_vec2 t0 = in->uvs[m0], t1 = in->uvs[m1], t2 = in->uvs[m2];
            f->t0[0] = t0.x, f->t0[1] = t0.y;
            f->t1[0] = (double)t1.x - t0.x, f->t1[1] = (double)t1.y - t0.y;
            f->t2[0] = (double)t2.x - t0.x, f->t2[1] = (double)t2.y - t0.y;
            double uv_area = 0.5 * fabs(f->t1[0] * f->t2[1] - f->t2[0] * f->t1[1]);
            f->uv_scale = uv_area > 1e-20 ? f->area / uv_area : 0.0;
        }
        if (in->normals) {
            const gdr_vec3 n0 = in->normals[m0], n1 = in->normals[m1], n2 = in->normals[m2];
            f->n0[0] = n0.x, f->n0[1] = n0.y, f->n0[2] = n0.z;
            f->n1[0] = (double)n1.x - n0.x, f->n1[1] = (double)n1.y - n0.y, f->n1[2] = (double)n1.z - n0.z;
            f->n2[0] = (double)n2.x - n0.x, f->n2[1] = (double)n2.y - n0.y, f->n2[2] = (double)n2.z - n0.z;
        }
    }
    return total;
}

/* For each corner of the fan whose triangle survives moving onto the target (not holds_b), its
 * triangle's longest edge once moved there, and its affine uv and normal extrapolated over its plane
 * to q, the target's position (once per target: every wedge of the target is compared with them). */
static void extrapolate_fan(const run *r, uint32_t n, const double q[3])
{
    for (uint32_t i = 0; i < n; i++) {
        lod_simplify_corner *f = &r->s->info[i];
        if (f->holds_b)
            continue;
        double d[3], e12[3];
        sub(q, f->p0, d);
        sub(f->e1, f->e2, e12);
        double r1 = dot(d, f->e1), r2 = dot(d, f->e2);
        f->edge2_at_q = max2(max2(f->g11 - 2.0 * r1 + dot(d, d), f->g22 - 2.0 * r2 + dot(d, d)), dot(e12, e12));
        if (f->inv_det == 0.0)
            continue;
        double u = (f->g22 * r1 - f->g12 * r2) * f->inv_det, v = (f->g11 * r2 - f->g12 * r1) * f->inv_det;
        if (f->uv_scale > 0.0)
            for (int k = 0; k < 2; k++)
                f->uv_at_q[k] = f->t0[k] + u * f->t1[k] + v * f->t2[k];
        if (r->in->normals)
            for (int k = 0; k < 3; k++)
                f->normal_at_q[k] = f->n0[k] + u * f->n1[k] + v * f->n2[k];
    }
}

/* The largest change the texture shows over a fan corner's slide to uv tb: over the box of its
 * triangle's uvs before, the uv its field continues to at the target, and tb (lod_texture.h). Every
 * texel the triangle shows before and after the move lies in that box. */
static double slide_variation(const run *r, const lod_simplify_corner *f, gdr_vec2 tb)
{
    const double uv[5][2] = {{f->t0[0], f->t0[1]},
                             {f->t0[0] + f->t1[0], f->t0[1] + f->t1[1]},
                             {f->t0[0] + f->t2[0], f->t0[1] + f->t2[1]},
                             {f->uv_at_q[0], f->uv_at_q[1]},
                             {tb.x, tb.y}};
    return lod_texture_variation(r->in->texture, uv, 5);
}

/* The error of giving a fan corner the attributes of wedge wb at the target (extrapolate_fan):
 * its triangle's normal there against wb's, as an area-weighted squared length (returned), and its
 * uv against wb's: the texture slide, a mesh length times the largest change the texture shows
 * under it (slide_variation), squared (*slide2). A caller that keeps only the largest slide above
 * `counts_above`, capped by the triangle's longest edge (wedge_error), gives that bound: where the slide
 * unweighted (the change is at most 1) or that edge is no more than it, the slide cannot count,
 * the texture is not read and *slide2 is 0. -INFINITY: always measured. */
static inline double corner_attribute_error(const run *r, const lod_simplify_corner *f, uint32_t wb,
                                            double *slide2, double counts_above)
{
    const lod_simplify_input *in = r->in;
    *slide2 = 0.0;
    if (f->inv_det == 0.0)
        return 0.0;
    const uint32_t mb = in->vertex_source[wb];
    if (f->uv_scale > 0.0) {
        const gdr_vec2 tb = in->uvs[mb];
        double du = f->uv_at_q[0] - tb.x, dv = f->uv_at_q[1] - tb.y;
        *slide2 = (du * du + dv * dv) * f->uv_scale;
        int cannot_count = !in->every_slide && (*slide2 <= counts_above || f->edge2_at_q <= counts_above);
        if (*slide2 > 0.0 && in->texture && cannot_count)
            *slide2 = 0.0;
        else if (*slide2 > 0.0 && in->texture) {
            double v = slide_variation(r, f, tb);
            *slide2 *= v * v;
        }
    }
    if (!in->normals)
        return 0.0;
    const gdr_vec3 nb = in->normals[mb];
    double dx = f->normal_at_q[0] - nb.x, dy = f->normal_at_q[1] - nb.y, dz = f->normal_at_q[2] - nb.z;
    return (dx * dx + dy * dy + dz * dz) * f->area * (in->normal_weight > 0.0 ? in->normal_weight : NORMAL_WEIGHT) *
           f->area;
}

/* The error of wedge wa taking wedge wb when a moves to q = b's position, over wa's triangles that
 * survive (those not holding b): the normals' area-weighted error (returned), and in *slide2 the
 * largest slide a triangle would be charged for it, at most the triangle's longest edge (squared),
 * as the group's error counts it (output_slide). */
static inline double wedge_error(const run *r, uint32_t n, uint32_t wa, uint32_t wb, double *slide2)
{
    double error = 0.0;
    *slide2 = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        const lod_simplify_corner *f = &r->s->info[i];
        if (f->wedge != wa || f->holds_b)
            continue;
        double s2;
        error += corner_attribute_error(r, f, wb, &s2, *slide2);
        s2 = s2 < f->edge2_at_q ? s2 : f->edge2_at_q;
        *slide2 = s2 > *slide2 ? s2 : *slide2;
    }
    return error;
}

/* The largest slide (squared) a triangle of a's fan that survives the move already carries, as the
 * group's error states it (output_slide: capped by its longest edge), where the move stretches that
 * edge and so raises the capped slide; 0 where none does. A collapse that lengthens a triangle an
 * earlier collapse slid across charts raises the group's slide as much as a new slide would: a
 * sliver charged while short and stretched later set DamagedHelmet's coarse slide (0.39 units) at
 * no cost to the collapse that stretched it. */
static double stretched_slide2(const run *r, const uint32_t *fan, uint32_t n)
{
    double largest = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        const lod_simplify_corner *f = &r->s->info[i];
        double carried = r->s->tri_slide[fan[i] / 3];
        if (f->holds_b || carried == 0.0)
            continue;
        double e12 = f->g11 + f->g22 - 2.0 * f->g12, edge2 = max2(max2(f->g11, f->g22), e12);
        double before = min2(carried * carried, edge2), after = min2(carried * carried, f->edge2_at_q);
        if (after > before && after > largest)
            largest = after;
    }
    return largest;
}

/* The geometric part of the cost of moving a onto b, whose edge with a holds edge_triangles of a's
 * triangles: the quadric's mean squared distance at b, or INFINITY where the collapse is not allowed
 * (no triangle along a-b, or more than two; a border position not along a border edge). The whole
 * cost is never below it (the attribute error is a sum of squares), so it orders the candidates
 * before their attribute errors are computed. */
static inline double pair_geometry(const run *r, uint32_t a, uint32_t b, uint32_t edge_triangles)
{
    const lod_simplify_scratch *s = r->s;
    if (edge_triangles == 0 || edge_triangles > 2 || ((s->flags[a] & FLAG_BORDER) && edge_triangles != 1))
        return INFINITY;
    double q[3];
    load(r, b, q);
    const double *qa = s->quadric + (size_t)a * QUADRIC_SIZE;
    return qa[10] > 0.0 ? quadric_eval(qa, q) / qa[10] : 0.0;
}

/* The triangles of a's fan that hold b (each once, however many of its corners lie at b). */
static uint32_t edge_triangles(const run *r, uint32_t b, const uint32_t *fan, uint32_t n)
{
    uint32_t k = 0;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = fan[i];
        k += corner_position(r, corner_after(c, 1)) == b || corner_position(r, corner_after(c, 2)) == b;
    }
    return k;
}

/* The cost of moving a (fan prepared in s->info, its area, wedges) onto b, its geometric part
 * (pair_geometry, finite) given: that plus the normals' error averaged over a's fan by area plus the
 * largest texture slide a surviving triangle would be charged, at most its longest edge (all squared
 * lengths). The slide is weighed as the group's error counts it (output_slide: the largest over the
 * triangles, capped by their size), not averaged by area: a slide on a thin triangle or across charts
 * sets the group's error as much as one on a large triangle does. Sets s->choice for a's wedges (each
 * the wedge of b with the least normal error plus slide). */
static double pair_cost(run *r, uint32_t b, double geometry, const uint32_t *fan, uint32_t n, double area,
                        const uint32_t *wedges, uint32_t wedge_count)
{
    lod_simplify_scratch *s = r->s;
    for (uint32_t i = 0; i < n; i++) {
        lod_simplify_corner *f = &s->info[i];
        f->holds_b = f->other[0] == b || f->other[1] == b;
    }
    double q[3];
    load(r, b, q);
    extrapolate_fan(r, n, q);
    uint32_t b_wedges = NONE;
    double normal = 0.0, slide2 = stretched_slide2(r, fan, n), scale = area > 0.0 ? 1.0 / area : 0.0;
    for (uint32_t k = 0; k < wedge_count; k++) {
        uint32_t wa = wedges[k], best = NONE;
        double best_error = INFINITY, best_normal = 0.0, best_slide2 = 0.0, e, n2, s2;
        /* the wedges of b that share a triangle along a-b with wa */
        for (uint32_t i = 0; i < n; i++) {
            if (s->info[i].wedge != wa || !s->info[i].holds_b)
                continue;
            uint32_t c = fan[i], base = c - c % 3;
            for (uint32_t j = 0; j < 3; j++) {
                uint32_t wb = s->tri[base + j];
                if (wedge_position(r, wb) != b || wb == best)
                    continue;
                n2 = wedge_error(r, n, wa, wb, &s2) * scale;
                if ((e = n2 + s2 * UV_WEIGHT) < best_error)
                    best = wb, best_error = e, best_normal = n2, best_slide2 = s2;
            }
        }
        if (best == NONE) { /* a seam or hard-edge corner: the wedge of b that best continues wa */
            if (b_wedges == NONE) {
                uint32_t m = gather_fan(r, b, s->fan_b);
                b_wedges = gather_wedges(r, s->fan_b, m, s->wedges_b);
            }
            for (uint32_t j = 0; j < b_wedges; j++) {
                n2 = wedge_error(r, n, wa, s->wedges_b[j], &s2) * scale;
                if ((e = n2 + s2 * UV_WEIGHT) < best_error || best == NONE)
                    best = s->wedges_b[j], best_error = e, best_normal = n2, best_slide2 = s2;
            }
        }
        if (best == NONE)
            return INFINITY;
        s->choice[wa] = best;
        normal += best_normal;
        slide2 = best_slide2 > slide2 ? best_slide2 : slide2;
    }
    return geometry + normal + slide2 * UV_WEIGHT;
}

/* --- validity ----------------------------------------------------------------------------------------- */

/* No triangle around a (not holding b) flips, turns too far or collapses to zero area. */
static int keeps_orientation(const run *r, uint32_t a, uint32_t b, const uint32_t *fan, uint32_t n)
{
    double pa[3], pb[3];
    load(r, a, pa), load(r, b, pb);
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = fan[i];
        if (triangle_holds(r, c / 3, b))
            continue;
        double p1[3], p2[3], e1[3], e2[3], f1[3], f2[3], n0[3], n1[3];
        load(r, corner_position(r, corner_after(c, 1)), p1);
        load(r, corner_position(r, corner_after(c, 2)), p2);
        sub(p1, pa, e1), sub(p2, pa, e2), sub(p1, pb, f1), sub(p2, pb, f2);
        cross(e1, e2, n0), cross(f1, f2, n1);
        double l0 = dot(n0, n0), l1 = dot(n1, n1);
        if (l0 == 0.0)
            continue; /* degenerate before: nothing to keep */
        if (!(l1 > 0.0) || dot(n0, n1) <= MIN_NORMAL_COS * sqrt(l0 * l1))
            return 0;
    }
    return 1;
}

/* The link condition (the positions next to both a and b are the third corners of the triangles
 * along a-b), and no triangle that would repeat another by position. */
static int keeps_topology(run *r, uint32_t a, uint32_t b, const uint32_t *fan, uint32_t n)
{
    lod_simplify_scratch *s = r->s;
    uint32_t near_a, count = gather_neighbours(r, fan, n, s->neighbours, &near_a), third = ++s->token;
    (void)count;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = fan[i], base = c - c % 3;
        if (!triangle_holds(r, c / 3, b))
            continue;
        for (uint32_t j = 0; j < 3; j++) {
            uint32_t p = corner_position(r, base + j);
            if (p != a && p != b)
                s->mark[p] = third;
        }
    }
    uint32_t *fan_b = s->fan_b, m = gather_fan(r, b, fan_b);
    for (uint32_t i = 0; i < m; i++) {
        uint32_t c = fan_b[i];
        uint32_t x = corner_position(r, corner_after(c, 1)), y = corner_position(r, corner_after(c, 2));
        if ((x != a && s->mark[x] == near_a) || (y != a && s->mark[y] == near_a))
            return 0;
        if (x == a || y == a || s->mark[x] != third || s->mark[y] != third)
            continue;
        /* b, x, y exists: a triangle a, x, y (either way round) would repeat it */
        for (uint32_t k = 0; k < n; k++) {
            uint32_t t = fan[k] / 3;
            if (!triangle_holds(r, t, b) && triangle_holds(r, t, x) && triangle_holds(r, t, y))
                return 0;
        }
    }
    return 1;
}

/* Moving a onto a locked b keeps every edge between b and another locked position x that a
 * triangle removed by the move (one holding a and b) runs along: a triangle of a's fan holding x and
 * not b must survive to carry it (it becomes b, x, ...). Where a's edge to x is open none does: a
 * triangle hanging off the group's border into a mesh hole (the bunny's: a's only triangle) would
 * vanish with its edge b-x, the group would no longer meet its neighbour there, lod_group.c would
 * reject the whole group, and its clusters would stay a level behind at every step. */
static int keeps_locked_edges(const run *r, uint32_t a, uint32_t b, const uint32_t *fan, uint32_t n)
{
    const uint8_t *locked = r->in->locked;
    if (!locked[b])
        return 1;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = fan[i];
        uint32_t x = corner_position(r, corner_after(c, 1)), y = corner_position(r, corner_after(c, 2));
        if (x != b && y != b)
            continue;
        x = x == b ? y : x; /* the removed triangle's third corner */
        if (x == a || x == b || !locked[x])
            continue;
        int carried = 0;
        for (uint32_t k = 0; k < n && !carried; k++) {
            uint32_t t = fan[k] / 3;
            carried = !triangle_holds(r, t, b) && triangle_holds(r, t, x);
        }
        if (!carried)
            return 0;
    }
    return 1;
}

/* --- collapses ------------------------------------------------------------------------------------------ */

/* One evaluation of a position a: its fan, neighbours and wedges; per neighbour the cost of moving
 * onto it as far as computed (exact[i]: the whole cost, else its geometric part, a lower bound);
 * the fan's attribute frames once the first whole cost needs them. */
typedef struct evaluation {
    uint32_t a, n, count, wedge_count;
    double area; /* the fan's area, once prepared (prepared) */
    int prepared;
} evaluation;

/* Neighbour i's whole cost (as the float the order compares). */
static void settle_cost(run *r, evaluation *e, uint32_t i)
{
    lod_simplify_scratch *s = r->s;
    if (!e->prepared) {
        e->area = prepare_fan(r, s->fan, e->n);
        e->prepared = 1;
    }
    s->costs[i] = (float)pair_cost(r, s->neighbours[i], s->geometry[i], s->fan, e->n, e->area, s->wedges,
                                   e->wedge_count);
    s->exact[i] = 1;
    r->settled_a = e->a, r->settled_b = s->neighbours[i];
}

/* The neighbour not yet taken with the smallest cost (ties by position index), INFINITY's included,
 * or NONE when all are taken. A geometric part is a lower bound of its whole cost (both as floats),
 * so only the candidate that leads by its lower bound has its whole cost computed; the order is the
 * one the whole costs give. */
static uint32_t next_cheapest(run *r, evaluation *e)
{
    lod_simplify_scratch *s = r->s;
    for (;;) {
        uint32_t m = NONE;
        for (uint32_t j = 0; j < e->count; j++) {
            if (s->taken[j])
                continue;
            if (m == NONE || s->costs[j] < s->costs[m] ||
                (s->costs[j] == s->costs[m] && s->neighbours[j] < s->neighbours[m]))
                m = j;
        }
        if (m == NONE || s->exact[m])
            return m;
        settle_cost(r, e, m);
    }
}

/* a's cheapest collapse; with `valid`, the cheapest that passes the checks. Returns its cost
 * (INFINITY: none) and target. */
static double best_collapse(run *r, uint32_t a, int valid, uint32_t *target)
{
    lod_simplify_scratch *s = r->s;
    *target = NONE;
    r->settled_a = r->settled_b = NONE;
    if (r->in->locked[a] || (s->flags[a] & FLAG_REMOVED) || (valid && s->pass[a] == r->pass))
        return INFINITY;
    evaluation e = {.a = a, .n = gather_fan(r, a, s->fan)};
    if (e.n == 0 || !reserve_fan(r, e.n))
        return INFINITY;
    e.count = gather_candidates(r, a, s->fan, e.n, s->neighbours);
    e.wedge_count = gather_wedges(r, s->fan, e.n, s->wedges);
    for (uint32_t i = 0; i < e.count; i++) {
        s->geometry[i] = pair_geometry(r, a, s->neighbours[i], s->edge_count[i]);
        s->costs[i] = (float)s->geometry[i];
        s->exact[i] = !(s->geometry[i] < INFINITY);
        s->taken[i] = 0;
    }
    /* the neighbours in order of cost (ties by index), the first that passes the checks */
    for (uint32_t m; (m = next_cheapest(r, &e)) != NONE;) {
        s->taken[m] = 1;
        uint32_t b = s->neighbours[m];
        if (!(s->costs[m] < INFINITY))
            return INFINITY;
        if (valid && s->pass[b] == r->pass)
            continue;
        if (!valid || (keeps_orientation(r, a, b, s->fan, e.n) && keeps_topology(r, a, b, s->fan, e.n) &&
                       keeps_locked_edges(r, a, b, s->fan, e.n))) {
            *target = b;
            return s->costs[m];
        }
    }
    return INFINITY;
}

static void queue(run *r, uint32_t p)
{
    uint32_t target;
    double cost = best_collapse(r, p, 0, &target);
    if (cost < INFINITY) {
        heap_push(r->s, (float)cost, p);
        r->s->flags[p] |= FLAG_QUEUED;
    }
}

/* Moves a onto b (the checks passed). The evaluation that chose b computed its whole cost last
 * where it settled no other neighbour after it: s->fan, s->info and s->choice then hold that move
 * (nothing has changed since; the checks write neither) and are not computed again. */
static void collapse(run *r, uint32_t a, uint32_t b)
{
    lod_simplify_scratch *s = r->s;
    uint32_t n = gather_fan(r, a, s->fan);
    if (!reserve_fan(r, n))
        return;
    if (r->settled_a != a || r->settled_b != b) {
        uint32_t wedge_count = gather_wedges(r, s->fan, n, s->wedges);
        pair_cost(r, b, pair_geometry(r, a, b, edge_triangles(r, b, s->fan, n)), s->fan, n, prepare_fan(r, s->fan, n),
                  s->wedges, wedge_count); /* sets s->choice, and s->info for b */
    }
    for (uint32_t i = 0; i < n; i++) { /* the slide charged to each surviving triangle whose corner moves */
        const lod_simplify_corner *f = &s->info[i];
        double s2;
        if (f->holds_b)
            continue;
        corner_attribute_error(r, f, s->choice[f->wedge], &s2, -INFINITY);
        float slide = (float)sqrt(s2);
        uint32_t t = s->fan[i] / 3;
        s->tri_slide[t] = slide > s->tri_slide[t] ? slide : s->tri_slide[t];
    }
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = s->fan[i];
        if (s->alive[c / 3] && triangle_holds(r, c / 3, b)) {
            s->alive[c / 3] = 0;
            r->triangles--;
        }
    }
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = s->fan[i];
        if (!s->alive[c / 3])
            continue;
        s->tri[c] = s->choice[s->tri[c]];
        s->next[c] = s->head[b];
        s->head[b] = c;
    }
    s->head[a] = NONE;
    s->flags[a] |= FLAG_REMOVED;
    s->pass[b] = r->pass;
    for (int k = 0; k < QUADRIC_SIZE; k++)
        s->quadric[(size_t)b * QUADRIC_SIZE + k] += s->quadric[(size_t)a * QUADRIC_SIZE + k];
    /* b and its neighbours changed: those not in the heap are evaluated again (those in it are, lazily,
     * when they come up) */
    uint32_t m = gather_fan(r, b, s->fan), token;
    if (!reserve_fan(r, m))
        return;
    uint32_t *near = s->near; /* queue()'s walks overwrite s->neighbours */
    uint32_t count = gather_neighbours(r, s->fan, m, s->neighbours, &token);
    memcpy(near, s->neighbours, count * sizeof *near);
    for (uint32_t i = 0; i < count; i++)
        if (!(s->flags[near[i]] & FLAG_QUEUED) && s->pass[near[i]] != r->pass)
            queue(r, near[i]);
}

/* --- setup ------------------------------------------------------------------------------------------------ */

static int reserve(lod_simplify_scratch *s, const lod_simplify_input *in)
{
    size_t nc = in->index_count, np = in->position_count;
    return LOD_RESERVE(s, tri, nc) && LOD_RESERVE(s, next, nc) && LOD_RESERVE(s, alive, nc / 3 + 1) &&
           LOD_RESERVE(s, head, np) && LOD_RESERVE(s, quadric, np * QUADRIC_SIZE) && LOD_RESERVE(s, flags, np) &&
           LOD_RESERVE(s, mark, np) && LOD_RESERVE(s, pass, np) && LOD_RESERVE(s, heap, np) && LOD_RESERVE(s, fan, nc) &&
           LOD_RESERVE(s, fan_b, nc) && LOD_RESERVE(s, wedges, in->vertex_count) &&
           LOD_RESERVE(s, wedges_b, in->vertex_count) &&
           LOD_RESERVE(s, choice, in->vertex_count) && LOD_RESERVE(s, costs, np) && LOD_RESERVE(s, slot, np) &&
           LOD_RESERVE(s, tri_slide, nc / 3 + 1);
}

/* The k-th smallest of n values (reordering them). */
static float select_kth(float *v, size_t n, size_t k)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        float pivot = v[lo + (hi - lo) / 2];
        size_t i = lo, j = hi;
        while (i <= j) {
            while (v[i] < pivot)
                i++;
            while (v[j] > pivot)
                j--;
            if (i <= j) {
                float t = v[i];
                v[i] = v[j], v[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return v[k];
    }
    return v[k];
}

#define PASS_ERROR_BOUND 1.5f
/* A pass moves positions up to PASS_ERROR_BOUND times the cost of the collapse that would, were
 * they all independent, reach the target: collapses spread over the group instead of piling onto
 * a few positions. */
static float pass_limit(lod_simplify_scratch *s, size_t needed)
{
    if (needed >= s->heap_count)
        return INFINITY;
    for (size_t i = 0; i < s->heap_count; i++)
        s->costs[i] = s->heap[i].cost;
    return select_kth(s->costs, s->heap_count, needed) * PASS_ERROR_BOUND;
}

/* Corner lists. A triangle with two corners at one position (degenerate by position) stays: it
 * closes the edges of its neighbours, and dropping it would open them. */
static void build_lists(run *r)
{
    lod_simplify_scratch *s = r->s;
    const lod_simplify_input *in = r->in;
    size_t nt = in->index_count / 3;
    memcpy(s->tri, in->indices, in->index_count * sizeof *s->tri);
    for (uint32_t p = 0; p < in->position_count; p++)
        s->head[p] = NONE, s->flags[p] = 0, s->mark[p] = 0, s->pass[p] = 0;
    s->token = 0;
    r->triangles = nt;
    for (size_t t = nt; t-- > 0;) {
        s->alive[t] = 1;
        for (uint32_t j = 0; j < 3; j++) {
            uint32_t c = (uint32_t)t * 3 + j, p = corner_position(r, c);
            s->next[c] = s->head[p];
            s->head[p] = c;
        }
    }
}

/* For every corner c (at position pa, the next corner of its triangle at pb), the entries of pa's
 * corner list whose triangle holds pb, into along[c]: how many triangles lie along the edge pa-pb as
 * build_quadrics counts them. One pass over each position's list counts every position its
 * triangles hold (a triangle once per entry), instead of a pass over the list per edge. */
static void count_along(run *r, uint32_t *along)
{
    lod_simplify_scratch *s = r->s;
    for (uint32_t pa = 0; pa < r->in->position_count; pa++) {
        uint32_t t = ++s->token;
        for (uint32_t c = s->head[pa]; c != NONE; c = s->next[c]) {
            uint32_t base = c - c % 3, q[3];
            for (uint32_t j = 0; j < 3; j++)
                q[j] = corner_position(r, base + j);
            for (uint32_t j = 0; j < 3; j++) {
                if ((j > 0 && q[j] == q[0]) || (j > 1 && q[j] == q[1]))
                    continue; /* a position the triangle holds twice counts once */
                if (s->mark[q[j]] != t) {
                    s->mark[q[j]] = t;
                    s->slot[q[j]] = 0;
                }
                s->slot[q[j]]++;
            }
        }
        for (uint32_t c = s->head[pa]; c != NONE; c = s->next[c])
            along[c] = s->slot[corner_position(r, corner_after(c, 1))];
    }
}

/* Area-weighted triangle planes, and for each open border edge (one triangle along it, or more than
 * two: a non-manifold edge) a plane through it perpendicular to its triangle. */
static void build_quadrics(run *r)
{
    lod_simplify_scratch *s = r->s;
    const lod_simplify_input *in = r->in;
    memset(s->quadric, 0, (size_t)in->position_count * QUADRIC_SIZE * sizeof *s->quadric);
    uint32_t *along_edge = s->fan; /* free until the first evaluation */
    count_along(r, along_edge);
    size_t nt = in->index_count / 3;
    for (size_t t = 0; t < nt; t++) {
        if (!s->alive[t])
            continue;
        double p[3][3], e1[3], e2[3], nrm[3];
        for (uint32_t j = 0; j < 3; j++)
            load(r, corner_position(r, (uint32_t)t * 3 + j), p[j]);
        sub(p[1], p[0], e1), sub(p[2], p[0], e2), cross(e1, e2, nrm);
        double len = sqrt(dot(nrm, nrm));
        if (len == 0.0)
            continue;
        for (int k = 0; k < 3; k++)
            nrm[k] /= len;
        for (uint32_t j = 0; j < 3; j++)
            quadric_add_plane(s->quadric + (size_t)corner_position(r, (uint32_t)t * 3 + j) * QUADRIC_SIZE, nrm,
                              -dot(nrm, p[0]), 0.5 * len);
        for (uint32_t j = 0; j < 3; j++) {
            uint32_t pa = corner_position(r, (uint32_t)t * 3 + j), pb = corner_position(r, (uint32_t)t * 3 + (j + 1) % 3);
            if (along_edge[t * 3 + j] == 2)
                continue;
            s->flags[pa] |= FLAG_BORDER;
            s->flags[pb] |= FLAG_BORDER;
            double e[3], m[3];
            sub(p[(j + 1) % 3], p[j], e);
            cross(e, nrm, m);
            double ml = sqrt(dot(m, m));
            if (ml == 0.0)
                continue;
            for (int k = 0; k < 3; k++)
                m[k] /= ml;
            double w = BORDER_WEIGHT * dot(e, e);
            quadric_add_plane(s->quadric + (size_t)pa * QUADRIC_SIZE, m, -dot(m, p[j]), w);
            quadric_add_plane(s->quadric + (size_t)pb * QUADRIC_SIZE, m, -dot(m, p[j]), w);
        }
    }
}

/* The largest texture slide of the output triangles: a triangle's is the largest slide a collapse
 * charged to it (moving one of its corners), but at most its longest edge. A slide confined to a
 * triangle changes at most the pixels the triangle covers, as a surface moved by the triangle's size
 * would: where a seam corner takes the uv of another chart its slide in mesh length can exceed the
 * model, while the texels it spoils lie within its triangles. A collapse's slide is measured against
 * the level it simplifies, as before (not summed over the collapses of a group: summed, it kept
 * WaterBottle at 34% of its triangles at 256 x 144 pixels instead of 27%, at the same image). */
static float output_slide(const run *r)
{
    float largest = 0.0f;
    size_t nt = r->in->index_count / 3;
    for (size_t t = 0; t < nt; t++) {
        if (!r->s->alive[t] || r->s->tri_slide[t] == 0.0f)
            continue;
        const uint32_t *w = r->s->tri + t * 3;
        float slide = r->s->tri_slide[t], edge2 = 0.0f;
        for (int k = 0; k < 3; k++) {
            double p[3], q[3], d[3];
            load(r, wedge_position(r, w[k]), p);
            load(r, wedge_position(r, w[(k + 1) % 3]), q);
            sub(p, q, d);
            edge2 = (float)dot(d, d) > edge2 ? (float)dot(d, d) : edge2;
        }
        float edge = sqrtf(edge2);
        slide = slide < edge ? slide : edge;
        largest = slide > largest ? slide : largest;
    }
    return largest;
}

int lod_simplify(lod_simplify_scratch *s, const lod_simplify_input *in, uint32_t *out, lod_simplify_result *res)
{
    *res = (lod_simplify_result){0};
    if (!reserve(s, in))
        return 0;
    run r = {.s = s, .in = in, .settled_a = NONE, .settled_b = NONE};
    build_lists(&r);
    build_quadrics(&r);
    memset(s->tri_slide, 0, (in->index_count / 3) * sizeof *s->tri_slide);
    s->heap_count = 0;
    r.pass = 1;
    uint32_t pass_start = UINT32_MAX;
    for (uint32_t p = 0; p < in->position_count; p++)
        queue(&r, p);
    size_t target = in->target_index_count / 3;
    float limit = r.triangles > target ? pass_limit(s, (r.triangles - target) / 2) : INFINITY;
    while (!r.failed) {
        if (s->heap_count && s->heap[0].cost > limit) { /* the pass is over */
            for (size_t i = 0; i < s->heap_count; i++)
                s->flags[s->heap[i].position] &= (uint8_t)~FLAG_QUEUED;
            s->heap_count = 0;
        }
        if (!s->heap_count) { /* a new pass: every position is evaluated again and may move */
            if (res->collapses == pass_start)
                break; /* the last pass moved nothing */
            pass_start = res->collapses;
            r.pass++;
            for (uint32_t p = 0; p < in->position_count; p++)
                if (!(s->flags[p] & FLAG_QUEUED))
                    queue(&r, p);
            if (!s->heap_count)
                break;
            limit = r.triangles > target ? pass_limit(s, (r.triangles - target) / 2) : INFINITY;
        }
        if (r.triangles <= target)
            break;
        lod_simplify_heap_item item = heap_pop(s);
        s->flags[item.position] &= (uint8_t)~FLAG_QUEUED;
        uint32_t b;
        double cost = best_collapse(&r, item.position, 1, &b);
        if (!(cost < INFINITY))
            continue; /* queued again when its neighbourhood changes */
        if (s->heap_count && (float)cost > s->heap[0].cost) {
            heap_push(s, (float)cost, item.position); /* dearer than it was: wait for its turn */
            s->flags[item.position] |= FLAG_QUEUED;
            continue;
        }
        collapse(&r, item.position, b);
        res->collapses++;
    }
    if (r.failed)
        return 0;
    size_t k = 0, nt = in->index_count / 3;
    for (size_t t = 0; t < nt; t++)
        if (s->alive[t])
            for (uint32_t j = 0; j < 3; j++)
                out[k++] = s->tri[t * 3 + j];
    res->index_count = k;
    res->slide = output_slide(&r);
    return 1;
}

void lod_simplify_scratch_free(lod_simplify_scratch *s)
{
    free(s->tri);
    free(s->next);
    free(s->alive);
    free(s->head);
    free(s->quadric);
    free(s->flags);
    free(s->mark);
    free(s->pass);
    free(s->heap);
    free(s->fan);
    free(s->fan_b);
    free(s->info);
    free(s->neighbours);
    free(s->near);
    free(s->wedges);
    free(s->wedges_b);
    free(s->choice);
    free(s->tri_slide);
    free(s->costs);
    free(s->geometry);
    free(s->exact);
    free(s->taken);
    free(s->edge_count);
    free(s->slot);
    memset(s, 0, sizeof *s);
}
