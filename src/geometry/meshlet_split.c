/* Level-0 meshlets split where their triangles lie far apart (meshlet_split.h).
 *
 * meshoptimizer 0.18 grows a meshlet through triangles next to it; once none is free it takes the
 * free triangle nearest to the meshlet's centre, however far. The meshlet then holds two places
 * and its sphere covers the space between them, and so does the sphere of every LOD group above it
 * (a group's sphere encloses its children's). Here a meshlet's triangles are put in parts: triangles
 * sharing a vertex are in one part, and parts whose bounding boxes come closer than the chunk's
 * median meshlet size (half its box diagonal) are joined. A meshlet with more than one part is
 * replaced by one meshlet per part. Nearby unconnected pieces (a UV seam's two sides, small parts
 * side by side) stay together; only a jump farther than a typical meshlet is cut. */
#include "geometry/meshlet_split.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>

/* meshoptimizer's own limits on a meshlet: local indices are bytes. */
#define MAX_LOCAL 256u
#define MAX_TRIANGLES 512u

#define MAX_PARTS 8u
/* Pieces of split meshlets are merged while their union stays within this many median sizes. */
#define MERGED_SIZE_DEFAULT 1.0
static double env_or(const char *name, double d) { const char *e = getenv(name); return e ? atof(e) : d; } /* TMP */
#define LINK_EDGES env_or("TMP_LINK_EDGES", 2.0)
#define SIZE_RATIO env_or("TMP_SIZE_RATIO", 2.0)
#define OUTLIER env_or("TMP_OUTLIER", 2.0)
#define MERGED_SIZE env_or("TMP_MERGED_SIZE", MERGED_SIZE_DEFAULT)

typedef struct box {
    float lo[3], hi[3];
} box;

static void box_empty(box *b)
{
    for (int k = 0; k < 3; k++) {
        b->lo[k] = FLT_MAX;
        b->hi[k] = -FLT_MAX;
    }
}

static void box_add(box *b, const float *p)
{
    for (int k = 0; k < 3; k++) {
        b->lo[k] = p[k] < b->lo[k] ? p[k] : b->lo[k];
        b->hi[k] = p[k] > b->hi[k] ? p[k] : b->hi[k];
    }
}

/* The distance between two boxes (0 where they overlap). */
static double box_gap(const box *a, const box *b)
{
    double sum = 0.0;
    for (int k = 0; k < 3; k++) {
        double d = (double)a->lo[k] - b->hi[k];
        double e = (double)b->lo[k] - a->hi[k];
        d = d > e ? d : e;
        sum += d > 0.0 ? d * d : 0.0;
    }
    return sqrt(sum);
}

static double half_diagonal(const box *b)
{
    double sum = 0.0;
    for (int k = 0; k < 3; k++) {
        double d = (double)b->hi[k] - b->lo[k];
        sum += d * d;
    }
    return 0.5 * sqrt(sum);
}

static box box_union(const box *x, const box *y)
{
    box b = *x;
    box_add(&b, y->lo);
    box_add(&b, y->hi);
    return b;
}

static uint32_t find(uint8_t *parent, uint32_t x)
{
    while (parent[x] != x)
        x = parent[x] = parent[parent[x]];
    return x;
}

static void unite(uint8_t *parent, uint32_t a, uint32_t b)
{
    a = find(parent, a);
    b = find(parent, b);
    if (a != b)
        parent[a > b ? a : b] = (uint8_t)(a < b ? a : b);
}

static double distance(const float *x, const float *y)
{
    double dx = (double)x[0] - y[0], dy = (double)x[1] - y[1], dz = (double)x[2] - y[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* The parts of meshlet m: part[t] for each of its triangles, numbered in the order of their first
 * triangle; returns the number of parts (1: the meshlet stays whole). Triangles sharing a vertex
 * are one part, and so are parts that come within LINK_EDGES mean edge lengths of each other (a
 * seam's two sides, a crack). The meshlet is split only where that leaves at most MAX_PARTS parts
 * (more: scattered pieces, such as a triangle soup, that no cut makes compact) and the meshlet is
 * more than SIZE_RATIO times as large (half box diagonal) as its largest part: a jump, not a
 * hole or a bay of the surface. */
static uint32_t meshlet_parts(const struct meshopt_Meshlet *m, const uint32_t *vertices, const uint8_t *triangles,
                              const float *positions, uint8_t *part, double *whole_size, double *part_size)
{
    uint8_t parent[MAX_LOCAL], component[MAX_LOCAL];
    for (uint32_t v = 0; v < m->vertex_count; v++)
        parent[v] = (uint8_t)v, component[v] = UINT8_MAX;
    const uint8_t *tri = triangles + m->triangle_offset;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        unite(parent, tri[3 * t], tri[3 * t + 1]);
        unite(parent, tri[3 * t], tri[3 * t + 2]);
    }
    /* Components of shared vertices, numbered by first triangle, with their boxes. */
    box boxes[MAX_TRIANGLES];
    uint32_t count = 0;
    double edges = 0.0;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        uint32_t root = find(parent, tri[3 * t]);
        if (component[root] == UINT8_MAX)
            box_empty(&boxes[count]), component[root] = (uint8_t)count++;
        part[t] = component[root];
        const float *corner[3];
        for (int k = 0; k < 3; k++) {
            corner[k] = positions + 3 * (size_t)vertices[m->vertex_offset + tri[3 * t + k]];
            box_add(&boxes[part[t]], corner[k]);
        }
        edges += distance(corner[0], corner[1]) + distance(corner[1], corner[2]) + distance(corner[2], corner[0]);
    }
    if (count == 1) {
        *whole_size = *part_size = half_diagonal(&boxes[0]);
        return 1;
    }
    /* Single linkage: components whose boxes come within `link` are one part. A meshlet has at most
     * one component per triangle (its vertex limit keeps that near 21), so pairs are cheap. */
    double link = LINK_EDGES * edges / (3.0 * m->triangle_count);
    uint8_t joined[MAX_LOCAL], number[MAX_LOCAL];
    for (uint32_t i = 0; i < count; i++)
        joined[i] = (uint8_t)i, number[i] = UINT8_MAX;
    for (uint32_t i = 0; i < count; i++)
        for (uint32_t j = i + 1; j < count; j++)
            if (find(joined, i) != find(joined, j) && box_gap(&boxes[i], &boxes[j]) <= link)
                unite(joined, i, j);
    box parts[MAX_PARTS + 1], whole;
    box_empty(&whole);
    uint32_t n = 0;
    for (uint32_t i = 0; i < count; i++) {
        uint32_t root = find(joined, i);
        if (number[root] == UINT8_MAX) {
            if (n == MAX_PARTS) {
                n = 0; /* too many: left whole below */
                break;
            }
            box_empty(&parts[n]);
            number[root] = (uint8_t)n++;
        }
        parts[number[root]] = box_union(&parts[number[root]], &boxes[i]);
        whole = box_union(&whole, &boxes[i]);
    }
    double largest = 0.0;
    for (uint32_t i = 0; i < n; i++)
        largest = half_diagonal(&parts[i]) > largest ? half_diagonal(&parts[i]) : largest;
    *whole_size = half_diagonal(&whole);
    *part_size = n < 2 ? *whole_size : largest;
    if (n < 2 || !(*whole_size > SIZE_RATIO * largest)) {
        memset(part, 0, m->triangle_count);
        return 1;
    }
    for (uint32_t t = 0; t < m->triangle_count; t++)
        part[t] = number[find(joined, part[t])];
    return n;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The median of values[count] (reordered). */
static double median_of(double *values, size_t count)
{
    qsort(values, count, sizeof *values, by_value);
    return values[count / 2];
}

/* One part of a split meshlet: its triangles, vertex set (sorted ids) and box. Parts of different
 * meshlets that lie together and fit the limits are merged: `next` chains the parts merged into
 * the first one (`head`), which then holds the union's counts, vertices and box. */
typedef struct piece {
    uint32_t meshlet, part, next, head;
    uint32_t triangle_count, vertex_count;
    uint32_t vertices[MAX_LOCAL];
    box bounds;
} piece;

#define NO_PIECE UINT32_MAX

static void piece_init(piece *q, const meshlet_arrays *a, uint32_t meshlet, const uint8_t *part, uint32_t p,
                       const float *positions)
{
    const struct meshopt_Meshlet *m = &a->meshlets[meshlet];
    const uint8_t *tri = a->triangles + m->triangle_offset;
    uint8_t seen[MAX_LOCAL] = {0};
    *q = (piece){.meshlet = meshlet, .part = p, .next = NO_PIECE, .head = NO_PIECE};
    box_empty(&q->bounds);
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        if (part[t] != p)
            continue;
        q->triangle_count++;
        for (int k = 0; k < 3; k++) {
            uint8_t v = tri[3 * t + k];
            if (!seen[v]) {
                seen[v] = 1;
                q->vertices[q->vertex_count++] = a->vertices[m->vertex_offset + v];
                box_add(&q->bounds, positions + 3 * (size_t)a->vertices[m->vertex_offset + v]);
            }
        }
    }
}

static int by_id(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* The size of the union of two sorted vertex sets, into `out` when out is not NULL. */
static uint32_t union_size(const piece *x, const piece *y, uint32_t *out)
{
    uint32_t i = 0, j = 0, n = 0;
    while (i < x->vertex_count || j < y->vertex_count) {
        uint32_t v;
        if (j == y->vertex_count || (i < x->vertex_count && x->vertices[i] < y->vertices[j]))
            v = x->vertices[i++];
        else if (i == x->vertex_count || y->vertices[j] < x->vertices[i])
            v = y->vertices[j++];
        else
            v = x->vertices[i++], j++;
        if (out)
            out[n] = v;
        n++;
    }
    return n;
}


/* Merges pieces that lie within `link` of each other, fit the limits together and stay within
 * `largest` (half box diagonal): each piece in order takes the partner whose union is smallest,
 * until none fits. The split's leftovers mostly lie next to each other (the far part of one
 * meshlet is where the meshlets after it grow), so this wins back most of the fill. */
static void merge_pieces(piece *q, uint32_t count, double link, double largest, uint32_t max_vertices,
                         uint32_t max_triangles)
{
    for (uint32_t i = 0; i < count; i++) {
        if (q[i].head != NO_PIECE)
            continue;
        uint32_t tail = i;
        for (;;) {
            uint32_t best = NO_PIECE;
            double best_size = largest;
            for (uint32_t j = i + 1; j < count; j++) {
                if (q[j].head != NO_PIECE || q[i].triangle_count + q[j].triangle_count > max_triangles ||
                    box_gap(&q[i].bounds, &q[j].bounds) > link)
                    continue;
                box b = box_union(&q[i].bounds, &q[j].bounds);
                double size = half_diagonal(&b);
                if (size <= best_size && union_size(&q[i], &q[j], NULL) <= max_vertices)
                    best = j, best_size = size;
            }
            if (best == NO_PIECE)
                break;
            uint32_t merged[2 * MAX_LOCAL];
            q[i].vertex_count = union_size(&q[i], &q[best], merged);
            memcpy(q[i].vertices, merged, q[i].vertex_count * sizeof *merged);
            q[i].triangle_count += q[best].triangle_count;
            q[i].bounds = box_union(&q[i].bounds, &q[best].bounds);
            q[best].head = i;
            q[tail].next = best;
            tail = best;
        }
    }
}

/* Appends the triangles of part p of meshlet m to the meshlet r being written (its vertices in
 * first-use order, found among the ones it has: at most 64). */
static void append_part(const meshlet_arrays *a, const struct meshopt_Meshlet *m, const uint8_t *part, uint32_t p,
                        meshlet_arrays *out, struct meshopt_Meshlet *r)
{
    const uint8_t *tri = a->triangles + m->triangle_offset;
    uint32_t *listed = out->vertices + r->vertex_offset;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        if (part[t] != p)
            continue;
        for (int k = 0; k < 3; k++) {
            uint32_t v = a->vertices[m->vertex_offset + tri[3 * t + k]], local = 0;
            while (local < r->vertex_count && listed[local] != v)
                local++;
            if (local == r->vertex_count)
                listed[r->vertex_count++] = v;
            out->triangles[r->triangle_offset + 3 * r->triangle_count + (uint32_t)k] = (uint8_t)local;
        }
        r->triangle_count++;
    }
}

/* What the split computed: each meshlet's part count, its first triangle in `part` (the parts of
 * every triangle, in meshlet order), its first piece (pieces exist for split meshlets only). */
typedef struct split_plan {
    const uint32_t *parts;
    const uint8_t *part;
    const size_t *first_triangle;
    const uint32_t *first_piece;
    const piece *pieces;
    size_t meshlet_count; /* meshlets written */
} split_plan;

/* Writes the split (and merged) meshlets into out (allocated here). */
static int emit(const meshlet_arrays *a, const split_plan *plan, meshlet_arrays *out)
{
    const struct meshopt_Meshlet *last = &a->meshlets[a->count - 1];
    size_t vertices = (size_t)last->vertex_offset + last->vertex_count;
    size_t bytes = (size_t)last->triangle_offset + ((last->triangle_count * 3 + 3) & ~3u) + 4 * plan->meshlet_count;
    out->meshlets = malloc(plan->meshlet_count * sizeof *out->meshlets);
    out->vertices = malloc(vertices * sizeof *out->vertices);
    out->triangles = calloc(bytes, 1); /* the padding between meshlets stays zero */
    if (!out->meshlets || !out->vertices || !out->triangles) {
        free(out->meshlets);
        free(out->vertices);
        free(out->triangles);
        return -1;
    }
    uint32_t vo = 0, to = 0;
    size_t k = 0;
    for (size_t i = 0; i < a->count; i++) {
        for (uint32_t p = 0; p < plan->parts[i]; p++) {
            uint32_t head = plan->parts[i] > 1 ? plan->first_piece[i] + p : NO_PIECE;
            if (head != NO_PIECE && plan->pieces[head].head != NO_PIECE)
                continue; /* written with the piece it was merged into */
            struct meshopt_Meshlet r = {.vertex_offset = vo, .triangle_offset = to};
            if (head == NO_PIECE)
                append_part(a, &a->meshlets[i], plan->part + plan->first_triangle[i], 0, out, &r);
            for (uint32_t q = head; q != NO_PIECE; q = plan->pieces[q].next) {
                uint32_t m = plan->pieces[q].meshlet;
                append_part(a, &a->meshlets[m], plan->part + plan->first_triangle[m], plan->pieces[q].part, out, &r);
            }
            vo += r.vertex_count;
            to += (r.triangle_count * 3 + 3) & ~3u;
            out->meshlets[k++] = r;
        }
    }
    out->count = k;
    return 0;
}


/* --- reflow ------------------------------------------------------------------------------- */

/* One triangle in the order the meshlets are rewritten: its meshlet and index there. */
typedef struct tri_ref {
    uint32_t meshlet, triangle;
} tri_ref;

/* The triangles in meshoptimizer's order, cut into runs that never hold a jump: a split meshlet's
 * first part ends the run it continues, its middle parts are runs of their own, and its last part
 * (where meshoptimizer grew on, and where the next meshlet starts) begins a new run. Writes the
 * order into `order` and, for each triangle, whether a run starts there; returns the count. */
static size_t runs(const meshlet_arrays *a, const split_plan *plan, tri_ref *order, uint8_t *starts)
{
    size_t n = 0;
    for (size_t i = 0; i < a->count; i++) {
        const struct meshopt_Meshlet *m = &a->meshlets[i];
        const uint8_t *part = plan->part + plan->first_triangle[i];
        for (uint32_t p = 0; p < plan->parts[i]; p++)
            for (uint32_t t = 0; t < m->triangle_count; t++)
                if (part[t] == p) {
                    starts[n] = p > 0 && (n == 0 || order[n - 1].meshlet != i || part[order[n - 1].triangle] != p);
                    order[n++] = (tri_ref){(uint32_t)i, t};
                }
    }
    return n;
}

/* Cuts the runs greedily into meshlets at the limits (a new meshlet at every run start). */
static int emit_runs(const meshlet_arrays *a, const split_plan *plan, uint32_t max_vertices, uint32_t max_triangles,
                     meshlet_arrays *out)
{
    const struct meshopt_Meshlet *last = &a->meshlets[a->count - 1];
    size_t triangles = 0, vertex_ids = 0;
    for (size_t i = 0; i < a->count; i++)
        triangles += a->meshlets[i].triangle_count;
    size_t vertices = (size_t)last->vertex_offset + last->vertex_count;
    for (size_t v = 0; v < vertices; v++)
        vertex_ids = a->vertices[v] + 1 > vertex_ids ? a->vertices[v] + 1 : vertex_ids;
    tri_ref *order = malloc(triangles * sizeof *order);
    uint8_t *starts = malloc(triangles);
    uint32_t *stamp = malloc(vertex_ids * sizeof *stamp), *local = malloc(vertex_ids * sizeof *local);
    out->meshlets = malloc(triangles * sizeof *out->meshlets);
    out->vertices = malloc(3 * triangles * sizeof *out->vertices);
    out->triangles = calloc(3 * triangles + 4 * triangles, 1);
    int status = order && starts && stamp && local && out->meshlets && out->vertices && out->triangles ? 0 : -1;
    if (status == 0) {
        memset(stamp, 0xff, vertex_ids * sizeof *stamp);
        size_t n = runs(a, plan, order, starts), k = 0;
        struct meshopt_Meshlet r = {0};
        uint32_t vo = 0, to = 0;
        for (size_t i = 0; i < n; i++) {
            const struct meshopt_Meshlet *m = &a->meshlets[order[i].meshlet];
            const uint8_t *tri = a->triangles + m->triangle_offset + 3 * order[i].triangle;
            uint32_t fresh = 0;
            for (int c = 0; c < 3; c++)
                fresh += stamp[a->vertices[m->vertex_offset + tri[c]]] != k;
            if (r.triangle_count > 0 &&
                (starts[i] || r.vertex_count + fresh > max_vertices || r.triangle_count == max_triangles)) {
                out->meshlets[k++] = r;
                vo += r.vertex_count;
                to += (r.triangle_count * 3 + 3) & ~3u;
                r = (struct meshopt_Meshlet){.vertex_offset = vo, .triangle_offset = to};
            }
            for (int c = 0; c < 3; c++) {
                uint32_t v = a->vertices[m->vertex_offset + tri[c]];
                if (stamp[v] != k) {
                    stamp[v] = (uint32_t)k;
                    local[v] = r.vertex_count;
                    out->vertices[vo + r.vertex_count++] = v;
                }
                out->triangles[to + 3 * r.triangle_count + (uint32_t)c] = (uint8_t)local[v];
            }
            r.triangle_count++;
        }
        out->meshlets[k++] = r;
        out->count = k;
    } else {
        free(out->meshlets);
        free(out->vertices);
        free(out->triangles);
    }
    free(order);
    free(starts);
    free(stamp);
    free(local);
    return status;
}

/* The pieces of the split meshlets, merged where they fit; returns the meshlets left, or 0 when
 * out of memory. */
static size_t plan_pieces(const meshlet_arrays *a, const float *positions, split_plan *plan, uint32_t *first_piece,
                          size_t piece_count, double link, double largest, uint32_t max_vertices,
                          uint32_t max_triangles, piece **out)
{
    piece *q = malloc((piece_count + 1) * sizeof *q);
    if (!q)
        return 0;
    uint32_t n = 0;
    for (size_t i = 0; i < a->count; i++) {
        first_piece[i] = n;
        for (uint32_t p = 0; plan->parts[i] > 1 && p < plan->parts[i]; p++, n++) {
            piece_init(&q[n], a, (uint32_t)i, plan->part + plan->first_triangle[i], p, positions);
            qsort(q[n].vertices, q[n].vertex_count, sizeof *q[n].vertices, by_id);
        }
    }
    merge_pieces(q, n, link, largest, max_vertices, max_triangles);
    size_t meshlets = 0;
    for (size_t i = 0; i < a->count; i++)
        meshlets += plan->parts[i] > 1 ? 0 : 1;
    for (uint32_t i = 0; i < n; i++)
        meshlets += q[i].head == NO_PIECE;
    *out = q;
    return meshlets;
}

int gdr_meshlets_split_far_parts(meshlet_arrays *a, const float *positions, uint32_t max_vertices,
                                 uint32_t max_triangles)
{
    if (getenv("TMP_DBG")) fprintf(stderr, "split %zu\n", a->count);
    if (a->count < 2 || getenv("TMP_SPLIT_OFF"))
        return 0; /* nothing to measure a jump against */
    size_t triangles = 0;
    for (size_t i = 0; i < a->count; i++)
        triangles += a->meshlets[i].triangle_count;
    double *sizes = malloc(a->count * sizeof *sizes);
    uint32_t *parts = malloc(a->count * sizeof *parts), *first_piece = malloc(a->count * sizeof *first_piece);
    size_t *first_triangle = malloc(a->count * sizeof *first_triangle);
    uint8_t *part = malloc(triangles);
    int status = sizes && parts && first_piece && first_triangle && part ? 0 : -1;
    size_t pieces = 0;
    double *whole = malloc(a->count * sizeof *whole);
    status = whole ? status : -1;
    for (size_t i = 0, first = 0; status == 0 && i < a->count; i++) {
        first_triangle[i] = first;
        parts[i] = meshlet_parts(&a->meshlets[i], a->vertices, a->triangles, positions, part + first, &whole[i],
                                 &sizes[i]);
        first += a->meshlets[i].triangle_count;
    }
    /* The typical meshlet size: the median of the meshlets' largest parts (a jump does not move it). */
    double median = 0.0;
    if (status == 0) {
        median = median_of(sizes, a->count);
    }
    for (size_t i = 0; status == 0 && i < a->count; i++) {
        if (parts[i] > 1 && !(whole[i] > OUTLIER * median)) {
            parts[i] = 1;
            memset(part + first_triangle[i], 0, a->meshlets[i].triangle_count);
        }
        pieces += parts[i] > 1 ? parts[i] : 0;
    }
    free(whole);
    split_plan plan = {parts, part, first_triangle, first_piece, NULL, 0};
    piece *q = NULL;
    if (status == 0 && pieces > 0) {
        plan.meshlet_count = plan_pieces(a, positions, &plan, first_piece, pieces, LINK_EDGES * median,
                                         MERGED_SIZE * median, max_vertices, max_triangles, &q);
        plan.pieces = q;
        meshlet_arrays out = {0};
        if (getenv("TMP_REFLOW"))
            status = emit_runs(a, &plan, max_vertices, max_triangles, &out);
        else
            status = plan.meshlet_count == 0 ? -1 : emit(a, &plan, &out);
        if (status == 0) {
            free(a->meshlets);
            free(a->vertices);
            free(a->triangles);
            *a = out;
        }
    }
    free(q);
    free(sizes);
    free(parts);
    free(first_piece);
    free(first_triangle);
    free(part);
    return status;
}
