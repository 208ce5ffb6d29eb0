/* The LOD nodes' absent counts of a streamed scene, kept up to date one group at a time
 * (docs/STREAMING.md, "Node counts"). A node's count is the number of clusters below it whose
 * refined group is absent (gdr_lod_nodes_count_absent_refined); when group R comes or goes, only
 * the leaves holding clusters made from R (refined group R) and their ancestors change, each by the
 * number of such clusters below it. Setting a group walks up from those leaves: the work and the
 * words to upload follow the changed groups, not the mesh. The changed words come back as runs of
 * consecutive nodes, for one copy each. */
#ifndef GDR_RENDER_NODE_COUNTS_H
#define GDR_RENDER_NODE_COUNTS_H

#include <stdbool.h>
#include <stdint.h>

#include "gdr/core.h"
#include "gdr/mesh_clusters.h"
#include "gdr/thread_pool.h"

typedef struct gdr_node_counts gdr_node_counts;

/* A run of changed counts: nodes [first, first + count) of the scene (global node indices). */
typedef struct gdr_node_run {
    uint32_t first, count;
} gdr_node_run;

/* For `mesh_count` meshes, mesh m's nodes at global index node_offsets[m] + n. Every group starts
 * absent and every node changed (the first runs cover them all). The clusters must outlive it. */
gdr_status gdr_node_counts_create(const gdr_mesh_clusters *const *meshes, const uint32_t *node_offsets,
                                  uint32_t mesh_count, gdr_node_counts **out, gdr_error *err);
/* The same, the per-mesh work on `pool` (NULL: this thread), one task per mesh: the same counts. */
gdr_status gdr_node_counts_create_on(const gdr_mesh_clusters *const *meshes, const uint32_t *node_offsets,
                                     uint32_t mesh_count, gdr_thread_pool *pool, gdr_node_counts **out,
                                     gdr_error *err);
void gdr_node_counts_destroy(gdr_node_counts *counts);

/* Group `group` of mesh `mesh` becomes resident or absent. Returns the nodes whose count it changed
 * (0 when the group already was so). */
uint32_t gdr_node_counts_set(gdr_node_counts *counts, uint32_t mesh, uint32_t group, bool resident);

/* The current counts, by global node index. */
const uint32_t *gdr_node_counts_words(const gdr_node_counts *counts);
/* Mesh `mesh`'s absent groups. */
uint32_t gdr_node_counts_absent_groups(const gdr_node_counts *counts, uint32_t mesh);
/* The nodes changed since the last call (at most the scene's node count), as sorted runs of
 * consecutive indices into `runs` (room for the scene's node count); forgets them. Returns the
 * number of runs; *words the nodes in them. */
uint32_t gdr_node_counts_take_changes(gdr_node_counts *counts, gdr_node_run *runs, uint32_t *words);
/* The scene's node count. */
uint32_t gdr_node_counts_node_total(const gdr_node_counts *counts);

#endif
