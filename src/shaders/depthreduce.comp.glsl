#version 460
// Depth pyramid (HZB) build (src/render/hzb.c, docs/OCCLUSION.md): each texel is the minimum
// (reverse-Z: the farthest depth) of everything it covers. One dispatch writes up to
// GDR_HZB_LEVELS_PER_DISPATCH levels: each 16x16 workgroup computes a 16x16 tile of the first one
// and reduces it in shared memory to 8x8, 4x4, 2x2 and 1x1 texels of the next ones, so a 1440p
// pyramid of 12 levels takes 3 dispatches instead of 12 (each dispatch and barrier costs about
// 4 us on the H100, more than the work of the small levels).
//  - The first level of the first dispatch comes from the depth buffer (the depth image, or the
//    depth word of a visibility buffer's pixels): the pyramid is the depth size rounded down to
//    powers of two, so a level-0 texel spans between 1 and 2 depth pixels per axis, not on pixel
//    boundaries; it takes the minimum over every depth pixel its area overlaps (up to 3 x 3), read
//    exactly: no row or column is lost for odd or non-power-of-two sizes.
//  - The first level of a later dispatch: 2x2 texels of the level before, in one fetch of a
//    min-reduction sampler at the corner the four share (each weighted 1/4; exact coordinates, as
//    sizes are powers of two).
//  - Every further level: the minimum of its 2x2 texels of the level before in shared memory;
//    texels past a level's edge (an axis that reached 1) hold +infinity, so they change nothing.
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "gpu_shared/occlusion_math.h"

#define TILE 16u

layout(local_size_x = TILE, local_size_y = TILE) in;

layout(set = 0, binding = 0) uniform sampler2D source; // depth (nearest) or the level before (min reduction)
layout(set = 0, binding = 1, r32f) uniform writeonly image2D destination[GDR_HZB_LEVELS_PER_DISPATCH];

layout(push_constant, scalar) uniform DepthReducePushBlock { GdrDepthReducePush push; };
layout(buffer_reference, scalar) readonly buffer VisibilityPixels { uint64_t items[]; };

shared float tile[TILE][TILE];

// Depth pixel p of level 0's source.
float source_depth(uvec2 p)
{
    if (push.visibility_buffer == 0ul)
        return texelFetch(source, ivec2(p), 0).x;
    uint64_t pixel = VisibilityPixels(push.visibility_buffer).items[p.y * push.source_width + p.x];
    return uintBitsToFloat(uint(pixel >> 32));
}

// Texel p of the dispatch's first level.
float first_level_texel(uvec2 p)
{
    uvec2 source_size = uvec2(push.source_width, push.source_height);
    uvec2 destination_size = uvec2(push.destination_width, push.destination_height);
    if (push.from_depth == 0u) {
        // The corner shared by source texels 2p .. 2p + 1; where the source is one texel wide the
        // coordinate is its right/bottom edge and clamp-to-edge folds the second texel onto the first.
        vec2 corner = vec2(2u * p + 1u) / vec2(source_size);
        return textureLod(source, corner, 0.0).x;
    }
    // Texel p covers depth pixels [p * S / D, (p + 1) * S / D) (S source, D destination size);
    // the pixels it overlaps are floor(p S / D) .. ceil((p + 1) S / D) - 1. S / D < 2, so at most 3.
    uvec2 first = p * source_size / destination_size;
    uvec2 end = ((p + 1u) * source_size + destination_size - 1u) / destination_size;
    float farthest = source_depth(first);
    for (uint y = first.y; y < end.y; y++)
        for (uint x = first.x; x < end.x; x++)
            farthest = min(farthest, source_depth(uvec2(x, y)));
    return farthest;
}

// Level `k` of the dispatch (constant indices into the array: no dynamic indexing needed).
void store(uint k, uvec2 p, float value)
{
    switch (k) {
    case 0u: imageStore(destination[0], ivec2(p), vec4(value)); break;
    case 1u: imageStore(destination[1], ivec2(p), vec4(value)); break;
    case 2u: imageStore(destination[2], ivec2(p), vec4(value)); break;
    case 3u: imageStore(destination[3], ivec2(p), vec4(value)); break;
    default: imageStore(destination[4], ivec2(p), vec4(value)); break;
    }
}

void main()
{
    const float beyond = uintBitsToFloat(0x7f800000u); // +infinity: past the level's edge
    uvec2 local = gl_LocalInvocationID.xy;
    uvec2 size = uvec2(push.destination_width, push.destination_height);
    uvec2 p = gl_WorkGroupID.xy * TILE + local;
    float value = beyond;
    if (all(lessThan(p, size))) {
        value = first_level_texel(p);
        store(0u, p, value);
    }
    tile[local.y][local.x] = value;
    for (uint k = 1u; k < push.level_count; k++) {
        barrier();
        uint span = TILE >> k;
        bool reduces = all(lessThan(local, uvec2(span)));
        float farthest = beyond;
        if (reduces) {
            uvec2 c = 2u * local;
            farthest = min(min(tile[c.y][c.x], tile[c.y][c.x + 1u]), min(tile[c.y + 1u][c.x], tile[c.y + 1u][c.x + 1u]));
        }
        barrier();
        if (reduces) {
            tile[local.y][local.x] = farthest;
            uvec2 q = gl_WorkGroupID.xy * span + local;
            if (all(lessThan(q, max(size >> k, uvec2(1u)))))
                store(k, q, farthest);
        }
    }
}
