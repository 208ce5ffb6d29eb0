/* Materials on the GPU: the material buffer (GdrGpuMaterial per scene material, then a default
 * white untextured one for instances without a material) and the bindless textures (one image per
 * scene texture with its full mip chain, in the runtime-sized combined-image-sampler array at set
 * GDR_TEXTURE_SET, binding 0, of every frame pipeline). */
#ifndef GDR_RENDER_MATERIALS_H
#define GDR_RENDER_MATERIALS_H

#include "gdr/scene.h"
#include "vk/vk_buffer.h"
#include "vk/vk_image.h"

typedef struct gdr_renderer gdr_renderer;

typedef struct gdr_materials {
    VkDescriptorSetLayout set_layout; /* binding 0: GDR_MAX_TEXTURES combined image samplers, partially bound */
    VkDescriptorPool pool;
    VkDescriptorSet set;
    VkSampler sampler;                /* trilinear, repeat in both directions */
    gdr_vk_buffer buffer;             /* GdrGpuMaterial[material_count + 1] */
    gdr_vk_image *textures;           /* texture_count images, R8G8B8A8 sRGB or UNORM, every mip level */
    uint32_t texture_count;
    uint32_t material_count;          /* the scene's; the default material is at this index */
    uint64_t bytes;                   /* device memory of the buffer and the textures */
} gdr_materials;

/* The descriptor set layout, pool, set and sampler; before the frame pipelines (their layout takes
 * set_layout as set GDR_TEXTURE_SET). */
gdr_status gdr_materials_create(gdr_renderer *r, gdr_error *err);
/* The scene's materials and textures (mip chains built here, on the CPU), written into the set. */
gdr_status gdr_materials_upload(gdr_renderer *r, const gdr_scene *scene, gdr_error *err);
void gdr_materials_destroy(gdr_renderer *r);

/* Levels of a full mip chain down to 1x1 for a width x height image. */
uint32_t gdr_mip_level_count(uint32_t width, uint32_t height);
/* Mip level `level` (>= 1) of an RGBA8 image from level - 1 (prev, prev_w x prev_h), with a box
 * filter in linear light for sRGB data (srgb = 1) or directly on the values otherwise; out holds
 * max(prev_w / 2, 1) x max(prev_h / 2, 1) texels. Returns false when stb's resizer fails. */
bool gdr_mip_downsample(const uint8_t *prev, uint32_t prev_w, uint32_t prev_h, uint32_t srgb, uint8_t *out);

#endif
