/* The C side of Debian's libsquish (a C++ library): one 4 x 4 block at a time. */
#ifndef GDR_IO_TEXTURE_SQUISH_H
#define GDR_IO_TEXTURE_SQUISH_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Which block format (libsquish's names: DXT1 = BC1, DXT5 = BC3). */
typedef enum gdr_squish_kind { GDR_SQUISH_BC1, GDR_SQUISH_BC3, GDR_SQUISH_BC4, GDR_SQUISH_BC5 } gdr_squish_kind;

/* libsquish's colour fits (BC1, BC3's colour part), fastest first. */
typedef enum gdr_squish_fit { GDR_SQUISH_RANGE_FIT, GDR_SQUISH_CLUSTER_FIT, GDR_SQUISH_ITERATIVE_CLUSTER_FIT } gdr_squish_fit;

/* Compresses 16 RGBA8 texels (row-major, 4 rows of 4) into one block; BC4 reads R, BC5 R and G. */
void gdr_squish_compress_block(const uint8_t *rgba, void *block, gdr_squish_kind kind, gdr_squish_fit fit);
/* Decodes one block into 16 RGBA8 texels: BC1 and BC3 as their formats define; BC4 into R and
 * BC5 into R and G, the other channels left as they are. */
void gdr_squish_decompress_block(uint8_t *rgba, const void *block, gdr_squish_kind kind);

#ifdef __cplusplus
}
#endif

#endif
