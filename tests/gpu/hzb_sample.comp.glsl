#version 460
// test_hzb: the occlusion query of src/gpu_shared/occlusion_math.h in GLSL, and the one fetch
// through the pyramid's min-reduction sampler that a culling shader makes with it. One thread per
// sphere; out: 8 uints per sphere (testable, level, x0, y0, x1, y1, fetched value, nearest depth).
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "gpu_shared/occlusion_math.h"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0) uniform sampler2D hzb;
layout(set = 0, binding = 1, scalar) readonly buffer Spheres { vec4 spheres[]; }; // view-space centre, radius
layout(set = 0, binding = 2, scalar) writeonly buffer Results { uint results[]; };

layout(push_constant, scalar) uniform Push {
    GdrOcclusionParams params;
    uint count;
} push;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count)
        return;
    vec4 s = spheres[i];
    GdrOcclusionQuery q = gdr_occlusion_query(s.xyz, s.w, push.params);
    float farthest = textureLod(hzb, vec2(q.sample_u, q.sample_v), float(q.level)).x;
    results[i * 8u + 0u] = q.testable ? 1u : 0u;
    results[i * 8u + 1u] = uint(q.level);
    results[i * 8u + 2u] = uint(q.x0);
    results[i * 8u + 3u] = uint(q.y0);
    results[i * 8u + 4u] = uint(q.x1);
    results[i * 8u + 5u] = uint(q.y1);
    results[i * 8u + 6u] = floatBitsToUint(farthest);
    results[i * 8u + 7u] = floatBitsToUint(q.nearest_depth);
}
