/* Internals of the LOD DAG build (lod_dag.c drives it, lod_weld.c joins near-equal positions,
 * lod_graph.c partitions a step's clusters, lod_group.c simplifies one group). Not part of the
 * public API. */
#ifndef GDR_GEOMETRY_LOD_INTERNAL_H
#define GDR_GEOMETRY_LOD_INTERNAL_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include <meshoptimizer.h>

#include "core/progress.h"
#include "gdr/thread_pool.h"
#include "geometry/lod_grid.h"
#include "geometry/lod_simplify.h"
#include "geometry/lod_sort.h"
#include "gdr/geometry.h"
#include "gdr/scene.h"

/* A group is formed only when simplification keeps at most this share of its triangles. */
#define LOD_MAX_KEPT_SHARE 0.85
#define LOD_CONE_WEIGHT 0.25f
/* A group with more samples than this farther than its floor keeps them (lod_redirect.c). */
#define LOD_EXCESS_LIMIT 1024u
/* A group passes samples only when that at least halves its error: its sphere may grow by half. */
#define LOD_REDIRECT_GAIN 0.5f

/* Positions closer than this share of the mesh's bounding radius on every axis are one position
 * (lod_weld.c, gdr_lod_weld_setup): to grouping, simplification and the error's samples and walks.
 * Seams whose two sides differ by rounding (sinf(2 pi) != 0) then close like bit-equal ones
 * instead of being open borders. */
#define LOD_WELD_SCALE 1e-6

/* lod_build.owner: a position no group of the step uses, or that two groups share. */
#define OWNER_NONE UINT32_MAX
#define OWNER_SHARED (UINT32_MAX - 1)

_Static_assert(GDR_CLUSTER_MAX_VERTICES <= 64, "boundary edges are counted in a 64 x 64 table");


/* Progress shared by the meshes of one call; only worker 0 (the calling thread) draws. */
typedef struct lod_progress {
    gdr_progress bar;
    atomic_uint_fast64_t done;
} lod_progress;

/* A group's samples are measured keeping this many of their largest distance bounds; a group whose
 * floor LOD_EXCESS_LIMIT + 1 kept bounds could lower is measured again keeping those (lod_error.c,
 * keep_more). Fewer kept bounds settle more samples unmeasured: the smallest of them is larger. */
#define LOD_KEPT_FIRST 65u

/* The `limit` (at most LOD_EXCESS_LIMIT + 1) largest sample distance bounds of a group, or of a
 * range of its samples (squared, ascending, with their gathered samples), and the largest distance
 * (squared). */
typedef struct lod_kept {
    float d2[LOD_EXCESS_LIMIT + 1];
    uint32_t sample[LOD_EXCESS_LIMIT + 1], count, limit;
    float worst;
} lod_kept;

/* Per-worker scratch, reused from task to task. */
typedef struct lod_scratch {
    uint32_t *map; /* mesh vertex -> local vertex, UINT32_MAX when unused (mesh vertex_count entries) */
    uint32_t *local_to_mesh;
    size_t local_to_mesh_cap;
    uint8_t *locked;
    size_t locked_cap;
    float *positions;
    size_t positions_cap;
    /* simplification over positions (lod_simplify.c): local vertex -> local position, mesh position id
     * -> local position (UINT32_MAX when unused; position_count entries), per local position its
     * coordinates and lock */
    uint32_t *vertex_position, *position_map;
    size_t vertex_position_cap;
    float *local_positions;
    size_t local_positions_cap;
    uint8_t *position_locked;
    size_t position_locked_cap;
    lod_simplify_scratch simplify;
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
    /* measuring the group's deviation (lod_error.c) */
    uint32_t *out_corners, *out_cluster, *ring_start, *ring;
    size_t out_corners_cap, out_cluster_cap, ring_start_cap, ring_cap;
    uint32_t out_triangle_count;
    lod_kept top; /* the group's largest sample distance bounds */
    uint32_t *sample_ids, *sample_cluster, *vertex_local;
    size_t sample_ids_cap, sample_cluster_cap, vertex_local_cap;
    gdr_vec3 *sample_points, *vertex_points;
    size_t sample_points_cap, vertex_points_cap;
    uint32_t gathered;
    lod_grid grid;
    lod_triangle_grid triangle_grid;
    uint32_t *region_refs, *region_corners; /* level-0 triangles around the group's samples */
    size_t region_refs_cap, region_corners_cap;
    lod_triangle_grid region_grid;
    int region_built;
    uint32_t *span_refs, *span_corners; /* level-0 triangles around its simplified triangles' corners */
    uint32_t *span_positions;           /* those corners' positions, each once */
    size_t span_refs_cap, span_corners_cap, span_positions_cap;
    lod_triangle_grid span_grid;
    int span_built;
    int grid_holds_samples; /* `grid` was rebuilt over sample_points (lod_error.c, nearest_sample) */
    float *coarse_d2; /* per simplified triangle: its largest coarse probe distance, squared */
    size_t coarse_d2_cap;
    float *edge_d2; /* per simplified triangle edge: its largest coarse probe (squared), -1 once refined */
    size_t edge_d2_cap;
    lod_kept *range_kept; /* per range, when one group's samples are measured in ranges */
    size_t range_kept_cap;
    uint32_t range_size; /* samples per range */
    uint8_t edge_count[64 * 64];
} lod_scratch;

/* What simplifying one group produced. */
typedef struct group_result {
    int formed;        /* simplified enough: the group is formed and `clusters` replace its members */
    int border_reject; /* simplification moved a locked border */
    int out_of_memory;
    float error;       /* the larger of its deviation and the largest error its members came with */
    float deviation;   /* measured against the full-detail surface (lod_error.c) */
    float slide;       /* the largest texture slide one of its collapses charged (lod_simplify.c): part of
                          the error, as D2 is */
    gdr_vec4 sphere;
    uint32_t input_triangles;
    uint32_t group;         /* its id among the DAG's groups, once formed (or passed through) */
    uint32_t first_cluster; /* where its new clusters went in lod_build.clusters */
    gdr_cluster *clusters; /* offsets relative to the arrays below; freed once taken into the build */
    uint32_t cluster_count;
    uint32_t *vertices;
    uint32_t vertex_count;
    uint8_t *triangles;
    uint32_t triangle_bytes;
    uint32_t *samples;              /* the group's samples, by the new cluster they pass to */
    uint32_t *cluster_sample_first; /* new cluster i: samples[first[i] .. first[i + 1]) */
    float floor;                    /* the error without D1: members' errors and D2 (lod_redirect.c) */
    uint32_t *excess;               /* samples farther than `floor` from the new clusters, */
    float *excess_distance;         /* with their distance to them */
    uint32_t excess_count;
    float d1;                       /* D1: the largest distance from a sample to the new clusters */
    float kept_bound;               /* the smallest kept bound (not squared); every sample not kept lies
                                       within it of the cluster it passes to; -1: every sample was kept */
    uint32_t *kept;                 /* the kept samples (kept_count), recorded only for an observer */
    uint32_t kept_count;
} group_result;

struct lod_build;

/* One step's groups, as an observer sees them once their errors are set: group g's members are
 * members[member_start[g] .. member_start[g + 1]) and its result results[g]; the samples are packed
 * (lod_build.samples) over the clusters of `frontier`, the frontier the step made. Before the first
 * step: no groups, level 0's frontier. */
typedef struct lod_step_view {
    uint32_t depth, groups;
    const uint32_t *members, *member_start;
    const group_result *results;
    const uint32_t *frontier;
    uint32_t frontier_count;
} lod_step_view;

/* What a test may ask the build to show it (NULL in every other build: nothing recorded): `step`
 * is called on the building thread at each step, with the build as it stands, so that a test can
 * check every sample against the cluster it was handed to. */
typedef struct lod_observer {
    void (*step)(void *user, const struct lod_build *b, const lod_step_view *view);
    void *user;
} lod_observer;

typedef struct lod_build {
    gdr_mesh *mesh;
    gdr_lod_options opt;
    const lod_texture_set *texture; /* the textures the mesh's materials sample (NULL: unknown) */
    const lod_observer *observer; /* NULL but in tests */
    gdr_thread_pool *pool;
    uint32_t worker_base; /* worker index offset of this build's scratch (0: draws progress) */
    lod_scratch *scratch;
    uint32_t scratch_count;
    uint32_t *position_id; /* mesh vertex -> id of its position (vertices with equal coordinates share it,
                              and those within LOD_WELD_SCALE of each other) */
    uint32_t position_count;
    float weld_slack;      /* the largest distance between two vertices of one position id: added to
                              every group's error at the end (0 where no positions were welded) */
    uint32_t *owner;       /* position id -> group using it in this step, OWNER_SHARED or OWNER_NONE */
    /* samples of the full-detail surface (lod_error.c): position ids, owned by frontier clusters */
    uint32_t *sample_vertex;   /* position id -> a mesh vertex at that position */
    uint32_t *adjacency_start; /* position id -> level-0 triangles around it: adjacency[start[p] .. start[p + 1]) */
    uint32_t *adjacency;       /* level-0 triangles as cluster << 7 | triangle */
    uint32_t *level0_offsets;  /* per level-0 cluster: its vertex offset, its triangle offset (compact: the
                                  walks read them for every triangle they look at) */
    uint32_t *samples;         /* frontier cluster c owns samples[first[c] .. + count[c]) */
    uint32_t sample_count;
    uint32_t *cluster_sample_first, *cluster_sample_count;
    uint32_t *cluster_sample_source; /* UINT32_MAX: in `samples`; else in results[source].samples */
    size_t cluster_sample_cap;
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
    /* the groups whose deviation is measured: measured_results[measured[i]], i < measured_count, of
     * the step before (its members and results; its new clusters are in `clusters` by now) */
    const uint32_t *measured;
    uint32_t measured_count;
    const uint32_t *measured_members, *measured_member_start;
    group_result *measured_results;
    int sloppy;     /* the step's one group is the whole frontier, simplified by lod_sloppy.c */
    int lone_group; /* one group is measured, on the calling thread outside any job */
    /* the next step's partition, when it runs as task 0 of the job: the simplification tasks wait
     * for it (partitioned set under partition_lock) */
    struct lod_stage *partitioning;
    pthread_mutex_t partition_lock;
    pthread_cond_t partition_cond;
    int partitioned;
    gdr_status partition_status;
    gdr_error partition_error;
    const uint32_t *frontier;
    uint32_t frontier_count;
    key_record *edge_records;      /* boundary edges of frontier clusters, per chunk */
    uint32_t *edge_record_counts;  /* per frontier cluster */
} lod_build;

/* gdr_mesh_build_lod_dag with an observer (NULL: the same), for tests. */
gdr_status gdr_lod_build_observed(gdr_mesh *mesh, const gdr_lod_options *options, const lod_observer *observer,
                                  gdr_lod_stats *stats, gdr_error *err);
/* gdr_lod_build_observed with the textures the mesh's uvs sample (NULL: unknown, as there), for tests;
 * gdr_scene_build_lod finds them from the mesh's materials. */
gdr_status gdr_lod_build_textured(gdr_mesh *mesh, const gdr_lod_options *options, const lod_texture_set *texture,
                                  const lod_observer *observer, gdr_lod_stats *stats, gdr_error *err);

/* Grows *p (a pointer to an array) to hold at least `need` elements of `size` bytes; returns 0 when
 * out of memory. */
int gdr_lod_reserve(void *p, size_t *cap, size_t need, size_t size);
/* gdr_lod_reserve with the common case (room enough) inline: the simplifier reserves its fan arrays
 * at every evaluation. */
static inline int gdr_lod_reserve_inline(void *p, size_t *cap, size_t need, size_t size)
{
    return need <= *cap || gdr_lod_reserve(p, cap, need, size);
}
#define LOD_RESERVE(s, field, need) gdr_lod_reserve_inline(&(s)->field, &(s)->field##_cap, (need), sizeof *(s)->field)

static inline size_t gdr_lod_align4(size_t n) { return (n + 3) & ~(size_t)3; }
/* The root of x in a union-find forest over parent[] (halving the path on the way). */
static inline uint32_t gdr_lod_find_root(uint32_t *parent, uint32_t x)
{
    while (parent[x] != x)
        x = parent[x] = parent[parent[x]];
    return x;
}
static inline const uint8_t *gdr_lod_cluster_triangles(const lod_build *b, const gdr_cluster *c)
{
    return b->triangles + c->triangle_offset;
}
static inline const uint32_t *gdr_lod_cluster_vertices(const lod_build *b, const gdr_cluster *c)
{
    return b->vertices + c->vertex_offset;
}

/* Adds to the shared progress; only worker 0 of the calling thread draws. */
void gdr_lod_progress_add(lod_build *b, uint64_t amount, uint32_t worker);

/* lod_weld.c: gives near-equal positions (LOD_WELD_SCALE) one position id, after
 * meshoptimizer's remap gave bit-equal ones one; 0: out of memory. */
int gdr_lod_weld_setup(lod_build *b);

/* lod_graph.c: the number of parts of the frontier (b->frontier), and its partition into them,
 * groups of neighbours: part[f] in [0, parts). The cluster graph is built on `pool`, or (NULL) on
 * this thread as `worker` (inside a job). */
uint32_t gdr_lod_part_count(const lod_build *b);
gdr_status gdr_lod_partition(lod_build *b, gdr_thread_pool *pool, uint32_t worker, int32_t *part, uint32_t parts,
                             gdr_error *err);

/* lod_group.c: a thread-pool task that simplifies group g of the step into b->results[g] (and
 * splits it into clusters); one that measures the deviation of group measured[i]. */
void gdr_lod_simplify_group_task(void *user, uint32_t g, uint32_t worker);
void gdr_lod_measure_group_task(void *user, uint32_t i, uint32_t worker);
/* A group's sphere (into r), over its members and the groups they came from. */
void gdr_lod_group_sphere(lod_build *b, lod_scratch *s, const uint32_t *members, uint32_t count, group_result *r);
void gdr_lod_result_free(group_result *r);
/* lod_sloppy.c: simplifies s->indices (index_count, over s->positions' vertex_count vertices) into
 * s->simplified by vertex clustering, which merges separate pieces; returns the index count (0:
 * nothing left). For the groups of a step where edge collapses formed none (lod_build.sloppy). */
size_t gdr_lod_simplify_sloppy(lod_scratch *s, size_t index_count, uint32_t vertex_count);

/* lod_error.c: the samples of the full-detail surface and the groups' measured deviation. */
int gdr_lod_error_setup(lod_build *b); /* after position ids and the owner table; 0: out of memory */
void gdr_lod_error_free(lod_build *b);
/* Sets r->deviation and r's samples by new cluster, after the split into clusters (members: the
 * group's count member clusters). */
int gdr_lod_group_deviation(lod_build *b, lod_scratch *s, const uint32_t *members, uint32_t count,
                            uint32_t local_count, group_result *r);
/* New cluster `cluster` owns the samples of `from` (pass-through) / of r's new cluster `index`. */
int gdr_lod_error_inherit(lod_build *b, uint32_t cluster, uint32_t from);
int gdr_lod_error_adopt(lod_build *b, uint32_t cluster, uint32_t group, const group_result *r, uint32_t index);
/* lod_redirect.c: after a step's groups are measured, samples that set a group's error may pass to
 * a neighbouring group's new cluster; lowers errors and grows spheres (docs/GEOMETRY.md). */
int gdr_lod_redirect_samples(lod_build *b, uint32_t groups);
/* Squared distance from p to triangle (a, b, c) (lod_error.c). */
float gdr_lod_point_triangle_d2(gdr_vec3 p, gdr_vec3 a, gdr_vec3 b, gdr_vec3 c);
/* Packs the samples of the next frontier into one array (before the step's results are freed). */
int gdr_lod_error_gather(lod_build *b, const uint32_t *frontier, uint32_t count);
void gdr_lod_scratch_free(lod_scratch *s);

#endif
