/* Block compression of textures, inside the library (gdr/io.h has the public part). */
#ifndef GDR_IO_TEXTURE_CODEC_H
#define GDR_IO_TEXTURE_CODEC_H

#include <stdint.h>

#include "gdr/scene.h"

/* The format gdr_scene_compress_textures gives texture t, whose uses read `channels` (bits R 1,
 * G 2, B 4, A 8; 0: no material uses it, left as it is), a metallic-roughness texture
 * (channels G and B) getting `metallic_roughness_format`. */
uint32_t gdr_io_texture_format_for(const gdr_texture *t, uint32_t channels, uint32_t metallic_roughness_format);

/* Encodes block rows [first_block_row, first_block_row + block_rows) of a w x h RGBA8 level into
 * `blocks` (the whole level's blocks, row-major) in `format` (a BC gdr_texture_format) with the
 * colour fit `fit` (a gdr_squish_fit). */
void gdr_io_texture_encode_rows(const uint8_t *level, uint32_t w, uint32_t h, uint32_t format, uint32_t fit,
                                uint32_t first_block_row, uint32_t block_rows, uint8_t *blocks);

#endif
