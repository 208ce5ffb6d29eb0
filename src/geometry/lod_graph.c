/* The cluster graph of one DAG step and its partition into groups (METIS). Two clusters are
 * neighbours when they share edges (by position, so attribute seams do not cut them apart); the
 * edge weight is the number of shared edges. */
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include <metis.h>

#include "geometry/lod_internal.h"

_Static_assert(sizeof(idx_t) == sizeof(int32_t), "METIS built with 32-bit idx_t");

/* Key of the undirected edge between two positions. */
static uint64_t edge_key(uint32_t a, uint32_t b) { return a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a; }

/* The edges of frontier cluster f that no other triangle of the cluster shares, as position keys;
 * edges between equal positions are left out. First counted (b->edge_records NULL) into
 * b->edge_record_counts[f], then written from b->edge_record_counts[f] on. */
static void boundary_edges_task(void *user, uint32_t f, uint32_t worker)
{
    lod_build *b = user;
    lod_scratch *s = &b->scratch[worker];
    const gdr_cluster *c = &b->clusters[b->frontier[f]];
    const uint8_t *t = gdr_lod_cluster_triangles(b, c);
    const uint32_t *v = gdr_lod_cluster_vertices(b, c);
    uint32_t n = c->triangle_count * 3;
    uint16_t edge[GDR_CLUSTER_MAX_TRIANGLES * 3]; /* corner i's edge to the next corner: lo * 64 + hi */
    for (uint32_t i = 0; i < n; i += 3)
        for (uint32_t k = 0; k < 3; k++) {
            uint32_t a = t[i + k], e = t[i + (k == 2 ? 0 : k + 1)];
            edge[i + k] = (uint16_t)(a < e ? a * 64 + e : e * 64 + a);
        }
    for (uint32_t i = 0; i < n; i++)
        if (s->edge_count[edge[i]] < 255)
            s->edge_count[edge[i]]++;
    key_record *out = b->edge_records ? b->edge_records + b->edge_record_counts[f] : NULL;
    uint32_t count = 0;
    for (uint32_t i = 0; i < n; i++) {
        if (s->edge_count[edge[i]] != 1)
            continue;
        uint32_t pa = b->position_id[v[edge[i] >> 6]], pe = b->position_id[v[edge[i] & 63]];
        if (pa != pe && out)
            out[count] = (key_record){.key = edge_key(pa, pe), .value = f};
        count += pa != pe;
    }
    for (uint32_t i = 0; i < n; i++)
        s->edge_count[edge[i]] = 0;
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

/* boundary_edges_task over the frontier: on `pool`, or (NULL) on this thread as `worker`. */
static void boundary_edges(lod_build *b, gdr_thread_pool *pool, uint32_t worker)
{
    if (pool)
        gdr_thread_pool_run(pool, b->frontier_count, boundary_edges_task, b);
    else
        for (uint32_t f = 0; f < b->frontier_count; f++)
            boundary_edges_task(b, f, worker);
}

/* The pairs of distinct clusters that share an edge, from the edge records sorted by edge, both
 * ways, into pairs (NULL: only counted); returns how many. */
static size_t sharing_pairs(const key_record *edges, size_t total, key_record *pairs)
{
    size_t p = 0;
    for (size_t i = 0; i < total;) {
        size_t j = i + 1;
        while (j < total && edges[j].key == edges[i].key)
            j++;
        for (size_t x = i; x < j; x++)
            for (size_t y = x + 1; y < j; y++) {
                if (edges[x].value == edges[y].value)
                    continue;
                if (pairs) {
                    pairs[p] = (key_record){.key = (uint64_t)edges[x].value << 32 | edges[y].value};
                    pairs[p + 1] = (key_record){.key = (uint64_t)edges[y].value << 32 | edges[x].value};
                }
                p += 2;
            }
        i = j;
    }
    return p;
}

/* The graph over n clusters from the sorted pairs: a pair's weight is how many edges the two
 * share. Returns 0 when out of memory. */
static int graph_from_pairs(cluster_graph *g, uint32_t n, const key_record *pairs, size_t pair_count)
{
    g->xadj = calloc((size_t)n + 1, sizeof *g->xadj);
    g->adjncy = malloc((pair_count ? pair_count : 1) * sizeof *g->adjncy);
    g->adjwgt = malloc((pair_count ? pair_count : 1) * sizeof *g->adjwgt);
    if (!g->xadj || !g->adjncy || !g->adjwgt)
        return 0;
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
    return 1;
}

static int build_graph(lod_build *b, gdr_thread_pool *pool, uint32_t worker, cluster_graph *g)
{
    uint32_t n = b->frontier_count;
    b->edge_record_counts = malloc((size_t)n * sizeof *b->edge_record_counts);
    if (!b->edge_record_counts)
        return 0;
    boundary_edges(b, pool, worker);
    size_t total = 0;
    for (uint32_t f = 0; f < n; f++) {
        uint32_t c = b->edge_record_counts[f];
        b->edge_record_counts[f] = (uint32_t)total;
        total += c;
    }
    b->edge_records = malloc((total ? total : 1) * sizeof *b->edge_records);
    if (!b->edge_records)
        return 0;
    boundary_edges(b, pool, worker);
    key_record *edges = b->edge_records;
    key_record *tmp = malloc((total ? total : 1) * sizeof *tmp);
    if (!tmp)
        return 0;
    lod_sort_key_records(edges, tmp, total);
    free(tmp);
    size_t pair_count = sharing_pairs(edges, total, NULL);
    key_record *pairs = malloc((pair_count ? pair_count : 1) * sizeof *pairs);
    key_record *pairs_tmp = malloc((pair_count ? pair_count : 1) * sizeof *pairs_tmp);
    int ok = pairs && pairs_tmp;
    if (ok) {
        sharing_pairs(edges, total, pairs);
        lod_sort_key_records(pairs, pairs_tmp, pair_count);
        ok = graph_from_pairs(g, n, pairs, pair_count);
    }
    free(pairs);
    free(pairs_tmp);
    return ok;
}

/* METIS keeps its random state in globals: one partition at a time, always from the same seed. */
static pthread_mutex_t metis_lock = PTHREAD_MUTEX_INITIALIZER;

/* Groups of about as many triangles as group_size level-0 clusters, at most one per two clusters. */
uint32_t gdr_lod_part_count(const lod_build *b)
{
    uint32_t n = b->frontier_count;
    uint64_t triangles = 0;
    for (uint32_t f = 0; f < n; f++)
        triangles += b->clusters[b->frontier[f]].triangle_count;
    uint64_t parts64 = (triangles + b->group_triangles - 1) / b->group_triangles;
    uint32_t parts = (uint32_t)(parts64 < (n + 1) / 2 ? parts64 : (n + 1) / 2);
    return parts > 1 ? parts : 1;
}

/* Partitions the frontier into `parts` (gdr_lod_part_count) groups of neighbours holding about as
 * many triangles each (METIS balances triangle counts): part[f] in [0, parts). Weighing by
 * triangles keeps groups large when simplified clusters come out smaller than level-0 ones, so the
 * share of locked border in a group does not grow from step to step. Recursive bisection: with
 * parts of four clusters it cuts fewer edges than METIS_PartGraphKway here and runs 4x faster. */
gdr_status gdr_lod_partition(lod_build *b, gdr_thread_pool *pool, uint32_t worker, int32_t *part, uint32_t parts,
                             gdr_error *err)
{
    uint32_t n = b->frontier_count;
    if (parts <= 1) {
        memset(part, 0, n * sizeof *part);
        return GDR_OK;
    }
    cluster_graph g = {0};
    int built = build_graph(b, pool, worker, &g);
    free(b->edge_records);
    free(b->edge_record_counts);
    b->edge_records = NULL;
    b->edge_record_counts = NULL;
    if (!built) {
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
    return GDR_OK;
}
