/* GLSL only: the material of a surface point (glTF metallic-roughness) and its shading, one
 * definition for the forward vertex and mesh paths and the visibility buffer's resolve. Each path
 * gives the same inputs: the interpolated texture coordinate, normal and vertex colour, and the
 * screen-space derivatives of the texture coordinate and of the world position (the forward paths
 * from dFdx/dFdy, the resolve analytically from the triangle), so that mip selection and the
 * tangent frame agree between paths. The includer must enable GL_EXT_nonuniform_qualifier (the
 * texture index varies per pixel in the resolve). */
#ifndef GDR_MATERIAL_H
#define GDR_MATERIAL_H

#include "gpu_shared/glsl_buffers.h"
#include "gpu_shared/shading.h"

layout(set = GDR_TEXTURE_SET, binding = 0) uniform texture2D gdr_images[];
layout(set = GDR_TEXTURE_SET, binding = 1) uniform sampler gdr_samplers[GDR_SAMPLER_SLOTS];

/* A point of a triangle as every path sees it. */
struct GdrSurfacePoint {
    vec3 position;   // world space
    vec3 normal;     // world space, interpolated, not normalised
    vec2 uv;         // TEXCOORD_0
    vec4 color;      // vertex colour (white without one) times the instance colour
    vec2 duv_dx, duv_dy; // uv one pixel right and one pixel down, minus uv
    vec3 dp_dx, dp_dy;   // the same for position
};

/* The material's values at a point, ready for the BRDF. */
struct GdrSurface {
    vec4 base_color; // linear RGB, alpha
    vec3 normal;     // unit, world space, normal map applied
    float metallic;
    float roughness; // perceptual (glTF's); the BRDF squares it
    float occlusion;
    vec3 emissive;   // linear
};

/* The vertex colour of vertex `vertex` (an index into GdrGpuScene.vertices) of mesh `mesh`; white
 * without reading anything in frames of scenes without vertex colours. */
vec4 gdr_vertex_color(uint frame_flags, uint mesh, uint vertex)
{
    if ((frame_flags & GDR_FRAME_VERTEX_COLORS) == 0u)
        return vec4(1.0);
    uint first = UintsRef(GDR_SCENE.mesh_color_offsets).items[mesh];
    if (first == GDR_GPU_NO_COLORS)
        return vec4(1.0);
    uint at = 2u * (first + vertex - MeshesRef(GDR_SCENE.meshes).items[mesh].vertex_offset);
    UintsRef words = UintsRef(GDR_SCENE.vertex_colors);
    return vec4(unpackUnorm2x16(words.items[at]), unpackUnorm2x16(words.items[at + 1u]));
}

/* Texture reference t at texture coordinate uv with screen derivatives dx, dy (before its transform). */
vec4 gdr_texture_sample(GdrGpuTextureRef t, vec2 uv, vec2 dx, vec2 dy)
{
    mat2 m = mat2(t.matrix.xy, t.matrix.zw);
    return textureGrad(sampler2D(gdr_images[nonuniformEXT(t.texture)], gdr_samplers[nonuniformEXT(t.sampler_slot)]),
                       t.offset + m * uv, m * dx, m * dy);
}

/* Material `i`'s fields are read through the buffer reference one by one, where they are used:
 * a local copy of the whole GdrGpuMaterial (224 bytes) may cost its full load per pixel. */
#define GDR_MATERIAL(i) MaterialsRef(GDR_SCENE.materials).items[i]

/* Texture k of material `material` at point p, or `absent` when the material has none. */
vec4 gdr_material_texture(uint material, int k, GdrSurfacePoint p, vec4 absent)
{
    if (GDR_MATERIAL(material).textures[k].texture == GDR_GPU_NO_TEXTURE)
        return absent;
    return gdr_texture_sample(GDR_MATERIAL(material).textures[k], p.uv, p.duv_dx, p.duv_dy);
}

/* Base colour and alpha only: what the alpha test needs. */
vec4 gdr_material_base_color(uint material, GdrSurfacePoint p)
{
    return GDR_MATERIAL(material).base_color * p.color * gdr_material_texture(material, GDR_MATERIAL_BASE_COLOR, p, vec4(1.0));
}

/* Whether material `material` keeps point p: MASK keeps alpha >= cutoff; BLEND is drawn as an
 * ordered dither (screen-door transparency: a 4x4 Bayer threshold per pixel), OPAQUE keeps everything. */
bool gdr_material_keeps(uint material, GdrSurfacePoint p, uvec2 pixel)
{
    uint mode = GDR_MATERIAL(material).alpha_mode;
    if (mode == GDR_ALPHA_MODE_OPAQUE)
        return true;
    float alpha = gdr_material_base_color(material, p).a;
    if (mode == GDR_ALPHA_MODE_MASK)
        return alpha >= GDR_MATERIAL(material).alpha_cutoff;
    const uint bayer[16] = uint[16](0u, 8u, 2u, 10u, 12u, 4u, 14u, 6u, 3u, 11u, 1u, 9u, 15u, 7u, 13u, 5u);
    return alpha > (float(bayer[(pixel.y & 3u) * 4u + (pixel.x & 3u)]) + 0.5) / 16.0;
}

/* The per-triangle tangent frame from the derivatives (the tangent along +u, orthogonalised against
 * the normal; the bitangent's sign from the direction of -v, glTF's "up" in the image), and the
 * normal texture's direction in it. Without usable derivatives the normal stays. */
vec3 gdr_apply_normal_map(uint material, GdrSurfacePoint p, vec3 n)
{
    if (GDR_MATERIAL(material).textures[GDR_MATERIAL_NORMAL].texture == GDR_GPU_NO_TEXTURE)
        return n;
    float det = p.duv_dx.x * p.duv_dy.y - p.duv_dx.y * p.duv_dy.x;
    vec3 dp_du = p.dp_dx * p.duv_dy.y - p.dp_dy * p.duv_dx.y;
    vec3 dp_dv = p.dp_dy * p.duv_dx.x - p.dp_dx * p.duv_dy.x;
    vec3 tangent = dp_du - n * dot(n, dp_du);
    if (abs(det) < 1e-20 || dot(tangent, tangent) < 1e-30)
        return n;
    tangent = normalize(tangent) * sign(det);
    vec3 bitangent = cross(n, tangent);
    if (dot(bitangent, dp_dv) * sign(det) > 0.0)
        bitangent = -bitangent;
    /* x and y only: z follows from a unit normal, so that a two-channel (BC5) normal map needs
     * nothing more; the scale applies to x and y after (glTF's normalTextureInfo.scale). */
    vec2 xy = gdr_material_texture(material, GDR_MATERIAL_NORMAL, p, vec4(0.5, 0.5, 1.0, 1.0)).xy * 2.0 - 1.0;
    vec3 texel = vec3(xy * GDR_MATERIAL(material).normal_scale, sqrt(max(1.0 - dot(xy, xy), 0.0)));
    return normalize(mat3(tangent, bitangent, n) * texel);
}

GdrSurface gdr_material_surface(uint material, GdrSurfacePoint p)
{
    GdrSurface s;
    s.base_color = gdr_material_base_color(material, p);
    vec4 mr = gdr_material_texture(material, GDR_MATERIAL_METALLIC_ROUGHNESS, p, vec4(1.0));
    s.metallic = clamp(GDR_MATERIAL(material).metallic * mr.b, 0.0, 1.0);
    s.roughness = clamp(GDR_MATERIAL(material).roughness * mr.g, 0.0, 1.0);
    float occlusion = gdr_material_texture(material, GDR_MATERIAL_OCCLUSION, p, vec4(1.0)).r;
    s.occlusion = 1.0 + GDR_MATERIAL(material).occlusion_strength * (occlusion - 1.0);
    s.emissive = GDR_MATERIAL(material).emissive * gdr_material_texture(material, GDR_MATERIAL_EMISSIVE, p, vec4(1.0)).rgb;
    float length2 = dot(p.normal, p.normal);
    vec3 n = length2 > 0.0 ? p.normal * inversesqrt(length2) : vec3(0.0, 1.0, 0.0);
    s.normal = gdr_apply_normal_map(material, p, n);
    return s;
}

/* The shaded view's colour of point p with material `material` under the frame's light and camera
 * (read through the reference: a copy of the globals would load all of them per pixel). */
vec4 gdr_shade_material(uint material, GdrSurfacePoint p, FrameGlobalsRef g)
{
    GdrSurface s = gdr_material_surface(material, p);
    vec3 v = normalize(g.value.eye_position.xyz - p.position);
    return gdr_shade_surface(s.base_color.rgb, s.normal, s.metallic, s.roughness, s.occlusion, s.emissive,
                             g.value.light_direction.xyz, v);
}

#endif
