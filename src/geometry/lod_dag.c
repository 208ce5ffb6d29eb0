/* The cluster LOD DAG (issue 5, seed 004): group neighbouring clusters with METIS, merge and
 * simplify each group with its shared border locked (meshoptimizer), split the result into new
 * clusters, repeat up to a root. The contract (and the cut rule it serves) is in gdr/geometry.h;
 * docs/GEOMETRY.md explains the choices.
 *
 * Determinism: the groups of one step are simplified in parallel, each task writing only its own
 * result; results are appended in group order by the calling thread, and METIS runs with a fixed
 * seed on the calling thread. The bytes produced do not depend on the thread count. */
#include <assert.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>
#include <metis.h>

#include "core/progress.h"
#include "core/thread_pool.h"
#include "gdr/geometry.h"
#include "gdr/scene.h"

/* A group is formed only when simplification keeps at most this share of its triangles. */
#define LOD_MAX_KEPT_SHARE 0.85
/* Smallest group error, relative to the mesh's bounding radius: errors are > 0, so threshold 0
 * selects level 0 even where simplification was exact (flat areas). */
#define LOD_MIN_ERROR_SCALE 1e-6f
#define LOD_CONE_WEIGHT 0.25f
#define LOD_MAX_GROUP_SIZE 32u
/* Meshes with fewer triangles are built side by side, one per task, by gdr_scene_build_lod. */
#define LOD_SMALL_MESH_TRIANGLES 65536u

#define OWNER_NONE UINT32_MAX
#define OWNER_SHARED (UINT32_MAX - 1)

_Static_assert(GDR_CLUSTER_MAX_VERTICES <= 64, "boundary edges are counted in a 64 x 64 table");
_Static_assert(sizeof(idx_t) == 4, "METIS built with 32-bit idx_t");

/* --- small helpers --------------------------------------------------------------------------- */

/* Grows *p to hold at least `need` elements of `size` bytes; returns 0 when out of memory. */
static int reserve(void *pp, size_t *cap, size_t need, size_t size)
{
    void **p = pp;
    if (need <= *cap)
        return 1;
    size_t n = *cap ? *cap : 16;
    while (n < need)
        n *= 2;
    void *q = realloc(*p, n * size);
    if (!q)
        return 0;
    *p = q;
    *cap = n;
    return 1;
}

static size_t align4(size_t n) { return (n + 3) & ~(size_t)3; }

/* The smallest float >= x. */
static float round_up_to_float(double x)
{
    float f = (float)x;
    return (double)f < x ? nextafterf(f, INFINITY) : f;
}

/* A sphere containing every sphere of the list, in double, rounded up, with a relative slack of
 * 1e-6 so that containment survives float evaluation of the distances. */
static gdr_vec4 enclosing_sphere(const gdr_vec4 *s, size_t n)
{
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (size_t i = 0; i < n; i++) {
        const double c[3] = {s[i].x, s[i].y, s[i].z}, r = s[i].w;
        for (int k = 0; k < 3; k++) {
            lo[k] = c[k] - r < lo[k] ? c[k] - r : lo[k];
            hi[k] = c[k] + r > hi[k] ? c[k] + r : hi[k];
        }
    }
    float centre[3];
    for (int k = 0; k < 3; k++)
        centre[k] = (float)(0.5 * (lo[k] + hi[k]));
    double radius = 0.0;
    for (size_t i = 0; i < n; i++) {
        double dx = (double)s[i].x - centre[0], dy = (double)s[i].y - centre[1], dz = (double)s[i].z - centre[2];
        double d = sqrt(dx * dx + dy * dy + dz * dz) + s[i].w;
        radius = d > radius ? d : radius;
    }
    return (gdr_vec4){centre[0], centre[1], centre[2], round_up_to_float(radius * (1.0 + 1e-6))};
}

/* Culling bounds of a new cluster, to the same contract as level 0 (gdr/geometry.h): the sphere
 * reaches every vertex (grown in double and rounded up); no triangle of non-zero area or no useful
 * cone gives cutoff 1 with a zero axis. */
static void cluster_bounds(gdr_cluster *c, const uint32_t *vertices, const uint8_t *triangles, const gdr_mesh *mesh)
{
    struct meshopt_Bounds b = meshopt_computeMeshletBounds(vertices, triangles, c->triangle_count,
                                                           &mesh->positions[0].x, mesh->vertex_count,
                                                           sizeof(gdr_vec3));
    int has_area = b.radius > 0.0f || b.cone_cutoff != 0.0f || b.cone_axis[0] != 0.0f || b.cone_axis[1] != 0.0f ||
                   b.cone_axis[2] != 0.0f;
    double centre[3] = {b.center[0], b.center[1], b.center[2]};
    if (!has_area) {
        double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
        for (uint32_t i = 0; i < c->vertex_count; i++) {
            const float *p = &mesh->positions[vertices[i]].x;
            for (int k = 0; k < 3; k++) {
                lo[k] = p[k] < lo[k] ? p[k] : lo[k];
                hi[k] = p[k] > hi[k] ? p[k] : hi[k];
            }
        }
        for (int k = 0; k < 3; k++)
            centre[k] = (double)(float)(0.5 * (lo[k] + hi[k]));
    }
    double radius = has_area ? b.radius : 0.0;
    for (uint32_t i = 0; i < c->vertex_count; i++) {
        const gdr_vec3 p = mesh->positions[vertices[i]];
        double dx = p.x - centre[0], dy = p.y - centre[1], dz = p.z - centre[2];
        double d = sqrt(dx * dx + dy * dy + dz * dz);
        radius = d > radius ? d : radius;
    }
    c->sphere = (gdr_vec4){(float)centre[0], (float)centre[1], (float)centre[2], round_up_to_float(radius)};
    if (has_area && b.cone_cutoff < 1.0f) {
        c->cone_apex = (gdr_vec3){b.cone_apex[0], b.cone_apex[1], b.cone_apex[2]};
        c->cone_axis = (gdr_vec3){b.cone_axis[0], b.cone_axis[1], b.cone_axis[2]};
        c->cone_cutoff = b.cone_cutoff;
    } else {
        c->cone_apex = (gdr_vec3){c->sphere.x, c->sphere.y, c->sphere.z};
        c->cone_axis = (gdr_vec3){0.0f, 0.0f, 0.0f};
        c->cone_cutoff = 1.0f;
    }
}

/* Sorts 16-byte records by their 64-bit key (LSD radix, stable; byte positions where every key
 * agrees are skipped). tmp holds n records. */
typedef struct key_record {
    uint64_t key;
    uint32_t value;
    uint32_t pad;
} key_record;

static void radix_sort(key_record *a, key_record *tmp, size_t n)
{
    for (int shift = 0; shift < 64; shift += 8) {
        size_t count[256] = {0};
        for (size_t i = 0; i < n; i++)
            count[(a[i].key >> shift) & 255]++;
        if (n == 0 || count[(a[0].key >> shift) & 255] == n)
            continue;
        size_t sum = 0;
        for (int d = 0; d < 256; d++) {
            size_t c = count[d];
            count[d] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++)
            tmp[count[(a[i].key >> shift) & 255]++] = a[i];
        memcpy(a, tmp, n * sizeof *a);
    }
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static int contains_u64(const uint64_t *sorted, size_t n, uint64_t key)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (sorted[mid] < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < n && sorted[lo] == key;
}

/* --- the build state --------------------------------------------------------------------------- */

/* Progress shared by the meshes of one call; only worker 0 (the calling thread) draws. */
typedef struct lod_progress {
    gdr_progress bar;
    atomic_uint_fast64_t done;
} lod_progress;

/* Per-worker scratch, reused from task to task. */
typedef struct lod_scratch {
    uint32_t *map; /* mesh vertex -> local vertex, UINT32_MAX when unused (mesh vertex_count entries) */
    uint32_t *local_to_mesh;
    size_t local_to_mesh_cap;
    uint8_t *locked;
    size_t locked_cap;
    float *positions;
    size_t positions_cap;
    unsigned int *indices, *simplified;
    size_t indices_cap, simplified_cap;
    uint64_t *edges_in, *edges_out;
    size_t edges_in_cap, edges_out_cap;
    gdr_vec4 *spheres;
    size_t spheres_cap;
    struct meshopt_Meshlet *meshlets;
    size_t meshlets_cap;
    unsigned int *meshlet_vertices;
    size_t meshlet_vertices_cap;
    unsigned char *meshlet_triangles;
    size_t meshlet_triangles_cap;
    uint8_t edge_count[64 * 64];
} lod_scratch;

/* What simplifying one group produced. */
typedef struct group_result {
    int formed;        /* simplified enough: the group is formed and `clusters` replace its members */
    int border_reject; /* simplification moved a locked border */
    int out_of_memory;
    float error;       /* own simplification error plus the largest error its members came with */
    gdr_vec4 sphere;
    uint32_t input_triangles;
    gdr_cluster *clusters; /* offsets relative to the arrays below */
    uint32_t cluster_count;
    uint32_t *vertices;
    uint32_t vertex_count;
    uint8_t *triangles;
    uint32_t triangle_bytes;
} group_result;

typedef struct lod_build {
    gdr_mesh *mesh;
    gdr_lod_options opt;
    gdr_thread_pool *pool;
    uint32_t worker_base; /* worker index offset of this build's scratch (0: draws progress) */
    lod_scratch *scratch;
    uint32_t scratch_count;
    uint32_t *position_id; /* mesh vertex -> id of its position (vertices with equal coordinates share it) */
    uint32_t position_count;
    uint32_t *owner;       /* position id -> group using it in this step, OWNER_SHARED or OWNER_NONE */
    float min_error;
    uint64_t group_triangles; /* triangles a group aims at: group_size average level-0 clusters */
    lod_progress *progress;
    uint64_t progress_budget;
    atomic_uint_fast64_t progress_given;
    gdr_lod_stats stats;
    int out_of_memory;
    /* the growing result (owned by mesh->clusters' arrays once done) */
    gdr_cluster *clusters;
    size_t cluster_count, cluster_cap;
    uint32_t *vertices;
    size_t vertex_count, vertex_cap;
    uint8_t *triangles;
    size_t triangle_bytes, triangle_cap;
    gdr_cluster_group *groups;
    size_t group_count, group_cap;
    /* one step */
    const uint32_t *members;      /* frontier cluster ids ordered by group */
    const uint32_t *member_start; /* group g: members[member_start[g] .. member_start[g + 1]) */
    group_result *results;
    const uint32_t *frontier;
    uint32_t frontier_count;
    key_record *edge_records;      /* boundary edges of frontier clusters, per chunk */
    uint32_t *edge_record_counts;  /* per frontier cluster */
} lod_build;

static void progress_add(lod_build *b, uint64_t amount, uint32_t worker)
{
    if (!b->progress)
        return;
    atomic_fetch_add(&b->progress_given, amount);
    uint64_t done = atomic_fetch_add(&b->progress->done, amount) + amount;
    if (b->worker_base + worker == 0)
        gdr_progress_update(&b->progress->bar, done);
}

static void scratch_free(lod_scratch *s)
{
    free(s->map);
    free(s->local_to_mesh);
    free(s->locked);
    free(s->positions);
    free(s->indices);
    free(s->simplified);
    free(s->edges_in);
    free(s->edges_out);
    free(s->spheres);
    free(s->meshlets);
    free(s->meshlet_vertices);
    free(s->meshlet_triangles);
}

/* --- boundary edges and the cluster graph -------------------------------------------------------- */

/* Key of the undirected edge between two positions. */
static uint64_t edge_key(uint32_t a, uint32_t b) { return a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a; }

static const uint8_t *cluster_triangles(const lod_build *b, const gdr_cluster *c) { return b->triangles + c->triangle_offset; }
static const uint32_t *cluster_vertices(const lod_build *b, const gdr_cluster *c) { return b->vertices + c->vertex_offset; }

/* The edges of frontier cluster f that no other triangle of the cluster shares, as position keys;
 * edges between equal positions are left out. First counted (b->edge_records NULL) into
 * b->edge_record_counts[f], then written from b->edge_record_counts[f] on. */
static void boundary_edges_task(void *user, uint32_t f, uint32_t worker)
{
    lod_build *b = user;
    lod_scratch *s = &b->scratch[worker];
    const gdr_cluster *c = &b->clusters[b->frontier[f]];
    const uint8_t *t = cluster_triangles(b, c);
    const uint32_t *v = cluster_vertices(b, c);
    uint32_t n = c->triangle_count * 3;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t a = t[i], e = t[i - i % 3 + (i % 3 + 1) % 3];
        uint32_t lo = a < e ? a : e, hi = a < e ? e : a;
        if (s->edge_count[lo * 64 + hi] < 255)
            s->edge_count[lo * 64 + hi]++;
    }
    key_record *out = b->edge_records ? b->edge_records + b->edge_record_counts[f] : NULL;
    uint32_t count = 0;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t a = t[i], e = t[i - i % 3 + (i % 3 + 1) % 3];
        uint32_t lo = a < e ? a : e, hi = a < e ? e : a;
        if (s->edge_count[lo * 64 + hi] == 1) {
            uint32_t pa = b->position_id[v[a]], pe = b->position_id[v[e]];
            if (pa != pe && out)
                out[count] = (key_record){.key = edge_key(pa, pe), .value = f};
            count += pa != pe;
        }
    }
    for (uint32_t i = 0; i < n; i++) {
        uint32_t a = t[i], e = t[i - i % 3 + (i % 3 + 1) % 3];
        s->edge_count[(a < e ? a : e) * 64 + (a < e ? e : a)] = 0;
    }
    if (!out)
        b->edge_record_counts[f] = count;
}

/* The frontier's cluster graph in METIS's CSR form (edge weight: shared edge count). */
typedef struct cluster_graph {
    idx_t *xadj, *adjncy, *adjwgt;
} cluster_graph;

static void graph_free(cluster_graph *g)
{
    free(g->xadj);
    free(g->adjncy);
    free(g->adjwgt);
}

static int build_graph(lod_build *b, cluster_graph *g)
{
    uint32_t n = b->frontier_count;
    b->edge_record_counts = malloc((size_t)n * sizeof *b->edge_record_counts);
    if (!b->edge_record_counts)
        return 0;
    gdr_thread_pool_run(b->pool, n, boundary_edges_task, b);
    size_t total = 0;
    for (uint32_t f = 0; f < n; f++) {
        uint32_t c = b->edge_record_counts[f];
        b->edge_record_counts[f] = (uint32_t)total;
        total += c;
    }
    b->edge_records = malloc((total ? total : 1) * sizeof *b->edge_records);
    if (!b->edge_records)
        return 0;
    gdr_thread_pool_run(b->pool, n, boundary_edges_task, b);
    key_record *edges = b->edge_records;
    key_record *tmp = malloc((total ? total : 1) * sizeof *tmp);
    if (!tmp)
        return 0;
    radix_sort(edges, tmp, total);
    /* Pairs of distinct clusters that share an edge, both ways. */
    size_t pair_count = 0;
    for (size_t i = 0; i < total;) {
        size_t j = i + 1;
        while (j < total && edges[j].key == edges[i].key)
            j++;
        for (size_t x = i; x < j; x++)
            for (size_t y = x + 1; y < j; y++)
                pair_count += edges[x].value != edges[y].value ? 2 : 0;
        i = j;
    }
    key_record *pairs = malloc((pair_count ? pair_count : 1) * sizeof *pairs);
    key_record *pairs_tmp = malloc((pair_count ? pair_count : 1) * sizeof *pairs_tmp);
    if (!pairs || !pairs_tmp) {
        free(tmp);
        free(pairs);
        free(pairs_tmp);
        return 0;
    }
    size_t p = 0;
    for (size_t i = 0; i < total;) {
        size_t j = i + 1;
        while (j < total && edges[j].key == edges[i].key)
            j++;
        for (size_t x = i; x < j; x++)
            for (size_t y = x + 1; y < j; y++)
                if (edges[x].value != edges[y].value) {
                    pairs[p++] = (key_record){.key = (uint64_t)edges[x].value << 32 | edges[y].value};
                    pairs[p++] = (key_record){.key = (uint64_t)edges[y].value << 32 | edges[x].value};
                }
        i = j;
    }
    free(tmp);
    radix_sort(pairs, pairs_tmp, pair_count);
    free(pairs_tmp);
    g->xadj = calloc((size_t)n + 1, sizeof *g->xadj);
    g->adjncy = malloc((pair_count ? pair_count : 1) * sizeof *g->adjncy);
    g->adjwgt = malloc((pair_count ? pair_count : 1) * sizeof *g->adjwgt);
    if (!g->xadj || !g->adjncy || !g->adjwgt) {
        free(pairs);
        return 0;
    }
    size_t m = 0;
    for (size_t i = 0; i < pair_count;) {
        size_t j = i + 1;
        while (j < pair_count && pairs[j].key == pairs[i].key)
            j++;
        uint32_t from = (uint32_t)(pairs[i].key >> 32), to = (uint32_t)pairs[i].key;
        g->adjncy[m] = (idx_t)to;
        g->adjwgt[m] = (idx_t)(j - i);
        g->xadj[from + 1]++;
        m++;
        i = j;
    }
    for (uint32_t f = 0; f < n; f++)
        g->xadj[f + 1] += g->xadj[f];
    free(pairs);
    return 1;
}

/* METIS keeps its random state in globals: one partition at a time, always from the same seed. */
static pthread_mutex_t metis_lock = PTHREAD_MUTEX_INITIALIZER;

/* Partitions the frontier into groups of neighbours holding about as many triangles as
 * group_size level-0 clusters (METIS balances triangle counts): part[f] in [0, parts). Weighing by
 * triangles keeps groups large when simplified clusters come out smaller than level-0 ones, so the
 * share of locked border in a group does not grow from step to step. Recursive bisection: with
 * parts of four clusters it cuts fewer edges than METIS_PartGraphKway here and runs 4x faster. */
static gdr_status partition(lod_build *b, idx_t *part, uint32_t *out_parts, gdr_error *err)
{
    uint32_t n = b->frontier_count;
    uint64_t triangles = 0;
    for (uint32_t f = 0; f < n; f++)
        triangles += b->clusters[b->frontier[f]].triangle_count;
    uint64_t parts64 = (triangles + b->group_triangles - 1) / b->group_triangles;
    uint32_t parts = (uint32_t)(parts64 < (n + 1) / 2 ? parts64 : (n + 1) / 2);
    if (parts <= 1) {
        memset(part, 0, n * sizeof *part);
        *out_parts = 1;
        return GDR_OK;
    }
    cluster_graph g = {0};
    if (!build_graph(b, &g)) {
        graph_free(&g);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory for the cluster graph",
                             b->mesh->name);
    }
    idx_t *weights = malloc((size_t)n * sizeof *weights);
    if (!weights) {
        graph_free(&g);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory for the cluster graph",
                             b->mesh->name);
    }
    for (uint32_t f = 0; f < n; f++)
        weights[f] = (idx_t)b->clusters[b->frontier[f]].triangle_count;
    idx_t nvtxs = (idx_t)n, ncon = 1, nparts = (idx_t)parts, objval = 0;
    idx_t options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    options[METIS_OPTION_SEED] = 1;
    options[METIS_OPTION_NUMBERING] = 0;
    pthread_mutex_lock(&metis_lock);
    int r = METIS_PartGraphRecursive(&nvtxs, &ncon, g.xadj, g.adjncy, weights, NULL, g.adjwgt, &nparts, NULL, NULL,
                                     options, &objval, part);
    pthread_mutex_unlock(&metis_lock);
    graph_free(&g);
    free(weights);
    if (r != METIS_OK)
        return gdr_error_set(err, r == METIS_ERROR_MEMORY ? GDR_ERROR_OUT_OF_MEMORY : GDR_ERROR_INVALID_ARGUMENT,
                             "mesh '%s': METIS_PartGraphRecursive failed (%d) on %u clusters in %u parts", b->mesh->name,
                             r, n, parts);
    for (uint32_t f = 0; f < n; f++)
        if (part[f] < 0 || (uint32_t)part[f] >= parts)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': METIS returned part %d of %u",
                                 b->mesh->name, (int)part[f], parts);
    *out_parts = parts;
    return GDR_OK;
}

/* --- simplifying one group -------------------------------------------------------------------- */

#define RESERVE(s, field, need) reserve(&(s)->field, &(s)->field##_cap, (need), sizeof *(s)->field)

/* The sphere and error that group g would have: over its members and the groups they came from. */
static void group_bounds(lod_build *b, lod_scratch *s, uint32_t first, uint32_t count, group_result *r)
{
    uint32_t n = 0;
    float child_error = 0.0f;
    for (uint32_t i = 0; i < count; i++) {
        const gdr_cluster *c = &b->clusters[b->members[first + i]];
        s->spheres[n++] = c->sphere;
        if (c->refined_group != GDR_NO_INDEX) {
            const gdr_cluster_group *from = &b->groups[c->refined_group];
            s->spheres[n++] = from->sphere;
            child_error = from->error > child_error ? from->error : child_error;
        }
    }
    r->sphere = enclosing_sphere(s->spheres, n);
    r->error = child_error;
}

/* Every border edge of the input (an edge between two locked positions that no other input
 * triangle runs the other way) must still be there: else the group would no longer meet its
 * neighbours exactly. (A locked vertex may lose all its triangles, when they only touched other
 * groups at that point: that leaves no gap.) */
static int border_kept(lod_build *b, lod_scratch *s, size_t in_count, size_t out_count)
{
    size_t na = 0, nb = 0;
    for (int pass = 0; pass < 2; pass++) {
        const unsigned int *idx = pass ? s->simplified : s->indices;
        size_t count = pass ? out_count : in_count;
        uint64_t *keys = pass ? s->edges_out : s->edges_in;
        size_t k = 0;
        for (size_t i = 0; i < count; i++) {
            unsigned int a = idx[i], e = idx[i - i % 3 + (i % 3 + 1) % 3];
            if (s->locked[a] && s->locked[e])
                keys[k++] = (uint64_t)b->position_id[s->local_to_mesh[a]] << 32 |
                            b->position_id[s->local_to_mesh[e]];
        }
        qsort(keys, k, sizeof *keys, compare_u64);
        *(pass ? &nb : &na) = k;
    }
    for (size_t i = 0; i < na; i++) {
        uint64_t reverse = s->edges_in[i] << 32 | s->edges_in[i] >> 32;
        if ((uint32_t)s->edges_in[i] == (uint32_t)(s->edges_in[i] >> 32))
            continue;
        if (!contains_u64(s->edges_in, na, reverse) && !contains_u64(s->edges_out, nb, s->edges_in[i]))
            return 0;
    }
    return 1;
}

/* Splits the simplified triangles into clusters (meshoptimizer), written to r. */
static int split_into_clusters(lod_build *b, lod_scratch *s, size_t index_count, uint32_t local_count,
                               group_result *r)
{
    const uint32_t max_v = GDR_CLUSTER_MAX_VERTICES, max_t = GDR_CLUSTER_MAX_TRIANGLES;
    size_t bound = meshopt_buildMeshletsBound(index_count, max_v, max_t);
    if (!RESERVE(s, meshlets, bound) || !RESERVE(s, meshlet_vertices, bound * max_v) ||
        !RESERVE(s, meshlet_triangles, bound * max_t * 3))
        return 0;
    size_t count = meshopt_buildMeshlets(s->meshlets, s->meshlet_vertices, s->meshlet_triangles, s->simplified,
                                         index_count, s->positions, local_count, sizeof(float) * 3, max_v, max_t,
                                         LOD_CONE_WEIGHT);
    size_t vertex_total = 0, triangle_bytes = 0;
    for (size_t i = 0; i < count; i++) {
        vertex_total += s->meshlets[i].vertex_count;
        triangle_bytes += align4((size_t)s->meshlets[i].triangle_count * 3);
    }
    r->clusters = malloc(count * sizeof *r->clusters);
    r->vertices = malloc(vertex_total * sizeof *r->vertices);
    r->triangles = calloc(triangle_bytes, 1);
    if (!r->clusters || !r->vertices || !r->triangles)
        return 0;
    size_t vo = 0, to = 0;
    for (size_t i = 0; i < count; i++) {
        const struct meshopt_Meshlet *m = &s->meshlets[i];
        gdr_cluster *c = &r->clusters[i];
        *c = (gdr_cluster){.vertex_offset = (uint32_t)vo, .triangle_offset = (uint32_t)to,
                           .vertex_count = m->vertex_count, .triangle_count = m->triangle_count,
                           .group = GDR_NO_INDEX, .refined_group = GDR_NO_INDEX};
        for (uint32_t k = 0; k < m->vertex_count; k++)
            r->vertices[vo + k] = s->local_to_mesh[s->meshlet_vertices[m->vertex_offset + k]];
        memcpy(r->triangles + to, s->meshlet_triangles + m->triangle_offset, (size_t)m->triangle_count * 3);
        cluster_bounds(c, r->vertices + vo, r->triangles + to, b->mesh);
        vo += m->vertex_count;
        to += align4((size_t)m->triangle_count * 3);
    }
    r->cluster_count = (uint32_t)count;
    r->vertex_count = (uint32_t)vo;
    r->triangle_bytes = (uint32_t)to;
    return 1;
}

static void simplify_group_task(void *user, uint32_t g, uint32_t worker)
{
    lod_build *b = user;
    lod_scratch *s = &b->scratch[worker];
    group_result *r = &b->results[g];
    uint32_t first = b->member_start[g], count = b->member_start[g + 1] - first;
    const gdr_vec3 *mesh_positions = b->mesh->positions;

    size_t triangles = 0;
    for (uint32_t i = 0; i < count; i++)
        triangles += b->clusters[b->members[first + i]].triangle_count;
    r->input_triangles = (uint32_t)triangles;
    size_t index_count = triangles * 3;
    if (!RESERVE(s, spheres, (size_t)count * 2) || !RESERVE(s, indices, index_count) ||
        !RESERVE(s, simplified, index_count) || !RESERVE(s, local_to_mesh, index_count) ||
        !RESERVE(s, locked, index_count) || !RESERVE(s, edges_in, index_count) ||
        !RESERVE(s, edges_out, index_count) || !RESERVE(s, positions, index_count * 9)) {
        r->out_of_memory = 1;
        return;
    }
    group_bounds(b, s, first, count, r);

    /* Merge: the members' triangles over a compact local vertex list. */
    uint32_t local_count = 0;
    size_t k = 0;
    for (uint32_t i = 0; i < count; i++) {
        const gdr_cluster *c = &b->clusters[b->members[first + i]];
        const uint8_t *t = cluster_triangles(b, c);
        const uint32_t *v = cluster_vertices(b, c);
        for (uint32_t j = 0; j < c->triangle_count * 3; j++) {
            uint32_t mv = v[t[j]];
            if (s->map[mv] == UINT32_MAX) {
                s->map[mv] = local_count;
                s->local_to_mesh[local_count++] = mv;
            }
            s->indices[k++] = s->map[mv];
        }
    }
    /* Lock what other groups share. meshoptimizer 0.18 can only lock topological borders, which
     * would also freeze the mesh's own open edges; instead each shared vertex gets two unused
     * copies of its position, and the simplifier never moves a position held by more than two
     * vertices. border_kept() checks that it held. */
    uint32_t padded = local_count;
    for (uint32_t l = 0; l < local_count; l++) {
        uint32_t mv = s->local_to_mesh[l];
        s->map[mv] = UINT32_MAX;
        const gdr_vec3 p = mesh_positions[mv];
        memcpy(s->positions + (size_t)l * 3, &p, sizeof p);
        s->locked[l] = b->owner[b->position_id[mv]] == OWNER_SHARED;
    }
    for (uint32_t l = 0; l < local_count; l++)
        if (s->locked[l])
            for (int copy = 0; copy < 2; copy++, padded++)
                memcpy(s->positions + (size_t)padded * 3, s->positions + (size_t)l * 3, sizeof(float) * 3);

    size_t target = (size_t)((double)triangles * b->opt.target_ratio) * 3;
    target = target < 3 ? 3 : target;
    float relative_error = 0.0f;
    size_t out_count = meshopt_simplify(s->simplified, s->indices, index_count, s->positions, padded,
                                        sizeof(float) * 3, target, FLT_MAX, 0, &relative_error);
    int enough = out_count > 0 && (double)out_count <= (double)index_count * LOD_MAX_KEPT_SHARE;
    for (size_t i = 0; i < out_count && enough; i++)
        enough = s->simplified[i] < local_count;
    if (enough && !border_kept(b, s, index_count, out_count)) {
        r->border_reject = 1;
        enough = 0;
    }
    progress_add(b, triangles / 2, worker);
    if (!enough)
        return;
    float scale = meshopt_simplifyScale(s->positions, local_count, sizeof(float) * 3);
    r->error = r->error + relative_error * scale;
    if (!split_into_clusters(b, s, out_count, local_count, r)) {
        r->out_of_memory = 1;
        return;
    }
    r->formed = 1;
}

static void result_free(group_result *r)
{
    free(r->clusters);
    free(r->vertices);
    free(r->triangles);
    memset(r, 0, sizeof *r);
}

/* --- one mesh ----------------------------------------------------------------------------------- */

static int push_group(lod_build *b, gdr_cluster_group g)
{
    if (!reserve(&b->groups, &b->group_cap, b->group_count + 1, sizeof *b->groups))
        return 0;
    b->groups[b->group_count++] = g;
    return 1;
}

static int push_cluster(lod_build *b, gdr_cluster c)
{
    if (!reserve(&b->clusters, &b->cluster_cap, b->cluster_count + 1, sizeof *b->clusters))
        return 0;
    b->clusters[b->cluster_count++] = c;
    return 1;
}

/* Appends a formed group's clusters, made from group `group`. */
static int append_result(lod_build *b, const group_result *r, uint32_t group, uint32_t *frontier,
                         uint32_t *frontier_count)
{
    if (!reserve(&b->vertices, &b->vertex_cap, b->vertex_count + r->vertex_count, sizeof *b->vertices) ||
        !reserve(&b->triangles, &b->triangle_cap, b->triangle_bytes + r->triangle_bytes, 1) ||
        b->vertex_count + r->vertex_count > UINT32_MAX || b->triangle_bytes + r->triangle_bytes > UINT32_MAX)
        return 0;
    for (uint32_t i = 0; i < r->cluster_count; i++) {
        gdr_cluster c = r->clusters[i];
        c.vertex_offset += (uint32_t)b->vertex_count;
        c.triangle_offset += (uint32_t)b->triangle_bytes;
        c.refined_group = group;
        frontier[(*frontier_count)++] = (uint32_t)b->cluster_count;
        if (!push_cluster(b, c))
            return 0;
    }
    memcpy(b->vertices + b->vertex_count, r->vertices, (size_t)r->vertex_count * sizeof *b->vertices);
    memcpy(b->triangles + b->triangle_bytes, r->triangles, r->triangle_bytes);
    b->vertex_count += r->vertex_count;
    b->triangle_bytes += r->triangle_bytes;
    return 1;
}

/* Forms the root group over the frontier. */
static int form_root(lod_build *b, uint32_t depth)
{
    lod_scratch *s = &b->scratch[0];
    if (!reserve(&s->spheres, &s->spheres_cap, (size_t)b->frontier_count * 2, sizeof *s->spheres))
        return 0;
    uint32_t n = 0;
    for (uint32_t f = 0; f < b->frontier_count; f++) {
        const gdr_cluster *c = &b->clusters[b->frontier[f]];
        s->spheres[n++] = c->sphere;
        if (c->refined_group != GDR_NO_INDEX)
            s->spheres[n++] = b->groups[c->refined_group].sphere;
        b->stats.root_triangles += c->triangle_count;
    }
    uint32_t root = (uint32_t)b->group_count;
    if (!push_group(b, (gdr_cluster_group){.sphere = enclosing_sphere(s->spheres, n), .error = INFINITY,
                                           .depth = depth}))
        return 0;
    for (uint32_t f = 0; f < b->frontier_count; f++)
        b->clusters[b->frontier[f]].group = root;
    b->stats.root_clusters = b->frontier_count;
    return 1;
}

/* One step over the frontier: partition, simplify the groups, form those that simplified. Sets
 * *progress when at least one group was formed. next receives the next frontier. */
static gdr_status lod_step(lod_build *b, uint32_t depth, uint32_t *next, uint32_t *next_count, int *progress,
                           gdr_error *err)
{
    uint32_t n = b->frontier_count;
    idx_t *part = malloc((size_t)n * sizeof *part);
    uint32_t *members = malloc((size_t)n * sizeof *members);
    uint32_t *start = NULL;
    gdr_status status = GDR_OK;
    uint32_t parts = 0;
    if (!part || !members) {
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory", b->mesh->name);
        goto done;
    }
    status = partition(b, part, &parts, err);
    free(b->edge_records);
    free(b->edge_record_counts);
    b->edge_records = NULL;
    b->edge_record_counts = NULL;
    if (status != GDR_OK)
        goto done;
    /* Groups are the non-empty parts in order; members ordered by group, stable. */
    start = calloc((size_t)parts + 1, sizeof *start);
    b->results = calloc(parts, sizeof *b->results);
    if (!start || !b->results) {
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory", b->mesh->name);
        goto done;
    }
    for (uint32_t f = 0; f < n; f++)
        start[part[f]]++; /* members per part */
    uint32_t groups = 0;
    for (uint32_t p = 0; p < parts; p++) {
        uint32_t size = start[p];
        start[p] = groups; /* part -> group */
        groups += size > 0;
    }
    for (uint32_t f = 0; f < n; f++)
        part[f] = (idx_t)start[part[f]];
    memset(start, 0, ((size_t)parts + 1) * sizeof *start);
    for (uint32_t f = 0; f < n; f++)
        start[part[f] + 1]++;
    for (uint32_t g = 0; g < groups; g++)
        start[g + 1] += start[g];
    for (uint32_t f = 0; f < n; f++)
        members[start[part[f]]++] = b->frontier[f];
    for (uint32_t g = groups; g > 0; g--) /* start[g] now holds the end of group g: shift back */
        start[g] = start[g - 1];
    start[0] = 0;
    /* Which positions each group shares with another. */
    for (uint32_t g = 0; g < groups; g++)
        for (uint32_t i = start[g]; i < start[g + 1]; i++) {
            const gdr_cluster *c = &b->clusters[members[i]];
            const uint32_t *v = cluster_vertices(b, c);
            for (uint32_t j = 0; j < c->vertex_count; j++) {
                uint32_t *o = &b->owner[b->position_id[v[j]]];
                *o = *o == OWNER_NONE || *o == g ? g : OWNER_SHARED;
            }
        }
    b->members = members;
    b->member_start = start;
    gdr_thread_pool_run(b->pool, groups, simplify_group_task, b);
    for (uint32_t i = 0; i < n; i++) {
        const gdr_cluster *c = &b->clusters[members[i]];
        const uint32_t *v = cluster_vertices(b, c);
        for (uint32_t j = 0; j < c->vertex_count; j++)
            b->owner[b->position_id[v[j]]] = OWNER_NONE;
    }

    uint32_t formed = 0;
    for (uint32_t g = 0; g < groups; g++) {
        if (b->results[g].out_of_memory) {
            status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory simplifying a group",
                                   b->mesh->name);
            goto done;
        }
        formed += (uint32_t)b->results[g].formed;
        if (!b->results[g].formed) {
            b->stats.stuck_groups++;
            b->stats.border_rejects += (uint64_t)b->results[g].border_reject;
        }
    }
    *progress = formed > 0;
    *next_count = 0;
    if (!formed)
        goto done;
    for (uint32_t g = 0; g < groups; g++) {
        group_result *r = &b->results[g];
        uint32_t count = start[g + 1] - start[g];
        if (!r->formed && depth > 0) {
            /* Regrouped at the next step with other neighbours. */
            for (uint32_t i = start[g]; i < start[g + 1]; i++)
                next[(*next_count)++] = members[i];
            continue;
        }
        uint32_t id = (uint32_t)b->group_count;
        float error = r->error > b->min_error ? r->error : b->min_error;
        if (!push_group(b, (gdr_cluster_group){.sphere = r->sphere, .error = error, .depth = depth}))
            goto oom;
        for (uint32_t i = start[g]; i < start[g + 1]; i++)
            b->clusters[members[i]].group = id;
        if (r->formed) {
            if (!append_result(b, r, id, next, next_count))
                goto oom;
        } else {
            /* Step 0: the members pass through unchanged, sharing their data, so that level-0
             * clusters only ever belong to step-0 groups (and stay contiguous). */
            for (uint32_t i = start[g]; i < start[g + 1]; i++) {
                gdr_cluster c = b->clusters[members[i]];
                c.group = GDR_NO_INDEX;
                c.refined_group = id;
                next[(*next_count)++] = (uint32_t)b->cluster_count;
                if (!push_cluster(b, c))
                    goto oom;
            }
            b->stats.passthrough_clusters += count;
        }
    }
    goto done;
oom:
    status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory for the DAG", b->mesh->name);
done:
    if (b->results)
        for (uint32_t g = 0; g < parts; g++)
            result_free(&b->results[g]);
    free(b->results);
    b->results = NULL;
    free(part);
    free(members);
    free(start);
    return status;
}

static int compare_by_data(const void *a, const void *b)
{
    const gdr_cluster *x = a, *y = b;
    if (x->triangle_offset != y->triangle_offset)
        return x->triangle_offset < y->triangle_offset ? -1 : 1;
    return x->vertex_offset < y->vertex_offset ? -1 : x->vertex_offset > y->vertex_offset;
}

/* Drops any DAG of c: back to level 0 in its original data extents, groups freed. Level 0 is put
 * back in data order, the order gdr_meshlets_build made it in (a DAG build reorders it by
 * group), so a rebuild gives the same bytes as the first build. */
static void truncate_to_level0(gdr_mesh_clusters *c)
{
    size_t vertex_end = 0, triangle_end = 0;
    for (uint32_t i = 0; i < c->level0_cluster_count; i++) {
        const gdr_cluster *k = &c->clusters[i];
        size_t ve = (size_t)k->vertex_offset + k->vertex_count;
        size_t te = align4((size_t)k->triangle_offset + (size_t)k->triangle_count * 3);
        vertex_end = ve > vertex_end ? ve : vertex_end;
        triangle_end = te > triangle_end ? te : triangle_end;
    }
    if (c->cluster_count > c->level0_cluster_count || c->group_count) {
        c->cluster_count = c->level0_cluster_count;
        c->vertex_count = (uint32_t)(vertex_end < c->vertex_count ? vertex_end : c->vertex_count);
        c->triangle_byte_count = (uint32_t)(triangle_end < c->triangle_byte_count ? triangle_end
                                                                                   : c->triangle_byte_count);
    }
    for (uint32_t i = 0; i < c->cluster_count; i++)
        c->clusters[i].group = c->clusters[i].refined_group = GDR_NO_INDEX;
    if (c->cluster_count > 1)
        qsort(c->clusters, c->cluster_count, sizeof *c->clusters, compare_by_data);
    free(c->groups);
    c->groups = NULL;
    c->group_count = 0;
    c->dag_depth = 0;
}

/* Level 0 must be whole and in range before anything reads it. */
static gdr_status check_level0(const gdr_mesh *mesh, gdr_error *err)
{
    const gdr_mesh_clusters *c = &mesh->clusters;
    if (!c->vertices || !c->triangles)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': clusters without data", mesh->name);
    if (!mesh->positions || mesh->vertex_count == 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': no vertex positions", mesh->name);
    for (uint32_t i = 0; i < c->level0_cluster_count; i++) {
        const gdr_cluster *k = &c->clusters[i];
        if (k->vertex_count == 0 || k->vertex_count > GDR_CLUSTER_MAX_VERTICES || k->triangle_count == 0 ||
            k->triangle_count > GDR_CLUSTER_MAX_TRIANGLES ||
            (uint64_t)k->vertex_offset + k->vertex_count > c->vertex_count ||
            (uint64_t)k->triangle_offset + (uint64_t)k->triangle_count * 3 > c->triangle_byte_count)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                 "mesh '%s': clusters[%u]: counts or offsets out of range", mesh->name, i);
        for (uint32_t j = 0; j < k->triangle_count * 3; j++)
            if (c->triangles[k->triangle_offset + j] >= k->vertex_count)
                return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                     "mesh '%s': clusters[%u]: triangle corner %u out of range", mesh->name, i, j);
        for (uint32_t j = 0; j < k->vertex_count; j++)
            if (c->vertices[k->vertex_offset + j] >= mesh->vertex_count)
                return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                     "mesh '%s': clusters[%u]: vertex %u out of range", mesh->name, i, j);
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const gdr_vec3 p = mesh->positions[v];
        if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': position %u is not finite", mesh->name,
                                 v);
    }
    return GDR_OK;
}

static gdr_status resolve_options(const gdr_lod_options *in, gdr_lod_options *out, gdr_error *err)
{
    gdr_lod_options o = in ? *in : (gdr_lod_options){0};
    if (o.group_size == 0)
        o.group_size = 4;
    if (o.target_ratio == 0.0f)
        o.target_ratio = 0.5f;
    if (o.group_size < 2 || o.group_size > LOD_MAX_GROUP_SIZE)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "LOD options: group_size %u is outside [2, %u]",
                             o.group_size, LOD_MAX_GROUP_SIZE);
    if (!(o.target_ratio > 0.0f && o.target_ratio < (float)LOD_MAX_KEPT_SHARE))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "LOD options: target_ratio %g is outside (0, %g)",
                             (double)o.target_ratio, LOD_MAX_KEPT_SHARE);
    if (o.thread_count > GDR_THREAD_POOL_MAX_THREADS)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "LOD options: thread_count %u exceeds %u",
                             o.thread_count, GDR_THREAD_POOL_MAX_THREADS);
    *out = o;
    return GDR_OK;
}

/* Orders the clusters by group (stable), so each group's clusters are contiguous, and fills in
 * first_cluster / cluster_count. Level-0 clusters only belong to step-0 groups (or to a root
 * formed at step 0), which come first, so level 0 stays in front. */
static int order_by_group(lod_build *b)
{
    size_t n = b->cluster_count;
    gdr_cluster *sorted = malloc(n * sizeof *sorted);
    uint32_t *start = calloc(b->group_count + 1, sizeof *start);
    if (!sorted || !start) {
        free(sorted);
        free(start);
        return 0;
    }
    for (size_t i = 0; i < n; i++)
        start[b->clusters[i].group + 1]++;
    for (size_t g = 0; g < b->group_count; g++) {
        b->groups[g].first_cluster = start[g];
        b->groups[g].cluster_count = start[g + 1];
        start[g + 1] += start[g];
    }
    for (size_t i = 0; i < n; i++)
        sorted[start[b->clusters[i].group]++] = b->clusters[i];
    free(start);
    free(b->clusters);
    b->clusters = sorted;
    b->cluster_cap = n;
    return 1;
}

/* Builds the DAG of b->mesh (whose level 0 is checked); scratch is set up here. */
static gdr_status build_mesh(lod_build *b, gdr_error *err)
{
    gdr_mesh *mesh = b->mesh;
    gdr_mesh_clusters *mc = &mesh->clusters;
    gdr_status status = GDR_OK;
    uint32_t level0 = mc->level0_cluster_count;
    uint32_t *frontier = NULL, *next = NULL;

    b->clusters = mc->clusters;
    b->cluster_count = b->cluster_cap = mc->cluster_count;
    b->vertices = mc->vertices;
    b->vertex_count = b->vertex_cap = mc->vertex_count;
    b->triangles = mc->triangles;
    b->triangle_bytes = b->triangle_cap = mc->triangle_byte_count;
    mc->clusters = NULL;
    mc->vertices = NULL;
    mc->triangles = NULL;
    b->min_error = fmaxf(mesh->bounds.w * LOD_MIN_ERROR_SCALE, FLT_MIN);

    b->position_id = malloc((size_t)mesh->vertex_count * sizeof *b->position_id);
    b->scratch = calloc(b->scratch_count, sizeof *b->scratch);
    if (!b->position_id || !b->scratch)
        goto oom;
    b->position_count = (uint32_t)meshopt_generateVertexRemap(b->position_id, NULL, mesh->vertex_count,
                                                              mesh->positions, mesh->vertex_count, sizeof(gdr_vec3));
    b->owner = malloc((size_t)b->position_count * sizeof *b->owner);
    if (!b->owner)
        goto oom;
    memset(b->owner, 0xff, (size_t)b->position_count * sizeof *b->owner);
    for (uint32_t w = 0; w < b->scratch_count; w++) {
        b->scratch[w].map = malloc((size_t)mesh->vertex_count * sizeof *b->scratch[w].map);
        if (!b->scratch[w].map)
            goto oom;
        memset(b->scratch[w].map, 0xff, (size_t)mesh->vertex_count * sizeof *b->scratch[w].map);
    }
    /* A frontier never holds more clusters than level 0 plus what one step adds. */
    size_t frontier_cap = level0;
    frontier = malloc(frontier_cap * sizeof *frontier);
    if (!frontier)
        goto oom;
    for (uint32_t i = 0; i < level0; i++)
        frontier[i] = i;
    b->frontier_count = level0;
    for (uint32_t i = 0; i < level0; i++)
        b->stats.input_triangles += b->clusters[i].triangle_count;
    b->progress_budget = b->stats.input_triangles;
    b->group_triangles = (b->stats.input_triangles * b->opt.group_size + level0 - 1) / level0;

    gdr_lod_stop stop = GDR_LOD_STOP_NONE;
    uint32_t depth = 0;
    for (;; depth++) {
        b->frontier = frontier;
        if (b->frontier_count == 1) {
            stop = GDR_LOD_STOP_SINGLE_CLUSTER;
            break;
        }
        if (depth >= GDR_LOD_MAX_LEVELS) {
            stop = GDR_LOD_STOP_LEVEL_LIMIT;
            break;
        }
        /* The next frontier: members carried or passed through, plus new clusters, of which a
         * group makes fewer than it had triangles. */
        size_t bound = 0;
        for (uint32_t f = 0; f < b->frontier_count; f++)
            bound += b->clusters[frontier[f]].triangle_count;
        free(next);
        next = malloc((bound + b->frontier_count) * sizeof *next);
        if (!next)
            goto oom;
        uint32_t next_count = 0;
        int progressed = 0;
        status = lod_step(b, depth, next, &next_count, &progressed, err);
        if (status != GDR_OK)
            goto fail;
        if (!progressed) {
            stop = GDR_LOD_STOP_NO_PROGRESS;
            break;
        }
        uint32_t *t = frontier;
        frontier = next;
        next = t;
        b->frontier_count = next_count;
    }
    b->frontier = frontier;
    if (!form_root(b, depth) || !order_by_group(b))
        goto oom;
    /* Hand the result to the mesh (arrays sized exactly). */
    gdr_cluster *cl = realloc(b->clusters, b->cluster_count * sizeof *cl);
    uint32_t *vx = realloc(b->vertices, (b->vertex_count ? b->vertex_count : 1) * sizeof *vx);
    uint8_t *tr = realloc(b->triangles, b->triangle_bytes ? b->triangle_bytes : 1);
    gdr_cluster_group *gr = realloc(b->groups, b->group_count * sizeof *gr);
    b->clusters = cl ? cl : b->clusters;
    b->vertices = vx ? vx : b->vertices;
    b->triangles = tr ? tr : b->triangles;
    b->groups = gr ? gr : b->groups;
    mc->clusters = b->clusters;
    mc->cluster_count = (uint32_t)b->cluster_count;
    mc->vertices = b->vertices;
    mc->vertex_count = (uint32_t)b->vertex_count;
    mc->triangles = b->triangles;
    mc->triangle_byte_count = (uint32_t)b->triangle_bytes;
    mc->groups = b->groups;
    mc->group_count = (uint32_t)b->group_count;
    mc->dag_depth = depth;
    b->clusters = NULL;
    b->vertices = NULL;
    b->triangles = NULL;
    b->groups = NULL;

    b->stats.mesh_count = 1;
    b->stats.stop_counts[stop] = 1;
    b->stats.max_depth = depth;
    b->stats.group_count = mc->group_count;
    b->stats.cluster_count = mc->cluster_count;
    for (uint32_t i = 0; i < mc->cluster_count; i++)
        b->stats.dag_triangles += mc->clusters[i].triangle_count;
    uint64_t given = atomic_load(&b->progress_given);
    progress_add(b, given < b->progress_budget ? b->progress_budget - given : 0, 0);
    goto cleanup;
oom:
    status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory for the LOD DAG", mesh->name);
fail:
    /* Back to level 0, in its original order (only step-0 work touched it). */
    mc->clusters = b->clusters;
    mc->vertices = b->vertices;
    mc->triangles = b->triangles;
    mc->cluster_count = (uint32_t)b->cluster_count;
    mc->vertex_count = (uint32_t)b->vertex_count;
    mc->triangle_byte_count = (uint32_t)b->triangle_bytes;
    truncate_to_level0(mc);
    b->clusters = NULL;
    b->vertices = NULL;
    b->triangles = NULL;
    free(b->groups);
    b->groups = NULL;
    b->group_count = 0;
cleanup:
    free(frontier);
    free(next);
    free(b->position_id);
    free(b->owner);
    if (b->scratch)
        for (uint32_t w = 0; w < b->scratch_count; w++)
            scratch_free(&b->scratch[w]);
    free(b->scratch);
    return status;
}

static void stats_add(gdr_lod_stats *sum, const gdr_lod_stats *s)
{
    sum->mesh_count += s->mesh_count;
    for (int i = 0; i < GDR_LOD_STOP_COUNT; i++)
        sum->stop_counts[i] += s->stop_counts[i];
    sum->max_depth = s->max_depth > sum->max_depth ? s->max_depth : sum->max_depth;
    sum->group_count += s->group_count;
    sum->cluster_count += s->cluster_count;
    sum->input_triangles += s->input_triangles;
    sum->dag_triangles += s->dag_triangles;
    sum->root_clusters += s->root_clusters;
    sum->root_triangles += s->root_triangles;
    sum->stuck_groups += s->stuck_groups;
    sum->border_rejects += s->border_rejects;
    sum->passthrough_clusters += s->passthrough_clusters;
}

/* Builds one mesh's DAG with `pool` (NULL: on the calling thread, as worker `worker`). */
static gdr_status build_one(gdr_mesh *mesh, const gdr_lod_options *o, gdr_thread_pool *pool, uint32_t worker,
                            lod_progress *progress, gdr_lod_stats *stats, gdr_error *err)
{
    const gdr_mesh_clusters *c = &mesh->clusters;
    if (c->level0_cluster_count == 0 || c->level0_cluster_count > c->cluster_count || !c->clusters)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "mesh '%s': the LOD DAG needs level-0 clusters (gdr_meshlets_build)", mesh->name);
    truncate_to_level0(&mesh->clusters);
    gdr_status status = check_level0(mesh, err);
    if (status != GDR_OK)
        return status;
    lod_build b = {.mesh = mesh, .opt = *o, .pool = pool, .worker_base = worker, .progress = progress,
                   .scratch_count = gdr_thread_pool_thread_count(pool)};
    status = build_mesh(&b, err);
    if (status == GDR_OK && stats)
        *stats = b.stats;
    return status;
}

gdr_status gdr_mesh_build_lod_dag(gdr_mesh *mesh, const gdr_lod_options *options, gdr_lod_stats *stats,
                                  gdr_error *err)
{
    if (!mesh)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "gdr_mesh_build_lod_dag: mesh must not be NULL");
    if (stats)
        *stats = (gdr_lod_stats){0};
    gdr_lod_options o;
    gdr_status status = resolve_options(options, &o, err);
    if (status != GDR_OK)
        return status;
    gdr_thread_pool *pool = NULL;
    if (o.thread_count != 1) {
        status = gdr_thread_pool_create(o.thread_count, &pool, err);
        if (status != GDR_OK)
            return status;
    }
    lod_progress progress;
    gdr_progress_begin(&progress.bar, "LOD DAG", mesh->clusters.level0_cluster_count ? mesh->index_count / 3 : 1,
                       o.no_progress);
    atomic_init(&progress.done, 0);
    status = build_one(mesh, &o, pool, 0, &progress, stats, err);
    gdr_progress_end(&progress.bar);
    gdr_thread_pool_destroy(pool);
    return status;
}

/* --- a scene ------------------------------------------------------------------------------------- */

typedef struct scene_job {
    gdr_scene *scene;
    const gdr_lod_options *opt;
    const uint32_t *small; /* mesh indices built one per task */
    lod_progress *progress;
    gdr_lod_stats *stats;  /* per mesh */
    gdr_status *status;    /* per mesh */
    gdr_error *errors;     /* per mesh */
} scene_job;

static void small_mesh_task(void *user, uint32_t i, uint32_t worker)
{
    scene_job *job = user;
    uint32_t m = job->small[i];
    job->status[m] = build_one(&job->scene->meshes[m], job->opt, NULL, worker, job->progress, &job->stats[m],
                               &job->errors[m]);
}

static int needs_dag(const gdr_mesh *m) { return m->clusters.level0_cluster_count > 0 && m->clusters.group_count == 0; }

gdr_status gdr_scene_build_lod(gdr_scene *scene, const gdr_lod_options *options, gdr_lod_stats *stats,
                               gdr_error *err)
{
    if (!scene)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "gdr_scene_build_lod: scene must not be NULL");
    if (stats)
        *stats = (gdr_lod_stats){0};
    gdr_lod_options o;
    gdr_status status = resolve_options(options, &o, err);
    if (status != GDR_OK)
        return status;
    gdr_meshlet_options meshlet_options = {.thread_count = o.thread_count};
    status = gdr_scene_build_clusters(scene, &meshlet_options, err);
    if (status != GDR_OK)
        return status;

    uint32_t n = scene->mesh_count;
    uint32_t *small = malloc((n ? n : 1) * sizeof *small);
    uint8_t *built = calloc(n ? n : 1, 1);
    gdr_lod_stats *mesh_stats = calloc(n ? n : 1, sizeof *mesh_stats);
    gdr_status *statuses = calloc(n ? n : 1, sizeof *statuses);
    gdr_error *errors = calloc(n ? n : 1, sizeof *errors);
    gdr_thread_pool *pool = NULL;
    if (!small || !built || !mesh_stats || !statuses || !errors) {
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "gdr_scene_build_lod: out of memory");
        goto done;
    }
    if (o.thread_count != 1) {
        status = gdr_thread_pool_create(o.thread_count, &pool, err);
        if (status != GDR_OK)
            goto done;
    }
    uint64_t total = 0;
    uint32_t small_count = 0;
    for (uint32_t m = 0; m < n; m++)
        if (needs_dag(&scene->meshes[m])) {
            total += scene->meshes[m].index_count / 3;
            built[m] = 1;
            if (scene->meshes[m].index_count / 3 < LOD_SMALL_MESH_TRIANGLES)
                small[small_count++] = m;
        }
    lod_progress progress;
    gdr_progress_begin(&progress.bar, "LOD DAG", total, o.no_progress);
    atomic_init(&progress.done, 0);
    scene_job job = {.scene = scene, .opt = &o, .small = small, .progress = &progress, .stats = mesh_stats,
                     .status = statuses, .errors = errors};
    gdr_thread_pool_run(pool, small_count, small_mesh_task, &job);
    for (uint32_t m = 0; m < n; m++)
        if (built[m] && scene->meshes[m].index_count / 3 >= LOD_SMALL_MESH_TRIANGLES)
            statuses[m] = build_one(&scene->meshes[m], &o, pool, 0, &progress, &mesh_stats[m], &errors[m]);
    gdr_progress_end(&progress.bar);
    for (uint32_t m = 0; m < n && status == GDR_OK; m++)
        if (built[m] && statuses[m] != GDR_OK)
            status = gdr_error_set(err, statuses[m], "meshes[%u]: %s", m, errors[m].message);
    for (uint32_t m = 0; m < n; m++) {
        if (!built[m])
            continue;
        if (status != GDR_OK)
            truncate_to_level0(&scene->meshes[m].clusters);
        else if (stats)
            stats_add(stats, &mesh_stats[m]);
    }
done:
    gdr_thread_pool_destroy(pool);
    free(small);
    free(built);
    free(mesh_stats);
    free(statuses);
    free(errors);
    return status;
}
