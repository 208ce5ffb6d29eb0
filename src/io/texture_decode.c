/* Decoding a texture level back to RGBA8 texels, as a device samples it (gdr/scene.h lists what
 * each format samples as): for devices without BC sampling, and to measure what compression cost. */
#include <string.h>

#include "gdr/io.h"
#include "io/texture_squish.h"

/* 16 decoded texels with the channels the format does not store set as a device reads them. */
static void decode_block(const uint8_t *block, uint32_t format, uint8_t out[64])
{
    static const gdr_squish_kind kinds[GDR_TEXTURE_FORMAT_COUNT] = {
        [GDR_TEXTURE_BC1] = GDR_SQUISH_BC1, [GDR_TEXTURE_BC3] = GDR_SQUISH_BC3, [GDR_TEXTURE_BC4] = GDR_SQUISH_BC4,
        [GDR_TEXTURE_BC5] = GDR_SQUISH_BC5, [GDR_TEXTURE_BC5_GB] = GDR_SQUISH_BC5};
    memset(out, 0, 64);
    gdr_squish_decompress_block(out, block, kinds[format]);
    for (int i = 0; i < 16; i++) {
        uint8_t *t = out + i * 4;
        if (format == GDR_TEXTURE_BC5_GB) {
            t[2] = t[1];
            t[1] = t[0];
            t[0] = 0;
        }
        if (format != GDR_TEXTURE_BC3)
            t[3] = 255; /* BC1 as its RGB format: opaque (its 3-colour mode's fourth entry is black) */
    }
}

gdr_status gdr_texture_decode_level(const gdr_texture *t, uint32_t level, uint8_t *rgba, gdr_error *err)
{
    if (t->format >= GDR_TEXTURE_FORMAT_COUNT || level >= t->levels)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "texture '%s': format %u or level %u is out of range",
                             t->name, t->format, level);
    uint32_t w = t->width >> level ? t->width >> level : 1, h = t->height >> level ? t->height >> level : 1;
    const uint8_t *src = t->rgba + gdr_texture_format_level_offset(t->format, t->width, t->height, level);
    if (t->format == GDR_TEXTURE_RGBA8) {
        memcpy(rgba, src, (size_t)w * h * 4);
        return GDR_OK;
    }
    uint32_t blocks_x = (w + 3) / 4, blocks_y = (h + 3) / 4, block_bytes = gdr_texture_block_bytes(t->format);
    for (uint32_t by = 0; by < blocks_y; by++)
        for (uint32_t bx = 0; bx < blocks_x; bx++) {
            uint8_t texels[64];
            decode_block(src + ((size_t)by * blocks_x + bx) * block_bytes, t->format, texels);
            for (uint32_t y = 0; y < 4 && by * 4 + y < h; y++)
                for (uint32_t x = 0; x < 4 && bx * 4 + x < w; x++)
                    memcpy(rgba + (((size_t)by * 4 + y) * w + bx * 4 + x) * 4, texels + (y * 4 + x) * 4, 4);
        }
    return GDR_OK;
}
