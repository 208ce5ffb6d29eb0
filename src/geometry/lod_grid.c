/* A uniform grid over a point set for nearest-point queries (lod_grid.h). */
#include "geometry/lod_grid.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define GRID_MAX_DIM 1024
_Static_assert(GRID_MAX_DIM <= 65536, "a kept run holds cell coordinates in 16 bits");
#define GRID_MIN_CELLS 32768.0

static int grid_reserve(uint32_t **p, size_t *cap, size_t need)
{
    if (need <= *cap)
        return 1;
    size_t n = *cap ? *cap : 64;
    while (n < need)
        n *= 2;
    uint32_t *q = realloc(*p, n * sizeof *q);
    if (!q)
        return 0;
    *p = q;
    *cap = n;
    return 1;
}

static uint32_t cell_coordinate(const lod_grid *g, float x, int k)
{
    float c = (x - g->lo[k]) * g->inv_cell;
    if (!(c > 0.0f))
        return 0;
    return c >= g->top[k] ? g->dim[k] - 1 : (uint32_t)c;
}

/* The points lie on a surface: about two per occupied cell when the cell edge is about twice the
 * largest extent over the square root of the count (a sphere's or a square's spacing). Triangles
 * pass their mean edge scale (`spacing`: the mean square root of their areas), taken instead when
 * smaller: a strip or a curved band has far less area than its largest extent squared, and cells
 * sized by the extent would hold a hundred of its triangles. At most max_cells cells in all (larger
 * cells for the groups that span most of a mesh). */
static void choose_cells(lod_grid *g, const float hi[3], uint32_t n, double spacing, double min_cell,
                         double max_cells)
{
    float extent[3], largest = 0.0f;
    for (int k = 0; k < 3; k++) {
        extent[k] = hi[k] - g->lo[k];
        largest = extent[k] > largest ? extent[k] : largest;
    }
    float cell = 2.0f * largest / sqrtf((float)n + 1.0f), by_spacing = (float)(2.0 * spacing);
    if (by_spacing > 0.0f && by_spacing < cell)
        cell = by_spacing;
    if (cell < (float)min_cell)
        cell = (float)min_cell;
    if (!(cell > 0.0f))
        cell = 1.0f;
    for (int attempt = 0; attempt < 64; attempt++) {
        double cells = 1.0;
        for (int k = 0; k < 3; k++)
            cells *= fmin(floor(extent[k] / cell) + 1.0, GRID_MAX_DIM);
        if (cells <= max_cells)
            break;
        cell *= 1.25f;
    }
    for (int k = 0; k < 3; k++) {
        double d = floor(extent[k] / cell) + 1.0;
        g->dim[k] = d > GRID_MAX_DIM ? GRID_MAX_DIM : (uint32_t)d;
    }
    /* A capped axis: cells stretch along it; the search bound uses the largest cell edge. */
    for (int k = 0; k < 3; k++)
        if (extent[k] / (float)g->dim[k] > cell)
            cell = extent[k] / (float)g->dim[k] * 1.0001f;
    g->cell = cell;
    g->inv_cell = 1.0f / cell;
    for (int k = 0; k < 3; k++)
        g->top[k] = (float)(g->dim[k] - 1);
}

static uint32_t point_cell(const lod_grid *g, gdr_vec3 p)
{
    return (cell_coordinate(g, p.z, 2) * g->dim[1] + cell_coordinate(g, p.y, 1)) * g->dim[0] +
           cell_coordinate(g, p.x, 0);
}

/* Cells sized for a surface hold a few points each. Points on a curve (a fan's rim, a strip's
 * edge) fill the cells it crosses with about the square root of their count each, and no grid of
 * O(n) cells over their box does better: a query would cost O(sqrt n). Past this mean number of
 * points in a point's own cell (summed over the points: the sum of the squared cell counts), a k-d
 * tree answers instead; sound surfaces stay below 5, and the constant keeps small grids, whose
 * queries are cheap whatever their cells, on the grid. Both give the exact nearest point, so only
 * the cost depends on the choice. */
#define GRID_CROWDED_MEAN 16.0
#define GRID_CROWDED_FLOOR 4096.0

static int crowded(const lod_grid *g, size_t cells, uint32_t n)
{
    double sum = 0.0;
    for (size_t c = 0; c < cells; c++)
        sum += (double)g->start[c + 1] * (double)g->start[c + 1];
    return sum > GRID_CROWDED_MEAN * n + GRID_CROWDED_FLOOR;
}

int lod_grid_build(lod_grid *g, const gdr_vec3 *points, uint32_t n, double cells_per_point)
{
    g->points = points;
    g->count = n;
    float hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    g->lo[0] = g->lo[1] = g->lo[2] = FLT_MAX;
    for (uint32_t i = 0; i < n; i++) {
        const float *p = &points[i].x;
        for (int k = 0; k < 3; k++) {
            g->lo[k] = p[k] < g->lo[k] ? p[k] : g->lo[k];
            hi[k] = p[k] > hi[k] ? p[k] : hi[k];
        }
    }
    choose_cells(g, hi, n, 0.0, 0.0, cells_per_point * n + 64.0);
    size_t cells = (size_t)g->dim[0] * g->dim[1] * g->dim[2];
    if (!grid_reserve(&g->start, &g->start_cap, cells + 1) || !grid_reserve(&g->items, &g->items_cap, n))
        return 0;
    memset(g->start, 0, (cells + 1) * sizeof *g->start);
    /* Each point's cell is found twice (to count, then to store) rather than kept: 4 bytes a point
     * less, and a group near the DAG's root indexes most of the mesh's positions. */
    for (uint32_t i = 0; i < n; i++)
        g->start[point_cell(g, points[i]) + 1]++;
    g->use_tree = crowded(g, cells, n);
    if (g->use_tree)
        return lod_point_tree_build(&g->tree, points, n);
    for (size_t c = 0; c < cells; c++)
        g->start[c + 1] += g->start[c];
    for (uint32_t i = 0; i < n; i++)
        g->items[g->start[point_cell(g, points[i])]++] = i;
    for (size_t c = cells; c > 0; c--) /* start[c] now holds the end of cell c: shift back */
        g->start[c] = g->start[c - 1];
    g->start[0] = 0;
    return 1;
}

/* The nearest of the points listed in cells first .. last - 1 (cell indices, consecutive along x:
 * their lists lie one after another) into best; ties: the lowest index. */
static void visit_cells(const lod_grid *g, size_t first, size_t last, const float q[3], uint32_t *best,
                        float *best_d2)
{
    uint32_t found = *best;
    float found_d2 = *best_d2; /* in locals: through the pointers, every store would be reloaded */
    for (uint32_t i = g->start[first], end = g->start[last]; i < end; i++) {
        uint32_t item = g->items[i];
        const gdr_vec3 p = g->points[item];
        float dx = p.x - q[0], dy = p.y - q[1], dz = p.z - q[2];
        float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < found_d2 || (d2 == found_d2 && item < found)) {
            found_d2 = d2;
            found = item;
        }
    }
    *best = found;
    *best_d2 = found_d2;
}

static void visit_cell(const lod_grid *g, uint32_t x, uint32_t y, uint32_t z, const float q[3], uint32_t *best,
                       float *best_d2)
{
    size_t c = ((size_t)z * g->dim[1] + y) * g->dim[0] + x;
    visit_cells(g, c, c + 1, q, best, best_d2);
}

/* Distance from q to the nearest cell the search has not reached once every cell within Chebyshev
 * distance r of cell `at` is searched: to the nearest face of that block of cells beyond which the
 * grid has more cells (at least r cell edges, up to r + 1). INFINITY when none is left. */
static float unsearched_reach(const float lo[3], float cell, const uint32_t dim[3], const int32_t at[3], int32_t r,
                              const float q[3])
{
    float reach = INFINITY;
    for (int k = 0; k < 3; k++) {
        /* (not fminf: a library call at -O3; the same result, NaN included) */
        if (at[k] - r > 0) {
            float d = q[k] - (lo[k] + (float)(at[k] - r) * cell);
            reach = d < reach ? d : reach;
        }
        if (at[k] + r + 1 < (int32_t)dim[k]) {
            float d = lo[k] + (float)(at[k] + r + 1) * cell - q[k];
            reach = d < reach ? d : reach;
        }
    }
    return reach > 0.0f ? reach : 0.0f; /* rounding may put q just outside its cell */
}

/* The search has found best_d2 and reached every cell within Chebyshev distance r: done when no
 * cell left can hold anything nearer. */
static int search_done(const float lo[3], float cell, const uint32_t dim[3], const int32_t at[3], int32_t r,
                       const float q[3], float best_d2)
{
    float reach = unsearched_reach(lo, cell, dim, at, r, q);
    return reach == INFINITY || reach * reach >= best_d2;
}

/* The cells along axis k within `reach` of q[k], clamped to [at - r, at + r]: a point farther than
 * reach from q along one axis is farther than reach from q. `reach` is widened a little so that
 * a point at exactly the best distance so far (a tie, which the lowest index wins) is never left
 * out by rounding. */
static void reach_range(const lod_grid *g, const float q[3], float reach, int k, int32_t at, int32_t r,
                        int32_t *lo, int32_t *hi)
{
    *lo = at - r;
    *hi = at + r;
    if (reach == INFINITY)
        return;
    float margin = reach * 1.001f + 1e-18f;
    int32_t a = (int32_t)cell_coordinate(g, q[k] - margin, k), b = (int32_t)cell_coordinate(g, q[k] + margin, k);
    *lo = a > *lo ? a : *lo;
    *hi = b < *hi ? b : *hi;
}

/* Searches the cells at Chebyshev distance r > 0 from `at` (its shell) that lie within the best
 * distance so far of q along every axis; the others hold nothing nearer. A row of cells on the
 * shell is one run of the items' list. */
static void visit_shell(const lod_grid *g, const int32_t at[3], int32_t r, const float q[3], uint32_t *best,
                        float *best_d2)
{
    int32_t lo[3], hi[3];
    float reach = sqrtf(*best_d2);
    for (int k = 0; k < 3; k++) {
        reach_range(g, q, reach, k, at[k], r, &lo[k], &hi[k]);
        lo[k] = lo[k] > 0 ? lo[k] : 0;
        hi[k] = hi[k] < (int32_t)g->dim[k] - 1 ? hi[k] : (int32_t)g->dim[k] - 1;
    }
    if (lo[0] > hi[0])
        return;
    for (int32_t z = lo[2]; z <= hi[2]; z++)
        for (int32_t y = lo[1]; y <= hi[1]; y++) {
            size_t row = ((size_t)z * g->dim[1] + (uint32_t)y) * g->dim[0];
            if (z == at[2] - r || z == at[2] + r || y == at[1] - r || y == at[1] + r) {
                visit_cells(g, row + (uint32_t)lo[0], row + (uint32_t)hi[0] + 1, q, best, best_d2); /* the row's run */
                continue;
            }
            /* a row through the inside: only the shell's two faces (r > 0: two cells) */
            if (at[0] - r >= lo[0])
                visit_cells(g, row + (uint32_t)(at[0] - r), row + (uint32_t)(at[0] - r) + 1, q, best, best_d2);
            if (at[0] + r <= hi[0])
                visit_cells(g, row + (uint32_t)(at[0] + r), row + (uint32_t)(at[0] + r) + 1, q, best, best_d2);
        }
}

uint32_t lod_grid_nearest(const lod_grid *g, gdr_vec3 point, float *distance_squared)
{
    if (g->use_tree)
        return lod_point_tree_nearest(&g->tree, point, distance_squared);
    const float q[3] = {point.x, point.y, point.z};
    int32_t at[3];
    for (int k = 0; k < 3; k++)
        at[k] = (int32_t)cell_coordinate(g, q[k], k);
    uint32_t best = UINT32_MAX;
    float best_d2 = INFINITY;
    /* The shell of radius 0 is q's own cell (visited directly: most queries end after it or the
     * next), then shells outwards until no cell left can hold anything nearer. */
    visit_cell(g, (uint32_t)at[0], (uint32_t)at[1], (uint32_t)at[2], q, &best, &best_d2);
    for (int32_t r = 0; !search_done(g->lo, g->cell, g->dim, at, r, q, best_d2);)
        visit_shell(g, at, ++r, q, &best, &best_d2);
    *distance_squared = best_d2;
    return best;
}

void lod_grid_free(lod_grid *g)
{
    free(g->start);
    free(g->items);
    lod_point_tree_free(&g->tree);
    memset(g, 0, sizeof *g);
}

/* --- triangles ------------------------------------------------------------------------------------ */

static gdr_vec3 corner(const lod_triangle_grid *g, uint32_t t, int k)
{
    const float *p = g->positions + (size_t)g->corners[(size_t)t * 3 + k] * 3;
    return (gdr_vec3){p[0], p[1], p[2]};
}

static uint32_t tri_cell(const lod_triangle_grid *g, float x, int k)
{
    float c = (x - g->lo[k]) * g->inv_cell;
    if (!(c > 0.0f))
        return 0;
    return c >= g->top[k] ? g->dim[k] - 1 : (uint32_t)c;
}

/* Triangle t's box in cells: each axis's smallest and largest coordinate, then their cells (the
 * cell of a coordinate never decreases with it, so these are the smallest and largest corner cells). */
static void tri_box(const lod_triangle_grid *g, uint32_t t, uint32_t lo[3], uint32_t hi[3])
{
    const float *p[3];
    for (int j = 0; j < 3; j++)
        p[j] = g->positions + (size_t)g->corners[(size_t)t * 3 + j] * 3;
    for (int k = 0; k < 3; k++) {
        float a = p[0][k], b = p[0][k];
        a = p[1][k] < a ? p[1][k] : a;
        b = p[1][k] > b ? p[1][k] : b;
        a = p[2][k] < a ? p[2][k] : a;
        b = p[2][k] > b ? p[2][k] : b;
        lo[k] = tri_cell(g, a, k);
        hi[k] = tri_cell(g, b, k);
    }
}

static double edge_length(gdr_vec3 a, gdr_vec3 b)
{
    double x = (double)b.x - a.x, y = (double)b.y - a.y, z = (double)b.z - a.z;
    return sqrt(x * x + y * y + z * z);
}

/* The square root of triangle t's area: its edge scale (0 when degenerate); *perimeter receives its
 * perimeter. */
static double triangle_scale(const lod_triangle_grid *g, uint32_t t, double *perimeter)
{
    gdr_vec3 a = corner(g, t, 0), b = corner(g, t, 1), c = corner(g, t, 2);
    double u[3] = {b.x - a.x, b.y - a.y, b.z - a.z}, v[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
    double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2], z = u[0] * v[1] - u[1] * v[0];
    *perimeter = edge_length(a, b) + edge_length(b, c) + edge_length(c, a);
    return sqrt(0.5 * sqrt(x * x + y * y + z * z));
}

/* A triangle of area a and perimeter p crosses about a / cell^2 + p / cell cells (its inside, and a
 * run of cells along each edge). Triangles far longer than their spacing (a fan's, whose n triangles
 * all reach from its hub to its rim) would be listed O(sqrt n) times each in cells sized by that
 * spacing: O(n^1.5) entries, and as much clipping. The cells are kept at least large enough that
 * the estimate stays within GRID_LISTED_PER_TRIANGLE * n + GRID_LISTED_FLOOR entries: a sound
 * surface's estimate is 3 to 5 per triangle, the long triangles of a CAD mesh's small group up to 60
 * (the floor keeps such groups, of a few hundred triangles, as they were). Larger cells only hold
 * more triangles, of which a query looks at GRID_CELL_LIMIT: an answer stays a distance to one of
 * the triangles, never below the nearest. */
#define GRID_LISTED_PER_TRIANGLE 16.0
#define GRID_LISTED_FLOOR 65536.0

static double smallest_cell(double area, double perimeter, uint32_t n)
{
    double budget = GRID_LISTED_PER_TRIANGLE * n + GRID_LISTED_FLOOR; /* area/c^2 + perimeter/c <= budget */
    return (perimeter + sqrt(perimeter * perimeter + 4.0 * budget * area)) / (2.0 * budget);
}

/* Cells about as large as the triangles, over the corners' box. A group's triangles often lie on a
 * curved band whose box is mostly empty: 4n + 64 cells would force cells of dozens of triangles, so
 * a small grid may have up to GRID_MIN_CELLS (128 KiB of cell starts, kept between builds). */
static void tri_choose_cells(lod_triangle_grid *g, uint32_t n)
{
    float hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    g->lo[0] = g->lo[1] = g->lo[2] = FLT_MAX;
    double scale = 0.0, area = 0.0, perimeter = 0.0;
    for (uint32_t t = 0; t < n; t++) {
        for (int j = 0; j < 3; j++) {
            gdr_vec3 p = corner(g, t, j);
            const float *x = &p.x;
            for (int k = 0; k < 3; k++) {
                g->lo[k] = x[k] < g->lo[k] ? x[k] : g->lo[k];
                hi[k] = x[k] > hi[k] ? x[k] : hi[k];
            }
        }
        double edges, s = triangle_scale(g, t, &edges);
        scale += s;
        area += s * s;
        perimeter += edges;
    }
    lod_grid shape = {.lo = {g->lo[0], g->lo[1], g->lo[2]}};
    choose_cells(&shape, hi, n, scale / n, smallest_cell(area, perimeter, n), fmax(4.0 * n + 64.0, GRID_MIN_CELLS));
    g->cell = shape.cell;
    g->inv_cell = shape.inv_cell;
    memcpy(g->dim, shape.dim, sizeof g->dim);
    memcpy(g->top, shape.top, sizeof g->top);
}

/* --- listing a triangle in the cells it crosses ------------------------------------------------ */

/* Listing a long triangle in every cell of its bounding box would fill cells it never comes near
 * (a coarse group's diagonal triangles cover most of its box), and a query gives each cell only
 * GRID_CELL_LIMIT triangles: the nearest triangle would be missed. So a triangle is listed in the
 * cells it crosses, found by clipping it to each slab of cells along z, then each row along y; the
 * clipped polygon's x extent is the run of cells it crosses in that row. Slabs, rows and runs are
 * widened by CLIP_MARGIN of a cell so that rounding can only add cells, never drop one. */
#define CLIP_MARGIN 1e-3
#define CLIP_MAX 10 /* a triangle clipped by four planes has at most 7 corners; rounding may add */

typedef struct clip_polygon {
    double p[CLIP_MAX][3]; /* in cell units from the grid's corner */
    int n;
    int overflow; /* too many corners from rounding: use the unclipped extent */
} clip_polygon;

/* The part of `in` where sign * (x[k] - at) >= 0 (Sutherland–Hodgman, one plane). */
static void clip_plane(const clip_polygon *in, int k, double at, double sign, clip_polygon *out)
{
    out->n = 0;
    out->overflow = in->overflow;
    for (int i = 0; i < in->n && !out->overflow; i++) {
        const double *a = in->p[i], *b = in->p[i + 1 < in->n ? i + 1 : 0];
        double da = sign * (a[k] - at), db = sign * (b[k] - at);
        int crosses = (da >= 0.0) != (db >= 0.0);
        if (out->n + (da >= 0.0) + crosses > CLIP_MAX) {
            out->overflow = 1;
            break;
        }
        if (da >= 0.0)
            memcpy(out->p[out->n++], a, sizeof out->p[0]);
        if (crosses) {
            double t = da / (da - db), *q = out->p[out->n++];
            for (int j = 0; j < 3; j++)
                q[j] = a[j] + t * (b[j] - a[j]);
            q[k] = at;
        }
    }
    if (out->overflow)
        *out = *in; /* unclipped: larger, so only more cells */
}

/* `in` clipped to cell `i`'s slab along axis k, widened by the margin; the grid's first and last
 * slabs are open outwards (queries outside the grid fall into them). */
static void clip_slab(const lod_triangle_grid *g, const clip_polygon *in, int k, uint32_t i, clip_polygon *out)
{
    clip_polygon half;
    if (i > 0)
        clip_plane(in, k, (double)i - CLIP_MARGIN, 1.0, &half);
    else
        half = *in;
    if (i + 1 < g->dim[k])
        clip_plane(&half, k, (double)i + 1.0 + CLIP_MARGIN, -1.0, out);
    else
        *out = half;
}

/* The cells along axis k that the polygon reaches (widened by the margin); 0 when it is empty. */
static int clip_extent(const lod_triangle_grid *g, const clip_polygon *c, int k, uint32_t *lo, uint32_t *hi)
{
    if (c->n == 0)
        return 0;
    double a = c->p[0][k], b = a;
    for (int i = 1; i < c->n; i++) {
        a = c->p[i][k] < a ? c->p[i][k] : a;
        b = c->p[i][k] > b ? c->p[i][k] : b;
    }
    double top = (double)g->dim[k] - 1.0;
    a = floor(a - CLIP_MARGIN);
    b = floor(b + CLIP_MARGIN);
    *lo = a > 0.0 ? (a < top ? (uint32_t)a : (uint32_t)top) : 0;
    *hi = b > 0.0 ? (b < top ? (uint32_t)b : (uint32_t)top) : 0;
    return 1;
}

/* Counts (store == 0) or stores triangle t in cells x0 .. x1 of row (y, z). */
static void list_run(lod_triangle_grid *g, uint32_t t, uint32_t x0, uint32_t x1, uint32_t y, uint32_t z, int store)
{
    size_t row = ((size_t)z * g->dim[1] + y) * g->dim[0];
    for (uint32_t x = x0; x <= x1; x++) {
        if (store)
            g->items[g->start[row + x]++] = t;
        else
            g->start[row + x + 1]++;
    }
}

/* Remembers run x0 .. x1 of row (y, z) of triangle t for the storing pass; 0 when out of memory. */
static int keep_run(lod_triangle_grid *g, uint32_t t, uint32_t x0, uint32_t x1, uint32_t y, uint32_t z)
{
    if (g->run_count == g->runs_cap) {
        size_t n = g->runs_cap ? g->runs_cap * 2 : 256;
        lod_grid_run *r = realloc(g->runs, n * sizeof *r);
        if (!r)
            return 0;
        g->runs = r;
        g->runs_cap = n;
    }
    g->runs[g->run_count++] = (lod_grid_run){t, (uint16_t)x0, (uint16_t)x1, (uint16_t)y, (uint16_t)z};
    return 1;
}

/* Counts triangle t's runs of the cells it crosses (clipped, see CLIP_MARGIN) and keeps them for
 * the storing pass. Returns 0 when out of memory. */
static int count_clipped(lod_triangle_grid *g, uint32_t t)
{
    clip_polygon tri = {.n = 3}, slab, row;
    for (int j = 0; j < 3; j++) {
        gdr_vec3 p = corner(g, t, j);
        const float *x = &p.x;
        for (int k = 0; k < 3; k++)
            tri.p[j][k] = ((double)x[k] - (double)g->lo[k]) * (double)g->inv_cell;
    }
    uint32_t z0, z1, y0, y1, x0, x1;
    clip_extent(g, &tri, 2, &z0, &z1);
    for (uint32_t z = z0; z <= z1; z++) {
        clip_slab(g, &tri, 2, z, &slab);
        if (!clip_extent(g, &slab, 1, &y0, &y1))
            continue;
        for (uint32_t y = y0; y <= y1; y++) {
            clip_slab(g, &slab, 1, y, &row);
            if (!clip_extent(g, &row, 0, &x0, &x1))
                continue;
            list_run(g, t, x0, x1, y, z, 0);
            if (!keep_run(g, t, x0, x1, y, z))
                return 0;
        }
    }
    return 1;
}

/* Lists triangle t in the cells it crosses (see CLIP_MARGIN). A triangle whose box spans at most two
 * cells along each axis is listed in its whole box instead: at most a few cells it does not cross,
 * all next to it, and clipping would cost more than those save (most level-0 triangles are such).
 * The counting pass (store == 0) clips and keeps the runs; the storing pass takes them from there
 * (the triangles in the same order). Returns 0 when out of memory. */
static int list_triangle(lod_triangle_grid *g, uint32_t t, int store)
{
    uint32_t lo[3], hi[3];
    tri_box(g, t, lo, hi);
    if (hi[0] - lo[0] <= 1 && hi[1] - lo[1] <= 1 && hi[2] - lo[2] <= 1) {
        for (uint32_t z = lo[2]; z <= hi[2]; z++)
            for (uint32_t y = lo[1]; y <= hi[1]; y++)
                list_run(g, t, lo[0], hi[0], y, z, store);
        return 1;
    }
    if (!store)
        return count_clipped(g, t);
    for (; g->run_next < g->run_count && g->runs[g->run_next].t == t; g->run_next++) {
        const lod_grid_run *r = &g->runs[g->run_next];
        list_run(g, t, r->x0, r->x1, r->y, r->z, 1);
    }
    return 1;
}

/* A cell's triangles are looked at up to this many (the centre of a fan lies in cells of thousands):
 * the nearest of fewer triangles is farther, so the distance found stays an upper bound. Cells sized
 * by the triangles and triangles listed only where they cross keep sound meshes below it (no query
 * of the blob's, the knot's or a 1 M-triangle torus's build meets a full cell): there it is exact. */
#define GRID_CELL_LIMIT 64u

int lod_triangle_grid_build(lod_triangle_grid *g, const float *positions, const uint32_t *corners, uint32_t n)
{
    g->positions = positions;
    g->corners = corners;
    g->count = n;
    g->cell_limit = GRID_CELL_LIMIT;
    tri_choose_cells(g, n);
    size_t cells = (size_t)g->dim[0] * g->dim[1] * g->dim[2];
    if (!grid_reserve(&g->start, &g->start_cap, cells + 1))
        return 0;
    memset(g->start, 0, (cells + 1) * sizeof *g->start);
    g->run_count = g->run_next = 0;
    for (uint32_t t = 0; t < n; t++)
        if (!list_triangle(g, t, 0))
            return 0;
    for (size_t c = 0; c < cells; c++)
        g->start[c + 1] += g->start[c];
    if (!grid_reserve(&g->items, &g->items_cap, (size_t)g->start[cells] + 1))
        return 0;
    for (uint32_t t = 0; t < n; t++)
        list_triangle(g, t, 1);
    for (size_t c = cells; c > 0; c--) /* start[c] now holds the end of cell c: shift back */
        g->start[c] = g->start[c - 1];
    g->start[0] = 0;
    return 1;
}

/* Squared distance from q to cell c: no triangle listed there comes nearer than this. */
static float cell_d2(const lod_triangle_grid *g, const int32_t c[3], const float q[3])
{
    float d2 = 0.0f;
    for (int k = 0; k < 3; k++) {
        float a = g->lo[k] + (float)c[k] * g->cell, gap = a - q[k];
        if (gap <= 0.0f)
            gap = q[k] - (a + g->cell);
        d2 += gap > 0.0f ? gap * gap : 0.0f;
    }
    return d2;
}

/* The nearest of cell c's triangles (up to g->cell_limit) into best, unless the cell is farther
 * than best already: a triangle listed there whose nearest point is nearer lies in a nearer cell too,
 * where it is listed as well. Ties: the lowest triangle index. A cell of more than GRID_SPREAD_ABOVE
 * times the limit (a fan's hub or a fan cut to linear listing, where thousands of thin triangles
 * cross a cell) gives triangles spread evenly over its list instead of its first ones: the list is
 * in triangle order, neighbours on the surface lie near each other in it, and the first ones cover
 * a corner of the cell (on a fan of 80,000 triangles its groups' mean error was 0.092 of the radius
 * with the first ones, 0.015 spread). A cell just over the limit (a CAD mesh's) keeps its first
 * ones, as before: spread there, one group of regr01.obj stated more. */
#define GRID_SPREAD_ABOVE 4u
static void visit_triangle_cell(const lod_triangle_grid *g, const int32_t c[3], gdr_vec3 point, const float q[3],
                                lod_point_triangle_fn *distance, uint32_t *best, float *best_d2)
{
    if (cell_d2(g, c, q) > *best_d2)
        return;
    size_t k = ((size_t)c[2] * g->dim[1] + (uint32_t)c[1]) * g->dim[0] + (uint32_t)c[0];
    uint32_t first = g->start[k], count = g->start[k + 1] - first, looked = count < g->cell_limit ? count : g->cell_limit;
    uint32_t spread = count > GRID_SPREAD_ABOVE * looked ? count : looked;
    for (uint32_t j = 0; j < looked; j++) {
        uint32_t t = g->items[first + (uint32_t)((uint64_t)j * spread / looked)];
        float d = distance(point, corner(g, t, 0), corner(g, t, 1), corner(g, t, 2));
        if (d < *best_d2 || (d == *best_d2 && t < *best)) {
            *best_d2 = d;
            *best = t;
        }
    }
}

/* Every triangle, the nearest into best: what a query falls back to once its search has visited as
 * many cells as a grid of 4n + 64 would hold (a sparse soup of tiny triangles makes cells tiny and
 * most of them empty), so that no query costs more than the grid's size or the triangles' count. */
static void visit_all_triangles(const lod_triangle_grid *g, gdr_vec3 point, lod_point_triangle_fn *distance,
                                uint32_t *best, float *best_d2)
{
    *best = UINT32_MAX;
    *best_d2 = INFINITY;
    for (uint32_t t = 0; t < g->count; t++) {
        float d = distance(point, corner(g, t, 0), corner(g, t, 1), corner(g, t, 2));
        if (d < *best_d2) {
            *best_d2 = d;
            *best = t;
        }
    }
}

uint32_t lod_triangle_grid_nearest(const lod_triangle_grid *g, gdr_vec3 point, lod_point_triangle_fn *distance,
                                   float *distance_squared)
{
    const float q[3] = {point.x, point.y, point.z};
    uint64_t visited = 0, budget = 4ull * g->count + 64u;
    int32_t at[3];
    for (int k = 0; k < 3; k++)
        at[k] = (int32_t)tri_cell(g, q[k], k);
    uint32_t best = UINT32_MAX;
    float best_d2 = INFINITY;
    for (int32_t r = 0;; r++) {
        for (int32_t z = at[2] - r; z <= at[2] + r; z++) {
            if (z < 0 || z >= (int32_t)g->dim[2])
                continue;
            for (int32_t y = at[1] - r; y <= at[1] + r; y++) {
                if (y < 0 || y >= (int32_t)g->dim[1])
                    continue;
                int shell = r == 0 || z == at[2] - r || z == at[2] + r || y == at[1] - r || y == at[1] + r;
                for (int32_t x = at[0] - r; x <= at[0] + r; x += shell ? 1 : 2 * r) {
                    const int32_t c[3] = {x, y, z};
                    if (x >= 0 && x < (int32_t)g->dim[0])
                        visit_triangle_cell(g, c, point, q, distance, &best, &best_d2);
                    visited++;
                }
            }
        }
        if (search_done(g->lo, g->cell, g->dim, at, r, q, best_d2))
            break;
        if (visited > budget) {
            visit_all_triangles(g, point, distance, &best, &best_d2);
            break;
        }
    }
    *distance_squared = best_d2;
    return best;
}

void lod_triangle_grid_free(lod_triangle_grid *g)
{
    free(g->start);
    free(g->items);
    free(g->runs);
    memset(g, 0, sizeof *g);
}
