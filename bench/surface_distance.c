/* Point-to-surface distances on a uniform grid of triangles (surface_distance.h). */
#include "surface_distance.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GRID_MAX_CELLS (1u << 23)

struct triangle_grid {
    surface s;
    double lo[3], cell;
    int dim[3];
    uint32_t *start, *items; /* cell c: items[start[c] .. start[c + 1]) */
};

typedef struct dvec {
    double x, y, z;
} dvec;

static dvec dv(gdr_vec3 v) { return (dvec){v.x, v.y, v.z}; }
static dvec sub(dvec a, dvec b) { return (dvec){a.x - b.x, a.y - b.y, a.z - b.z}; }
static double dot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dvec mad(dvec a, dvec b, double t) { return (dvec){a.x + b.x * t, a.y + b.y * t, a.z + b.z * t}; }

/* Squared distance from p to triangle abc (closest point by Voronoi region, in double); the
 * closest point in *closest where not NULL. */
static double point_triangle_closest(dvec p, dvec a, dvec b, dvec c, dvec *closest)
{
    dvec ab = sub(b, a), ac = sub(c, a), ap = sub(p, a), q;
    double d1 = dot(ab, ap), d2 = dot(ac, ap);
    dvec bp = sub(p, b), cp = sub(p, c);
    double d3 = dot(ab, bp), d4 = dot(ac, bp), d5 = dot(ab, cp), d6 = dot(ac, cp);
    double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
    if (d1 <= 0 && d2 <= 0)
        q = a;
    else if (d3 >= 0 && d4 <= d3)
        q = b;
    else if (d6 >= 0 && d5 <= d6)
        q = c;
    else if (vc <= 0 && d1 >= 0 && d3 <= 0)
        q = mad(a, ab, d1 / (d1 - d3));
    else if (vb <= 0 && d2 >= 0 && d6 <= 0)
        q = mad(a, ac, d2 / (d2 - d6));
    else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
        q = mad(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    else {
        double den = va + vb + vc;
        q = den > 0 ? mad(mad(a, ab, vb / den), ac, vc / den) : a;
    }
    dvec d = sub(p, q);
    if (closest)
        *closest = q;
    return dot(d, d);
}

static double point_triangle_d2(dvec p, dvec a, dvec b, dvec c) { return point_triangle_closest(p, a, b, c, NULL); }

static int cell_of(const triangle_grid *g, double x, int k)
{
    double c = (x - g->lo[k]) / g->cell;
    if (!(c > 0))
        return 0;
    return c >= g->dim[k] - 1 ? g->dim[k] - 1 : (int)c;
}

static void triangle_cells(const triangle_grid *g, size_t t, int lo[3], int hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = INT32_MAX;
        hi[k] = 0;
    }
    for (int j = 0; j < 3; j++) {
        const float *p = &g->s.positions[g->s.indices[3 * t + j]].x;
        for (int k = 0; k < 3; k++) {
            int c = cell_of(g, p[k], k);
            lo[k] = c < lo[k] ? c : lo[k];
            hi[k] = c > hi[k] ? c : hi[k];
        }
    }
}

/* Cell edge: about two triangles' edge lengths, at most GRID_MAX_CELLS cells. */
static void choose_grid(triangle_grid *g)
{
    double hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    g->lo[0] = g->lo[1] = g->lo[2] = DBL_MAX;
    for (size_t i = 0; i < g->s.triangle_count * 3; i++) {
        const float *p = &g->s.positions[g->s.indices[i]].x;
        for (int k = 0; k < 3; k++) {
            g->lo[k] = p[k] < g->lo[k] ? p[k] : g->lo[k];
            hi[k] = p[k] > hi[k] ? p[k] : hi[k];
        }
    }
    double area = surface_area(g->s);
    g->cell = 2.0 * sqrt(area / (double)(g->s.triangle_count + 1)) + 1e-30;
    for (;;) {
        double cells = 1;
        for (int k = 0; k < 3; k++)
            cells *= floor((hi[k] - g->lo[k]) / g->cell) + 1;
        if (cells <= GRID_MAX_CELLS)
            break;
        g->cell *= 1.25;
    }
    for (int k = 0; k < 3; k++)
        g->dim[k] = (int)floor((hi[k] - g->lo[k]) / g->cell) + 1;
}

triangle_grid *triangle_grid_create(surface s)
{
    triangle_grid *g = calloc(1, sizeof *g);
    g->s = s;
    choose_grid(g);
    size_t cells = (size_t)g->dim[0] * g->dim[1] * g->dim[2];
    g->start = calloc(cells + 1, sizeof *g->start);
    size_t total = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t t = 0; t < s.triangle_count; t++) {
            int lo[3], hi[3];
            triangle_cells(g, t, lo, hi);
            for (int z = lo[2]; z <= hi[2]; z++)
                for (int y = lo[1]; y <= hi[1]; y++)
                    for (int x = lo[0]; x <= hi[0]; x++) {
                        size_t c = ((size_t)z * g->dim[1] + y) * g->dim[0] + x;
                        if (pass == 0)
                            g->start[c + 1]++;
                        else
                            g->items[g->start[c]++] = (uint32_t)t;
                    }
        }
        if (pass == 0) {
            for (size_t c = 0; c < cells; c++)
                g->start[c + 1] += g->start[c];
            total = g->start[cells];
            g->items = malloc((total + 1) * sizeof *g->items);
        }
    }
    for (size_t c = cells; c > 0; c--)
        g->start[c] = g->start[c - 1];
    g->start[0] = 0;
    if (!g->items) {
        fprintf(stderr, "surface_distance: out of memory\n");
        exit(1);
    }
    return g;
}

void triangle_grid_destroy(triangle_grid *g)
{
    if (!g)
        return;
    free(g->start);
    free(g->items);
    free(g);
}

static void visit(const triangle_grid *g, int x, int y, int z, dvec p, double *best, uint32_t *nearest)
{
    size_t c = ((size_t)z * g->dim[1] + y) * g->dim[0] + x;
    for (uint32_t i = g->start[c]; i < g->start[c + 1]; i++) {
        const uint32_t *t = g->s.indices + (size_t)g->items[i] * 3;
        double d = point_triangle_d2(p, dv(g->s.positions[t[0]]), dv(g->s.positions[t[1]]), dv(g->s.positions[t[2]]));
        if (d < *best) {
            *best = d;
            *nearest = g->items[i];
        }
    }
}

/* The barycentric coordinates of triangle t's point nearest to p. */
static void closest_barycentric(const triangle_grid *g, uint32_t t, dvec p, double w[3])
{
    const uint32_t *i = g->s.indices + (size_t)t * 3;
    dvec a = dv(g->s.positions[i[0]]), b = dv(g->s.positions[i[1]]), c = dv(g->s.positions[i[2]]), q;
    point_triangle_closest(p, a, b, c, &q);
    dvec v0 = sub(b, a), v1 = sub(c, a), v2 = sub(q, a);
    double d00 = dot(v0, v0), d01 = dot(v0, v1), d11 = dot(v1, v1), d20 = dot(v2, v0), d21 = dot(v2, v1);
    double den = d00 * d11 - d01 * d01;
    w[1] = den > 0 ? (d11 * d20 - d01 * d21) / den : 0;
    w[2] = den > 0 ? (d00 * d21 - d01 * d20) / den : 0;
    w[0] = 1 - w[1] - w[2];
}

double triangle_grid_distance(const triangle_grid *g, gdr_vec3 point)
{
    uint32_t nearest;
    double d = triangle_grid_nearest(g, point, &nearest, NULL);
    return d;
}

/* Shells of cells around p's cell, until the next shell cannot hold anything nearer. */
double triangle_grid_nearest(const triangle_grid *g, gdr_vec3 point, uint32_t *nearest, double barycentric[3])
{
    dvec p = dv(point);
    const double q[3] = {p.x, p.y, p.z};
    int at[3];
    for (int k = 0; k < 3; k++)
        at[k] = cell_of(g, q[k], k);
    /* A point outside the grid: the distance to the grid's box adds to every shell's reach. */
    double outside = 0;
    for (int k = 0; k < 3; k++) {
        double below = g->lo[k] - q[k], above = q[k] - (g->lo[k] + g->dim[k] * g->cell);
        double o = below > 0 ? below : above > 0 ? above : 0;
        outside = o > outside ? o : outside;
    }
    int max_r = g->dim[0] > g->dim[1] ? g->dim[0] : g->dim[1];
    max_r = g->dim[2] > max_r ? g->dim[2] : max_r;
    double best = INFINITY;
    *nearest = UINT32_MAX;
    for (int r = 0; r <= max_r; r++) {
        double reach = (r - 1) * g->cell + outside;
        if (r > 0 && best < INFINITY && reach > 0 && reach * reach >= best)
            break;
        for (int z = at[2] - r; z <= at[2] + r; z++) {
            if (z < 0 || z >= g->dim[2])
                continue;
            for (int y = at[1] - r; y <= at[1] + r; y++) {
                if (y < 0 || y >= g->dim[1])
                    continue;
                int shell = r == 0 || z == at[2] - r || z == at[2] + r || y == at[1] - r || y == at[1] + r;
                for (int x = at[0] - r; x <= at[0] + r; x += shell ? 1 : 2 * r)
                    if (x >= 0 && x < g->dim[0])
                        visit(g, x, y, z, p, &best, nearest);
            }
        }
    }
    if (barycentric && *nearest != UINT32_MAX)
        closest_barycentric(g, *nearest, p, barycentric);
    return sqrt(best);
}

double surface_area(surface s)
{
    double area = 0;
    for (size_t t = 0; t < s.triangle_count; t++) {
        dvec a = dv(s.positions[s.indices[3 * t]]), b = dv(s.positions[s.indices[3 * t + 1]]),
             c = dv(s.positions[s.indices[3 * t + 2]]);
        dvec u = sub(b, a), v = sub(c, a);
        dvec n = {u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
        area += 0.5 * sqrt(dot(n, n));
    }
    return area;
}

/* Samples of one triangle: a barycentric grid of about `spacing` (corners and edge midpoints
 * included; at most 8 steps an edge) and the centroid; a triangle smaller than that gives its centroid only (its corners
 * are sampled once per vertex by the caller). */
static double sample_triangle(dvec a, dvec b, dvec c, const triangle_grid *to, double spacing)
{
    double longest = sqrt(fmax(dot(sub(b, a), sub(b, a)), fmax(dot(sub(c, a), sub(c, a)), dot(sub(c, b), sub(c, b)))));
    int n = (int)ceil(longest / spacing);
    n = n > 8 ? 8 : n;
    double worst = 0;
    for (int i = 0; n >= 2 && i <= n; i++)
        for (int j = 0; i + j <= n; j++) {
            double u = (double)i / n, v = (double)j / n;
            dvec p = mad(mad(a, sub(b, a), u), sub(c, a), v);
            double d = triangle_grid_distance(to, (gdr_vec3){(float)p.x, (float)p.y, (float)p.z});
            worst = d > worst ? d : worst;
        }
    dvec centroid = {(a.x + b.x + c.x) / 3, (a.y + b.y + c.y) / 3, (a.z + b.z + c.z) / 3};
    double d = triangle_grid_distance(to, (gdr_vec3){(float)centroid.x, (float)centroid.y, (float)centroid.z});
    return d > worst ? d : worst;
}

double surface_one_sided(surface from, const triangle_grid *to, double spacing)
{
    double worst = 0;
    uint8_t *seen = calloc(from.vertex_count + 1, 1);
    for (size_t t = 0; t < from.triangle_count; t++) {
        const uint32_t *i = from.indices + 3 * t;
        double d = sample_triangle(dv(from.positions[i[0]]), dv(from.positions[i[1]]), dv(from.positions[i[2]]), to,
                                   spacing);
        worst = d > worst ? d : worst;
        for (int k = 0; k < 3; k++)
            if (!seen[i[k]]) {
                seen[i[k]] = 1;
                d = triangle_grid_distance(to, from.positions[i[k]]);
                worst = d > worst ? d : worst;
            }
    }
    free(seen);
    return worst;
}
