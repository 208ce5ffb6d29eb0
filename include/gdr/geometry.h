/* gdr geometry: a mesh as clusters (meshlets, issue 4) and the cluster LOD DAG over them (issue 5).
 *
 * A cluster is a small piece of a mesh: at most GDR_CLUSTER_MAX_VERTICES vertices and
 * GDR_CLUSTER_MAX_TRIANGLES triangles whose corners are uint8 indices into the cluster's own
 * vertex list, which in turn indexes the mesh's vertices. Clusters are the unit of culling and
 * drawing. Level 0 (the first `level0_cluster_count` clusters) covers the mesh's triangles
 * exactly; the LOD DAG appends coarser clusters, grouped, up to a root.
 *
 * Memory: every array of gdr_mesh_clusters is allocated with malloc and owned by the struct;
 * gdr_mesh_clusters_free releases it. A mesh of a gdr_scene owns its clusters (gdr_mesh.clusters)
 * and gdr_scene_destroy frees them. */
#ifndef GDR_GEOMETRY_H
#define GDR_GEOMETRY_H

#include <stdint.h>

#include "gdr/core.h"
#include "gdr/math.h"

#ifdef __cplusplus
extern "C" {
#endif

#define GDR_CLUSTER_MAX_VERTICES 64u
#define GDR_CLUSTER_MAX_TRIANGLES 124u

typedef struct gdr_cluster {
    uint32_t vertex_offset;   /* first entry of this cluster in gdr_mesh_clusters.vertices */
    uint32_t triangle_offset; /* first byte in gdr_mesh_clusters.triangles (3 bytes per triangle); a
                                 multiple of 4, so a shader can read whole 32-bit words (the bytes
                                 between clusters are zero) */
    uint32_t vertex_count;    /* 1 .. GDR_CLUSTER_MAX_VERTICES */
    uint32_t triangle_count;  /* 1 .. GDR_CLUSTER_MAX_TRIANGLES */
    gdr_vec4 sphere;          /* bounding sphere in mesh space: centre xyz, radius w; contains every
                                 vertex of the cluster */
    gdr_vec3 cone_apex;       /* normal cone in mesh space (meshopt_computeMeshletBounds, checked and
                                 made conservative in double: the test below is exact on these floats) */
    gdr_vec3 cone_axis;       /* unit length, or zero when the cluster has no useful cone */
    float cone_cutoff;        /* every triangle of the cluster is back-facing (or edge-on) from p when
                                 dot(normalize(cone_apex - p), cone_axis) >= cone_cutoff
                                 (meshoptimizer's perspective test; cutoff = sine of the half-angle
                                 of the cone of triangle normals around the axis). 1 with a zero
                                 axis: no useful cone, never cone-culled. In world space: apex as a
                                 point, axis as a direction (renormalised); valid under rotation,
                                 translation and uniform scale, not mirroring or non-uniform scale.
                                 Guard p == apex (NaN: do not cull). docs/GEOMETRY.md */
    uint32_t group;           /* LOD DAG: the group this cluster is part of (merged and simplified into
                                 coarser clusters); GDR_NO_INDEX without a DAG */
    uint32_t refined_group;   /* LOD DAG: the more detailed group this cluster was made from;
                                 GDR_NO_INDEX for original (level-0) geometry */
    uint32_t reserved;
} gdr_cluster;

/* A group of clusters of the LOD DAG (issue 5). */
typedef struct gdr_cluster_group {
    gdr_vec4 sphere;        /* mesh space; contains the spheres of the groups its clusters came from */
    float error;            /* simplification error in mesh-space units; INFINITY for the root */
    uint32_t depth;         /* DAG depth: 0 for groups of original clusters */
    uint32_t first_cluster; /* clusters whose `group` is this group are [first_cluster, +cluster_count) */
    uint32_t cluster_count;
} gdr_cluster_group;

typedef struct gdr_mesh_clusters {
    gdr_cluster *clusters;
    uint32_t cluster_count;
    uint32_t level0_cluster_count; /* clusters[0 .. level0_cluster_count) are the original meshlets */
    uint32_t *vertices;            /* mesh vertex index of every cluster-local vertex */
    uint32_t vertex_count;
    uint8_t *triangles;            /* cluster-local vertex indices, 3 per triangle */
    uint32_t triangle_byte_count;
    gdr_cluster_group *groups;     /* empty (NULL, 0) until the LOD DAG is built */
    uint32_t group_count;
    uint32_t dag_depth;            /* number of DAG levels above level 0; 0 without a DAG */
} gdr_mesh_clusters;

/* Options of the meshlet builder; zero-initialise, every field has a default. */
typedef struct gdr_meshlet_options {
    uint32_t max_vertices;  /* 0: GDR_CLUSTER_MAX_VERTICES; at most that */
    uint32_t max_triangles; /* 0: GDR_CLUSTER_MAX_TRIANGLES; at most that, a multiple of 4 */
    float cone_weight;      /* 0: the default (0.25); in (0, 1]; favours clusters with tight normal
                               cones over small ones */
    uint32_t thread_count;  /* gdr_scene_build_clusters: workers including the caller, at most 256;
                               0: one per processor. The result does not depend on it. */
} gdr_meshlet_options;

typedef struct gdr_mesh gdr_mesh;   /* gdr/scene.h */
typedef struct gdr_scene gdr_scene; /* gdr/scene.h */

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
 * thread count. Each mesh built also has its vertices renumbered in the order its clusters first
 * use them (positions, normals, uvs, indices and cluster vertices together; the triangles and
 * their order are unchanged), for fetch locality. On failure the error names the first failing
 * mesh ("meshes[3]: mesh 'rock': ...") and no mesh keeps clusters from this call. */
GDR_API gdr_status gdr_scene_build_clusters(gdr_scene *scene, const gdr_meshlet_options *options, gdr_error *err);

GDR_API void gdr_mesh_clusters_free(gdr_mesh_clusters *clusters);

#ifdef __cplusplus
}
#endif
#endif
