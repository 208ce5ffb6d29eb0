/* Materials on the GPU: the material buffer (GdrGpuMaterial per scene material, then glTF's default
 * material for instances without one), the vertex colours, and the bindless textures: one image per
 * scene texture with its mip chain (gdr_texture) in the sampled-image array at set GDR_TEXTURE_SET,
 * binding 0, and a sampler per glTF sampler state the materials use at binding 1. */
#ifndef GDR_RENDER_MATERIALS_H
#define GDR_RENDER_MATERIALS_H

#include "gdr/scene.h"
#include "vk/vk_buffer.h"
#include "vk/vk_image.h"

typedef struct gdr_renderer gdr_renderer;

typedef struct gdr_materials {
    VkDescriptorSetLayout set_layout; /* binding 0: GDR_MAX_TEXTURES sampled images; 1: GDR_SAMPLER_SLOTS samplers */
    VkDescriptorPool pool;
    VkDescriptorSet set;
    VkSampler samplers[GDR_SAMPLER_STATES]; /* made for the states the materials use, else VK_NULL_HANDLE */
    gdr_vk_buffer buffer;             /* GdrGpuMaterial[material_count + 1] */
    gdr_vk_buffer vertex_colors;      /* uint32[2] per vertex of the meshes that have colours: RGBA16 unorm */
    gdr_vk_buffer mesh_color_offsets; /* uint32 per mesh: its first entry in vertex_colors, or GDR_GPU_NO_COLORS */
    gdr_vk_image *textures;           /* texture_count images in the texture's BC format, or R8G8B8A8 (sRGB or
                                         UNORM) for RGBA8 textures and decoded ones; every mip level */
    uint32_t texture_count;
    uint32_t material_count;          /* the scene's; the default material is at this index */
    uint32_t scene_flags;             /* GDR_MATERIALS_* of the scene's materials */
    uint64_t bytes;                   /* device memory of the buffers and the textures */
    uint64_t texture_bytes;           /* device memory of the textures alone */
    uint32_t textures_compressed;     /* sampled in their BC format */
    uint32_t textures_decoded;        /* BC textures decoded to RGBA8 at upload */
} gdr_materials;

#define GDR_MATERIALS_MASKED 1u       /* some material is MASK or BLEND: the raster paths test alpha */
#define GDR_MATERIALS_DOUBLE_SIDED 2u /* some material is double-sided: back faces culled per material */
#define GDR_MATERIALS_VERTEX_COLORS 4u /* some mesh has vertex colours */

/* The descriptor set layout, pool and set; before the frame pipelines (their layout takes
 * set_layout as set GDR_TEXTURE_SET). */
gdr_status gdr_materials_create(gdr_renderer *r, gdr_error *err);
/* The scene's materials, vertex colours and textures, written into the set; after the geometry
 * (the vertex colours follow its vertex offsets). */
gdr_status gdr_materials_upload(gdr_renderer *r, const gdr_scene *scene, gdr_error *err);
void gdr_materials_destroy(gdr_renderer *r);

#endif
