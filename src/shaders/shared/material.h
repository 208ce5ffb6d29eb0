/* GLSL only: the material of a surface point, one definition for the forward vertex and mesh
 * paths and the visibility buffer's resolve. The includer's shader must enable
 * GL_EXT_nonuniform_qualifier (the texture index varies per pixel in the resolve). */
#ifndef GDR_MATERIAL_H
#define GDR_MATERIAL_H

#include "glsl_buffers.h"

layout(set = GDR_TEXTURE_SET, binding = 0) uniform texture2D gdr_images[];
layout(set = GDR_TEXTURE_SET, binding = 1) uniform sampler gdr_samplers[GDR_SAMPLER_SLOTS];

/* The linear base colour of material `material` at texture coordinate `uv`: its factor, times
 * its base-colour texture (sRGB decoded by the image format) sampled with the explicit
 * derivatives duv_dx, duv_dy (screen-space derivatives of uv: the mip level follows from them the
 * same way in every path), times the instance colour. */
vec4 gdr_material_base_color(uint material, vec4 instance_color, vec2 uv, vec2 duv_dx, vec2 duv_dy)
{
    GdrGpuMaterial m = MaterialsRef(GDR_SCENE.materials).items[material];
    vec4 color = m.base_color * instance_color;
    if (m.base_color_texture != GDR_GPU_NO_TEXTURE)
        color *= textureGrad(sampler2D(gdr_images[nonuniformEXT(m.base_color_texture)],
                                       gdr_samplers[nonuniformEXT(m.base_color_sampler)]),
                             uv, duv_dx, duv_dy);
    return color;
}

#endif
