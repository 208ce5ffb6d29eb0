/* Textures onto the GPU (texture_upload.h). */
#include "render/texture_upload.h"

#include <stdlib.h>
#include <string.h>

#include "gdr/io.h"
#include "render/renderer_internal.h"

/* The Vulkan format of a texture's block format, and its view's swizzle (BC5_GB's two channels
 * are G and B). */
static VkFormat block_format(const gdr_texture *t, VkComponentMapping *components)
{
    *components = (VkComponentMapping){0};
    switch (t->format) {
    case GDR_TEXTURE_BC1:
        return t->srgb ? VK_FORMAT_BC1_RGB_SRGB_BLOCK : VK_FORMAT_BC1_RGB_UNORM_BLOCK;
    case GDR_TEXTURE_BC3:
        return t->srgb ? VK_FORMAT_BC3_SRGB_BLOCK : VK_FORMAT_BC3_UNORM_BLOCK;
    case GDR_TEXTURE_BC4:
        return VK_FORMAT_BC4_UNORM_BLOCK;
    case GDR_TEXTURE_BC5:
        return VK_FORMAT_BC5_UNORM_BLOCK;
    case GDR_TEXTURE_BC5_GB:
        *components = (VkComponentMapping){VK_COMPONENT_SWIZZLE_ZERO, VK_COMPONENT_SWIZZLE_R, VK_COMPONENT_SWIZZLE_G,
                                           VK_COMPONENT_SWIZZLE_ONE};
        return VK_FORMAT_BC5_UNORM_BLOCK;
    default:
        return VK_FORMAT_UNDEFINED;
    }
}

/* Whether the device samples `format` with linear filtering and copies into it. */
static bool device_samples(const gdr_vk_context *ctx, VkFormat format)
{
    if (!ctx->has_texture_compression_bc)
        return false;
    VkFormatProperties properties;
    vkGetPhysicalDeviceFormatProperties(ctx->physical_device, format, &properties);
    VkFormatFeatureFlags need = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT |
                                VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
    return (properties.optimalTilingFeatures & need) == need;
}

/* One layout transition of every level of an image, in a one-time command buffer of its own. */
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

/* A level as rows of `row_texels` texels (1 for RGBA8, 4 for rows of blocks) of `row_bytes` each. */
typedef struct level_data {
    const uint8_t *bytes;
    uint32_t width, height, row_texels;
    size_t row_bytes;
} level_data;

/* Copies one mip level into an image in TRANSFER_DST layout through the staging buffer, in bands
 * of whole rows (of texels or blocks) that fit it. */
static gdr_status upload_level(gdr_renderer *r, VkImage image, uint32_t level, const level_data *d, gdr_error *err)
{
    uint32_t rows_total = (d->height + d->row_texels - 1) / d->row_texels;
    uint32_t rows_per_copy = (uint32_t)(r->staging.size / d->row_bytes);
    gdr_status status = GDR_OK;
    for (uint32_t row = 0; status == GDR_OK && row < rows_total; row += rows_per_copy) {
        uint32_t rows = rows_total - row < rows_per_copy ? rows_total - row : rows_per_copy;
        memcpy(r->staging.mapped, d->bytes + (size_t)row * d->row_bytes, (size_t)rows * d->row_bytes);
        VkCommandBuffer cmd;
        status = gdr_vk_begin_one_time(r->ctx, &cmd, err);
        if (status != GDR_OK)
            break;
        uint32_t y = row * d->row_texels, h = rows * d->row_texels;
        VkBufferImageCopy region = {.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, level, 0, 1},
                                    .imageOffset = {0, (int32_t)y, 0},
                                    .imageExtent = {d->width, y + h > d->height ? d->height - y : h, 1}};
        vkCmdCopyBufferToImage(cmd, r->staging.buffer, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        status = gdr_vk_end_one_time(r->ctx, cmd, err);
    }
    return status;
}

/* Level l of t as the image takes it: its blocks, or (decode) its texels decoded into `scratch`. */
static gdr_status level_for(const gdr_texture *t, uint32_t l, bool decode, uint8_t *scratch, level_data *d,
                            gdr_error *err)
{
    uint32_t w = t->width >> l ? t->width >> l : 1, h = t->height >> l ? t->height >> l : 1;
    uint32_t block = gdr_texture_block_bytes(t->format);
    *d = (level_data){.bytes = t->rgba + gdr_texture_format_level_offset(t->format, t->width, t->height, l),
                      .width = w, .height = h, .row_texels = 1, .row_bytes = (size_t)w * 4};
    if (block && !decode) {
        d->row_texels = 4;
        d->row_bytes = (size_t)((w + 3) / 4) * block;
    } else if (block) {
        d->bytes = scratch;
        return gdr_texture_decode_level(t, l, scratch, err);
    }
    return GDR_OK;
}

static gdr_status upload_levels(gdr_renderer *r, const gdr_texture *t, VkImage image, bool decode, gdr_error *err)
{
    uint8_t *scratch = decode ? malloc((size_t)t->width * t->height * 4) : NULL;
    if (decode && !scratch)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "texture '%s': out of memory to decode it", t->name);
    gdr_status status = GDR_OK;
    for (uint32_t l = 0; status == GDR_OK && l < t->levels; l++) {
        level_data d;
        status = level_for(t, l, decode, scratch, &d, err);
        if (status == GDR_OK)
            status = upload_level(r, image, l, &d, err);
    }
    free(scratch);
    return status;
}

gdr_status gdr_texture_upload(gdr_renderer *r, const gdr_texture *t, gdr_vk_image *image, gdr_error *err)
{
    gdr_materials *m = &r->materials;
    VkComponentMapping components;
    VkFormat compressed = block_format(t, &components);
    bool decode = compressed != VK_FORMAT_UNDEFINED && !device_samples(r->ctx, compressed);
    gdr_vk_image_desc desc = {.width = t->width, .height = t->height,
                              .format = t->srgb ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM,
                              .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                              .mip_levels = t->levels};
    if (compressed != VK_FORMAT_UNDEFINED && !decode) {
        desc.format = compressed;
        desc.components = components;
    }
    gdr_status status = gdr_vk_image_create(&r->allocator, &desc, image, err);
    if (status == GDR_OK)
        status = transition(r->ctx, image->image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, err);
    if (status == GDR_OK)
        status = upload_levels(r, t, image->image, decode, err);
    if (status == GDR_OK)
        status = transition(r->ctx, image->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                            VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, err);
    if (status != GDR_OK)
        return status;
    m->bytes += image->bytes;
    m->texture_bytes += image->bytes;
    m->textures_compressed += compressed != VK_FORMAT_UNDEFINED && !decode;
    m->textures_decoded += decode;
    return GDR_OK;
}
