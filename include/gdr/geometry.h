/* gdr geometry: building a mesh's clusters (meshlets), the cluster LOD DAG over them, their
 * hierarchy and the vertices' quantization. The data these builders write (gdr_mesh_clusters,
 * gdr_vertex_quantization) is part of the scene model: gdr/mesh_clusters.h. */
#ifndef GDR_GEOMETRY_H
#define GDR_GEOMETRY_H

#include <stddef.h>
#include <stdint.h>

#include "gdr/core.h"
#include "gdr/math.h"
#include "gdr/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Options of the meshlet builder; zero-initialise, every field has a default. */
typedef struct gdr_meshlet_options {
    uint32_t max_vertices;  /* 0: GDR_CLUSTER_MAX_VERTICES; at most that */
    uint32_t max_triangles; /* 0: GDR_CLUSTER_MAX_TRIANGLES; at most that, a multiple of 4 */
    float cone_weight;      /* 0: the default (0.25); in (0, 1]; favours clusters with tight normal
                               cones over small ones */
    uint32_t thread_count;  /* workers including the caller, at most 256; 0: one per processor. A mesh
                               is built in chunks of 32,768 triangles, side by side; a scene's meshes
                               side by side. The result does not depend on it. */
} gdr_meshlet_options;

/* Moves every mesh's vertices onto its grid (positions, normals, uvs; the grid is chosen per mesh
 * from its bounds) and keeps every bound honest: the mesh sphere and each cluster's sphere grow by
 * the largest displacement d, each cluster's normal cone is measured again on the moved triangles,
 * each LOD group above level 0 states its error plus 2d (both its surface and the full-detail one
 * moved by at most d), group spheres grow by d and each hierarchy is built again. Meshes already
 * quantized are left as they are. A scene read for streaming is refused. */
GDR_API gdr_status gdr_scene_quantize_vertices(gdr_scene *scene, gdr_error *err);

/* Splits `mesh` into level-0 clusters (meshoptimizer), written to `out`, which must be zeroed;
 * on failure `out` stays empty. The mesh needs at least one triangle, indices below vertex_count
 * and finite positions; options (NULL: defaults) need max_vertices in [3, 64] and max_triangles a
 * multiple of 4 in [4, 124]. Every input triangle is in exactly one cluster, with its corners in
 * the same order; clusters, vertices and triangles arrays are sized exactly; every cluster's
 * group and refined_group are GDR_NO_INDEX and level0_cluster_count is cluster_count. */
GDR_API gdr_status gdr_meshlets_build(const gdr_mesh *mesh, const gdr_meshlet_options *options,
                                      gdr_mesh_clusters *out, gdr_error *err);

/* Builds the clusters of every mesh of `scene` whose clusters are empty and that has triangles
 * (options may be NULL), one mesh per task on a thread pool; the result does not depend on the
 * thread count. Each mesh built first has its vertices that are equal in every attribute, bit for
 * bit (position, normal, uv, colour), made one vertex, at most 128 triangle corners each (a mesh
 * with no two such vertices is left as it is; docs/GEOMETRY.md, "Welding equal vertices"), and
 * afterwards its vertices renumbered in the order its clusters first use them (positions,
 * normals, uvs, colours, indices and cluster vertices together; the triangles and their order are
 * unchanged, every corner keeps its attributes), for fetch locality. On failure the error names the first failing
 * mesh ("meshes[3]: mesh 'rock': ...") and no mesh keeps clusters from this call. */
GDR_API gdr_status gdr_scene_build_clusters(gdr_scene *scene, const gdr_meshlet_options *options, gdr_error *err);

/* --- LOD DAG ---------------------------------------------------------------------------------
 *
 * gdr_mesh_build_lod_dag turns level 0 into a DAG (seed 004, Nanite): the current clusters are
 * partitioned into groups of neighbours holding about as many triangles as sixteen level-0 clusters
 * (METIS over the graph of clusters that share edges, weighted by the number of shared edges);
 * each group's triangles are merged, simplified to about half (meshoptimizer) with every vertex
 * that the group shares with other groups locked, and split into new clusters; repeat until one
 * cluster is left, then simplify that one further, step by step, until it holds at most
 * gdr_lod_options.root_triangles triangles, or until nothing simplifies any more. The clusters that
 * remain form the root group.
 *
 * After the build:
 *  - every cluster has a `group` (the group it is part of); level-0 clusters have refined_group
 *    GDR_NO_INDEX, every other cluster has the group it was made from as refined_group;
 *  - the clusters of group g are clusters[groups[g].first_cluster .. + cluster_count), so the
 *    clusters are ordered by group; level 0 still comes first (level0_cluster_count of them,
 *    reordered by group), and clusters' data offsets need not increase with the cluster index;
 *  - errors are mesh-space distances; a group's error is the larger of its clusters' measured
 *    deviation from the full-detail surface (level 0) they replace, both ways (docs/GEOMETRY.md,
 *    "The error"), and the errors of the groups its clusters were made from; it is > 0 (at least
 *    1e-6 of the mesh's bounding radius); its
 *    sphere contains their spheres and its clusters' spheres; the root group (the last one) has
 *    error INFINITY; groups[g].depth is the build step that formed the group (0 for groups of
 *    level-0 clusters), strictly greater than the depth of the groups its clusters were made from;
 *    dag_depth is the root's depth.
 *
 * The cut (what to draw for one view), with E(g) the projected error of group g in pixels:
 *     E(g) = error_w / max(distance(camera, centre_w) - radius_w, znear) * P[1][1] * 0.5 * viewport_height
 * where centre_w is the group sphere's centre through the instance transform and radius_w, error_w
 * are the radius and error times the transform's largest axis scale (E is INFINITY for the root):
 *     a cluster is drawn  <=>  passes(refined_group) && !passes(group),
 *     passes(GDR_NO_INDEX as refined_group) = true,  passes(GDR_NO_INDEX as group) = false,
 *     passes(g) = E(g) <= threshold.
 * Because E only grows from a group to the groups made from its clusters, this draws every part of
 * the surface exactly once, without cracks: threshold 0 draws exactly level 0, a threshold larger
 * than every finite E draws exactly the root group's clusters. A mesh without a DAG (no groups)
 * draws level 0. The same rule with passes(g) = (depth(g) < N and g is not the root) is a discrete
 * cut at DAG depth N (N = 0: level 0). src/geometry/lod_cut.h holds the CPU reference of both.
 *
 * A group whose simplification does not remove at least 15% of its triangles, or that would move
 * a locked border, is not formed: its clusters are grouped again at the next step with other
 * neighbours (at step 0 it is formed as a group whose new clusters are its clusters unchanged,
 * sharing their data, so that level 0 stays whole). When a whole step makes no progress the build
 * stops and what is left becomes the root group: gdr_lod_stats says why the build stopped. */

#define GDR_LOD_MAX_LEVELS 64u
/* The root a closed mesh simplifies down to, in triangles (docs/GEOMETRY.md, "A coarse end"). */
#define GDR_LOD_DEFAULT_ROOT_TRIANGLES 4u

typedef enum gdr_lod_stop {
    GDR_LOD_STOP_NONE = 0,       /* nothing built */
    GDR_LOD_STOP_SINGLE_CLUSTER, /* simplified down to one cluster of at most root_triangles
                                    triangles, or to one that simplifies no further: the root
                                    group holds it */
    GDR_LOD_STOP_NO_PROGRESS,    /* no group of the last step simplified enough: the root group
                                    holds the clusters that were left */
    GDR_LOD_STOP_LEVEL_LIMIT,    /* GDR_LOD_MAX_LEVELS steps; the root group holds what was left */
    GDR_LOD_STOP_COUNT
} gdr_lod_stop;

/* Options of the DAG build; zero-initialise, every field has a default. */
typedef struct gdr_lod_options {
    uint32_t group_size;   /* a group holds about as many triangles as this many level-0 clusters;
                              0: 16; in [2, 32] */
    float target_ratio;    /* share of a group's triangles that simplification aims to keep; 0: 0.5;
                              in (0, 0.85) */
    uint32_t thread_count; /* workers including the caller, at most 256; 0: one per processor. The
                              result does not depend on it (same bytes). */
    int no_progress;       /* 1: never draw a progress bar (default: on a terminal, after 0.3 s) */
    uint32_t root_triangles; /* the build goes on below one cluster until the lone cluster holds at
                                most this many triangles (or stops simplifying); 0:
                                GDR_LOD_DEFAULT_ROOT_TRIANGLES; in [1, GDR_CLUSTER_MAX_TRIANGLES]
                                (the largest: stop at one cluster, as before) */
    int ignore_uvs;        /* 1: the uvs neither steer simplification nor enter the error (no
                              material samples a texture through them). gdr_scene_build_lod sets it
                              for each mesh none of whose instances has a textured material. */
} gdr_lod_options;

/* What a build did; for a scene, sums over the meshes built. */
typedef struct gdr_lod_stats {
    uint32_t mesh_count;              /* meshes whose DAG was built */
    uint32_t stop_counts[GDR_LOD_STOP_COUNT]; /* meshes by the reason their build stopped */
    uint32_t max_depth;               /* largest dag_depth */
    uint64_t group_count;
    uint64_t cluster_count;           /* all levels */
    uint64_t input_triangles;         /* level 0 */
    uint64_t dag_triangles;           /* all clusters, level 0 included */
    uint64_t root_clusters, root_triangles;
    uint64_t stuck_groups;            /* groups not formed (too little reduction), regrouped later */
    uint64_t border_rejects;          /* of those, simplifications that moved a locked border */
    uint64_t passthrough_clusters;    /* clusters copied unchanged at step 0 (sharing their data) */
    uint64_t sloppy_groups;           /* whole-frontier groups simplified by vertex clustering, where a
                                         step formed no group (separate pieces, stuck seams) */
} gdr_lod_stats;

/* Builds the LOD DAG of `mesh` over its level-0 clusters (gdr_meshlets_build), appending the
 * coarser clusters, their vertices and triangles (indices of the mesh's own vertices: no vertex is
 * added) and the groups to mesh->clusters; a DAG already there is replaced. Needs level-0 clusters
 * whose data is in range and finite positions. options and stats may be NULL. On failure the mesh
 * keeps its level-0 clusters (order unchanged) and no DAG. */
GDR_API gdr_status gdr_mesh_build_lod_dag(gdr_mesh *mesh, const gdr_lod_options *options, gdr_lod_stats *stats,
                                          gdr_error *err);

/* Builds level-0 clusters where a mesh with triangles has none (gdr_scene_build_clusters, default
 * meshlet options but options->thread_count) and then the DAG of every mesh that has clusters but
 * no DAG. Large meshes are built one at a time with all threads, small ones side by side; the
 * result does not depend on the thread count. On failure the error names the first failing mesh
 * ("meshes[3]: mesh 'rock': ...") and no mesh keeps a DAG from this call. */
GDR_API gdr_status gdr_scene_build_lod(gdr_scene *scene, const gdr_lod_options *options, gdr_lod_stats *stats,
                                       gdr_error *err);

/* --- LOD hierarchy -----------------------------------------------------------------------------
 *
 * A bounding-volume hierarchy over the DAG's groups, so that a traversal from the root visits only
 * the parts of a mesh where the cut can lie (docs/GEOMETRY.md, "LOD hierarchy"). The leaves are
 * the groups, one leaf per group, naming the group's clusters (contiguous: see the DAG above);
 * level 0 is covered by the groups of depth 0, whose clusters have no refined group. A mesh
 * without a DAG gets leaves of up to GDR_LOD_LEAF_CLUSTERS_NO_DAG consecutive clusters, without a
 * group (max_error INFINITY, min_refined_error 0: the LOD test never skips them, only frustum and
 * occlusion tests can). Each DAG depth gets its own subtree (the groups of one depth have errors of
 * one scale, so a node's error bounds stay tight), built top-down by splitting the groups at the
 * median of their centres along the longest axis, three times per node: up to
 * GDR_LOD_NODE_MAX_CHILDREN children. The subtrees' roots, deepest first, are joined under a top
 * tree. Nodes are stored breadth first: the root is node 0, every node's children are contiguous
 * and come after it, and each level of the tree is a contiguous range, so a GPU can traverse level
 * by level or from a work queue.
 *
 * A node may be skipped (no cluster below it is in the cut) when gdr_lod_node_may_draw
 * (src/shaders/shared/lod_math.h) says so: either every group below passes (its max_error, seen
 * from the nearest point of its sphere, projects within the threshold) or no refined group below
 * passes (min_refined_error, seen from the farthest point, projects above it). The proof that this
 * never skips a cluster the flat cut draws, with float rounding, is in docs/GEOMETRY.md.
 *
 * gdr_meshlets_build and gdr_mesh_build_lod_dag build the hierarchy of what they build (and so the
 * scene-wide builds and gdr_cache_read), so clusters come with their hierarchy. */

/* (Re)builds clusters->lod_nodes over clusters' groups (or over its clusters without a DAG).
 * Needs the DAG's contract above (or clusters without groups). Fails only when out of memory, or
 * with more than GDR_LOD_NODE_MAX_LEVELS levels (never for 32-bit counts); on failure the
 * hierarchy is empty. */
GDR_API gdr_status gdr_mesh_clusters_build_hierarchy(gdr_mesh_clusters *clusters, gdr_error *err);

/* Checks that clusters->lod_nodes is a hierarchy of the contract above: a tree stored breadth first
 * whose leaves name each group exactly once (each cluster exactly once without a DAG), whose
 * spheres contain their children's spheres (and a leaf's the spheres of its group, its clusters and
 * their refined groups), and whose error bounds contain their children's (in double precision on
 * the stored floats). On a violation writes what and where
 * to `what` (at most what_size bytes) and returns 0. */
GDR_API int gdr_mesh_clusters_check_hierarchy(const gdr_mesh_clusters *clusters, char *what, size_t what_size);

/* A sphere (centre xyz, radius w) containing every sphere of the list: the centre of their bounding
 * box, the radius computed in double and rounded up, with a relative slack of 1e-6, so that
 * containment survives float evaluation of the distances. The LOD DAG's and the hierarchy's
 * spheres are made with it; so are the renderer's bounds over several groups. count 0: all zero. */
GDR_API gdr_vec4 gdr_lod_enclosing_sphere(const gdr_vec4 *spheres, size_t count);

#ifdef __cplusplus
}
#endif
#endif
