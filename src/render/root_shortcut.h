/* A mesh's root shortcut and root chain (GdrGpuMesh.root_*, docs/GEOMETRY.md "A coarse end"), worked
 * out from its groups and the refined groups of the clusters near its root: a scene uploaded whole
 * reads them from its clusters, a streamed one from its pinned page 0 when it arrives. */
#ifndef GDR_RENDER_ROOT_SHORTCUT_H
#define GDR_RENDER_ROOT_SHORTCUT_H

#include <stdbool.h>
#include <stdint.h>

#include "gdr/mesh_clusters.h"
#include "gpu_shared/gpu_types.h"

/* The refined group of mesh-local cluster `cluster` (GDR_NO_INDEX: none); *known false where its
 * record is not at hand (the walk stops there). */
typedef uint32_t gdr_cluster_refined_fn(const void *user, uint32_t cluster, bool *known);

/* Sets mesh's root_first, root_cluster_count, root_refined_sphere, root_refined_error and root_chain
 * for c, a mesh with a DAG (its root group the last). */
void gdr_root_shortcut_set(const gdr_mesh_clusters *c, gdr_cluster_refined_fn *refined, const void *user,
                           GdrGpuMesh *mesh);

/* gdr_cluster_refined_fn over c's own clusters (user: c). */
uint32_t gdr_cluster_refined_of_clusters(const void *user, uint32_t cluster, bool *known);

#endif
