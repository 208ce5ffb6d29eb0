// The C side of Debian's libsquish (src/io/texture_squish.h).
#include "io/texture_squish.h"

#include <squish.h>

#include <cstring>

namespace {

int flags_for(gdr_squish_kind kind, gdr_squish_fit fit)
{
    static const int kinds[] = {squish::kDxt1, squish::kDxt5, squish::kBc4, squish::kBc5};
    static const int fits[] = {squish::kColourRangeFit, squish::kColourClusterFit, squish::kColourIterativeClusterFit};
    return kinds[kind] | fits[fit];
}

// libsquish 1.15 compresses BC4 and BC5 but decodes every block as DXT1: a BC4 block is a DXT5
// block's alpha half, so it is decoded as one (behind a colour half of zeros) and its alpha read.
void decode_channel(uint8_t *rgba, const uint8_t *bc4_block, int channel)
{
    uint8_t dxt5[16] = {0};
    std::memcpy(dxt5, bc4_block, 8);
    uint8_t texels[64];
    squish::Decompress(texels, dxt5, squish::kDxt5);
    for (int i = 0; i < 16; i++)
        rgba[i * 4 + channel] = texels[i * 4 + 3];
}

} // namespace

extern "C" void gdr_squish_compress_block(const uint8_t *rgba, void *block, gdr_squish_kind kind, gdr_squish_fit fit)
{
    squish::Compress(rgba, block, flags_for(kind, fit));
}

extern "C" void gdr_squish_decompress_block(uint8_t *rgba, const void *block, gdr_squish_kind kind)
{
    const uint8_t *bytes = static_cast<const uint8_t *>(block);
    if (kind == GDR_SQUISH_BC4 || kind == GDR_SQUISH_BC5) {
        decode_channel(rgba, bytes, 0);
        if (kind == GDR_SQUISH_BC5)
            decode_channel(rgba, bytes + 8, 1);
        return;
    }
    squish::Decompress(rgba, block, flags_for(kind, GDR_SQUISH_CLUSTER_FIT));
}
