/* PNG through libpng: rows are inflated and converted one at a time straight into the RGBA8
 * result, so memory is the result plus a few rows whatever the file's bit depth, and inflating stops
 * when the last row is complete (data beyond it is never inflated). */
#include <setjmp.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <png.h>

#include "io/image_decoders.h"

/* Largest ancillary chunk libpng may allocate for (they are skipped unread, but a chunk's length is
 * checked against this first), and how many it may keep. */
#define PNG_CHUNK_MAX (1u << 20)
#define PNG_CHUNK_CACHE_MAX 128u

static uint32_t read_be32(const uint8_t *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/* Bit depths the PNG specification allows for each colour type. */
static bool valid_depth(uint8_t color_type, uint8_t depth)
{
    switch (color_type) {
    case 0: return depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16;
    case 3: return depth == 1 || depth == 2 || depth == 4 || depth == 8;
    case 2: case 4: case 6: return depth == 8 || depth == 16;
    default: return false;
    }
}

gdr_status gdr_io_png_probe(const uint8_t *data, size_t size, const char *name, gdr_io_image_info *info,
                            gdr_error *err)
{
    /* The signature (8 bytes), then IHDR: length 13, type, width, height, depth, colour type,
     * compression, filter, interlace, CRC (checked by libpng when decoding). */
    if (size < 8 + 25 || read_be32(data + 8) != 13 || memcmp(data + 12, "IHDR", 4) != 0)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: PNG: the file does not start with an IHDR chunk", name);
    const uint8_t *ihdr = data + 16;
    uint32_t width = read_be32(ihdr), height = read_be32(ihdr + 4);
    uint8_t depth = ihdr[8], color_type = ihdr[9];
    if (width == 0 || height == 0 || width > GDR_IO_IMAGE_MAX_SIDE || height > GDR_IO_IMAGE_MAX_SIDE)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: PNG: image size %ux%u is out of range (1..%u)", name,
                             width, height, GDR_IO_IMAGE_MAX_SIDE);
    if (!valid_depth(color_type, depth) || ihdr[10] != 0 || ihdr[11] != 0 || ihdr[12] > 1)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: PNG: IHDR: colour type %u, bit depth %u, compression %u, "
                             "filter %u, interlace %u is not a valid combination", name, color_type, depth, ihdr[10],
                             ihdr[11], ihdr[12]);
    /* libpng keeps the current and previous row at up to 8 bytes a pixel (16-bit RGBA), and one
     * ancillary chunk at most. */
    *info = (gdr_io_image_info){.format = GDR_IO_IMAGE_PNG, .width = width, .height = height,
                                .work_bytes = 2 * (8 * (uint64_t)width + 1) + PNG_CHUNK_MAX};
    return GDR_OK;
}

/* libpng's progressive reader, given the whole file at once: it inflates IDAT data only as long as
 * rows are missing and stops at the first byte of output beyond the last row, so a short image
 * with gigabytes of compressed data behind it costs one row, not the whole stream (libpng's
 * sequential reader inflates the rest to find the stream's end). */
typedef struct png_reader {
    png_bytep *rows;
    uint32_t width, height;
    bool ended; /* IEND reached: every row was complete before it */
    char message[200];
} png_reader;

static void on_error(png_structp png, png_const_charp message)
{
    png_reader *r = png_get_error_ptr(png);
    snprintf(r->message, sizeof r->message, "%s", message);
    png_longjmp(png, 1);
}

static void on_warning(png_structp png, png_const_charp message)
{
    (void)png; /* warnings (a damaged ancillary chunk, dropped; extra data after the rows) leave */
    (void)message; /* the pixels as they are */
}

/* After IHDR and the chunks before the image data: limits and transformations. Every colour type
 * and depth becomes 8-bit RGBA (16-bit keeps the high byte, as stb_image did; no gamma or
 * colour-space change: glTF ignores those chunks). */
static void on_info(png_structp png, png_infop info)
{
    png_reader *r = png_get_progressive_ptr(png);
    png_set_expand(png);
    png_set_strip_16(png);
    png_set_gray_to_rgb(png);
    png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    if (png_get_image_width(png, info) != r->width || png_get_image_height(png, info) != r->height ||
        png_get_rowbytes(png, info) != (size_t)r->width * 4)
        png_error(png, "the decoder's rows are not the header's size in RGBA");
}

/* One row of one pass (interlaced images come in seven passes, combined into the same rows). */
static void on_row(png_structp png, png_bytep row, png_uint_32 y, int pass)
{
    (void)pass;
    png_reader *r = png_get_progressive_ptr(png);
    if (row && y < r->height)
        png_progressive_combine_row(png, r->rows[y], row);
}

static void on_end(png_structp png, png_infop info)
{
    (void)info;
    ((png_reader *)png_get_progressive_ptr(png))->ended = true;
}

/* The decoding between setjmp and the end: returns false on a libpng error (r->message says it). */
static bool decode_rows(png_structp png, png_infop png_info, const uint8_t *data, size_t size, png_reader *r)
{
    if (setjmp(png_jmpbuf(png)))
        return false;
    png_set_user_limits(png, GDR_IO_IMAGE_MAX_SIDE, GDR_IO_IMAGE_MAX_SIDE);
    png_set_chunk_malloc_max(png, PNG_CHUNK_MAX);
    png_set_chunk_cache_max(png, PNG_CHUNK_CACHE_MAX);
    png_set_keep_unknown_chunks(png, PNG_HANDLE_CHUNK_NEVER, NULL, -1); /* all but IHDR PLTE tRNS IDAT IEND */
    png_set_progressive_read_fn(png, r, on_info, on_row, on_end);
    png_process_data(png, png_info, (png_bytep)data, size);
    if (!r->ended)
        snprintf(r->message, sizeof r->message, "the file ends before its IEND chunk (truncated)");
    return r->ended;
}

gdr_status gdr_io_png_decode(const uint8_t *data, size_t size, const char *name, const gdr_io_image_info *info,
                             uint8_t *rgba, gdr_error *err)
{
    png_reader r = {.width = info->width, .height = info->height};
    r.rows = malloc((size_t)info->height * sizeof *r.rows);
    png_structp png = r.rows ? png_create_read_struct(PNG_LIBPNG_VER_STRING, &r, on_error, on_warning) : NULL;
    png_infop png_info = png ? png_create_info_struct(png) : NULL;
    if (!png_info) {
        png_destroy_read_struct(png ? &png : NULL, NULL, NULL);
        free(r.rows);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: PNG: out of memory", name);
    }
    for (uint32_t y = 0; y < info->height; y++)
        r.rows[y] = rgba + (size_t)y * info->width * 4;
    bool decoded = decode_rows(png, png_info, data, size, &r);
    png_destroy_read_struct(&png, &png_info, NULL);
    free(r.rows);
    if (!decoded)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: PNG: %s", name, r.message[0] ? r.message : "decoding failed");
    return GDR_OK;
}
