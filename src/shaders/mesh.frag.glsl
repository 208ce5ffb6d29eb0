#version 460
// Forward path shading: a directional light, a sky/ground ambient term and a faint world grid.
#include "shared/glsl_buffers.h"

layout(location = 0) in vec3 in_normal;
layout(location = 1) in vec3 in_world_position;
layout(location = 2) flat in vec4 in_color;

layout(location = 0) out vec4 out_color;

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    vec3 n = normalize(in_normal);
    float diffuse = max(dot(n, g.light_direction.xyz), 0.0);
    float sky = 0.5 + 0.5 * n.y;
    vec3 checker = vec3(0.92 + 0.08 * mod(floor(in_world_position.x) + floor(in_world_position.z), 2.0));
    vec3 color = in_color.rgb * checker * (0.18 + 0.17 * sky + 0.7 * diffuse);
    out_color = vec4(pow(color, vec3(1.0 / 2.2)), 1.0);
}
