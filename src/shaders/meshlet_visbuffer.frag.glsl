#version 460
// The mesh-shader half of the visibility buffer: each fragment writes its depth and
// visibility id with the same 64-bit atomicMax as the compute rasteriser, so the two mix in one
// frame. No colour and no depth attachment: the atomic is the depth test. The depth is
// gl_FragCoord.z, the value the depth attachment would have received.
#extension GL_EXT_mesh_shader : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shared/glsl_buffers.h"
#include "shared/visbuffer.h"

layout(location = 3) perprimitiveEXT flat in uint in_visibility_id;

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    uint pixel = uint(gl_FragCoord.y) * uint(g.viewport.x) + uint(gl_FragCoord.x);
    atomicMax(push.visbuffer.items[pixel], gdr_visbuffer_pack(gl_FragCoord.z, in_visibility_id));
    if (g.view_mode == GDR_VIEW_OVERDRAW) // on this path: every fragment rasterised, as the compute rasteriser counts
        atomicAdd(OverdrawRef(GDR_FRAME.overdraw).items[pixel], 1u);
}
