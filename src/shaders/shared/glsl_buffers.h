/* GLSL only: buffer_reference views of the shared structs. */
#ifndef GDR_GLSL_BUFFERS_H
#define GDR_GLSL_BUFFERS_H

#extension GL_EXT_buffer_reference : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "gpu_types.h"

layout(buffer_reference, scalar) readonly buffer FrameGlobalsRef { GdrGpuFrameGlobals value; };
layout(buffer_reference, scalar) buffer InstancesRef { GdrGpuInstance items[]; };
layout(buffer_reference, scalar) readonly buffer MeshesRef { GdrGpuMesh items[]; };
layout(buffer_reference, scalar) writeonly buffer DrawCommandsRef { GdrGpuDrawCommand items[]; };
layout(buffer_reference, scalar) buffer DrawStatsRef { GdrGpuDrawStats value; };
layout(buffer_reference, scalar) readonly buffer InstanceUpdatesRef { GdrGpuInstanceUpdate items[]; };
layout(buffer_reference, scalar) buffer VisibilityRef { uint items[]; }; // occlusion culling's history (issue 6)

layout(push_constant, scalar) uniform PushConstantBlock { GdrGpuPushConstants push; };

#endif
