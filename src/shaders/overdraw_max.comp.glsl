#version 460
// Overdraw view, step 1 (seed 000): the largest per-pixel fragment count in one dispatch: subgroup
// max, then workgroup shared memory, then one global atomicMax per workgroup into the slot after
// the last pixel.
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "gpu_shared/glsl_buffers.h"

layout(local_size_x = GDR_REDUCE_WORKGROUP_SIZE) in;

shared uint workgroup_max;

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    uint pixels = uint(g.viewport.x) * uint(g.viewport.y);
    OverdrawRef counts = OverdrawRef(GDR_FRAME.overdraw);
    if (gl_LocalInvocationIndex == 0u)
        workgroup_max = 0u;
    barrier();
    uint id = gl_GlobalInvocationID.x;
    uint value = subgroupMax(id < pixels ? counts.items[id] : 0u);
    if (subgroupElect())
        atomicMax(workgroup_max, value);
    barrier();
    if (gl_LocalInvocationIndex == 0u)
        atomicMax(counts.items[pixels], workgroup_max);
}
