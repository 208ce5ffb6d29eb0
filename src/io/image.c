/* PNG / JPEG decoding through Debian's compiled stb_image (no implementation compiled here). */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image.h>

#include "gdr/io.h"

/* Larger images are refused before decoding, so a hostile header cannot ask for gigabytes. */
#define GDR_IMAGE_MAX_SIDE 16384u

gdr_status gdr_image_decode(const void *data, size_t size, const char *name, uint8_t **out_rgba,
                            uint32_t *out_width, uint32_t *out_height, gdr_error *err)
{
    *out_rgba = NULL;
    if (size == 0 || size > INT_MAX)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: image of %zu bytes", name, size);
    int w = 0, h = 0, channels = 0;
    if (!stbi_info_from_memory(data, (int)size, &w, &h, &channels))
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: not a readable image (%s)", name, stbi_failure_reason());
    if (w <= 0 || h <= 0 || (unsigned)w > GDR_IMAGE_MAX_SIDE || (unsigned)h > GDR_IMAGE_MAX_SIDE)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: image size %dx%d is out of range (1..%u)", name, w,
                             h, GDR_IMAGE_MAX_SIDE);
    stbi_uc *pixels = stbi_load_from_memory(data, (int)size, &w, &h, &channels, 4);
    if (!pixels)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: image decoding failed (%s)", name, stbi_failure_reason());
    size_t bytes = (size_t)w * (size_t)h * 4;
    uint8_t *copy = malloc(bytes);
    if (!copy) {
        stbi_image_free(pixels);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    memcpy(copy, pixels, bytes);
    stbi_image_free(pixels);
    *out_rgba = copy;
    *out_width = (uint32_t)w;
    *out_height = (uint32_t)h;
    return GDR_OK;
}
