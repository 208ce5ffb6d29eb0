/* The LOD cut on the CPU: the reference the GPU selection (meshlet.task) is checked against.
 * The per-group math is shared with the shaders (src/gpu_shared/lod_math.h); the
 * rule itself is documented in gdr/geometry.h ("The cut"). */
#ifndef GDR_GEOMETRY_LOD_CUT_H
#define GDR_GEOMETRY_LOD_CUT_H

#include "gpu_shared/lod_math.h"

#include <stdint.h>

#include "gdr/geometry.h"
#include "gdr/math.h"

/* One view of one mesh instance. */
typedef struct gdr_lod_view {
    gdr_mat4 transform;       /* mesh space -> world space */
    gdr_vec3 camera_position; /* world space */
    float projection_y;       /* P[1][1] of the projection (1 / tan(fovy / 2)) */
    float viewport_height;    /* pixels */
    float znear;              /* > 0 */
    float threshold;          /* pixels, finite; 0 draws level 0 */
} gdr_lod_view;

/* projection_y * 0.5 * viewport_height. */
float gdr_lod_projection_scale(const gdr_lod_view *view);

/* Whether group `group` passes for `view`: its projected error is <= threshold. The threshold
 * must be finite: the root's projected error is INFINITY and never passes. */
bool gdr_lod_group_passes(const gdr_mesh_clusters *clusters, uint32_t group, const gdr_lod_view *view);

/* The cut: selected[i] = 1 for each cluster i the rule draws, else 0 (cluster_count bytes).
 * Returns the number of clusters selected. */
uint32_t gdr_lod_cut_select(const gdr_mesh_clusters *clusters, const gdr_lod_view *view, uint8_t *selected);

/* The cut of a streamed mesh, of which only some groups are resident (group_resident[g] != 0):
 * a group that is absent counts as passing, so its clusters are not drawn and the clusters made
 * from it, in the groups above, are drawn instead where those do not pass. When the resident
 * groups are closed upwards (every group made from a resident group is resident, the root always
 * is), each source-to-root path still holds exactly one drawn cluster: no hole, no crack. With
 * every group resident it is gdr_lod_cut_select. Returns the number of clusters selected. */
uint32_t gdr_lod_cut_select_resident(const gdr_mesh_clusters *clusters, const gdr_lod_view *view,
                                     const uint8_t *group_resident, uint8_t *selected);

/* What a hierarchical cut did: the work a traversal of the LOD hierarchy saves. */
typedef struct gdr_lod_traversal_stats {
    uint64_t nodes_tested;    /* nodes whose test ran (the root and the children of nodes that passed) */
    uint64_t leaves_accepted; /* leaves that passed: their clusters were tested */
    uint64_t clusters_tested; /* clusters of those leaves, each tested by the cut rule */
} gdr_lod_traversal_stats;

/* The same cut as gdr_lod_cut_select (the same bytes in `selected`, cluster_count of them), found
 * by walking clusters->lod_nodes from the root with gdr_lod_node_may_draw (the test a GPU
 * traversal uses) and testing only the clusters of the leaves reached. A mesh without a hierarchy
 * falls back to the flat cut (every cluster tested). stats (may be NULL) are added to. */
uint32_t gdr_lod_cut_select_hierarchical(const gdr_mesh_clusters *clusters, const gdr_lod_view *view,
                                         uint8_t *selected, gdr_lod_traversal_stats *stats);

/* For the cut over resident groups by traversal: absent[n] = the clusters below node n whose refined
 * group is not resident (lod_node_count entries). A node test's second side ("no refined group
 * below passes", gdr_lod_node_may_draw) only holds where this is 0: an absent refined group counts
 * as passing. */
void gdr_lod_nodes_count_absent_refined(const gdr_mesh_clusters *clusters, const uint8_t *group_resident,
                                        uint32_t *absent);

/* gdr_lod_cut_select_resident found by walking the hierarchy: a node is skipped when every group
 * below passes (which an absent group does too), or, where absent[node] is 0, when no refined group
 * below passes; a leaf's clusters get the resident rule. The same bytes as
 * gdr_lod_cut_select_resident. stats (may be NULL) are added to. */
uint32_t gdr_lod_cut_select_hierarchical_resident(const gdr_mesh_clusters *clusters, const gdr_lod_view *view,
                                                  const uint8_t *group_resident, const uint32_t *absent,
                                                  uint8_t *selected, gdr_lod_traversal_stats *stats);

/* The discrete debug cut at DAG depth N (gdr/geometry.h): the same rule with
 * passes(g) = (depth(g) < depth and g is not the root). */
uint32_t gdr_lod_cut_select_depth(const gdr_mesh_clusters *clusters, uint32_t depth, uint8_t *selected);

/* Group `group`'s first refinement in c->refinements (they are in group order: a binary search), or
 * c->refinement_count where it has none. */
static inline uint32_t gdr_lod_first_refinement(const gdr_mesh_clusters *c, uint32_t group)
{
    uint32_t lo = 0, hi = c->refinement_count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (c->refinements[mid].group < group)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

#endif
