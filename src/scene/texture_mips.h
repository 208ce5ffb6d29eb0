/* Building a texture's mip chain (gdr/scene.h describes the layout). */
#ifndef GDR_SCENE_TEXTURE_MIPS_H
#define GDR_SCENE_TEXTURE_MIPS_H

#include <stdbool.h>
#include <stdint.h>

/* Fills levels 1.. of `chain` (gdr_texture_level_offset(width, height, count) bytes, level 0
 * already in place) from level 0. Returns false when the resizer fails (it allocates). */
bool gdr_texture_build_levels(uint32_t width, uint32_t height, uint32_t srgb, uint8_t *chain);

#endif
