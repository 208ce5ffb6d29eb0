// GLSL only: the occlusion test of a culling shader against the depth pyramid, which the
// frame binds as set 0, binding 0 (src/render/occlusion.c) with its min-reduction sampler. The math
// is occlusion_math.h's, shared with the CPU.
#ifndef GDR_OCCLUSION_TEST_H
#define GDR_OCCLUSION_TEST_H

#include "occlusion_math.h"

layout(set = 0, binding = 0) uniform sampler2D gdr_depth_pyramid;

// True when the sphere (view-space centre, radius) is surely hidden behind the pyramid's depth.
bool gdr_sphere_occluded(GdrGpuFrameGlobals g, vec3 view_center, float radius)
{
    GdrOcclusionQuery q = gdr_occlusion_query(view_center, radius, g.occlusion);
    if (!q.testable)
        return false;
    float farthest = textureLod(gdr_depth_pyramid, vec2(q.sample_u, q.sample_v), float(q.level)).x;
    return gdr_hzb_occludes(q.nearest_depth, farthest);
}

#endif
