#version 460
// Forward shading (shared/shading.h, shared/material.h) of the vertex pipeline and, compiled with
// GDR_PER_PRIMITIVE_COLOR (meshlet.frag), of the mesh shaders, whose colour (the debug views) and
// material come per primitive.
#ifdef GDR_PER_PRIMITIVE_COLOR
#extension GL_EXT_mesh_shader : require
#define GDR_COLOR_INPUT perprimitiveEXT flat in
#else
#define GDR_COLOR_INPUT flat in
#endif
#extension GL_EXT_nonuniform_qualifier : require
#include "shared/glsl_buffers.h"
#include "shared/material.h"
#include "shared/shading.h"

layout(early_fragment_tests) in;

layout(location = 0) in vec3 in_normal;
layout(location = 1) in vec3 in_world_position;
layout(location = 2) GDR_COLOR_INPUT vec4 in_color;
layout(location = 4) in vec2 in_uv;
layout(location = 5) GDR_COLOR_INPUT uint in_material;

layout(location = 0) out vec4 out_color;

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    if (g.view_mode == GDR_VIEW_OVERDRAW) // fragments that passed the depth test, per pixel
        atomicAdd(OverdrawRef(GDR_FRAME.overdraw).items[uint(gl_FragCoord.y) * uint(g.viewport.x) + uint(gl_FragCoord.x)], 1u);
    // The shaded view takes its colour from the material; the debug views from in_color alone.
    vec3 albedo = g.view_mode == GDR_VIEW_SHADED
                    ? gdr_material_base_color(in_material, in_color, in_uv, dFdx(in_uv), dFdy(in_uv)).rgb
                    : in_color.rgb;
    out_color = gdr_shade(g.light_direction.xyz, in_normal, in_world_position, albedo);
}
