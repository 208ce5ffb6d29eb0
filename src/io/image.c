/* PNG / JPEG decoding through Debian's compiled stb_image (no implementation compiled here). */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image.h>

#include "io/io_internal.h"

/* Larger images are refused before decoding, so a hostile header cannot ask for gigabytes. */
#define GDR_IMAGE_MAX_SIDE 16384u

/* stb_image's reason, or a sentence when it gives none (truncated data often gives none). */
static const char *failure_reason(void)
{
    const char *reason = stbi_failure_reason();
    return reason && reason[0] ? reason : "corrupt or truncated image data";
}

gdr_status gdr_io_image_size(const void *data, size_t size, const char *name, uint32_t *width, uint32_t *height,
                             gdr_error *err)
{
    int w = 0, h = 0, channels = 0;
    if (size == 0 || size > INT_MAX)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: image of %zu bytes", name, size);
    if (!stbi_info_from_memory(data, (int)size, &w, &h, &channels))
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: not a readable image (%s)", name, failure_reason());
    if (w <= 0 || h <= 0 || (unsigned)w > GDR_IMAGE_MAX_SIDE || (unsigned)h > GDR_IMAGE_MAX_SIDE)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: image size %dx%d is out of range (1..%u)", name, w,
                             h, GDR_IMAGE_MAX_SIDE);
    *width = (uint32_t)w;
    *height = (uint32_t)h;
    return GDR_OK;
}

gdr_status gdr_image_decode(const void *data, size_t size, const char *name, uint8_t **out_rgba,
                            uint32_t *out_width, uint32_t *out_height, gdr_error *err)
{
    *out_rgba = NULL;
    uint32_t width = 0, height = 0;
    gdr_status status = gdr_io_image_size(data, size, name, &width, &height, err);
    if (status != GDR_OK)
        return status;
    int w = 0, h = 0, channels = 0;
    stbi_uc *pixels = stbi_load_from_memory(data, (int)size, &w, &h, &channels, 4);
    if (!pixels)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: image decoding failed (%s)", name, failure_reason());
    if ((uint32_t)w != width || (uint32_t)h != height) {
        stbi_image_free(pixels);
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: image decoded as %dx%d, its header says %ux%u", name, w, h,
                             width, height);
    }
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
