/* GLSL only: the forward shading every raster path uses, and the debug-view colours. */
#ifndef GDR_SHADING_H
#define GDR_SHADING_H

#include "hash.h"

/* A directional light (the frame's light_direction), a sky/ground ambient term and a faint world
 * grid; returns sRGB-encoded colour. */
vec4 gdr_shade(vec3 light_direction, vec3 normal, vec3 world_position, vec3 albedo)
{
    vec3 n = normalize(normal);
    float diffuse = max(dot(n, light_direction), 0.0);
    float sky = 0.5 + 0.5 * n.y;
    vec3 checker = vec3(0.92 + 0.08 * mod(floor(world_position.x) + floor(world_position.z), 2.0));
    vec3 color = albedo * checker * (0.18 + 0.17 * sky + 0.7 * diffuse);
    return vec4(pow(color, vec3(1.0 / 2.2)), 1.0);
}

/* A bright colour from an id: three bytes of its hash, lifted away from black. */
vec3 gdr_id_color(uint id)
{
    uint h = gdr_hash(id);
    return vec3(float(h & 255u), float((h >> 8) & 255u), float((h >> 16) & 255u)) * (0.75 / 255.0) + 0.25;
}

// LOD view: DAG depth 0 (full detail) blue, through green and yellow, to red at depth 12 and
// beyond; neighbouring depths stay distinguishable.
vec3 gdr_depth_color(int depth)
{
    float t = clamp(float(depth) / 12.0, 0.0, 1.0);
    vec3 ramp = clamp(vec3(1.5 * t - 0.25, 1.0 - abs(2.0 * t - 1.0) * 1.2 + 0.2, 1.0 - 1.6 * t), 0.0, 1.0);
    return (depth & 1) == 0 ? ramp : ramp * 0.75;
}

/* The colour a triangle is shaded with under `view_mode` (GDR_VIEW_*): its instance's own colour,
 * or the debug views' colour of its cluster, instance, triangle or DAG depth. One definition for
 * the forward mesh shader and the visibility buffer's resolve. */
vec3 gdr_view_albedo(uint view_mode, vec3 instance_color, uint instance, uint meshlet, uint triangle, int group_depth)
{
    if (view_mode == GDR_VIEW_MESHLETS)
        return gdr_id_color(meshlet);
    if (view_mode == GDR_VIEW_INSTANCES)
        return gdr_id_color(instance);
    if (view_mode == GDR_VIEW_TRIANGLES)
        return gdr_id_color(meshlet * 128u + triangle);
    if (view_mode == GDR_VIEW_LOD)
        return gdr_depth_color(group_depth);
    return instance_color;
}

#endif
