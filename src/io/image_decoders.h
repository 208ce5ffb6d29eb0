/* The two image decoders behind image.c: each reads its format's headers (probe) and decodes
 * into a caller's RGBA8 buffer of width x height x 4 bytes, within the limits the probe counted. */
#ifndef GDR_IO_IMAGE_DECODERS_H
#define GDR_IO_IMAGE_DECODERS_H

#include <stddef.h>
#include <stdint.h>

#include "io/io_internal.h"

gdr_status gdr_io_png_probe(const uint8_t *data, size_t size, const char *name, gdr_io_image_info *info,
                            gdr_error *err);
gdr_status gdr_io_png_decode(const uint8_t *data, size_t size, const char *name, const gdr_io_image_info *info,
                             uint8_t *rgba, gdr_error *err);

/* More scans than any real progressive JPEG has (libjpeg's own progressions have 6 to 10, tuned
 * encoders some 20). Each scan visits every block of its components, even an empty one: 64 empty
 * scans of an 8192 x 8192 image cost about what decoding a real one does (docs/SECURITY.md). */
#define GDR_IO_JPEG_MAX_SCANS 64

gdr_status gdr_io_jpeg_probe(const uint8_t *data, size_t size, const char *name, gdr_io_image_info *info,
                             gdr_error *err);
gdr_status gdr_io_jpeg_decode(const uint8_t *data, size_t size, const char *name, const gdr_io_image_info *info,
                              uint8_t *rgba, gdr_error *err);

#endif
