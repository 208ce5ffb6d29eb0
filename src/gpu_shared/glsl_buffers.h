/* GLSL only: the buffer_reference types of the shared structs (gpu_types.h declares them, its
 * structs hold them), and the push constants of every frame pass. */
#ifndef GDR_GLSL_BUFFERS_H
#define GDR_GLSL_BUFFERS_H

#extension GL_EXT_buffer_reference : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "gpu_shared/gpu_types.h"

layout(buffer_reference, scalar) readonly buffer FrameGlobalsRef { GdrGpuFrameGlobals value; };
layout(buffer_reference, scalar) readonly buffer SceneRef { GdrGpuScene value; };
layout(buffer_reference, scalar) readonly buffer FrameBuffersRef { GdrGpuFrameBuffers value; };
layout(buffer_reference, scalar) buffer InstancesRef { GdrGpuInstance items[]; };
layout(buffer_reference, scalar) readonly buffer MeshesRef { GdrGpuMesh items[]; };
layout(buffer_reference, scalar) readonly buffer VerticesRef { GdrGpuVertex items[]; };
layout(buffer_reference, scalar) readonly buffer MeshletsRef { GdrGpuMeshlet items[]; };
layout(buffer_reference, scalar) readonly buffer LodNodesRef { GdrGpuLodNode items[]; };
layout(buffer_reference, scalar) readonly buffer UintsRef { uint items[]; };
layout(buffer_reference, scalar) buffer WritableUintsRef { uint items[]; };
layout(buffer_reference, scalar) writeonly buffer DrawCommandsRef { GdrGpuDrawCommand items[]; };
layout(buffer_reference, scalar) buffer DrawStatsRef { GdrGpuDrawStats value; };
layout(buffer_reference, scalar) readonly buffer InstanceUpdatesRef { GdrGpuInstanceUpdate items[]; };
layout(buffer_reference, scalar) buffer TaskCommandsRef { GdrGpuTaskCommand items[]; };
layout(buffer_reference, scalar) buffer OverdrawRef { uint items[]; };
layout(buffer_reference, scalar) writeonly buffer VisibleMeshletsRef { uvec2 items[]; };
layout(buffer_reference, scalar) buffer VisbufferRef { uint64_t items[]; };
layout(buffer_reference, scalar) readonly buffer RasterParamsRef { GdrGpuRasterParams value; };
layout(buffer_reference, scalar) buffer RasterCountersRef { GdrGpuRasterCounters value; };
layout(buffer_reference, scalar) buffer RasterClustersRef { GdrGpuRasterCluster items[]; };
layout(buffer_reference, scalar) buffer NodeVisitsRef { GdrGpuNodeVisit items[]; };
layout(buffer_reference, scalar) readonly buffer MaterialsRef { GdrGpuMaterial items[]; };
layout(buffer_reference, scalar) writeonly buffer StreamRequestsRef { GdrGpuStreamRequest items[]; };

layout(push_constant, scalar) uniform PushConstantBlock { GdrGpuPushConstants push; };

/* The scene's buffers and the frame slot's (GdrGpuScene, GdrGpuFrameBuffers). */
#define GDR_SCENE (push.scene.value)
#define GDR_FRAME (push.frame.value)

#endif
