#version 460
// Forward shading of the vertex pipeline and, compiled with GDR_PER_PRIMITIVE_COLOR (meshlet.frag),
// of the mesh shaders, whose debug colour and material come per primitive. The shaded view shades
// the material (shared/material.h), the debug views their colour (shared/shading.h).
// Compiled with GDR_ALPHA_TEST (the *_alpha variants, used when the scene has MASK, BLEND or
// double-sided materials) it cuts out what the material's alpha test drops and the back faces of
// single-sided materials (those pipelines do not cull); that needs late depth tests, so the
// variants without it keep early_fragment_tests.
#ifdef GDR_PER_PRIMITIVE_COLOR
#extension GL_EXT_mesh_shader : require
#define GDR_COLOR_INPUT perprimitiveEXT flat in
#else
#define GDR_COLOR_INPUT flat in
#endif
#extension GL_EXT_nonuniform_qualifier : require
#include "gpu_shared/glsl_buffers.h"
#include "gpu_shared/material.h"
#include "gpu_shared/material_flags.h"
#include "gpu_shared/shading.h"

#ifndef GDR_ALPHA_TEST
layout(early_fragment_tests) in;
#endif

layout(location = 0) in vec3 in_normal;
layout(location = 1) in vec3 in_world_position;
layout(location = 2) GDR_COLOR_INPUT vec4 in_color;
layout(location = 4) in vec2 in_uv;
layout(location = 5) GDR_COLOR_INPUT uint in_material;
layout(location = 6) in vec4 in_vertex_color;

layout(location = 0) out vec4 out_color;

void main()
{
    FrameGlobalsRef g = FrameGlobalsRef(push.globals); // fields read where used, not copied per fragment
    GdrSurfacePoint p = GdrSurfacePoint(in_world_position, in_normal, in_uv, in_vertex_color * in_color, dFdx(in_uv),
                                        dFdy(in_uv), dFdx(in_world_position), dFdy(in_world_position));
#ifdef GDR_ALPHA_TEST
    // Scenes with double-sided materials draw without the pipeline's back-face culling: the back
    // faces of the single-sided ones are dropped here.
    if (!gl_FrontFacing && !gdr_material_double_sided(g.value.flags, in_material))
        discard;
    if (!gdr_material_keeps(in_material, p, uvec2(gl_FragCoord.xy)))
        discard;
#endif
    p.normal = gl_FrontFacing ? p.normal : -p.normal; // a double-sided material's back face
    if (g.value.view_mode == GDR_VIEW_OVERDRAW) // fragments that passed the depth test (alpha variants: every one kept)
        atomicAdd(OverdrawRef(GDR_FRAME.overdraw).items[uint(gl_FragCoord.y) * uint(g.value.viewport.x) + uint(gl_FragCoord.x)], 1u);
    out_color = g.value.view_mode == GDR_VIEW_SHADED
                    ? gdr_shade_material(in_material, p, g)
                    : gdr_shade(g.value.light_direction.xyz, in_normal, in_world_position, in_color.rgb);
}
