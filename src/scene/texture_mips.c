/* Mip chains of the scene's textures (gdr/scene.h): built once, when a texture is added, so that
 * the cache keeps them and the renderer uploads them as they are. */
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image_resize.h>

#include "gdr/scene.h"
#include "scene/texture_mips.h"

uint32_t gdr_texture_level_count(uint32_t width, uint32_t height)
{
    uint32_t levels = 1;
    for (uint32_t side = width > height ? width : height; side > 1; side >>= 1)
        levels++;
    return levels;
}

size_t gdr_texture_level_offset(uint32_t width, uint32_t height, uint32_t level)
{
    size_t offset = 0;
    for (uint32_t l = 0; l < level; l++) {
        offset += (size_t)width * height * 4;
        width = width > 1 ? width / 2 : 1;
        height = height > 1 ? height / 2 : 1;
    }
    return offset;
}

uint32_t gdr_texture_block_bytes(uint32_t format)
{
    switch (format) {
    case GDR_TEXTURE_BC1:
    case GDR_TEXTURE_BC4:
        return 8;
    case GDR_TEXTURE_BC3:
    case GDR_TEXTURE_BC5:
    case GDR_TEXTURE_BC5_GB:
        return 16;
    default:
        return 0;
    }
}

size_t gdr_texture_format_level_offset(uint32_t format, uint32_t width, uint32_t height, uint32_t level)
{
    uint32_t block = gdr_texture_block_bytes(format);
    if (block == 0)
        return gdr_texture_level_offset(width, height, level);
    size_t offset = 0;
    for (uint32_t l = 0; l < level; l++) {
        offset += (size_t)((width + 3) / 4) * ((height + 3) / 4) * block;
        width = width > 1 ? width / 2 : 1;
        height = height > 1 ? height / 2 : 1;
    }
    return offset;
}

const char *gdr_texture_format_name(uint32_t format)
{
    static const char *const names[GDR_TEXTURE_FORMAT_COUNT] = {"rgba8", "bc1", "bc3", "bc4", "bc5", "bc5-gb"};
    return format < GDR_TEXTURE_FORMAT_COUNT ? names[format] : "?";
}

/* One level from the level above it (prev_w x prev_h): a box filter, in linear light for sRGB data,
 * weighted by alpha so that transparent texels do not bleed their colour into the level below. */
static bool downsample(const uint8_t *prev, uint32_t prev_w, uint32_t prev_h, uint32_t srgb, uint8_t *out)
{
    uint32_t w = prev_w > 1 ? prev_w / 2 : 1, h = prev_h > 1 ? prev_h / 2 : 1;
    return stbir_resize_uint8_generic(prev, (int)prev_w, (int)prev_h, 0, out, (int)w, (int)h, 0, 4, 3, 0,
                                      STBIR_EDGE_CLAMP, STBIR_FILTER_BOX,
                                      srgb ? STBIR_COLORSPACE_SRGB : STBIR_COLORSPACE_LINEAR, NULL) != 0;
}

bool gdr_texture_build_levels(uint32_t width, uint32_t height, uint32_t srgb, uint8_t *chain)
{
    uint32_t levels = gdr_texture_level_count(width, height);
    for (uint32_t l = 1; l < levels; l++) {
        uint32_t w = width >> (l - 1) ? width >> (l - 1) : 1, h = height >> (l - 1) ? height >> (l - 1) : 1;
        if (!downsample(chain + gdr_texture_level_offset(width, height, l - 1), w, h, srgb,
                        chain + gdr_texture_level_offset(width, height, l)))
            return false;
    }
    return true;
}
