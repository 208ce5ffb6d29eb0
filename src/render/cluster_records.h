/* The GPU records of every cluster of a scene (GdrGpuMeshlet) and of every LOD hierarchy node
 * (GdrGpuLodNode), filled on a thread pool (cluster_records.c). */
#ifndef GDR_RENDER_CLUSTER_RECORDS_H
#define GDR_RENDER_CLUSTER_RECORDS_H

#include "gdr/mesh_clusters.h"
#include "gdr/thread_pool.h"
#include "gpu_shared/gpu_types.h"

/* Where mesh m's records go: records first[m] .. first[m] + cluster_count - 1 of the output, their
 * vertex and triangle offsets shifted by vertex_base[m] and byte_base[m] (0 for a streamed scene,
 * whose pages set them). */
typedef struct gdr_cluster_record_layout {
    const gdr_mesh_clusters *const *clusters;
    const uint32_t *first, *vertex_base, *byte_base;
    uint32_t mesh_count;
} gdr_cluster_record_layout;

/* Cluster i of c with pool-global data offsets and its groups' LOD data inline. */
GdrGpuMeshlet gdr_cluster_record(const gdr_mesh_clusters *c, uint32_t i, uint32_t vertex_base, uint32_t byte_base);
/* The same for cluster k of c (c's own, or one of a page's): its groups' LOD data from c's groups. */
GdrGpuMeshlet gdr_cluster_record_of(const gdr_mesh_clusters *c, const gdr_cluster *k, uint32_t vertex_base,
                                    uint32_t byte_base);

/* Every mesh's records into out (sum of the meshes' cluster counts, zeroed by the caller), in chunks
 * of `chunk` clusters on the pool's threads; pool NULL fills them in order on the calling thread.
 * The bytes are the same either way: each record depends only on its own cluster. */
void gdr_cluster_records_fill(GdrGpuMeshlet *out, const gdr_cluster_record_layout *layout, uint32_t chunk,
                              gdr_thread_pool *pool);

/* Every mesh's hierarchy nodes for the GPU (GdrGpuLodNode: each gdr_lod_node's bytes, then its
 * culling sphere, which encloses its clusters' spheres or its children's culling spheres), mesh m's
 * at out + first[m], a mesh a task on the pool's threads (pool NULL: in order on this thread). */
void gdr_lod_node_records_fill(GdrGpuLodNode *out, const gdr_mesh_clusters *const *clusters, const uint32_t *first,
                               uint32_t mesh_count, gdr_thread_pool *pool);

#endif
