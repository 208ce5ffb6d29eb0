/* Near-equal positions welded for the LOD DAG build: positions within LOD_WELD_SCALE of the mesh's
 * radius of each other (and chains of them) get one position id, found through a hash of cells of
 * a few weld distances and a union-find (docs/GEOMETRY.md, "Near-equal positions"). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geometry/lod_internal.h"

/* Cells are this many weld distances wide: a position looks into a neighbouring cell only where it
 * lies within the weld distance of the face between them, so mostly into its own cell alone. */
#define WELD_CELL_SPAN 64.0

/* Position p's cell of WELD_CELL_SPAN weld distances, relative to the mesh's centre, and on each
 * axis which neighbouring cell may hold a position within the weld distance (bit 2k: the one below
 * along axis k, bit 2k + 1: above). */
typedef struct weld_entry {
    int32_t cell[3];
    uint32_t sides;
} weld_entry;

/* The positions of each cell: a hash table from a cell to its last position + 1 (0: empty), and
 * each position's previous one of the same cell (UINT32_MAX: none). */
typedef struct weld_cells {
    uint32_t *table, *previous, mask;
} weld_cells;

static uint32_t cell_hash(const int32_t *c, uint32_t mask)
{
    uint32_t h = (uint32_t)c[0] * 73856093u ^ (uint32_t)c[1] * 19349663u ^ (uint32_t)c[2] * 83492791u;
    return (h ^ h >> 15) & mask;
}

/* The table slot of cell c: the one holding it, or the empty one where it would go. */
static uint32_t *cell_slot(const weld_entry *e, const weld_cells *cells, const int32_t *c)
{
    for (uint32_t h = cell_hash(c, cells->mask);; h = (h + 1) & cells->mask) {
        uint32_t i = cells->table[h];
        if (i == 0 || !memcmp(e[i - 1].cell, c, sizeof e->cell))
            return &cells->table[h];
    }
}

/* Lists every position in its cell. Returns 0 when out of memory. */
static int fill_cells(const weld_entry *e, uint32_t n, weld_cells *cells)
{
    uint32_t mask = 1;
    while (mask < 2 * n)
        mask <<= 1;
    cells->table = calloc(mask, sizeof *cells->table);
    cells->previous = malloc((size_t)n * sizeof *cells->previous);
    cells->mask = mask - 1;
    if (!cells->table || !cells->previous)
        return 0;
    for (uint32_t p = 0; p < n; p++) {
        uint32_t *slot = cell_slot(e, cells, e[p].cell);
        cells->previous[p] = *slot ? *slot - 1 : UINT32_MAX;
        *slot = p + 1;
    }
    return 1;
}

/* The steps (-1, 0, 1) to the cells along axis k that may hold a position within the weld distance
 * of an entry with these sides: its own cell first. Returns how many. */
static int side_steps(uint32_t sides, int k, int *steps)
{
    int n = 0;
    steps[n++] = 0;
    if (sides & 1u << 2 * k)
        steps[n++] = -1;
    if (sides & 2u << 2 * k)
        steps[n++] = 1;
    return n;
}

/* Joins position p with every position of cell c that lies within `eps` on every axis (first[q]: a
 * vertex of position q). At most 64 positions of a cell are compared: a cluster of more positions
 * that close (a hostile mesh) is joined partly, which only leaves some seams open. */
static void weld_in_cell(const lod_build *b, const weld_entry *e, const weld_cells *cells, const uint32_t *first,
                         uint32_t *parent, double eps, uint32_t p, const int32_t *c)
{
    const gdr_vec3 *x = b->mesh->positions;
    uint32_t q = *cell_slot(e, cells, c);
    q = q ? q - 1 : UINT32_MAX;
    for (int seen = 0; q != UINT32_MAX && seen < 64; q = cells->previous[q], seen++) {
        gdr_vec3 u = x[first[p]], v = x[first[q]];
        if (q > p && fabs((double)u.x - v.x) <= eps && fabs((double)u.y - v.y) <= eps &&
            fabs((double)u.z - v.z) <= eps) {
            uint32_t rp = gdr_lod_find_root(parent, p), rq = gdr_lod_find_root(parent, q);
            parent[rp > rq ? rp : rq] = rp < rq ? rp : rq;
        }
    }
}

/* Joins every two positions within `eps` of each other on every axis, looking into the cells each
 * position's sides allow. Returns 0 when out of memory. */
static int weld_pairs(const lod_build *b, const weld_entry *e, uint32_t n, const uint32_t *first, uint32_t *parent,
                      double eps)
{
    weld_cells cells;
    int ok = fill_cells(e, n, &cells);
    for (uint32_t p = 0; ok && p < n; p++) {
        int steps[3][3], counts[3];
        for (int k = 0; k < 3; k++)
            counts[k] = side_steps(e[p].sides, k, steps[k]);
        for (int d = 0; d < counts[0] * counts[1] * counts[2]; d++) {
            int32_t c[3] = {e[p].cell[0] + steps[0][d % counts[0]], e[p].cell[1] + steps[1][d / counts[0] % counts[1]],
                            e[p].cell[2] + steps[2][d / (counts[0] * counts[1])]};
            weld_in_cell(b, e, &cells, first, parent, eps, p, c);
        }
    }
    free(cells.table);
    free(cells.previous);
    return ok;
}

/* Positions within LOD_WELD_SCALE of the radius of each other on every axis (and chains of them)
 * get one position id, the smallest of theirs; the ids they leave are used by no vertex. Sets
 * b->weld_slack, the largest distance between two vertices of one id (0: nothing welded), which
 * every group's error gets added (the error's samples are one vertex per id). Deterministic: it
 * depends on the positions alone. */
int gdr_lod_weld_setup(lod_build *b)
{
    const gdr_mesh *mesh = b->mesh;
    uint32_t n = b->position_count;
    double eps = (double)mesh->bounds.w * LOD_WELD_SCALE;
    if (n < 2 || !(eps > 0.0))
        return 1;
    uint32_t *first = malloc((size_t)n * sizeof *first), *parent = malloc((size_t)n * sizeof *parent);
    weld_entry *e = malloc((size_t)n * sizeof *e);
    int ok = first && parent && e;
    for (uint32_t v = mesh->vertex_count; ok && v-- > 0;)
        first[b->position_id[v]] = v;
    for (uint32_t p = 0; ok && p < n; p++) {
        gdr_vec3 x = first[p] < mesh->vertex_count ? mesh->positions[first[p]] : (gdr_vec3){0};
        double rel[3] = {(double)x.x - mesh->bounds.x, (double)x.y - mesh->bounds.y, (double)x.z - mesh->bounds.z};
        e[p].sides = 0;
        for (int k = 0; k < 3; k++) { /* within the bounding sphere: |rel| / eps <= 1e6 */
            double at = fmax(fmin(rel[k] / (WELD_CELL_SPAN * eps), 2e9), -2e9), cell = floor(at);
            e[p].cell[k] = (int32_t)cell;
            /* Within eps (a 1/WELD_CELL_SPAN of a cell) of a face, the cell across it may hold a
             * position within eps; the margin covers the rounding of the division. */
            double near = (1.0 + 1e-3) / WELD_CELL_SPAN;
            e[p].sides |= (at - cell <= near ? 1u : 0u) << 2 * k | (cell + 1.0 - at <= near ? 2u : 0u) << 2 * k;
        }
        parent[p] = p;
    }
    ok = ok && weld_pairs(b, e, n, first, parent, eps);
    double slack = 0.0; /* the largest distance from a vertex to the first vertex of its new id */
    for (uint32_t v = 0; ok && v < mesh->vertex_count; v++) {
        b->position_id[v] = gdr_lod_find_root(parent, b->position_id[v]);
        gdr_vec3 p = mesh->positions[v], q = mesh->positions[first[b->position_id[v]]];
        double dx = (double)p.x - q.x, dy = (double)p.y - q.y, dz = (double)p.z - q.z;
        slack = fmax(slack, sqrt(dx * dx + dy * dy + dz * dz));
    }
    /* Two vertices of one id are at most twice that apart (rounded up to a float). */
    b->weld_slack = slack > 0.0 ? nextafterf((float)(2.0 * slack), INFINITY) : 0.0f;
    free(first);
    free(parent);
    free(e);
    return ok;
}
