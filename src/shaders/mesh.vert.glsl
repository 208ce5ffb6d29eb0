#version 460
#extension GL_EXT_nonuniform_qualifier : require
// Forward path vertex shader: the instance comes from gl_InstanceIndex (= the draw's first_instance).
#include "gpu_shared/glsl_buffers.h"
#include "gpu_shared/material.h"
#include "gpu_shared/shading.h"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

layout(location = 0) out vec3 out_normal;
layout(location = 1) out vec3 out_world_position;
layout(location = 2) flat out vec4 out_color;
layout(location = 4) out vec2 out_uv;
layout(location = 5) flat out uint out_material;
layout(location = 6) out vec4 out_vertex_color;

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    GdrGpuInstance instance = InstancesRef(GDR_SCENE.instances).items[gl_InstanceIndex];
    vec4 world = instance.model * vec4(in_position, 1.0);
    gl_Position = g.view_projection * world;
    // The cofactor matrix transforms normals correctly under non-uniform scale (up to length).
    mat3 m = mat3(instance.model);
    mat3 cofactor = mat3(cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1]));
    out_normal = cofactor * in_normal;
    out_world_position = world.xyz;
    out_uv = in_uv;
    out_material = instance.material;
    out_vertex_color = gdr_vertex_color(g.flags, instance.mesh, gl_VertexIndex); // gl_VertexIndex counts the draw's vertexOffset
    out_color = g.view_mode == GDR_VIEW_INSTANCES ? vec4(gdr_id_color(gl_InstanceIndex), 1.0)
              : g.view_mode == GDR_VIEW_LOD    ? vec4(gdr_depth_color(0), 1.0) // full detail: depth 0
                                               : instance.color;
}
