// GLSL only: the occlusion tests of the culling shaders against the depth pyramid, which the
// frame binds as set 0, binding 0 (src/render/occlusion.c) with its min-reduction sampler. The math
// is occlusion_math.h's, shared with the CPU.
//
// Two-phase occlusion culling (seed 002): the early phase tests against last frame's pyramid, seen
// from last frame's camera (GdrGpuFrameGlobals.previous_view, previous_occlusion), and defers what
// it hides to the occluded lists; the late phase retests only those against this frame's pyramid
// (built from the early phase's depth), seen from this frame's camera. Only the late test culls for
// good, and the early phase's depth is part of the final image, so the image is the one without
// occlusion culling; the early test only decides what waits for the late phase.
#ifndef GDR_OCCLUSION_TEST_H
#define GDR_OCCLUSION_TEST_H

#include "gpu_shared/occlusion_math.h"
#include "gpu_shared/task_queue.h" // the phases

layout(set = 0, binding = 0) uniform sampler2D gdr_depth_pyramid;

// True when the sphere (view-space centre, radius) is surely hidden behind the pyramid's depth, as
// seen through `params`.
bool gdr_sphere_hidden(GdrOcclusionParams params, vec3 view_center, float radius)
{
    GdrOcclusionQuery q = gdr_occlusion_query(view_center, radius, params);
    if (!q.testable)
        return false;
    float farthest = textureLod(gdr_depth_pyramid, vec2(q.sample_u, q.sample_v), float(q.level)).x;
    return gdr_hzb_occludes(q.nearest_depth, farthest);
}

// The occlusion test of `phase` for a sphere (world-space centre, radius) that passed every other
// test: early, against last frame's pyramid and camera (never without a history); late, against
// this frame's.
bool gdr_phase_occluded(GdrGpuFrameGlobals g, uint phase, vec3 world_center, float radius)
{
    if (phase == GDR_PHASE_LATE)
        return gdr_sphere_hidden(g.occlusion, (g.view * vec4(world_center, 1.0)).xyz, radius);
    if (phase == GDR_PHASE_EARLY && (g.flags & GDR_FRAME_HISTORY) != 0u)
        return gdr_sphere_hidden(g.previous_occlusion, (g.previous_view * vec4(world_center, 1.0)).xyz, radius);
    return false;
}

#endif
