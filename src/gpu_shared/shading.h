/* GLSL only: the forward shading every raster path uses, and the debug-view colours. */
#ifndef GDR_SHADING_H
#define GDR_SHADING_H

#include "gpu_shared/hash.h"

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

/* --- The shaded view: glTF's metallic-roughness BRDF (the specification's appendix B) ---------- */

#define GDR_PI 3.14159265358979

/* Irradiance of the directional light on a surface facing it, and the ambient term: a sky/ground
 * hemisphere whose irradiance goes from GDR_AMBIENT_GROUND (normal straight down) to
 * GDR_AMBIENT_GROUND + GDR_AMBIENT_SKY (straight up). A white diffuse surface facing the light and
 * the sky reflects 0.7 + 0.35 of white, as the forward shading of the debug views. */
#define GDR_LIGHT_IRRADIANCE (0.7 * GDR_PI)
#define GDR_AMBIENT_GROUND 0.18
#define GDR_AMBIENT_SKY 0.17

/* GGX normal distribution, alpha = roughness^2. */
float gdr_ggx_d(float n_h, float alpha)
{
    float a2 = alpha * alpha;
    float d = n_h * n_h * (a2 - 1.0) + 1.0;
    return a2 / (GDR_PI * d * d);
}

/* Smith's height-correlated visibility for GGX: G / (4 |n.l| |n.v|). */
float gdr_smith_v(float n_l, float n_v, float alpha)
{
    float a2 = alpha * alpha;
    float gl = n_v * sqrt(n_l * n_l * (1.0 - a2) + a2);
    float gv = n_l * sqrt(n_v * n_v * (1.0 - a2) + a2);
    return gl + gv > 0.0 ? 0.5 / (gl + gv) : 0.0;
}

/* Khronos PBR Neutral tone mapping: colours below about 0.76 pass unchanged (minus a small toe
 * offset near black), brighter ones are compressed towards white without hue shifts. */
vec3 gdr_tone_map(vec3 color)
{
    const float start = 0.8 - 0.04, desaturation = 0.15;
    float x = min(color.r, min(color.g, color.b));
    float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    color -= offset;
    float peak = max(color.r, max(color.g, color.b));
    if (peak < start)
        return color;
    float d = 1.0 - start;
    float new_peak = 1.0 - d * d / (peak + d - start);
    color *= new_peak / peak;
    float g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(color, vec3(new_peak), g);
}

/* The sRGB transfer function (IEC 61966-2-1), linear [0, 1] to encoded. */
vec3 gdr_srgb_encode(vec3 c)
{
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

/* Outgoing radiance towards the viewer at surface s (unit normal n, unit vectors l towards the
 * light and v towards the viewer), then tone mapped and sRGB encoded. */
vec4 gdr_shade_surface(vec3 base_color, vec3 n, float metallic, float roughness, float occlusion, vec3 emissive,
                       vec3 l, vec3 v)
{
    vec3 c_diff = mix(base_color, vec3(0.0), metallic);
    vec3 f0 = mix(vec3(0.04), base_color, metallic);
    float alpha = max(roughness * roughness, 1e-3);
    float n_v = max(dot(n, v), 1e-4), n_l = max(dot(n, l), 0.0);
    vec3 h = normalize(l + v);
    float v_h = max(dot(v, h), 0.0), n_h = max(dot(n, h), 0.0);
    vec3 fresnel = f0 + (1.0 - f0) * pow(1.0 - v_h, 5.0);
    vec3 brdf = (1.0 - fresnel) * c_diff / GDR_PI + fresnel * gdr_ggx_d(n_h, alpha) * gdr_smith_v(n_l, n_v, alpha);
    // Ambient: the hemisphere's irradiance, reflected diffusely by c_diff and specularly by f0 (an
    // environment of one colour integrates the specular lobe to about f0).
    float ambient = (GDR_AMBIENT_GROUND + GDR_AMBIENT_SKY * (0.5 + 0.5 * n.y)) * occlusion;
    vec3 radiance = brdf * GDR_LIGHT_IRRADIANCE * n_l + (c_diff + f0) * ambient + emissive;
    return vec4(gdr_srgb_encode(gdr_tone_map(radiance)), 1.0);
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
