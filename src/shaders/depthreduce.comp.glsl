#version 460
// Depth pyramid (HZB) build, one dispatch per level (src/render/hzb.c, docs/OCCLUSION.md): each
// texel is the minimum (reverse-Z: the farthest depth) of everything it covers.
//  - Level 0 from the depth buffer (the depth image, or the depth word of a visibility buffer's
//    pixels): the pyramid is the depth size rounded down to powers of two,
//    so a level-0 texel spans between 1 and 2 depth pixels per axis, not on pixel boundaries; it
//    takes the minimum over every depth pixel its area overlaps (up to 3 x 3), read with exact
//    texelFetch: no row or column is lost for odd or non-power-of-two sizes.
//  - Every further level: 2x2 texels of the previous one, in one fetch of a min-reduction sampler
//    at the corner the four share (each weighted 1/4; exact coordinates, as sizes are powers of two).
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/occlusion_math.h"

layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(set = 0, binding = 0) uniform sampler2D source; // depth (nearest) or the previous level (min reduction)
layout(set = 0, binding = 1, r32f) uniform writeonly image2D destination;

layout(push_constant, scalar) uniform DepthReducePushBlock { GdrDepthReducePush push; };
layout(buffer_reference, scalar) readonly buffer VisibilityPixels { uint64_t items[]; };

// Depth pixel p of level 0's source.
float source_depth(uvec2 p)
{
    if (push.visibility_buffer == 0ul)
        return texelFetch(source, ivec2(p), 0).x;
    uint64_t pixel = VisibilityPixels(push.visibility_buffer).items[p.y * push.source_width + p.x];
    return uintBitsToFloat(uint(pixel >> 32));
}

void main()
{
    uvec2 p = gl_GlobalInvocationID.xy;
    uvec2 source_size = uvec2(push.source_width, push.source_height);
    uvec2 destination_size = uvec2(push.destination_width, push.destination_height);
    if (p.x >= destination_size.x || p.y >= destination_size.y)
        return;
    float farthest;
    if (push.from_depth != 0u) {
        // Texel p covers depth pixels [p * S / D, (p + 1) * S / D) (S source, D destination size);
        // the pixels it overlaps are floor(p S / D) .. ceil((p + 1) S / D) - 1. S / D < 2, so at most 3.
        uvec2 first = p * source_size / destination_size;
        uvec2 end = ((p + 1u) * source_size + destination_size - 1u) / destination_size;
        farthest = source_depth(first);
        for (uint y = first.y; y < end.y; y++)
            for (uint x = first.x; x < end.x; x++)
                farthest = min(farthest, source_depth(uvec2(x, y)));
    } else {
        // The corner shared by source texels 2p .. 2p + 1; where the source is one texel wide the
        // coordinate is its right/bottom edge and clamp-to-edge folds the second texel onto the first.
        vec2 corner = vec2(2u * p + 1u) / vec2(source_size);
        farthest = textureLod(source, corner, 0.0).x;
    }
    imageStore(destination, ivec2(p), vec4(farthest));
}
