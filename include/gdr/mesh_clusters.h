/* gdr mesh clusters: the data of a mesh as clusters (meshlets) and the cluster LOD DAG over them,
 * part of the scene model (a gdr_mesh owns its clusters); gdr/geometry.h builds them.
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
#ifndef GDR_MESH_CLUSTERS_H
#define GDR_MESH_CLUSTERS_H

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

/* A group of clusters of the LOD DAG. */
typedef struct gdr_cluster_group {
    gdr_vec4 sphere;        /* mesh space; contains the spheres of the groups its clusters came from */
    float error;            /* simplification error in mesh-space units; INFINITY for the root */
    uint32_t depth;         /* DAG depth: 0 for groups of original clusters */
    uint32_t first_cluster; /* clusters whose `group` is this group are [first_cluster, +cluster_count) */
    uint32_t cluster_count;
} gdr_cluster_group;

/* One node of a mesh's LOD hierarchy (below, "LOD hierarchy"). The GPU reads the same bytes as
 * GdrGpuLodNode (src/shaders/shared/gpu_types.h; the layouts are checked to agree). */
typedef struct gdr_lod_node {
    gdr_vec4 sphere;         /* mesh space; contains the sphere of every group, refined group and
                                cluster below the node */
    float max_error;         /* the largest error of a group below (INFINITY when the root group is) */
    float min_refined_error; /* the smallest error of a refined group of a cluster below; 0 when a
                                cluster below has none (level 0) */
    uint32_t first;          /* inner node: its first child (children are [first, first + count));
                                leaf: its first cluster (clusters [first, first + count)) */
    uint32_t count;          /* inner node: 1 .. GDR_LOD_NODE_MAX_CHILDREN; leaf: >= 1 */
    uint32_t group;          /* leaf: the group whose clusters it names, GDR_NO_INDEX without a DAG;
                                inner node: GDR_NO_INDEX */
    uint32_t flags;          /* GDR_LOD_NODE_LEAF */
    uint32_t reserved[2];    /* zero */
} gdr_lod_node;

#define GDR_LOD_NODE_LEAF 1u
#define GDR_LOD_NODE_MAX_CHILDREN 8u
#define GDR_LOD_NODE_MAX_LEVELS 32u
#define GDR_LOD_LEAF_CLUSTERS_NO_DAG 4u /* clusters per leaf of a mesh without a DAG */

/* What a group's clusters were made from: `cluster_count` clusters of group `group` have refined
 * group `refined_group` (gdr_mesh_clusters.refinements; cache section 'CLGR'). */
typedef struct gdr_cluster_refinement {
    uint32_t group, refined_group, cluster_count;
} gdr_cluster_refinement;

/* Clusters by size, the larger of their vertex and triangle counts: class b holds the sizes in
 * (2^(b-1), 2^b] (class 0: size 1), so the last holds up to 128 >= GDR_CLUSTER_MAX_TRIANGLES. */
#define GDR_CLUSTER_SIZE_CLASSES 8u

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
    gdr_lod_node *lod_nodes;       /* the hierarchy over the clusters (below, "LOD hierarchy"); empty
                                      (NULL, 0) only where a build failed */
    uint32_t lod_node_count;
    uint32_t lod_node_levels;      /* levels of lod_nodes: 1 for a root alone, at most GDR_LOD_NODE_MAX_LEVELS */
    /* A mesh read for streaming (gdr_scene.geometry_in_pages) holds no per-cluster array (clusters
     * NULL, cluster_count still its count: the records are in the pages) but these, which stand in for
     * what is read from the clusters otherwise; NULL and 0 in a mesh that holds its clusters. */
    gdr_vec4 *group_bounds;        /* per group: gdr_lod_enclosing_sphere of its clusters' spheres, in order */
    gdr_cluster_refinement *refinements; /* per group in order, its clusters' refined groups in order of first use */
    uint32_t refinement_count;
    uint32_t size_classes[GDR_CLUSTER_SIZE_CLASSES]; /* clusters per size class */
} gdr_mesh_clusters;

/* The size class of a cluster of `vertex_count` vertices and `triangle_count` triangles. */
static inline uint32_t gdr_cluster_size_class(uint32_t vertex_count, uint32_t triangle_count)
{
    uint32_t size = vertex_count > triangle_count ? vertex_count : triangle_count, b = 0;
    while (b + 1 < GDR_CLUSTER_SIZE_CLASSES && size > (1u << b))
        b++;
    return b;
}

GDR_API void gdr_mesh_clusters_free(gdr_mesh_clusters *clusters);

/* A mesh's vertices on a grid (gdr_scene_quantize_vertices): every position is
 * position_origin + q * 2^position_exponent with q a 16-bit integer per axis, every uv
 * uv_origin + q * 2^uv_exponent with q a 20-bit integer per axis, every normal the decoding of a
 * 10-bit octahedral pair, so that the cache's pages store them as those integers, losslessly
 * (docs/CACHE_FORMAT.md, "Geometry pages"). enabled 0: plain floats. */
typedef struct gdr_vertex_quantization {
    uint32_t enabled;
    int32_t position_exponent;
    gdr_vec3 position_origin; /* a multiple of 2^position_exponent */
    int32_t uv_exponent;
    gdr_vec2 uv_origin;       /* a multiple of 2^uv_exponent */
    float max_displacement;   /* the largest distance a position moved onto its grid point */
} gdr_vertex_quantization;

#define GDR_QUANTIZED_POSITION_BITS 16
#define GDR_QUANTIZED_UV_BITS 20

#ifdef __cplusplus
}
#endif
#endif
