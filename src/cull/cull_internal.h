/* Internal to src/cull: the scene's storage, the octree, and the hot tests in inline form. */
#ifndef GDR_CULL_INTERNAL_H
#define GDR_CULL_INTERNAL_H

#include <math.h>
#include <stdint.h>

#include "gdr/cull.h"

/* object_node values that are not node indices */
#define CULL_NODE_NONE UINT32_MAX          /* in no node: tested on its own every time */
#define CULL_NODE_INVALID (UINT32_MAX - 1) /* invalid or empty bounds: never visible */

#define CULL_OCTREE_DEFAULT_DEPTH 12u
#define CULL_OCTREE_MAX_DEPTH 20u
#define CULL_OCTREE_DEFAULT_LEAF 16u

/* A node of the loose octree. Nodes are stored in pre-order, so a subtree is the index range
 * [node, skip): culling walks the array and jumps over subtrees that need no more tests. */
typedef struct cull_node {
    gdr_vec3 center;
    float extent;         /* half-size of the node's loose cube, with the safety margin */
    float cell_half;      /* half-size of the node's cell (objects centred in it) */
    float fit_extent;     /* half-size an object box must fit in (loose cube without margin) */
    uint32_t skip;        /* first node after this subtree */
    uint32_t depth;
    uint32_t children[8]; /* octant (x >= cx) | (y >= cy) << 1 | (z >= cz) << 2; UINT32_MAX none */
} cull_node;

struct gdr_cull_scene {
    uint32_t object_count;
    gdr_cull_object *objects;
    uint32_t *object_node;
    cull_node *nodes;
    uint32_t node_count, node_capacity;
    uint32_t max_depth, leaf_objects;
    /* The per-view pass runs subtrees of at most task_nodes nodes as tasks; no view has more
     * than task_capacity of them (both fixed when the tree is built). */
    uint32_t task_nodes, task_capacity;
};

/* octree.c */
gdr_status cull_octree_build(gdr_cull_scene *scene, gdr_error *err);
/* Node index for an object with valid bounds (CULL_NODE_NONE if outside the root). */
uint32_t cull_octree_place(const gdr_cull_scene *scene, gdr_vec3 center, gdr_vec3 extent);
/* Two bits per node into node_bits (gdr_cull_word_count(2 * node_count) words, zeroed by the
 * caller): bit 2n = intersects the frustum, bit 2n + 1 = partly outside. The top of the tree is
 * walked on the calling thread, the subtrees below it as tasks on pool (NULL: all on the calling
 * thread); the bits and counts do not depend on the thread count. Fails only out of memory. */
gdr_status cull_octree_classify(const gdr_cull_scene *scene, const gdr_frustum *frustum, gdr_thread_pool *pool,
                                uint32_t *node_bits, uint32_t *nodes_tested, uint32_t *nodes_inside,
                                gdr_error *err);
static inline uint32_t cull_node_bits(const uint32_t *node_bits, uint32_t node)
{
    return (node_bits[node >> 4] >> ((node & 15u) * 2u)) & 3u;
}

/* bounds_tests.c */
bool cull_object_bounds_valid(const gdr_cull_object *object);

/* distance_cull.c: returns false when culled; sets *fading. */
typedef struct cull_distance_params {
    gdr_vec3 origin;
    float scale, fade_range;
    bool to_sphere_edge;
} cull_distance_params;
bool cull_distance_visible(const cull_distance_params *p, const gdr_cull_object *o, float center_distance,
                           bool *fading);

/* screen_size.c */
float cull_screen_size(float screen_scale, float radius, float center_distance);
bool cull_screen_size_visible(float size, float view_min, const gdr_cull_object *o);

/* bvh.c */
void cull_bvh_bounds(const gdr_bvh *bvh, gdr_vec3 *lo, gdr_vec3 *hi);

/* pvs_occlusion.c: conservative visibility from one point (the bake's proof). Each object's
 * triangles with a cross product that is not exactly zero (the only ones a ray can hit), with
 * the twin of each edge: the object's triangle sharing it in the opposite direction. */
typedef struct pvs_geometry {
    uint32_t object_count;
    uint32_t *first;   /* object_count + 1: object o owns triangles [first[o], first[o + 1]) */
    gdr_vec3 *corners; /* 3 per triangle */
    uint32_t *twin;    /* 3 per triangle (edge k: corner k to corner k + 1), or UINT32_MAX */
    gdr_vec3 *lo, *hi; /* per object: bounds of its triangles */
    uint32_t max_triangles;
} pvs_geometry;
gdr_status pvs_geometry_build(pvs_geometry *g, const gdr_bvh *bvh, uint32_t object_count, gdr_error *err);
void pvs_geometry_free(pvs_geometry *g);
typedef struct pvs_view_scratch pvs_view_scratch; /* a depth cube and buffers; one per thread */
gdr_status pvs_view_scratch_create(uint32_t resolution, uint32_t max_triangles, uint32_t object_count,
                                   pvs_view_scratch **out, gdr_error *err);
void pvs_view_scratch_destroy(pvs_view_scratch *s);
/* Sets the bit of every object with triangles that is not provably hidden from p. Requires that
 * no triangle touches the cube of half-size delta about p (the caller checks with the BVH).
 * Returns how many objects were tested (those whose bit was not set already). */
uint64_t pvs_visible_from_point(const pvs_geometry *g, pvs_view_scratch *s, gdr_vec3 p, float delta,
                                uint32_t *bits);

/* Precomputed visibility (precomputed_visibility.c bakes, pvs_blob.c (de)serialises,
 * pvs_query.c looks up). Cells are sorted by bucket; a bucket's cells are contiguous. */
#define PVS_CHUNK_ZSTD 1u
#define PVS_MAX_OBJECTS (1u << 28)
#define PVS_MAX_GRID_CELLS (1u << 24)
#define PVS_MAX_BUCKETS_PER_AXIS 4096u
#define PVS_MAX_CHUNK_BYTES (1u << 28)

typedef struct pvs_cell {
    uint32_t x, y, z;
    uint32_t chunk;  /* global chunk index */
    uint32_t offset; /* byte offset of the bitset in the chunk's uncompressed data */
} pvs_cell;

typedef struct pvs_bucket {
    uint32_t first_cell, cell_count;
} pvs_bucket;

typedef struct pvs_chunk {
    uint64_t data_offset;
    uint32_t compressed_size, uncompressed_size;
    uint32_t flags; /* PVS_CHUNK_ZSTD, or 0: stored */
} pvs_chunk;

struct gdr_pvs {
    uint32_t object_count;
    uint32_t grid[3];
    gdr_vec3 origin;
    float cell_size;
    uint32_t bucket_x, bucket_z;
    uint32_t cell_count, chunk_count;
    pvs_bucket *buckets; /* bucket_x * bucket_z; bucket = x % bucket_x + (z % bucket_z) * bucket_x */
    pvs_cell *cells;
    pvs_chunk *chunks;
    uint8_t *data;
    uint64_t data_size;
    uint32_t max_chunk_bytes;
    gdr_vec3 *samples; /* cell_count * samples_per_cell, or NULL */
    uint32_t samples_per_cell;
};

static inline uint32_t pvs_bucket_of(const gdr_pvs *p, uint32_t x, uint32_t z)
{
    return x % p->bucket_x + (z % p->bucket_z) * p->bucket_x;
}

/* The permuted 8-lane tests. A sphere is outside when some plane has dist < -r. */
static inline bool cull_sphere_outside(const gdr_frustum *f, gdr_vec3 c, float r)
{
    int outside = 0;
    for (int i = 0; i < 8; i++) {
        float dist = f->px[i] * c.x + f->py[i] * c.y + f->pz[i] * c.z + f->pd[i];
        outside |= dist < -r;
    }
    return outside != 0;
}

static inline bool cull_box_outside(const gdr_frustum *f, gdr_vec3 c, gdr_vec3 e)
{
    int outside = 0;
    for (int i = 0; i < 8; i++) {
        float dist = f->px[i] * c.x + f->py[i] * c.y + f->pz[i] * c.z + f->pd[i];
        float push = fabsf(f->px[i]) * e.x + fabsf(f->py[i]) * e.y + fabsf(f->pz[i]) * e.z;
        outside |= dist < -push;
    }
    return outside != 0;
}

static inline gdr_cull_outcome cull_box_classify(const gdr_frustum *f, gdr_vec3 c, gdr_vec3 e)
{
    int outside = 0, partly = 0;
    for (int i = 0; i < 8; i++) {
        float dist = f->px[i] * c.x + f->py[i] * c.y + f->pz[i] * c.z + f->pd[i];
        float push = fabsf(f->px[i]) * e.x + fabsf(f->py[i]) * e.y + fabsf(f->pz[i]) * e.z;
        outside |= dist < -push;
        partly |= dist < push;
    }
    return outside ? GDR_CULL_OUTSIDE : partly ? GDR_CULL_INTERSECTS : GDR_CULL_INSIDE;
}

#endif
