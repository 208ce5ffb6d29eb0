/* The point level: the coarsest level of a mesh with a LOD DAG, below its root. An instance whose
 * whole mesh projects within a pixel is drawn by the instance cull as one splat at its bounding
 * sphere's centre instead of its root clusters (docs/GEOMETRY.md, "The point level"). Compiled by C
 * (the CPU reference and the upload) and GLSL (drawcull.comp, the resolve) alike.
 *
 * - Error: the bounds' radius R. Every point of the mesh lies within R of the centre, so the splat
 *   deviates at most R from the surface: a truthful error, tested like a group's (the projected
 *   error of the bounds with error R, gdr_lod_group_projected_error).
 * - When: that projected error within the frame's threshold and within GDR_POINT_MAX_PX, so that a
 *   splat never stands for more than a pixel whatever the threshold.
 * - Coverage: the splat covers the pixel centres within point_radius of the projected centre,
 *   point_radius the radius of a disc of the mesh's mean projected area (a quarter of its surface
 *   area for a convex mesh, Cauchy's formula; at most R). Below a pixel, a centre is then covered
 *   with the probability a random placement of the mesh's silhouette would cover it: the far field
 *   keeps the coverage it has drawn as triangles, on average, rather than a pixel per instance.
 * - Depth: the centre's, behind the nearest surface by at most R: as an occluder it hides less than
 *   the mesh would (conservative for the depth pyramid). */
#ifndef GDR_POINT_LEVEL_H
#define GDR_POINT_LEVEL_H

#include "gpu_shared/lod_math.h"
#include "math/glsl_c_bridge.h"

/* A splat stands for at most this many pixels of projected error. */
#define GDR_POINT_MAX_PX 1.0f
/* The visibility-buffer triangle of a point (no cluster has this many triangles): the id is then
 * (instance << GDR_VISBUFFER_TRIANGLE_BITS) | GDR_VISBUFFER_POINT_TRIANGLE. */
#define GDR_VISBUFFER_POINT_TRIANGLE 127u
/* Instances a frame may draw as points: their index must fit the id beside the triangle bits. */
#define GDR_POINT_MAX_INSTANCES (1u << 25)

/* The splat radius of a mesh of this surface area and bounding radius (mesh units). */
GDR_SHARED_FN float gdr_point_radius(float surface_area, float radius)
{
    float disc = gdr_sqrt(gdr_max(surface_area, 0.0f) / (4.0f * 3.14159265f));
    return disc < radius ? disc : radius;
}

/* Whether an instance (transform columns c0..c3) of a mesh with bounds `bounds` and point error
 * `point_error` (0: none) is drawn as its point level at LOD threshold `threshold`. */
GDR_SHARED_FN bool gdr_point_level_passes(gdr_vec4 bounds, float point_error, gdr_vec3 c0, gdr_vec3 c1, gdr_vec3 c2,
                                          gdr_vec3 c3, gdr_vec3 camera, float znear, float projection_scale,
                                          float threshold)
{
    if (!(point_error > 0.0f))
        return false;
    float limit = threshold < GDR_POINT_MAX_PX ? threshold : GDR_POINT_MAX_PX;
    return gdr_lod_group_projected_error(bounds, point_error, c0, c1, c2, c3, camera, znear, projection_scale) <=
           limit;
}

/* Whether the centre of pixel (px, py) (integers, as floats), at (px + 1/2, py + 1/2), lies within
 * `radius` pixels of the splat centre `centre` (framebuffer pixels, y down). */
GDR_SHARED_FN bool gdr_point_covers(gdr_vec2 centre, float radius, float px, float py)
{
    float dx = px + 0.5f - centre.x, dy = py + 0.5f - centre.y;
    return dx * dx + dy * dy <= radius * radius;
}

#if defined(GDR_GLSL) && defined(GDR_POINT_SPLATS) /* the instance cull's variant with 64-bit atomics */
#include "gpu_shared/visbuffer.h"
/* Writes the splat of instance `instance` (world-space centre, world-space splat radius) into the
 * visibility buffer: every pixel centre it covers, at the centre's depth. Returns how many. */
uint gdr_point_splat(GdrGpuFrameGlobals g, uint instance, vec3 world_center, float world_radius)
{
    vec4 clip = g.view_projection * vec4(world_center, 1.0);
    if (!(clip.w > g.znear))
        return 0u;
    vec3 ndc = clip.xyz / clip.w;
    vec2 half_size = 0.5 * g.viewport;
    vec2 centre = vec2(half_size.x + half_size.x * ndc.x, half_size.y - half_size.y * ndc.y);
    float radius = min(world_radius * g.lod_projection_scale / clip.w, 2.0 * GDR_POINT_MAX_PX);
    ivec2 first = max(ivec2(floor(centre - radius - 0.5)), ivec2(0));
    ivec2 last = min(ivec2(floor(centre + radius - 0.5)) + 1, ivec2(g.viewport) - 1);
    uint64_t value = gdr_visbuffer_pack(clamp(ndc.z, 0.0, 1.0),
                                        (instance << GDR_VISBUFFER_TRIANGLE_BITS) | GDR_VISBUFFER_POINT_TRIANGLE);
    uint width = uint(g.viewport.x), covered = 0u;
    for (int y = first.y; y <= last.y; y++)
        for (int x = first.x; x <= last.x; x++)
            if (gdr_point_covers(centre, radius, float(x), float(y))) {
                atomicMax(push.visbuffer.items[uint(y) * width + uint(x)], value);
                covered++;
            }
    return covered;
}
#endif
#endif
