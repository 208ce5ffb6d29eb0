#version 460
// The mesh-shader half of the visibility buffer: each fragment writes its depth and
// visibility id with the same 64-bit atomicMax as the compute rasteriser, so the two mix in one
// frame. No colour and no depth attachment: the atomic is the depth test. The depth is
// gl_FragCoord.z, the value the depth attachment would have received.
// Compiled with GDR_ALPHA_TEST (meshlet_visbuffer_alpha.frag, used in scenes with MASK, BLEND or
// double-sided materials) it also drops what those materials drop; the variant without it reads no
// attribute, so opaque scenes pay nothing for them.
#extension GL_EXT_mesh_shader : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_EXT_nonuniform_qualifier : require
#include "gpu_shared/glsl_buffers.h"
#include "gpu_shared/visbuffer.h"

layout(location = 3) perprimitiveEXT flat in uint in_visibility_id;

#ifdef GDR_ALPHA_TEST
#include "gpu_shared/material.h"
#include "gpu_shared/material_flags.h"

layout(location = 4) in vec2 in_uv;
layout(location = 5) perprimitiveEXT flat in uint in_material;
layout(location = 6) in vec4 in_vertex_color;

// MASK and BLEND materials cut their holes here (the cluster binning sends their clusters to this
// path, never to the compute rasteriser), so the visibility buffer, and the depth pyramid built from
// it, hold only what is kept: occlusion culling stays conservative. The pipeline does not cull back
// faces in scenes with double-sided materials: single-sided ones are dropped here.
bool kept(GdrGpuFrameGlobals g)
{
    if (!gl_FrontFacing && !gdr_material_double_sided(g.flags, in_material))
        return false;
    if (!gdr_material_alpha_tested(g.flags, in_material))
        return true;
    GdrGpuRasterCluster entry =
        RasterClustersRef(RasterParamsRef(GDR_FRAME.raster).value.clusters).items[in_visibility_id >> GDR_VISBUFFER_TRIANGLE_BITS];
    vec4 color = in_vertex_color * InstancesRef(GDR_SCENE.instances).items[entry.instance].color;
    GdrSurfacePoint p = GdrSurfacePoint(vec3(0.0), vec3(0.0), in_uv, color, dFdx(in_uv), dFdy(in_uv), vec3(0.0), vec3(0.0));
    return gdr_material_keeps(in_material, p, uvec2(gl_FragCoord.xy));
}
#endif

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
#ifdef GDR_ALPHA_TEST
    if (!kept(g))
        return;
#endif
    uint pixel = uint(gl_FragCoord.y) * uint(g.viewport.x) + uint(gl_FragCoord.x);
    atomicMax(push.visbuffer.items[pixel], gdr_visbuffer_pack(gl_FragCoord.z, in_visibility_id));
    if (g.view_mode == GDR_VIEW_OVERDRAW) // on this path: every fragment rasterised, as the compute rasteriser counts
        atomicAdd(OverdrawRef(GDR_FRAME.overdraw).items[pixel], 1u);
}
