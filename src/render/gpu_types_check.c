/* Compile-time checks that the C view of the shared GPU structs matches the scalar layout GLSL
 * uses, and that the draw command matches Vulkan's. */
#include <stddef.h>
#include <vulkan/vulkan.h>

#include "gdr/geometry.h"
#include "gdr/renderer.h"
#include "shaders/shared/gpu_types.h"

_Static_assert(sizeof(GdrGpuVertex) == 32, "GdrGpuVertex");
_Static_assert(offsetof(GdrGpuVertex, normal) == 12 && offsetof(GdrGpuVertex, uv) == 24, "GdrGpuVertex offsets");
_Static_assert(sizeof(GdrGpuMesh) == 96 && offsetof(GdrGpuMesh, bounds) == 16 && offsetof(GdrGpuMesh, task_count) == 36 &&
                   offsetof(GdrGpuMesh, root_refined_sphere) == 64, "GdrGpuMesh");
_Static_assert(sizeof(GdrGpuMeshlet) == 128 && offsetof(GdrGpuMeshlet, sphere) == 16 &&
                   offsetof(GdrGpuMeshlet, cone_cutoff) == 44 && offsetof(GdrGpuMeshlet, group) == 60 &&
                   offsetof(GdrGpuMeshlet, group_sphere) == 80 && offsetof(GdrGpuMeshlet, group_error) == 112,
               "GdrGpuMeshlet");
_Static_assert(sizeof(GdrGpuTaskCommand) == 16, "GdrGpuTaskCommand");
_Static_assert(GDR_MESH_MAX_VERTICES == GDR_CLUSTER_MAX_VERTICES && GDR_MESH_MAX_TRIANGLES == GDR_CLUSTER_MAX_TRIANGLES,
               "the mesh shader's limits are gdr/geometry.h's");
_Static_assert(sizeof(GdrGpuInstance) == 96 && offsetof(GdrGpuInstance, color) == 64 &&
                   offsetof(GdrGpuInstance, mesh) == 80, "GdrGpuInstance");
_Static_assert(sizeof(GdrGpuInstanceUpdate) == 112 && offsetof(GdrGpuInstanceUpdate, instance) == 16,
               "GdrGpuInstanceUpdate");
_Static_assert(sizeof(GdrGpuDrawCommand) == sizeof(VkDrawIndexedIndirectCommand), "GdrGpuDrawCommand");
_Static_assert(offsetof(GdrGpuDrawCommand, vertex_offset) == offsetof(VkDrawIndexedIndirectCommand, vertexOffset) &&
                   offsetof(GdrGpuDrawCommand, first_instance) == offsetof(VkDrawIndexedIndirectCommand, firstInstance),
               "GdrGpuDrawCommand offsets");
_Static_assert(GDR_LOD_STATS_DEPTHS == GDR_LOD_STATS_DEPTH_COUNT, "LOD statistics: shaders and gdr/renderer.h");
_Static_assert(sizeof(GdrGpuDrawStats) == 64 + 8 * GDR_LOD_STATS_DEPTHS + 96 && offsetof(GdrGpuDrawStats, draw_count) == 0 &&
                   offsetof(GdrGpuDrawStats, task_groups_x) == 16, "GdrGpuDrawStats");
_Static_assert(offsetof(GdrGpuDrawStats, task_groups_z) - offsetof(GdrGpuDrawStats, task_groups_x) ==
                   offsetof(VkDrawMeshTasksIndirectCommandEXT, groupCountZ), "the mesh tasks command inside GdrGpuDrawStats");
_Static_assert(offsetof(GdrGpuFrameGlobals, viewport) == 208, "GdrGpuFrameGlobals.viewport");
_Static_assert(sizeof(GdrGpuFrameGlobals) == 288 && offsetof(GdrGpuFrameGlobals, instance_visibility) == 272 && offsetof(GdrGpuFrameGlobals, frustum) == 128 &&
                   offsetof(GdrGpuFrameGlobals, znear) == 176 && offsetof(GdrGpuFrameGlobals, update_count) == 192,
               "GdrGpuFrameGlobals");
_Static_assert(sizeof(GdrGpuPushConstants) == 120 && offsetof(GdrGpuPushConstants, updates) == 40 &&
                   offsetof(GdrGpuPushConstants, visbuffer) == 104,
               "GdrGpuPushConstants");
_Static_assert(sizeof(GdrGpuPushConstants) <= 128, "push constants must fit the guaranteed 128 bytes");
_Static_assert(sizeof(GdrGpuRasterCluster) == 8, "GdrGpuRasterCluster");
_Static_assert(sizeof(GdrGpuRasterCounters) == 72 && offsetof(GdrGpuRasterCounters, dispatch_z) == 8 &&
                   offsetof(GdrGpuRasterCounters, dispatch_x) == offsetof(VkDispatchIndirectCommand, x),
               "GdrGpuRasterCounters starts with a VkDispatchIndirectCommand");
_Static_assert(offsetof(GdrGpuRasterCounters, draw_y) == offsetof(GdrGpuRasterCounters, draw_x) + 4 &&
                   offsetof(GdrGpuRasterCounters, draw_z) == offsetof(GdrGpuRasterCounters, draw_x) + 8 &&
                   offsetof(GdrGpuRasterCounters, draw_x) % 4 == 0,
               "GdrGpuRasterCounters.draw_x..z is a VkDrawMeshTasksIndirectCommandEXT");
_Static_assert(sizeof(GdrGpuRasterParams) == 48 && offsetof(GdrGpuRasterParams, mode) == 16 &&
                   offsetof(GdrGpuRasterParams, ndc_scale) == 32, "GdrGpuRasterParams");
_Static_assert(GDR_MESH_MAX_TRIANGLES <= (1u << GDR_VISBUFFER_TRIANGLE_BITS) &&
                   GDR_RASTER_MAX_CLUSTERS <= (1ull << (32 - GDR_VISBUFFER_TRIANGLE_BITS)),
               "a visibility-buffer id holds a cluster slot and a triangle in 32 bits");
_Static_assert(GDR_MESH_MAX_VERTICES <= GDR_SW_RASTER_WORKGROUP_SIZE,
               "the software rasteriser transforms a cluster's vertices in one step");
