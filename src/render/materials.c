/* Materials on the GPU (materials.h). */
#include "render/materials.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/renderer_internal.h"
#include "render/texture_upload.h"
#include "vk/vk_descriptors.h"

_Static_assert(GDR_SAMPLER_STATES == GDR_SAMPLER_SLOTS, "one sampler slot per packed sampler state");
_Static_assert(GDR_ALPHA_MODE_OPAQUE == GDR_ALPHA_OPAQUE && GDR_ALPHA_MODE_MASK == GDR_ALPHA_MASK &&
                   GDR_ALPHA_MODE_BLEND == GDR_ALPHA_BLEND,
               "the shaders' alpha modes are gdr_alpha_mode's");

gdr_status gdr_materials_create(gdr_renderer *r, gdr_error *err)
{
    gdr_materials *m = &r->materials;
    const VkDescriptorBindingFlags flags[2] = {VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT,
                                               VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT};
    VkDescriptorSetLayoutBindingFlagsCreateInfo binding_flags = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO, .bindingCount = 2,
        .pBindingFlags = flags};
    const VkDescriptorSetLayoutBinding bindings[2] = {
        {0, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, GDR_MAX_TEXTURES, VK_SHADER_STAGE_ALL, NULL},
        {1, VK_DESCRIPTOR_TYPE_SAMPLER, GDR_SAMPLER_SLOTS, VK_SHADER_STAGE_ALL, NULL}};
    VkDescriptorSetLayoutCreateInfo info = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
                                            .pNext = &binding_flags, .bindingCount = 2, .pBindings = bindings};
    GDR_VK_TRY(err, vkCreateDescriptorSetLayout(r->ctx->device, &info, NULL, &m->set_layout));
    const VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, GDR_MAX_TEXTURES},
                                           {VK_DESCRIPTOR_TYPE_SAMPLER, GDR_SAMPLER_SLOTS}};
    gdr_status status = gdr_vk_descriptor_pool_create(r->ctx, 1, sizes, 2, &m->pool, err);
    if (status == GDR_OK)
        status = gdr_vk_descriptor_sets_allocate(r->ctx, m->pool, m->set_layout, 1, &m->set, err);
    return status;
}

static VkSamplerAddressMode address_mode(uint32_t wrap)
{
    return wrap == GDR_SAMPLER_WRAP_CLAMP    ? VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE
           : wrap == GDR_SAMPLER_WRAP_MIRROR ? VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT
                                             : VK_SAMPLER_ADDRESS_MODE_REPEAT;
}

/* The sampler of packed state `state` (GDR_SAMPLER_*), made on first use and written into slot
 * `state` of binding 1. Minification without mips reads level 0 only (maxLod 0). */
static gdr_status use_sampler(gdr_renderer *r, uint32_t state, gdr_error *err)
{
    gdr_materials *m = &r->materials;
    if (m->samplers[state])
        return GDR_OK;
    VkSamplerCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .magFilter = state & GDR_SAMPLER_MAG_NEAREST ? VK_FILTER_NEAREST : VK_FILTER_LINEAR,
        .minFilter = state & GDR_SAMPLER_MIN_NEAREST ? VK_FILTER_NEAREST : VK_FILTER_LINEAR,
        .mipmapMode = state & GDR_SAMPLER_MIP_NEAREST ? VK_SAMPLER_MIPMAP_MODE_NEAREST : VK_SAMPLER_MIPMAP_MODE_LINEAR,
        .addressModeU = address_mode(GDR_SAMPLER_WRAP_S(state)), .addressModeV = address_mode(GDR_SAMPLER_WRAP_T(state)),
        .addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT,
        .maxLod = state & GDR_SAMPLER_MIP_NONE ? 0.0f : VK_LOD_CLAMP_NONE};
    GDR_VK_TRY(err, vkCreateSampler(r->ctx->device, &info, NULL, &m->samplers[state]));
    VkDescriptorImageInfo image = {.sampler = m->samplers[state]};
    VkWriteDescriptorSet write = {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = m->set, .dstBinding = 1,
                                  .dstArrayElement = state, .descriptorCount = 1,
                                  .descriptorType = VK_DESCRIPTOR_TYPE_SAMPLER, .pImageInfo = &image};
    vkUpdateDescriptorSets(r->ctx->device, 1, &write, 0, NULL);
    return GDR_OK;
}

static GdrGpuTextureRef gpu_texture_ref(const gdr_texture_ref *t, uint32_t texture_count)
{
    float c = cosf(t->rotation), s = sinf(t->rotation);
    return (GdrGpuTextureRef){.texture = t->texture < texture_count ? t->texture : GDR_GPU_NO_TEXTURE,
                              .sampler_slot = t->sampler, .offset = t->offset,
                              .matrix = {c * t->scale.x, -s * t->scale.x, s * t->scale.y, c * t->scale.y}};
}

static GdrGpuMaterial gpu_material_from(const gdr_material *s, uint32_t texture_count)
{
    GdrGpuMaterial g = {.base_color = s->base_color, .emissive = s->emissive, .metallic = s->metallic_factor,
                        .roughness = s->roughness_factor, .normal_scale = s->normal_scale,
                        .occlusion_strength = s->occlusion_strength, .alpha_cutoff = s->alpha_cutoff,
                        .alpha_mode = s->alpha_mode, .double_sided = s->double_sided};
    const gdr_texture_ref *refs[GDR_MATERIAL_TEXTURES] = {
        [GDR_MATERIAL_BASE_COLOR] = &s->base_color_texture, [GDR_MATERIAL_METALLIC_ROUGHNESS] = &s->metallic_roughness_texture,
        [GDR_MATERIAL_NORMAL] = &s->normal_texture, [GDR_MATERIAL_OCCLUSION] = &s->occlusion_texture,
        [GDR_MATERIAL_EMISSIVE] = &s->emissive_texture};
    for (int k = 0; k < GDR_MATERIAL_TEXTURES; k++)
        g.textures[k] = gpu_texture_ref(refs[k], texture_count);
    return g;
}

/* A device buffer holding `bytes` of `data`, counted in the materials' memory. */
static gdr_status upload_buffer(gdr_renderer *r, gdr_vk_buffer *buffer, const void *data, size_t bytes, gdr_error *err)
{
    gdr_status status = gdr_vk_buffer_create(&r->allocator, bytes,
                                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                             GDR_VK_BUFFER_DEVICE, buffer, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, buffer, 0, data, bytes, err);
    r->materials.bytes += buffer->size;
    return status;
}

static gdr_status upload_material_buffer(gdr_renderer *r, const gdr_scene *scene, gdr_error *err)
{
    gdr_materials *m = &r->materials;
    uint32_t count = scene->material_count + 1;
    GdrGpuMaterial *materials = malloc(sizeof *materials * count);
    if (!materials)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "materials: out of memory for %u materials", count);
    /* Instances without a material: a white dielectric of roughness 0.5 (importers give glTF's
     * primitives without a material glTF's default material themselves). */
    gdr_material fallback = gdr_material_default();
    fallback.metallic_factor = 0.0f;
    fallback.roughness_factor = 0.5f;
    gdr_status status = GDR_OK;
    for (uint32_t i = 0; i < count && status == GDR_OK; i++) {
        const gdr_material *s = i < scene->material_count ? &scene->materials[i] : &fallback;
        materials[i] = gpu_material_from(s, scene->texture_count);
        if (s->alpha_mode != GDR_ALPHA_OPAQUE)
            m->scene_flags |= GDR_MATERIALS_MASKED;
        if (s->double_sided)
            m->scene_flags |= GDR_MATERIALS_DOUBLE_SIDED;
        for (int k = 0; k < GDR_MATERIAL_TEXTURES && status == GDR_OK; k++)
            status = materials[i].textures[k].sampler_slot < GDR_SAMPLER_STATES
                         ? use_sampler(r, materials[i].textures[k].sampler_slot, err)
                         : gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "material %u: sampler state %u is out of range",
                                         i, materials[i].textures[k].sampler_slot);
    }
    m->material_count = scene->material_count;
    if (status == GDR_OK)
        status = upload_buffer(r, &m->buffer, materials, sizeof *materials * count, err);
    free(materials);
    return status;
}

/* RGBA16 unorm in two words: r | g << 16, b | a << 16. */
static void pack_color(gdr_vec4 c, uint32_t *out)
{
    uint32_t q[4];
    const float *f = &c.x;
    for (int k = 0; k < 4; k++)
        q[k] = (uint32_t)lroundf((f[k] < 0.0f ? 0.0f : f[k] > 1.0f ? 1.0f : f[k]) * 65535.0f);
    out[0] = q[0] | q[1] << 16;
    out[1] = q[2] | q[3] << 16;
}

static gdr_status upload_vertex_colors(gdr_renderer *r, const gdr_scene *scene, gdr_error *err)
{
    gdr_materials *m = &r->materials;
    uint64_t total = 0;
    uint32_t *offsets = malloc(sizeof *offsets * (scene->mesh_count ? scene->mesh_count : 1));
    for (uint32_t i = 0; offsets && i < scene->mesh_count; i++) {
        offsets[i] = scene->meshes[i].colors && total < UINT32_MAX ? (uint32_t)total : GDR_GPU_NO_COLORS;
        m->scene_flags |= scene->meshes[i].colors ? GDR_MATERIALS_VERTEX_COLORS : 0u;
        total += scene->meshes[i].colors ? scene->meshes[i].vertex_count : 0;
    }
    uint32_t *words = offsets && total < UINT32_MAX / 2 ? malloc(sizeof *words * 2 * (total ? total : 1)) : NULL;
    gdr_status status = words ? GDR_OK
                              : gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "vertex colours: out of memory for %llu colours",
                                              (unsigned long long)total);
    for (uint32_t i = 0; status == GDR_OK && i < scene->mesh_count; i++)
        for (uint32_t v = 0; offsets[i] != GDR_GPU_NO_COLORS && v < scene->meshes[i].vertex_count; v++)
            pack_color(scene->meshes[i].colors[v], words + 2 * ((size_t)offsets[i] + v));
    if (status == GDR_OK)
        status = upload_buffer(r, &m->vertex_colors, words, sizeof *words * 2 * (total ? total : 1), err);
    if (status == GDR_OK)
        status = upload_buffer(r, &m->mesh_color_offsets, offsets, sizeof *offsets * (scene->mesh_count ? scene->mesh_count : 1),
                               err);
    free(words);
    free(offsets);
    return status;
}

/* Texture `index` of the bindless array. */
static void write_texture_descriptor(gdr_renderer *r, const gdr_vk_image *image, uint32_t index)
{
    VkDescriptorImageInfo info = {.imageView = image->view, .imageLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    VkWriteDescriptorSet write = {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = r->materials.set,
                                  .dstBinding = 0, .dstArrayElement = index, .descriptorCount = 1,
                                  .descriptorType = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, .pImageInfo = &info};
    vkUpdateDescriptorSets(r->ctx->device, 1, &write, 0, NULL);
}

gdr_status gdr_materials_upload(gdr_renderer *r, const gdr_scene *scene, gdr_error *err)
{
    gdr_materials *m = &r->materials;
    if (scene->texture_count > GDR_MAX_TEXTURES)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "scene: %u textures; the renderer holds at most %u",
                             scene->texture_count, GDR_MAX_TEXTURES);
    gdr_status status = upload_material_buffer(r, scene, err);
    if (status == GDR_OK)
        status = upload_vertex_colors(r, scene, err);
    m->textures = calloc(scene->texture_count ? scene->texture_count : 1, sizeof *m->textures);
    if (status == GDR_OK && !m->textures)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "materials: out of memory for %u textures",
                               scene->texture_count);
    for (uint32_t i = 0; status == GDR_OK && i < scene->texture_count; i++) {
        status = gdr_texture_upload(r, &scene->textures[i], &m->textures[i], err);
        if (status == GDR_OK)
            write_texture_descriptor(r, &m->textures[i], i);
        m->texture_count = i + 1; /* destroyed with the rest, whether or not it completed */
    }
    return status;
}

void gdr_materials_destroy(gdr_renderer *r)
{
    gdr_materials *m = &r->materials;
    VkDevice device = r->ctx->device;
    for (uint32_t i = 0; m->textures && i < m->texture_count; i++)
        gdr_vk_image_destroy(r->ctx, &m->textures[i]);
    free(m->textures);
    gdr_vk_buffer_destroy(r->ctx, &m->buffer);
    gdr_vk_buffer_destroy(r->ctx, &m->vertex_colors);
    gdr_vk_buffer_destroy(r->ctx, &m->mesh_color_offsets);
    for (uint32_t i = 0; i < GDR_SAMPLER_STATES; i++)
        if (m->samplers[i])
            vkDestroySampler(device, m->samplers[i], NULL);
    if (m->pool)
        vkDestroyDescriptorPool(device, m->pool, NULL);
    if (m->set_layout)
        vkDestroyDescriptorSetLayout(device, m->set_layout, NULL);
    memset(m, 0, sizeof *m);
}
