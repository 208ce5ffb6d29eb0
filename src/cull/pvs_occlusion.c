/* Conservative visibility from one point, for the precomputed-visibility bake.
 *
 * A cube map around the point p holds, per texel, a distance Z such that every ray from p through
 * the texel provably meets a surface no farther than Z (infinity where nothing is proven). An
 * object is hidden from p only when, on every cube face, every texel its bounds can project to
 * has Z strictly in front of the nearest point of its bounds. Anything not proven hidden is
 * visible. The proof (docs/CULLING.md, "Why the bake is conservative"):
 *
 *  - Occluders are fused per object and per layer: the layer of an object is its triangles that
 *    turn the same side towards p (orientation of (A-p, B-p, C-p), computed in double with a
 *    threshold; edge-on triangles belong to no layer). An edge is interior to the layer when
 *    exactly two triangles of the object share it, traversing it in opposite directions, and
 *    both are in the layer; any other edge of a layer triangle is a boundary edge.
 *  - Projected from p, a layer is an open map away from its boundary edges (both triangles at an
 *    interior edge lie on opposite sides of it, fans around interior vertices close up), so a
 *    texel that no projected boundary edge touches and whose centre lies in some layer triangle
 *    is covered entirely: every ray through it hits the layer.
 *  - Such a ray's hit is on a layer triangle whose projection overlaps the texel, and the depth
 *    of a plane over a texel is largest at one of its corners (1/depth is affine there), so the
 *    largest corner depth over the overlapping triangles (or their farthest vertex) bounds it.
 *  - Points of a triangle seen through a face have depth >= delta, because no triangle touches
 *    the cube of half-size delta about p (the caller checks it); triangles and edges are clipped
 *    at depth delta / 2, whose clip edges then project outside the face.
 *  - Float rounding: overlap, edge and range tests have margins far above double rounding; a
 *    centre wrongly found inside a triangle lies near an edge, which is either interior (the
 *    neighbour covers it) or a boundary edge, whose thickened raster then excludes the texel;
 *    the final depth comparison has a relative margin of 1e-4. An object's own layers cannot
 *    hide it: a texel they cover gets a bound at least the depth of some of its own points. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cull/cull_internal.h"

#define EDGE_NONE UINT32_MAX
#define DEPTH_MARGIN 1e-4 /* relative: hidden only when Z * (1 + margin) < the object's depth */

enum { TEXEL_COVERED = 1, TEXEL_EDGE = 2 };

struct pvs_view_scratch {
    uint32_t resolution;
    float *depth;       /* 6 * R * R: the cube, Z per texel */
    float *layer_depth; /* 6 * R * R: one layer's bound per texel, -1 where nothing overlaps */
    uint8_t *layer_flags;
    int8_t *facing;     /* per triangle of the current object: +1, -1, or 0 (edge-on) */
    struct object_order { double distance; uint32_t object; } *order; /* objects, nearest first */
    uint32_t order_capacity;
};

/* --- geometry: each object's triangles with their edge twins ------------------------------- */

typedef struct weld_key {
    uint32_t x, y, z, ref; /* position bits; ref = 3 * local triangle + corner */
} weld_key;

typedef struct edge_key {
    uint32_t a, b;  /* vertex ids, a < b */
    uint32_t ref;   /* 3 * local triangle + edge */
    uint32_t forward; /* the triangle goes a -> b */
} edge_key;

static int compare_weld(const void *pa, const void *pb)
{
    const weld_key *a = pa, *b = pb;
    if (a->x != b->x)
        return a->x < b->x ? -1 : 1;
    if (a->y != b->y)
        return a->y < b->y ? -1 : 1;
    if (a->z != b->z)
        return a->z < b->z ? -1 : 1;
    return a->ref < b->ref ? -1 : a->ref > b->ref;
}

static int compare_edge(const void *pa, const void *pb)
{
    const edge_key *a = pa, *b = pb;
    if (a->a != b->a)
        return a->a < b->a ? -1 : 1;
    if (a->b != b->b)
        return a->b < b->b ? -1 : 1;
    return a->ref < b->ref ? -1 : a->ref > b->ref;
}

static uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

/* Twins of the triangles [first, first + n): vertices are welded by exact position (what the
 * BVH sees); an edge gets a twin only when exactly two triangles share it in opposite
 * directions. */
static void find_twins(pvs_geometry *g, uint32_t first, uint32_t n, weld_key *welds, uint32_t *ids, edge_key *edges)
{
    for (uint32_t r = 0; r < 3 * n; r++) {
        gdr_vec3 c = g->corners[3 * (size_t)first + r];
        welds[r] = (weld_key){float_bits(c.x), float_bits(c.y), float_bits(c.z), r};
    }
    qsort(welds, 3 * (size_t)n, sizeof(weld_key), compare_weld);
    uint32_t id = 0;
    for (uint32_t r = 0; r < 3 * n; r++) {
        if (r && (welds[r].x != welds[r - 1].x || welds[r].y != welds[r - 1].y || welds[r].z != welds[r - 1].z))
            id++;
        ids[welds[r].ref] = id;
    }
    for (uint32_t t = 0; t < n; t++)
        for (uint32_t k = 0; k < 3; k++) {
            uint32_t from = ids[3 * t + k], to = ids[3 * t + (k + 1) % 3];
            edges[3 * t + k] = (edge_key){from < to ? from : to, from < to ? to : from, 3 * t + k, from < to};
        }
    qsort(edges, 3 * (size_t)n, sizeof(edge_key), compare_edge);
    for (uint32_t r = 0; r < 3 * n; r++)
        g->twin[3 * (size_t)first + r] = EDGE_NONE;
    for (uint32_t r = 0; r < 3 * n;) {
        uint32_t end = r + 1;
        while (end < 3 * n && edges[end].a == edges[r].a && edges[end].b == edges[r].b)
            end++;
        if (end - r == 2 && edges[r].forward != edges[r + 1].forward && edges[r].a != edges[r].b) {
            g->twin[3 * (size_t)first + edges[r].ref] = first + edges[r + 1].ref / 3;
            g->twin[3 * (size_t)first + edges[r + 1].ref] = first + edges[r].ref / 3;
        }
        r = end;
    }
}

gdr_status pvs_geometry_build(pvs_geometry *g, const gdr_bvh *bvh, uint32_t object_count, gdr_error *err)
{
    memset(g, 0, sizeof(*g));
    uint32_t tris = gdr_bvh_triangle_count(bvh);
    g->object_count = object_count;
    g->first = calloc((size_t)object_count + 2, sizeof(uint32_t));
    g->corners = malloc(3 * (size_t)(tris ? tris : 1) * sizeof(gdr_vec3));
    g->twin = malloc(3 * (size_t)(tris ? tris : 1) * sizeof(uint32_t));
    g->lo = malloc((size_t)(object_count ? object_count : 1) * sizeof(gdr_vec3));
    g->hi = malloc((size_t)(object_count ? object_count : 1) * sizeof(gdr_vec3));
    uint32_t *fill = calloc((size_t)object_count + 1, sizeof(uint32_t));
    if (!g->first || !g->corners || !g->twin || !g->lo || !g->hi || !fill) {
        free(fill);
        pvs_geometry_free(g);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "pvs bake: out of memory for %u triangles", tris);
    }
    /* A triangle whose edge cross product is exactly zero is never hit by a ray; every other
     * one counts, however small. */
    for (uint32_t t = 0; t < tris; t++) {
        gdr_vec3 c[3];
        uint32_t o;
        gdr_bvh_triangle(bvh, t, c, &o);
        gdr_vec3 n = gdr_vec3_cross(gdr_vec3_sub(c[1], c[0]), gdr_vec3_sub(c[2], c[0]));
        if (o < object_count && (n.x != 0.0f || n.y != 0.0f || n.z != 0.0f))
            g->first[o + 1]++;
    }
    for (uint32_t o = 0; o < object_count; o++) {
        g->first[o + 1] += g->first[o];
        uint32_t n = g->first[o + 1] - g->first[o];
        if (n > g->max_triangles)
            g->max_triangles = n;
    }
    for (uint32_t t = 0; t < tris; t++) {
        gdr_vec3 c[3];
        uint32_t o;
        gdr_bvh_triangle(bvh, t, c, &o);
        gdr_vec3 n = gdr_vec3_cross(gdr_vec3_sub(c[1], c[0]), gdr_vec3_sub(c[2], c[0]));
        if (o < object_count && (n.x != 0.0f || n.y != 0.0f || n.z != 0.0f))
            memcpy(&g->corners[3 * ((size_t)g->first[o] + fill[o]++)], c, sizeof(c));
    }
    free(fill);
    size_t scratch = 3 * (size_t)(g->max_triangles ? g->max_triangles : 1);
    weld_key *welds = malloc(scratch * sizeof(weld_key));
    uint32_t *ids = malloc(scratch * sizeof(uint32_t));
    edge_key *edges = malloc(scratch * sizeof(edge_key));
    if (!welds || !ids || !edges) {
        free(welds);
        free(ids);
        free(edges);
        pvs_geometry_free(g);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "pvs bake: out of memory for edge tables");
    }
    for (uint32_t o = 0; o < object_count; o++) {
        uint32_t first = g->first[o], n = g->first[o + 1] - first;
        gdr_vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t r = 3 * (size_t)first; r < 3 * ((size_t)first + n); r++) {
            gdr_vec3 c = g->corners[r];
            lo = (gdr_vec3){fminf(lo.x, c.x), fminf(lo.y, c.y), fminf(lo.z, c.z)};
            hi = (gdr_vec3){fmaxf(hi.x, c.x), fmaxf(hi.y, c.y), fmaxf(hi.z, c.z)};
        }
        g->lo[o] = lo;
        g->hi[o] = hi;
        if (n)
            find_twins(g, first, n, welds, ids, edges);
    }
    free(welds);
    free(ids);
    free(edges);
    return GDR_OK;
}

void pvs_geometry_free(pvs_geometry *g)
{
    free(g->first);
    free(g->corners);
    free(g->twin);
    free(g->lo);
    free(g->hi);
    memset(g, 0, sizeof(*g));
}

gdr_status pvs_view_scratch_create(uint32_t resolution, uint32_t max_triangles, uint32_t object_count,
                                   pvs_view_scratch **out, gdr_error *err)
{
    *out = NULL;
    size_t texels = 6 * (size_t)resolution * resolution;
    pvs_view_scratch *s = calloc(1, sizeof(*s));
    if (s) {
        s->resolution = resolution;
        s->depth = malloc(texels * sizeof(float));
        s->layer_depth = malloc(texels * sizeof(float));
        s->layer_flags = calloc(texels, 1);
        s->facing = malloc(max_triangles ? max_triangles : 1);
        s->order = malloc((object_count ? object_count : 1) * sizeof(*s->order));
    }
    if (!s || !s->depth || !s->layer_depth || !s->layer_flags || !s->facing || !s->order) {
        pvs_view_scratch_destroy(s);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "pvs bake: out of memory for a %u^2 depth cube",
                             resolution);
    }
    for (size_t i = 0; i < texels; i++)
        s->layer_depth[i] = -1.0f;
    *out = s;
    return GDR_OK;
}

void pvs_view_scratch_destroy(pvs_view_scratch *s)
{
    if (!s)
        return;
    free(s->depth);
    free(s->layer_depth);
    free(s->layer_flags);
    free(s->facing);
    free(s->order);
    free(s);
}

/* --- one cube face ---------------------------------------------------------------------------
 * Face f looks along axis a = f / 2, towards +a for even f and -a for odd f. A point q relative
 * to p has face coordinates (depth, b, c) = (s q[a], q[a + 1], q[a + 2]) and projects to
 * (u, v) = (b, c) / depth in [-1, 1]^2; texel (i, j) covers u in [-1 + i h, -1 + (i + 1) h],
 * v likewise with j, h = 2 / R. The ray through (u, v) is t (1, u, v): its depth is t. */

typedef struct face_point {
    double d, b, c;
} face_point;

static face_point to_face(int f, const double q[3])
{
    int a = f >> 1;
    double s = (f & 1) ? -1.0 : 1.0;
    return (face_point){s * q[a], q[(a + 1) % 3], q[(a + 2) % 3]};
}

static face_point lerp_point(face_point p, face_point q, double t)
{
    return (face_point){p.d + (q.d - p.d) * t, p.b + (q.b - p.b) * t, p.c + (q.c - p.c) * t};
}

/* A layer triangle as seen through one face: clipped at depth >= near, projected. */
typedef struct face_polygon {
    int count;
    double u[4], v[4];
    double n[3], num;  /* plane: the ray t (1, u, v) meets it at t = num / (n . (1, u, v)) */
    double max_depth;  /* of the clipped polygon */
    double orientation; /* sign of the projected polygon's area */
    double ulo, uhi, vlo, vhi;
    double ea[4], eb[4], ec[4], elen[4]; /* edge k: ea u + eb v + ec >= 0 inside; elen its length */
} face_polygon;

static bool make_polygon(const face_point in[3], double near, face_polygon *out)
{
    face_point pts[4];
    int count = 0;
    for (int k = 0; k < 3; k++) {
        face_point a = in[k], b = in[(k + 1) % 3];
        bool a_in = a.d >= near, b_in = b.d >= near;
        if (a_in)
            pts[count++] = a;
        if (a_in != b_in)
            pts[count++] = lerp_point(a, b, (near - a.d) / (b.d - a.d));
    }
    if (count < 3)
        return false;
    out->count = count;
    out->max_depth = 0.0;
    out->ulo = out->vlo = INFINITY;
    out->uhi = out->vhi = -INFINITY;
    for (int k = 0; k < count; k++) {
        out->u[k] = pts[k].b / pts[k].d;
        out->v[k] = pts[k].c / pts[k].d;
        out->max_depth = fmax(out->max_depth, pts[k].d);
        out->ulo = fmin(out->ulo, out->u[k]);
        out->uhi = fmax(out->uhi, out->u[k]);
        out->vlo = fmin(out->vlo, out->v[k]);
        out->vhi = fmax(out->vhi, out->v[k]);
    }
    double area = 0.0;
    for (int k = 0; k < count; k++) {
        int l = (k + 1) % count;
        area += out->u[k] * out->v[l] - out->u[l] * out->v[k];
    }
    if (!(area != 0.0) || !isfinite(area))
        return false;
    out->orientation = area > 0.0 ? 1.0 : -1.0;
    for (int k = 0; k < count; k++) {
        int l = (k + 1) % count;
        double du = out->u[l] - out->u[k], dv = out->v[l] - out->v[k];
        out->ea[k] = -out->orientation * dv;
        out->eb[k] = out->orientation * du;
        out->ec[k] = out->orientation * (dv * out->u[k] - du * out->v[k]);
        out->elen[k] = fabs(du) + fabs(dv);
    }
    face_point e1 = {in[1].d - in[0].d, in[1].b - in[0].b, in[1].c - in[0].c};
    face_point e2 = {in[2].d - in[0].d, in[2].b - in[0].b, in[2].c - in[0].c};
    out->n[0] = e1.b * e2.c - e1.c * e2.b;
    out->n[1] = e1.c * e2.d - e1.d * e2.c;
    out->n[2] = e1.d * e2.b - e1.b * e2.d;
    out->num = out->n[0] * in[0].d + out->n[1] * in[0].b + out->n[2] * in[0].c;
    return true;
}

/* Texel index range [lo, hi] touched by the interval [a, b] of u (or v), widened by margin;
 * false when it misses the face. */
static bool texel_range(double a, double b, double margin, uint32_t r, uint32_t *lo, uint32_t *hi)
{
    double h = 2.0 / (double)r;
    double fa = floor((a + 1.0 - margin) / h), fb = floor((b + 1.0 + margin) / h);
    if (!(fb >= 0.0) || !(fa <= (double)r - 1.0))
        return false;
    *lo = fa < 0.0 ? 0u : (uint32_t)fa;
    *hi = fb > (double)r - 1.0 ? r - 1u : (uint32_t)fb;
    return true;
}

/* False only when some polygon edge separates the square [u0, u1] x [v0, v1] by more than margin
 * (the square's own axes are handled by the caller's texel range): the edge function's largest
 * value over the square is at the corner its gradient points to. */
static bool polygon_overlaps(const face_polygon *p, double u0, double u1, double v0, double v1, double margin)
{
    for (int k = 0; k < p->count; k++) {
        double best = p->ea[k] * (p->ea[k] > 0.0 ? u1 : u0) + p->eb[k] * (p->eb[k] > 0.0 ? v1 : v0) + p->ec[k];
        if (best < -margin * p->elen[k])
            return false;
    }
    return true;
}

static bool polygon_contains(const face_polygon *p, double u, double v)
{
    for (int k = 0; k < p->count; k++)
        if (p->ea[k] * u + p->eb[k] * v + p->ec[k] < 0.0)
            return false;
    return true;
}

/* Upper bound of the depth of the polygon's points inside the texel's pyramid. Along the ray
 * through (u, v) the plane is at t = num / den(u, v), den affine: when den has num's sign at
 * every corner, the largest t is num over the corner value of den nearest zero. */
static double polygon_depth_bound(const face_polygon *p, double u0, double u1, double v0, double v1)
{
    double sign = p->num > 0.0 ? 1.0 : -1.0;
    double a = sign * p->n[1], b = sign * p->n[2];
    double least = sign * p->n[0] + a * (a > 0.0 ? u0 : u1) + b * (b > 0.0 ? v0 : v1);
    double t = fabs(p->num) / least;
    if (!(least > 0.0) || !(t < p->max_depth))
        return p->max_depth; /* the plane turns away inside the texel: the farthest vertex */
    return t;
}

typedef struct face_pass {
    pvs_view_scratch *s;
    int face;
    uint32_t r;
    double h, margin, near;
    uint32_t i0, i1, j0, j1; /* texels touched by this layer so far (i0 > i1: none) */
} face_pass;

static void touch(face_pass *fp, uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1)
{
    if (fp->i0 > fp->i1) {
        fp->i0 = i0, fp->i1 = i1, fp->j0 = j0, fp->j1 = j1;
        return;
    }
    fp->i0 = i0 < fp->i0 ? i0 : fp->i0;
    fp->i1 = i1 > fp->i1 ? i1 : fp->i1;
    fp->j0 = j0 < fp->j0 ? j0 : fp->j0;
    fp->j1 = j1 > fp->j1 ? j1 : fp->j1;
}

static void raster_polygon(face_pass *fp, const face_polygon *p)
{
    uint32_t i0, i1, j0, j1;
    if (!texel_range(p->ulo, p->uhi, fp->margin, fp->r, &i0, &i1) ||
        !texel_range(p->vlo, p->vhi, fp->margin, fp->r, &j0, &j1))
        return;
    touch(fp, i0, i1, j0, j1);
    size_t base = (size_t)fp->face * fp->r * fp->r;
    for (uint32_t j = j0; j <= j1; j++) {
        double v0 = -1.0 + j * fp->h, v1 = v0 + fp->h;
        for (uint32_t i = i0; i <= i1; i++) {
            double u0 = -1.0 + i * fp->h, u1 = u0 + fp->h;
            if (!polygon_overlaps(p, u0, u1, v0, v1, fp->margin))
                continue;
            size_t t = base + (size_t)j * fp->r + i;
            float bound = (float)polygon_depth_bound(p, u0, u1, v0, v1);
            if (bound > fp->s->layer_depth[t])
                fp->s->layer_depth[t] = bound;
            if (polygon_contains(p, 0.5 * (u0 + u1), 0.5 * (v0 + v1)))
                fp->s->layer_flags[t] |= TEXEL_COVERED;
        }
    }
}

/* Segment (pu, pv) -> (qu, qv) against the square grown by margin (Liang-Barsky). */
static bool segment_touches(double pu, double pv, double qu, double qv, double u0, double u1, double v0, double v1)
{
    double t0 = 0.0, t1 = 1.0;
    double d[2] = {qu - pu, qv - pv}, o[2] = {pu, pv}, lo[2] = {u0, v0}, hi[2] = {u1, v1};
    for (int k = 0; k < 2; k++) {
        if (d[k] == 0.0) {
            if (o[k] < lo[k] || o[k] > hi[k])
                return false;
            continue;
        }
        double ta = (lo[k] - o[k]) / d[k], tb = (hi[k] - o[k]) / d[k];
        if (ta > tb) {
            double tt = ta;
            ta = tb;
            tb = tt;
        }
        t0 = fmax(t0, ta);
        t1 = fmin(t1, tb);
        if (t0 > t1)
            return false;
    }
    return true;
}

static void raster_edge(face_pass *fp, face_point a, face_point b)
{
    if (a.d < fp->near && b.d < fp->near)
        return;
    if (a.d < fp->near)
        a = lerp_point(a, b, (fp->near - a.d) / (b.d - a.d));
    else if (b.d < fp->near)
        b = lerp_point(b, a, (fp->near - b.d) / (a.d - b.d));
    double pu = a.b / a.d, pv = a.c / a.d, qu = b.b / b.d, qv = b.c / b.d;
    uint32_t i0, i1, j0, j1;
    if (!texel_range(fmin(pu, qu), fmax(pu, qu), fp->margin, fp->r, &i0, &i1) ||
        !texel_range(fmin(pv, qv), fmax(pv, qv), fp->margin, fp->r, &j0, &j1))
        return;
    touch(fp, i0, i1, j0, j1);
    size_t base = (size_t)fp->face * fp->r * fp->r;
    double m = fp->margin;
    for (uint32_t j = j0; j <= j1; j++) {
        double v0 = -1.0 + j * fp->h, v1 = v0 + fp->h;
        for (uint32_t i = i0; i <= i1; i++) {
            double u0 = -1.0 + i * fp->h, u1 = u0 + fp->h;
            if (segment_touches(pu, pv, qu, qv, u0 - m, u1 + m, v0 - m, v1 + m))
                fp->s->layer_flags[base + (size_t)j * fp->r + i] |= TEXEL_EDGE;
        }
    }
}

/* Texels the layer covers without a boundary edge get min(Z, bound); the scratch is cleared. */
static void merge_layer(face_pass *fp)
{
    if (fp->i0 > fp->i1)
        return;
    pvs_view_scratch *s = fp->s;
    size_t base = (size_t)fp->face * fp->r * fp->r;
    for (uint32_t j = fp->j0; j <= fp->j1; j++)
        for (uint32_t i = fp->i0; i <= fp->i1; i++) {
            size_t t = base + (size_t)j * fp->r + i;
            if (s->layer_flags[t] == TEXEL_COVERED && s->layer_depth[t] > 0.0f && s->layer_depth[t] < s->depth[t])
                s->depth[t] = s->layer_depth[t];
            s->layer_flags[t] = 0;
            s->layer_depth[t] = -1.0f;
        }
}

/* The part of the object's bounds (relative to p) seen through face f: its least depth (at
 * least near) and the (u, v) rectangle it projects into; false when none of it is seen. */
static bool bounds_on_face(const double lo[3], const double hi[3], int f, double near, double *dmin, double *ulo,
                           double *uhi, double *vlo, double *vhi)
{
    int a = f >> 1, a1 = (a + 1) % 3, a2 = (a + 2) % 3;
    double d0 = (f & 1) ? -hi[a] : lo[a], d1 = (f & 1) ? -lo[a] : hi[a];
    d0 = fmax(d0, near);
    if (d1 < d0)
        return false;
    *ulo = fmin(lo[a1] / d0, lo[a1] / d1);
    *uhi = fmax(hi[a1] / d0, hi[a1] / d1);
    *vlo = fmin(lo[a2] / d0, lo[a2] / d1);
    *vhi = fmax(hi[a2] / d0, hi[a2] / d1);
    *dmin = d0;
    return *uhi >= -1.0 && *ulo <= 1.0 && *vhi >= -1.0 && *vlo <= 1.0;
}

static void relative_bounds(const pvs_geometry *g, uint32_t o, gdr_vec3 p, double lo[3], double hi[3])
{
    lo[0] = (double)g->lo[o].x - p.x, lo[1] = (double)g->lo[o].y - p.y, lo[2] = (double)g->lo[o].z - p.z;
    hi[0] = (double)g->hi[o].x - p.x, hi[1] = (double)g->hi[o].y - p.y, hi[2] = (double)g->hi[o].z - p.z;
}

/* True when some texel of the rectangle holds a bound beyond depth. */
static bool reaches_beyond(const pvs_view_scratch *s, int f, double ulo, double uhi, double vlo, double vhi,
                           double depth)
{
    uint32_t r = s->resolution, i0, i1, j0, j1;
    double margin = 1e-4 * 2.0 / r; /* the rasteriser's: every texel it could touch is looked at */
    if (!texel_range(ulo, uhi, margin, r, &i0, &i1) || !texel_range(vlo, vhi, margin, r, &j0, &j1))
        return false;
    const float *z = s->depth + (size_t)f * r * r;
    for (uint32_t j = j0; j <= j1; j++)
        for (uint32_t i = i0; i <= i1; i++)
            if ((double)z[(size_t)j * r + i] > depth)
                return true;
    return false;
}

static void rasterise_object(const pvs_geometry *g, pvs_view_scratch *s, uint32_t o, gdr_vec3 p, double near)
{
    uint32_t first = g->first[o], n = g->first[o + 1] - first;
    double lo[3], hi[3];
    relative_bounds(g, o, p, lo, hi);
    /* Layers: the sign of det(A - p, B - p, C - p); near zero (edge-on) is in neither. */
    for (uint32_t t = 0; t < n; t++) {
        const gdr_vec3 *c = &g->corners[3 * ((size_t)first + t)];
        double q[3][3];
        for (int k = 0; k < 3; k++)
            q[k][0] = (double)c[k].x - p.x, q[k][1] = (double)c[k].y - p.y, q[k][2] = (double)c[k].z - p.z;
        double cx = q[1][1] * q[2][2] - q[1][2] * q[2][1], cy = q[1][2] * q[2][0] - q[1][0] * q[2][2],
               cz = q[1][0] * q[2][1] - q[1][1] * q[2][0];
        double det = q[0][0] * cx + q[0][1] * cy + q[0][2] * cz;
        double scale = sqrt(q[0][0] * q[0][0] + q[0][1] * q[0][1] + q[0][2] * q[0][2]) *
                       sqrt(q[1][0] * q[1][0] + q[1][1] * q[1][1] + q[1][2] * q[1][2]) *
                       sqrt(q[2][0] * q[2][0] + q[2][1] * q[2][1] + q[2][2] * q[2][2]);
        s->facing[t] = det > 1e-9 * scale ? 1 : det < -1e-9 * scale ? -1 : 0;
    }
    uint32_t r = s->resolution;
    double h = 2.0 / (double)r;
    for (int f = 0; f < 6; f++) {
        double dmin, ulo, uhi, vlo, vhi;
        if (!bounds_on_face(lo, hi, f, near, &dmin, &ulo, &uhi, &vlo, &vhi))
            continue;
        /* it can cover a texel only if its projection holds a whole one */
        if (floor((fmin(uhi, 1.0) + 1.0) / h) - ceil((fmax(ulo, -1.0) + 1.0) / h) < 1.0 ||
            floor((fmin(vhi, 1.0) + 1.0) / h) - ceil((fmax(vlo, -1.0) + 1.0) / h) < 1.0)
            continue;
        /* A texel it covers gets a bound no nearer than dmin (some point of the object lies at its
         * centre), so where every texel it can reach is already at dmin or nearer it changes
         * nothing: skipping it keeps the result exact, and front-to-back order makes it common. */
        if (!reaches_beyond(s, f, ulo, uhi, vlo, vhi, dmin))
            continue;
        for (int layer = 1; layer >= -1; layer -= 2) {
            face_pass fp = {s, f, r, h, 1e-4 * h, near, 1, 0, 1, 0};
            for (uint32_t t = 0; t < n; t++) {
                if (s->facing[t] != layer)
                    continue;
                const gdr_vec3 *c = &g->corners[3 * ((size_t)first + t)];
                face_point fpts[3];
                for (int k = 0; k < 3; k++) {
                    double q[3] = {(double)c[k].x - p.x, (double)c[k].y - p.y, (double)c[k].z - p.z};
                    fpts[k] = to_face(f, q);
                }
                face_polygon poly;
                bool drawn = make_polygon(fpts, near, &poly);
                if (drawn)
                    raster_polygon(&fp, &poly);
                /* A triangle left out (behind the near plane, or degenerate in projection) makes
                 * all its edges boundaries of what was drawn. */
                for (int k = 0; k < 3; k++) {
                    uint32_t twin = g->twin[3 * ((size_t)first + t) + (size_t)k];
                    if (!drawn || twin == EDGE_NONE || s->facing[twin - first] != layer)
                        raster_edge(&fp, fpts[k], fpts[(k + 1) % 3]);
                }
            }
            merge_layer(&fp);
        }
    }
}

/* True when every texel the object's bounds reach, on every face, is proven nearer. */
static bool object_hidden(const pvs_geometry *g, const pvs_view_scratch *s, uint32_t o, gdr_vec3 p, double near)
{
    double lo[3], hi[3];
    relative_bounds(g, o, p, lo, hi);
    uint32_t r = s->resolution;
    for (int f = 0; f < 6; f++) {
        double dmin, ulo, uhi, vlo, vhi;
        uint32_t i0, i1, j0, j1;
        if (!bounds_on_face(lo, hi, f, near, &dmin, &ulo, &uhi, &vlo, &vhi) ||
            !texel_range(ulo, uhi, 1e-4 * 2.0 / r, r, &i0, &i1) || !texel_range(vlo, vhi, 1e-4 * 2.0 / r, r, &j0, &j1))
            continue;
        const float *depth = s->depth + (size_t)f * r * r;
        for (uint32_t j = j0; j <= j1; j++)
            for (uint32_t i = i0; i <= i1; i++)
                if (!((double)depth[(size_t)j * r + i] * (1.0 + DEPTH_MARGIN) < dmin))
                    return false;
    }
    return true;
}

static int compare_order(const void *pa, const void *pb)
{
    const struct object_order *a = pa, *b = pb;
    if (a->distance != b->distance)
        return a->distance < b->distance ? -1 : 1;
    return a->object < b->object ? -1 : a->object > b->object;
}

uint64_t pvs_visible_from_point(const pvs_geometry *g, pvs_view_scratch *s, gdr_vec3 p, float delta, uint32_t *bits)
{
    size_t texels = 6 * (size_t)s->resolution * s->resolution;
    for (size_t i = 0; i < texels; i++)
        s->depth[i] = INFINITY;
    double near = 0.5 * (double)delta;
    uint32_t count = 0;
    for (uint32_t o = 0; o < g->object_count; o++) {
        if (g->first[o + 1] == g->first[o])
            continue;
        double lo[3], hi[3], d2 = 0.0;
        relative_bounds(g, o, p, lo, hi);
        for (int a = 0; a < 3; a++) {
            double d = lo[a] > 0.0 ? lo[a] : hi[a] < 0.0 ? -hi[a] : 0.0;
            d2 += d * d;
        }
        s->order[count++] = (struct object_order){d2, o};
    }
    qsort(s->order, count, sizeof(*s->order), compare_order);
    for (uint32_t k = 0; k < count; k++)
        rasterise_object(g, s, s->order[k].object, p, near);
    uint64_t decided = 0;
    for (uint32_t o = 0; o < g->object_count; o++) {
        if (g->first[o + 1] == g->first[o] || gdr_cull_bit(bits, o))
            continue;
        decided++;
        if (!object_hidden(g, s, o, p, near))
            bits[o >> 5] |= 1u << (o & 31u);
    }
    return decided;
}
