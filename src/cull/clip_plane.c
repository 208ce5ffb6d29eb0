/* A box against one plane: the global clip plane (outside / needs clipping / inside). */
#include <math.h>

#include "cull/cull_internal.h"

gdr_cull_outcome gdr_plane_test_box(gdr_vec4 plane, gdr_vec3 center, gdr_vec3 extent)
{
    float dist = plane.x * center.x + plane.y * center.y + plane.z * center.z + plane.w;
    float push = fabsf(plane.x) * extent.x + fabsf(plane.y) * extent.y + fabsf(plane.z) * extent.z;
    if (dist < -push)
        return GDR_CULL_OUTSIDE;
    return dist < push ? GDR_CULL_INTERSECTS : GDR_CULL_INSIDE;
}
