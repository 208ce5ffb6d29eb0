/* gdr cull: the CPU culling library, in the style of UE5's scene visibility code.
 *
 * No Vulkan here. Sections (grep for "--- "):
 *   --- frustum         planes from a view-projection matrix; sphere and box tests
 *   --- cull scene      objects (bounds + draw distances + screen sizes + flags) in a loose octree
 *   --- cull view       one view's description (zero-initialised defaults) and gdr_cull_execute
 *   --- bvh             triangles for ray casts and box overlap queries
 *   --- precomputed visibility   offline bake over cells, runtime lookup, serialised blob
 *
 * Conventions: right-handed world space, column-major matrices (gdr/math.h), clip space as in
 * Vulkan: -w <= x <= w, -w <= y <= w, 0 <= z <= w (so standard and reverse-Z both work, and the
 * infinite reverse-Z projection simply has no far plane). Bitsets are arrays of uint32_t words:
 * object i is bit (i % 32) of word (i / 32); gdr_cull_word_count(n) words hold n objects.
 * See docs/CULLING.md for the math and the blob layout. */
#ifndef GDR_CULL_H
#define GDR_CULL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gdr/core.h"
#include "gdr/math.h"
#include "gdr/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The pool type of gdr/thread_pool.h (gdr_thread_pool_create / _destroy). Every function
 * here that takes one accepts NULL (run on the calling thread). */
typedef struct gdr_thread_pool gdr_thread_pool;

static inline uint32_t gdr_cull_word_count(uint32_t object_count) { return (object_count + 31u) / 32u; }
static inline bool gdr_cull_bit(const uint32_t *bits, uint32_t index)
{
    return (bits[index >> 5] >> (index & 31u)) & 1u;
}

/* --- frustum ------------------------------------------------------------------------------- */

/* Six planes n.p + d >= 0 (inside), normalised (|n| = 1), from a world -> clip matrix by
 * Gribb-Hartmann: left r3+r0, right r3-r0, bottom r3+r1, top r3-r1, z >= 0: r2, z <= w: r3-r2.
 * A plane whose normal vanishes (the far plane of an infinite projection) is dropped.
 * The tests use the "permuted" copy: the planes as four arrays of 8 lanes (x, y, z, d), the
 * unused lanes filled with an always-passing plane, so one loop of 8 tests every plane. */
typedef struct gdr_frustum {
    gdr_vec4 planes[6]; /* xyz = normal, w = d; only the first plane_count are meaningful */
    uint32_t plane_count;
    float px[8], py[8], pz[8], pd[8];
} gdr_frustum;

typedef enum gdr_cull_outcome {
    GDR_CULL_OUTSIDE = 0,   /* wholly outside some plane */
    GDR_CULL_INTERSECTS = 1, /* not outside any plane, partly outside at least one */
    GDR_CULL_INSIDE = 2,    /* on the inner side of every plane */
} gdr_cull_outcome;

GDR_API gdr_frustum gdr_frustum_from_matrix(gdr_mat4 view_projection);

/* Sphere: outside when some plane has n.c + d < -r; inside when every plane has n.c + d >= r. */
GDR_API gdr_cull_outcome gdr_frustum_test_sphere(const gdr_frustum *frustum, gdr_vec3 center, float radius);
/* Axis-aligned box (centre, half-size extent >= 0), with push = |n.x| e.x + |n.y| e.y + |n.z| e.z:
 * outside when some plane has n.c + d < -push; inside when every plane has n.c + d >= push. */
GDR_API gdr_cull_outcome gdr_frustum_test_box(const gdr_frustum *frustum, gdr_vec3 center, gdr_vec3 extent);
/* The same box test against one plane (not necessarily normalised); a zero normal gives INSIDE
 * when d >= 0 and OUTSIDE otherwise. Used for the global clip plane. */
GDR_API gdr_cull_outcome gdr_plane_test_box(gdr_vec4 plane, gdr_vec3 center, gdr_vec3 extent);

/* --- cull scene ---------------------------------------------------------------------------- */

typedef enum gdr_cull_object_flags {
    GDR_CULL_OBJECT_HIDDEN = 1u << 0,         /* never visible (wins over ALWAYS_VISIBLE) */
    GDR_CULL_OBJECT_ALWAYS_VISIBLE = 1u << 1, /* visible unless hidden: no test at all (a sky) */
    GDR_CULL_OBJECT_DYNAMIC = 1u << 2,        /* ignored by precomputed visibility (it moves) */
} gdr_cull_object_flags;

/* One object's bounds and culling parameters (48 bytes). The box and the sphere share a centre;
 * both must contain the object (the sphere usually has radius |extent|). Bounds with a NaN or
 * infinity, a negative radius or extent are invalid; a zero radius with a zero extent is empty:
 * invalid and empty objects are never visible (except ALWAYS_VISIBLE ones). Zero means "off" for
 * each of the four limits. */
typedef struct gdr_cull_object {
    gdr_vec3 center;
    float radius;
    gdr_vec3 extent;          /* half-size of the axis-aligned box */
    uint32_t flags;           /* gdr_cull_object_flags */
    float min_draw_distance;  /* culled when nearer than this (metres, scaled by the view) */
    float max_draw_distance;  /* culled when farther than this */
    float min_screen_size;    /* culled when the projected size is below this (see gdr_cull_view) */
    float max_screen_size;    /* culled when the projected size is this or more (LOD ranges) */
} gdr_cull_object;

typedef struct gdr_cull_scene gdr_cull_scene;

typedef struct gdr_cull_scene_desc {
    const gdr_cull_object *objects; /* copied */
    uint32_t object_count;
    uint32_t octree_max_depth;       /* 0: 12; at most 20 */
    uint32_t octree_leaf_objects;    /* a node with more objects than this splits; 0: 16 */
} gdr_cull_scene_desc;

GDR_API gdr_status gdr_cull_scene_create(const gdr_cull_scene_desc *desc, gdr_cull_scene **out, gdr_error *err);
GDR_API void gdr_cull_scene_destroy(gdr_cull_scene *scene);
GDR_API uint32_t gdr_cull_scene_object_count(const gdr_cull_scene *scene);
GDR_API uint32_t gdr_cull_scene_node_count(const gdr_cull_scene *scene);
/* Replaces objects [first, first + count) (moved, resized or re-flagged). A moved object goes to
 * the deepest existing octree node that holds it (the tree is not re-split; rebuild the scene
 * when many objects have moved). Not concurrent with gdr_cull_execute on the same scene. */
GDR_API gdr_status gdr_cull_scene_update(gdr_cull_scene *scene, uint32_t first, uint32_t count,
                                         const gdr_cull_object *objects, gdr_error *err);
/* What the bounds of a mesh's instances are made from: its box in mesh space (the range of its
 * vertices; lo > hi for a mesh without vertices) and its bounding sphere. Computed once per mesh
 * (one pass over its vertices) by gdr_cull_mesh_bounds_of, so that each instance costs O(1). */
typedef struct gdr_cull_mesh_bounds {
    gdr_vec3 lo, hi;
    gdr_vec4 sphere; /* gdr_mesh.bounds: centre xyz, radius w */
} gdr_cull_mesh_bounds;

GDR_API gdr_cull_mesh_bounds gdr_cull_mesh_bounds_of(const gdr_mesh *mesh);
/* The bounds of one instance of a mesh: the world box of the mesh box's transformed corners, and
 * the smaller of two spheres about the box centre that hold the mesh (the box's own, and one
 * around the transformed mesh sphere). An empty mesh gives an invalid object (radius -1): nothing
 * to draw. Flags and limits are zero. */
GDR_API gdr_cull_object gdr_cull_object_from_mesh_bounds(const gdr_cull_mesh_bounds *bounds, const gdr_mat4 *transform);
/* gdr_cull_object_from_mesh_bounds for every instance of a gdr_scene, each mesh's bounds computed
 * once: O(vertices + instances). Fills objects[0, scene->instance_count); an instance of a mesh
 * that does not exist gets an invalid object. Fails only when out of memory. */
GDR_API gdr_status gdr_cull_objects_from_scene(gdr_cull_object *objects, const gdr_scene *scene, gdr_error *err);

/* --- precomputed visibility (declared early: the view refers to it) ------------------------ */

typedef struct gdr_pvs gdr_pvs;             /* immutable after bake/load; shareable by threads */
typedef struct gdr_pvs_cache gdr_pvs_cache; /* lookups + the last decompressed chunk; one thread */

/* --- cull view ----------------------------------------------------------------------------- */

/* Everything about one view. Zero-initialise and fill what you need: every zero is a default. */
typedef struct gdr_cull_view {
    gdr_mat4 view;        /* world -> view; must be invertible (the origin comes from its inverse) */
    gdr_mat4 projection;  /* view -> clip (Vulkan clip space, see the top of this header) */
    /* distance culling */
    float distance_scale;          /* multiplies every object's draw distances; 0: 1 */
    float fade_range;              /* metres: visible objects within this of a draw distance fade */
    bool distance_to_sphere_edge;  /* nearest/farthest point of the sphere instead of its centre */
    /* screen size = screen_scale * radius / distance (distance <= radius: infinite), about the
     * projected diameter over the viewport height; screen_scale 0: max(|P00|, |P11|). */
    float screen_scale;
    float min_screen_size;         /* for every object (a global small-object cull); 0: off */
    /* global clip plane: visible where n.p + d >= 0; boxes crossing it are flagged needs_clipping;
     * all zero: off */
    gdr_vec4 clip_plane;
    bool skip_frustum;             /* no frustum test (distance / screen / plane queries only) */
    bool brute_force;              /* test every object, ignore the octree (reference, benchmark) */
    /* precomputed visibility: when the camera is inside a baked cell, objects the cell cannot see
     * are culled (objects flagged DYNAMIC or beyond the baked object count are not affected) */
    gdr_pvs_cache *visibility;
    uint32_t words_per_task;       /* bitset words per task; 0: 64 (2048 objects) */
} gdr_cull_view;

/* Where gdr_cull_execute writes; caller-owned arrays of gdr_cull_word_count(object_count) words.
 * fading and needs_clipping may be NULL. Bits past the last object are written as zero. */
typedef struct gdr_cull_result {
    uint32_t *visible;
    uint32_t *fading;          /* visible and inside a fade band */
    uint32_t *needs_clipping;  /* visible and crossing the clip plane */
} gdr_cull_result;

/* What was culled by which test (each culled object counted once, by the first test that culled
 * it, in this order: hidden, invalid, frustum, precomputed, distance, screen size, clip plane). */
typedef struct gdr_cull_stats {
    uint32_t visible, fading, needs_clipping;
    uint32_t hidden, invalid, frustum, precomputed, distance, screen_size, clip_plane;
    uint32_t always_visible;      /* visible without a test */
    uint32_t nodes_tested;        /* octree nodes that ran a box test */
    uint32_t nodes_inside;        /* nodes found fully inside (their subtree skipped the test) */
    uint32_t objects_tested;      /* objects that ran their own frustum test */
    uint32_t tasks;
    bool visibility_cell_found;   /* the camera was inside a baked cell */
} gdr_cull_stats;

/* Culls every object of the scene for one view. Results do not depend on the pool or its thread
 * count. stats may be NULL. Fails only for a bad view (non-invertible view matrix, NaNs) or when
 * out of memory. May run concurrently with other gdr_cull_execute calls on the same scene
 * (each with its own gdr_pvs_cache). */
GDR_API gdr_status gdr_cull_execute(const gdr_cull_scene *scene, const gdr_cull_view *view,
                                    gdr_thread_pool *pool, const gdr_cull_result *result,
                                    gdr_cull_stats *stats, gdr_error *err);

/* --- bvh ----------------------------------------------------------------------------------- */

typedef struct gdr_bvh gdr_bvh;

typedef struct gdr_ray_hit {
    float t;           /* origin + t * direction */
    float u, v;        /* barycentric coordinates of the hit on the triangle */
    uint32_t triangle; /* index in the order the triangles were given */
    uint32_t object;   /* the triangle's object */
} gdr_ray_hit;

/* positions: 3 * triangle_count points (copied); objects: triangle_count object ids (copied, or
 * NULL for all zero). Degenerate triangles are kept but never hit. */
GDR_API gdr_status gdr_bvh_create(const gdr_vec3 *positions, const uint32_t *objects,
                                  uint32_t triangle_count, gdr_bvh **out, gdr_error *err);
/* Every triangle of every instance, in world space; object = instance index. */
GDR_API gdr_status gdr_bvh_create_from_scene(const gdr_scene *scene, gdr_bvh **out, gdr_error *err);
GDR_API void gdr_bvh_destroy(gdr_bvh *bvh);
GDR_API uint32_t gdr_bvh_triangle_count(const gdr_bvh *bvh);
/* The three corners and object of triangle i (in the order given at creation). */
GDR_API void gdr_bvh_triangle(const gdr_bvh *bvh, uint32_t triangle, gdr_vec3 corners[3], uint32_t *object);
/* Nearest hit with t in (0, t_max], both faces; direction need not be normalised. */
GDR_API bool gdr_bvh_raycast(const gdr_bvh *bvh, gdr_vec3 origin, gdr_vec3 direction, float t_max,
                             gdr_ray_hit *hit);
/* Möller-Trumbore on one triangle, the test gdr_bvh_raycast uses (for references in tests). */
GDR_API bool gdr_ray_triangle(gdr_vec3 origin, gdr_vec3 direction, const gdr_vec3 corners[3],
                              float *t, float *u, float *v);
/* True when some triangle touches the box (exact separating-axis triangle/box test). */
GDR_API bool gdr_bvh_overlaps_box(const gdr_bvh *bvh, gdr_vec3 center, gdr_vec3 extent);
GDR_API bool gdr_triangle_overlaps_box(const gdr_vec3 corners[3], gdr_vec3 center, gdr_vec3 extent);

/* --- precomputed visibility ---------------------------------------------------------------- */

/* The bake: the region is cut into cells of cell_size; cells touched by a triangle are not empty
 * space and get no data (a lookup there returns NULL: nothing is culled). In every other cell,
 * samples_per_cell camera points are taken (stratified, jittered). From each, a depth cube map of
 * cube_resolution^2 texels per face is built conservatively: a texel holds a distance only where
 * one object's front (or back) surface provably covers all of it, and then the farthest that
 * surface can be in it. An object is hidden from the point only when its bounds lie strictly
 * behind every texel they project to; every other object with triangles is listed.
 * Guarantee (docs/CULLING.md): from every sample point, every object that some ray from that
 * point hits first is listed, whatever the ray. Points of the cell that were not sampled have no
 * guarantee (the tests measure how often they see an unlisted object). */
typedef struct gdr_pvs_bake_desc {
    const gdr_scene *scene;    /* static geometry; object i = instance i */
    gdr_vec3 region_min, region_max; /* both zero: the scene's bounds */
    float cell_size;           /* 0: the region's largest side / 16 */
    uint32_t samples_per_cell; /* 0: 8; at most 4096 */
    uint32_t cube_resolution;  /* texels along a side of each of the 6 cube faces; 0: 64; 4..1024 */
    uint32_t cells_per_chunk;  /* cells compressed together; 0: 16; fewer when a chunk would
                                  exceed 256 MB of bitsets */
    uint32_t bucket_count_x, bucket_count_z; /* the 2D bucket grid; 0: 16 each */
    int zstd_level;            /* 0: 3 */
    uint32_t seed;             /* 0: 1 */
    bool keep_samples;         /* keep the sample points (gdr_pvs_samples), for tests and tools */
    gdr_thread_pool *pool;
} gdr_pvs_bake_desc;

typedef struct gdr_pvs_bake_report {
    uint32_t grid[3];          /* cells along x, y, z */
    uint32_t cells_total, cells_baked, cells_occupied; /* occupied: touched by geometry */
    uint64_t samples_used;     /* camera points (samples_per_cell per baked cell) */
    uint64_t object_tests;     /* (sample, object) pairs tested against a depth cube */
    uint64_t unproven_samples; /* samples too close to geometry for the proof: every object listed */
    uint64_t visible_pairs;    /* (cell, object) pairs marked visible */
    size_t compressed_bytes, uncompressed_bytes;
} gdr_pvs_bake_report;

/* report may be NULL. */
GDR_API gdr_status gdr_pvs_bake(const gdr_pvs_bake_desc *desc, gdr_pvs **out,
                                gdr_pvs_bake_report *report, gdr_error *err);
GDR_API void gdr_pvs_destroy(gdr_pvs *pvs);
GDR_API uint32_t gdr_pvs_object_count(const gdr_pvs *pvs);
GDR_API uint32_t gdr_pvs_cell_count(const gdr_pvs *pvs);
/* Box of baked cell i (in [0, gdr_pvs_cell_count)). */
GDR_API void gdr_pvs_cell_bounds(const gdr_pvs *pvs, uint32_t cell, gdr_vec3 *min, gdr_vec3 *max);
/* The sample points of baked cell i (NULL and 0 unless baked with keep_samples). */
GDR_API const gdr_vec3 *gdr_pvs_samples(const gdr_pvs *pvs, uint32_t cell, uint32_t *count);

/* Serialised form (docs/CULLING.md): little-endian, checksummed. */
GDR_API size_t gdr_pvs_serialized_size(const gdr_pvs *pvs);
/* Writes gdr_pvs_serialized_size bytes; fails if capacity is smaller. */
GDR_API gdr_status gdr_pvs_serialize(const gdr_pvs *pvs, void *destination, size_t capacity, gdr_error *err);
/* Untrusted input: every size, offset and compressed chunk is checked; bad data is refused with
 * GDR_ERROR_PARSE. A chunk must hold exactly the bitsets of its cells (uncompressed size = its
 * cell count x the bitset size, in the chunk table and in the zstd frame), checked before any
 * decompression buffer is allocated. The data is copied. */
GDR_API gdr_status gdr_pvs_load(const void *data, size_t size, gdr_pvs **out, gdr_error *err);

/* The lookup cache keeps the last decompressed chunk (moving within a chunk costs nothing). */
GDR_API gdr_status gdr_pvs_cache_create(const gdr_pvs *pvs, gdr_pvs_cache **out, gdr_error *err);
GDR_API void gdr_pvs_cache_destroy(gdr_pvs_cache *cache);
GDR_API const gdr_pvs *gdr_pvs_cache_pvs(const gdr_pvs_cache *cache);
/* The visibility bitset (gdr_cull_word_count(gdr_pvs_object_count) words) of the cell holding
 * point, or NULL when the point is in no baked cell. Valid until the next lookup. */
GDR_API const uint32_t *gdr_pvs_lookup(gdr_pvs_cache *cache, gdr_vec3 point);
/* Decompressions done so far (cache misses), for tests and statistics. */
GDR_API uint64_t gdr_pvs_cache_decompressions(const gdr_pvs_cache *cache);

#ifdef __cplusplus
}
#endif
#endif
