/* Images: the two formats glTF allows, PNG (libpng) and JPEG (libjpeg-turbo), chosen by the file's
 * signature whatever its URI or mimeType says. Both decoders take limits (sides, chunk sizes, scans,
 * memory), so a small file cannot make them work for minutes or allocate gigabytes. */
#include <stdlib.h>
#include <string.h>

#include "io/image_decoders.h"
#include "io/io_internal.h"

/* Formats that glTF does not allow, by their signature, so that a refusal can say what the file is.
 * TGA has no signature: it falls under "unknown". */
static const char *other_format(const uint8_t *data, size_t size)
{
    static const struct {
        const char *prefix;
        size_t length;
        const char *name;
    } known[] = {
        {"BM", 2, "BMP"},          {"GIF8", 4, "GIF"},          {"8BPS", 4, "PSD"},
        {"#?RADIANCE", 10, "HDR"}, {"#?RGBE", 6, "HDR"},        {"\xabKTX", 4, "KTX"},
        {"DDS ", 4, "DDS"},        {"II*\0", 4, "TIFF"},        {"MM\0*", 4, "TIFF"},
        {"qoif", 4, "QOI"},        {"\x76\x2f\x31\x01", 4, "OpenEXR"},
    };
    for (size_t i = 0; i < sizeof known / sizeof known[0]; i++)
        if (size >= known[i].length && memcmp(data, known[i].prefix, known[i].length) == 0)
            return known[i].name;
    if (size >= 12 && memcmp(data, "RIFF", 4) == 0 && memcmp(data + 8, "WEBP", 4) == 0)
        return "WebP";
    if (size >= 2 && data[0] == 'P' && data[1] >= '1' && data[1] <= '7')
        return "PNM";
    return NULL;
}

gdr_status gdr_io_image_probe(const void *data, size_t size, const char *name, gdr_io_image_info *info,
                              gdr_error *err)
{
    static const uint8_t png_signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    const uint8_t *bytes = data;
    *info = (gdr_io_image_info){0};
    if (size >= 8 && memcmp(bytes, png_signature, 8) == 0)
        return gdr_io_png_probe(bytes, size, name, info, err);
    if (size >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff)
        return gdr_io_jpeg_probe(bytes, size, name, info, err);
    const char *other = other_format(bytes, size);
    if (other)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: a %s image; glTF images must be PNG or JPEG", name,
                             other);
    return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: not a PNG or JPEG image (%zu bytes without either's "
                         "signature)", name, size);
}

gdr_status gdr_io_image_decode(const void *data, size_t size, const char *name, const gdr_io_image_info *info,
                               uint8_t **out_rgba, gdr_error *err)
{
    *out_rgba = NULL;
    uint8_t *rgba = malloc((size_t)info->width * info->height * 4);
    if (!rgba)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory for %ux%u pixels", name, info->width,
                             info->height);
    gdr_status status = info->format == GDR_IO_IMAGE_PNG ? gdr_io_png_decode(data, size, name, info, rgba, err)
                                                          : gdr_io_jpeg_decode(data, size, name, info, rgba, err);
    if (status != GDR_OK) {
        free(rgba);
        return status;
    }
    *out_rgba = rgba;
    return GDR_OK;
}

gdr_status gdr_image_decode(const void *data, size_t size, const char *name, uint8_t **out_rgba,
                            uint32_t *out_width, uint32_t *out_height, gdr_error *err)
{
    *out_rgba = NULL;
    gdr_io_image_info info;
    gdr_status status = gdr_io_image_probe(data, size, name, &info, err);
    if (status == GDR_OK && info.work_bytes > GDR_DEFAULT_MAX_DECODED_BYTES)
        status = gdr_error_set(err, GDR_ERROR_CAPACITY, "%s: decoding would need %llu bytes besides the pixels "
                               "(more than %llu)", name, (unsigned long long)info.work_bytes,
                               (unsigned long long)GDR_DEFAULT_MAX_DECODED_BYTES);
    if (status == GDR_OK)
        status = gdr_io_image_decode(data, size, name, &info, out_rgba, err);
    if (status != GDR_OK)
        return status;
    *out_width = info.width;
    *out_height = info.height;
    return GDR_OK;
}
