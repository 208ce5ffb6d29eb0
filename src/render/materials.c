/* Materials on the GPU (materials.h). */
#include "render/materials.h"

#include <stdlib.h>
#include <string.h>

#include <stb/stb_image_resize.h>

#include "render/renderer_internal.h"
#include "vk/vk_descriptors.h"

uint32_t gdr_mip_level_count(uint32_t width, uint32_t height)
{
    uint32_t levels = 1;
    for (uint32_t side = width > height ? width : height; side > 1; side >>= 1)
        levels++;
    return levels;
}

bool gdr_mip_downsample(const uint8_t *prev, uint32_t prev_w, uint32_t prev_h, uint32_t srgb, uint8_t *out)
{
    uint32_t w = prev_w > 1 ? prev_w / 2 : 1, h = prev_h > 1 ? prev_h / 2 : 1;
    /* Wrap at the edges: glTF's default sampler repeats. Alpha-weighted, so transparent texels
     * do not bleed their colour into the level below. */
    return stbir_resize_uint8_generic(prev, (int)prev_w, (int)prev_h, 0, out, (int)w, (int)h, 0, 4, 3, 0,
                                      STBIR_EDGE_WRAP, STBIR_FILTER_BOX,
                                      srgb ? STBIR_COLORSPACE_SRGB : STBIR_COLORSPACE_LINEAR, NULL) != 0;
}

static gdr_status create_sampler(gdr_vk_context *ctx, VkSampler *out, gdr_error *err)
{
    VkSamplerCreateInfo info = {.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO, .magFilter = VK_FILTER_LINEAR,
                                .minFilter = VK_FILTER_LINEAR, .mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR,
                                .addressModeU = VK_SAMPLER_ADDRESS_MODE_REPEAT,
                                .addressModeV = VK_SAMPLER_ADDRESS_MODE_REPEAT,
                                .addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT, .maxLod = VK_LOD_CLAMP_NONE};
    GDR_VK_TRY(err, vkCreateSampler(ctx->device, &info, NULL, out));
    return GDR_OK;
}

gdr_status gdr_materials_create(gdr_renderer *r, gdr_error *err)
{
    gdr_materials *m = &r->materials;
    VkDescriptorBindingFlags flags = VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT;
    VkDescriptorSetLayoutBindingFlagsCreateInfo binding_flags = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO, .bindingCount = 1,
        .pBindingFlags = &flags};
    VkDescriptorSetLayoutBinding binding = {0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, GDR_MAX_TEXTURES,
                                            VK_SHADER_STAGE_ALL, NULL};
    VkDescriptorSetLayoutCreateInfo info = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
                                            .pNext = &binding_flags, .bindingCount = 1, .pBindings = &binding};
    GDR_VK_TRY(err, vkCreateDescriptorSetLayout(r->ctx->device, &info, NULL, &m->set_layout));
    VkDescriptorPoolSize size = {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, GDR_MAX_TEXTURES};
    gdr_status status = gdr_vk_descriptor_pool_create(r->ctx, 1, &size, 1, &m->pool, err);
    if (status == GDR_OK)
        status = gdr_vk_descriptor_sets_allocate(r->ctx, m->pool, m->set_layout, 1, &m->set, err);
    if (status == GDR_OK)
        status = create_sampler(r->ctx, &m->sampler, err);
    return status;
}

static GdrGpuMaterial gpu_material_from(const gdr_material *s, uint32_t texture_count)
{
    GdrGpuMaterial g = {.base_color = s->base_color, .base_color_texture = GDR_GPU_NO_TEXTURE,
                        .alpha_mode = s->alpha_mode, .alpha_cutoff = s->alpha_cutoff,
                        .double_sided = s->double_sided};
    if (s->base_color_texture < texture_count)
        g.base_color_texture = s->base_color_texture;
    return g;
}

static gdr_status upload_material_buffer(gdr_renderer *r, const gdr_scene *scene, gdr_error *err)
{
    gdr_materials *m = &r->materials;
    uint32_t count = scene->material_count + 1;
    GdrGpuMaterial *materials = malloc(sizeof *materials * count);
    if (!materials)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "materials: out of memory for %u materials", count);
    for (uint32_t i = 0; i < scene->material_count; i++)
        materials[i] = gpu_material_from(&scene->materials[i], scene->texture_count);
    materials[scene->material_count] = (GdrGpuMaterial){.base_color = {1, 1, 1, 1},
                                                        .base_color_texture = GDR_GPU_NO_TEXTURE};
    m->material_count = scene->material_count;
    gdr_status status = gdr_vk_buffer_create(&r->allocator, sizeof *materials * count,
                                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                             GDR_VK_BUFFER_DEVICE, &m->buffer, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &m->buffer, 0, materials, sizeof *materials * count, err);
    m->bytes += m->buffer.size;
    free(materials);
    return status;
}

/* One layout transition of every level of a texture, in a one-time command buffer of its own. */
static gdr_status transition(gdr_vk_context *ctx, VkImage image, VkImageLayout from, VkImageLayout to, gdr_error *err)
{
    VkCommandBuffer cmd;
    gdr_status status = gdr_vk_begin_one_time(ctx, &cmd, err);
    if (status != GDR_OK)
        return status;
    bool to_copy = to == VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    gdr_vk_image_barrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, from, to,
                         to_copy ? VK_PIPELINE_STAGE_2_NONE : VK_PIPELINE_STAGE_2_COPY_BIT,
                         to_copy ? VK_ACCESS_2_NONE : VK_ACCESS_2_TRANSFER_WRITE_BIT,
                         to_copy ? VK_PIPELINE_STAGE_2_COPY_BIT : VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                         to_copy ? VK_ACCESS_2_TRANSFER_WRITE_BIT : VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    return gdr_vk_end_one_time(ctx, cmd, err);
}

/* Copies one mip level into an image in TRANSFER_DST layout through the staging buffer, in bands
 * of whole rows that fit it. */
static gdr_status upload_level(gdr_renderer *r, VkImage image, uint32_t level, const uint8_t *texels, uint32_t w,
                               uint32_t h, gdr_error *err)
{
    uint32_t rows_per_copy = (uint32_t)(r->staging.size / ((VkDeviceSize)w * 4));
    gdr_status status = GDR_OK;
    for (uint32_t row = 0; status == GDR_OK && row < h; row += rows_per_copy) {
        uint32_t rows = h - row < rows_per_copy ? h - row : rows_per_copy;
        memcpy(r->staging.mapped, texels + (size_t)row * w * 4, (size_t)rows * w * 4);
        VkCommandBuffer cmd;
        status = gdr_vk_begin_one_time(r->ctx, &cmd, err);
        if (status != GDR_OK)
            break;
        VkBufferImageCopy region = {.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, level, 0, 1},
                                    .imageOffset = {0, (int32_t)row, 0}, .imageExtent = {w, rows, 1}};
        vkCmdCopyBufferToImage(cmd, r->staging.buffer, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        status = gdr_vk_end_one_time(r->ctx, cmd, err);
    }
    return status;
}

/* Every level of texture t: level 0 from the scene, each next one downsampled from the last into
 * one of two buffers used in turn (each as large as level 1). */
static gdr_status upload_levels(gdr_renderer *r, const gdr_texture *t, const gdr_vk_image *image, gdr_error *err)
{
    uint32_t w = t->width, h = t->height;
    size_t level1_bytes = (size_t)(w > 1 ? w / 2 : 1) * (h > 1 ? h / 2 : 1) * 4;
    uint8_t *buffers[2] = {malloc(level1_bytes), malloc(level1_bytes)};
    const uint8_t *current = t->rgba;
    gdr_status status = buffers[0] && buffers[1] ? GDR_OK
                                                 : gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "texture '%s': out of memory",
                                                                 t->name);
    for (uint32_t l = 0; status == GDR_OK && l < image->mip_levels; l++) {
        status = upload_level(r, image->image, l, current, w, h, err);
        if (status != GDR_OK || l + 1 == image->mip_levels)
            break;
        uint8_t *next = buffers[l & 1];
        if (!gdr_mip_downsample(current, w, h, t->srgb, next))
            status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "texture '%s': mip level %u: resize failed", t->name, l + 1);
        w = w > 1 ? w / 2 : 1;
        h = h > 1 ? h / 2 : 1;
        current = next;
    }
    free(buffers[0]);
    free(buffers[1]);
    return status;
}

static gdr_status upload_texture(gdr_renderer *r, const gdr_texture *t, uint32_t index, gdr_error *err)
{
    gdr_materials *m = &r->materials;
    gdr_vk_image_desc desc = {.width = t->width, .height = t->height,
                              .format = t->srgb ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM,
                              .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                              .mip_levels = gdr_mip_level_count(t->width, t->height)};
    gdr_vk_image *image = &m->textures[index];
    gdr_status status = gdr_vk_image_create(&r->allocator, &desc, image, err);
    if (status == GDR_OK)
        status = transition(r->ctx, image->image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, err);
    if (status == GDR_OK)
        status = upload_levels(r, t, image, err);
    if (status == GDR_OK)
        status = transition(r->ctx, image->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                            VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, err);
    if (status != GDR_OK)
        return status;
    uint64_t bytes = 0;
    for (uint32_t w = t->width, h = t->height, l = 0; l < desc.mip_levels; l++, w = w > 1 ? w / 2 : 1, h = h > 1 ? h / 2 : 1)
        bytes += (uint64_t)w * h * 4;
    m->bytes += bytes;
    VkDescriptorImageInfo info = {m->sampler, image->view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    VkWriteDescriptorSet write = {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = m->set, .dstBinding = 0,
                                  .dstArrayElement = index, .descriptorCount = 1,
                                  .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &info};
    vkUpdateDescriptorSets(r->ctx->device, 1, &write, 0, NULL);
    return GDR_OK;
}

gdr_status gdr_materials_upload(gdr_renderer *r, const gdr_scene *scene, gdr_error *err)
{
    gdr_materials *m = &r->materials;
    if (scene->texture_count > GDR_MAX_TEXTURES)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "scene: %u textures; the renderer holds at most %u",
                             scene->texture_count, GDR_MAX_TEXTURES);
    gdr_status status = upload_material_buffer(r, scene, err);
    m->textures = calloc(scene->texture_count ? scene->texture_count : 1, sizeof *m->textures);
    if (status == GDR_OK && !m->textures)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "materials: out of memory for %u textures",
                               scene->texture_count);
    for (uint32_t i = 0; status == GDR_OK && i < scene->texture_count; i++) {
        status = upload_texture(r, &scene->textures[i], i, err);
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
    if (m->sampler)
        vkDestroySampler(device, m->sampler, NULL);
    if (m->pool)
        vkDestroyDescriptorPool(device, m->pool, NULL);
    if (m->set_layout)
        vkDestroyDescriptorSetLayout(device, m->set_layout, NULL);
    memset(m, 0, sizeof *m);
}
