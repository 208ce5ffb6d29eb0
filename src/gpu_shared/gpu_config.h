/* Limits and workgroup sizes shared by the host and the shaders. */
#ifndef GDR_GPU_CONFIG_H
#define GDR_GPU_CONFIG_H

#define GDR_CULL_WORKGROUP_SIZE 64
#define GDR_SCATTER_WORKGROUP_SIZE 64
#define GDR_REDUCE_WORKGROUP_SIZE 256
#define GDR_FRAMES_IN_FLIGHT 2
/* Meshlet pipeline: a task workgroup tests up to this many clusters of one instance (one thread
 * each); a mesh workgroup draws one cluster (at most GDR_CLUSTER_MAX_VERTICES / _TRIANGLES of
 * gdr/geometry.h, repeated here for GLSL and checked in gpu_types_check.c). */
#define GDR_TASK_WORKGROUP_SIZE 32
#define GDR_MESH_WORKGROUP_SIZE 32
#define GDR_MESH_MAX_VERTICES 64
#define GDR_MESH_MAX_TRIANGLES 124
/* maxTaskWorkGroupCount[0] is at least this on every device: larger launches use y too. */
#define GDR_TASK_GROUPS_PER_ROW 65535
/* The cluster cull of the visibility-buffer modes (clustercull.comp) takes this many task commands
 * per workgroup, GDR_CLUSTER_CULL_LANES invocations each, which step through a command's clusters
 * as far as the workgroup's largest command needs: most commands of a large field are a distant
 * instance's root group, one or two clusters. */
#define GDR_CLUSTER_CULL_TASKS 32
#define GDR_CLUSTER_CULL_LANES 8
/* An instance that needs at most this many clusters (a distant instance's root group, a small mesh)
 * has them tested and binned by its instance-cull invocation (GDR_FRAME_DIRECT_CLUSTERS): a task
 * command of one or two clusters costs the cluster cull a whole GDR_CLUSTER_CULL_LANES slot and a
 * second pass over the instance. */
#define GDR_DIRECT_CLUSTERS 4
/* The instance cull walks at most this many clusters of a mesh's root chain (GdrGpuMesh.root_chain):
 * a chain halves its triangles at every step, so a cluster's 124 reach a handful in 5 or 6. */
#define GDR_LOD_ROOT_CHAIN 8
/* LOD statistics: clusters and triangles drawn per DAG depth, the last bucket for deeper ones. */
#define GDR_LOD_STATS_DEPTHS 32
/* The LOD hierarchy traversal (lodtraverse.comp): one invocation per node visit, one dispatch per
 * level of the hierarchies (at most GDR_LOD_TREE_LEVELS, gdr/geometry.h's GDR_LOD_NODE_MAX_LEVELS);
 * a level holds at most GDR_TRAVERSE_MAX_VISITS visits (a one-dimensional indirect dispatch). */
#define GDR_TRAVERSE_WORKGROUP_SIZE 64
/* Stream requests a frame appends at most (shared/residency.h); the rest are counted and dropped:
 * the groups still absent ask again the next frame. */
#define GDR_STREAM_REQUEST_CAPACITY 4096

/* Meshes of at most this many task commands of clusters are tested whole: their few commands cost
 * less than the traversal's levels (the same cut either way). */
#define GDR_TRAVERSE_MIN_TASKS 8
#define GDR_LOD_TREE_LEVELS 32
#define GDR_TRAVERSE_MAX_VISITS (65535u * GDR_TRAVERSE_WORKGROUP_SIZE)
/* Task commands a frame phase can hold at most (16 bytes each); a scene that could need more gets
 * this many, and a frame that needs more counts the excess (task_overflow). */
#define GDR_MAX_TASK_COMMANDS (1u << 24)
/* Instance records the CPU can send per frame through the update ring. */
#define GDR_INSTANCE_UPDATES_PER_FRAME 4096
/* Hybrid rasterisation: one software-raster workgroup per cluster; a visibility-buffer id
 * is (visible-cluster slot << GDR_VISBUFFER_TRIANGLE_BITS) | triangle, so a frame can name at most
 * GDR_RASTER_MAX_CLUSTERS visible clusters; vertices snap to GDR_SW_SUBPIXEL_BITS fractional bits
 * (subPixelPrecisionBits of lavapipe and of NVIDIA and AMD GPUs; the usual value). */
#define GDR_SW_RASTER_WORKGROUP_SIZE 64
#define GDR_VISBUFFER_TRIANGLE_BITS 7
#define GDR_RASTER_MAX_CLUSTERS (1u << 25)
#define GDR_SW_SUBPIXEL_BITS 8
#define GDR_SW_GROUPS_PER_ROW 65535
/* Tiny clusters (the coarse end of a distant instance's DAG) share a compute-raster workgroup, by
 * size class: class k (0 <= k < GDR_SW_TINY_CLASSES) takes the clusters of at most
 * GDR_SW_TINY_LANES << k vertices and as many triangles that no smaller class takes, with that many
 * invocations each (one per vertex, then one per triangle) and as many vertices of the workgroup's
 * shared memory: GDR_SW_RASTER_WORKGROUP_SIZE / (GDR_SW_TINY_LANES << k) clusters per workgroup.
 * A workgroup of its own would keep 60 of 64 invocations idle for a root of 4 triangles. */
#define GDR_SW_TINY_LANES 8u
#define GDR_SW_TINY_CLASSES 3
/* Mesh workgroups launched without a task shader (the visibility-buffer modes): maxMeshWorkGroupCount
 * is at least this in x and y on every device with mesh shaders. */
#define GDR_MESH_GROUPS_PER_ROW 65535
/* The visibility buffer's resolve: one workgroup per square tile of this many pixels a side. */
#define GDR_RESOLVE_TILE 8
/* The background colour, written as is into the UNORM colour target. */
/* The frame's directional light: the direction towards it, in world space, before normalisation. */
#define GDR_LIGHT_TOWARDS_X 0.35f
#define GDR_LIGHT_TOWARDS_Y 0.85f
#define GDR_LIGHT_TOWARDS_Z 0.4f
#define GDR_BACKGROUND_R 0.42f
#define GDR_BACKGROUND_G 0.55f
#define GDR_BACKGROUND_B 0.72f
/* Bindless textures: every texture of the scene in one array of sampled images (binding 0 of this
 * descriptor set; set 0 is the depth pyramid's) and a sampler per packed glTF sampler state
 * (binding 1, GDR_SAMPLER_STATES of them), both partially bound; a material names one of each. */
#define GDR_TEXTURE_SET 1
#define GDR_MAX_TEXTURES 4096
#define GDR_SAMPLER_SLOTS 256

#endif
