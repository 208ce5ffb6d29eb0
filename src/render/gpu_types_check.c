/* Compile-time checks of what the shared GPU structs share with Vulkan and the public headers (their
 * own layouts are checked next to their declarations in gpu_types.h). */
#include <stddef.h>
#include <vulkan/vulkan.h>

#include "gdr/mesh_clusters.h"
#include "gdr/renderer.h"
#include "gpu_shared/gpu_types.h"

_Static_assert(GDR_MESH_MAX_VERTICES == GDR_CLUSTER_MAX_VERTICES && GDR_MESH_MAX_TRIANGLES == GDR_CLUSTER_MAX_TRIANGLES,
               "the mesh shader's limits are gdr/mesh_clusters.h's");
_Static_assert(sizeof(GdrGpuDrawCommand) == sizeof(VkDrawIndexedIndirectCommand), "GdrGpuDrawCommand");
_Static_assert(offsetof(GdrGpuDrawCommand, vertex_offset) == offsetof(VkDrawIndexedIndirectCommand, vertexOffset) &&
                   offsetof(GdrGpuDrawCommand, first_instance) == offsetof(VkDrawIndexedIndirectCommand, firstInstance),
               "GdrGpuDrawCommand offsets");
_Static_assert(GDR_LOD_STATS_DEPTHS == GDR_LOD_STATS_DEPTH_COUNT, "LOD statistics: shaders and gdr/renderer.h");
_Static_assert(offsetof(GdrGpuDrawStats, task_groups_z) - offsetof(GdrGpuDrawStats, task_groups_x) ==
                   offsetof(VkDrawMeshTasksIndirectCommandEXT, groupCountZ), "the mesh tasks command inside GdrGpuDrawStats");
_Static_assert(sizeof(GdrGpuPushConstants) <= 128, "push constants must fit the guaranteed 128 bytes");
_Static_assert(offsetof(GdrGpuRasterCounters, dispatch_x) == offsetof(VkDispatchIndirectCommand, x),
               "GdrGpuRasterCounters starts with a VkDispatchIndirectCommand");
_Static_assert(offsetof(GdrGpuRasterCounters, draw_y) == offsetof(GdrGpuRasterCounters, draw_x) + 4 &&
                   offsetof(GdrGpuRasterCounters, draw_z) == offsetof(GdrGpuRasterCounters, draw_x) + 8 &&
                   offsetof(GdrGpuRasterCounters, draw_x) % 4 == 0,
               "GdrGpuRasterCounters.draw_x..z is a VkDrawMeshTasksIndirectCommandEXT");
_Static_assert(GDR_MESH_MAX_TRIANGLES <= (1u << GDR_VISBUFFER_TRIANGLE_BITS) &&
                   GDR_RASTER_MAX_CLUSTERS <= (1ull << (32 - GDR_VISBUFFER_TRIANGLE_BITS)),
               "a visibility-buffer id holds a cluster slot and a triangle in 32 bits");
_Static_assert(GDR_MESH_MAX_VERTICES <= GDR_SW_RASTER_WORKGROUP_SIZE,
               "the software rasteriser transforms a cluster's vertices in one step");
_Static_assert(GDR_SW_RASTER_WORKGROUP_SIZE % GDR_SW_TINY_LANES == 0 &&
                   (GDR_SW_TINY_LANES << (GDR_SW_TINY_CLASSES - 1)) < GDR_SW_RASTER_WORKGROUP_SIZE &&
                   GDR_MESH_MAX_VERTICES == GDR_SW_RASTER_WORKGROUP_SIZE,
               "every tiny class shares a workgroup, and its clusters' vertices fit their slices of the shared vertices");
_Static_assert(GDR_RASTER_TINY_CLASSES == GDR_SW_TINY_CLASSES, "tiny classes: shaders and gdr/renderer.h");
_Static_assert(GDR_LOD_TREE_LEVELS == GDR_LOD_NODE_MAX_LEVELS, "the traversal has a level for every level of a hierarchy");
