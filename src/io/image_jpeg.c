/* JPEG through libjpeg-turbo, bounded: the scans a file may hold (a progress hook counts them as
 * they are read) and the memory the decoder may take for a multi-scan image's coefficients
 * (max_memory_to_use: beyond it libjpeg would need a backing store, which Debian's build refuses). */
#include <setjmp.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include <jpeglib.h>
#include <jerror.h>

#include "io/image_decoders.h"

/* libjpeg's error manager, extended with where to jump and the status and message to report. */
typedef struct jpeg_reader {
    struct jpeg_error_mgr pub;
    struct jpeg_progress_mgr progress;
    jmp_buf jump;
    gdr_status status; /* GDR_ERROR_PARSE but for gdr's own limits */
    char message[JMSG_LENGTH_MAX + 64];
} jpeg_reader;

static void on_error_exit(j_common_ptr cinfo)
{
    jpeg_reader *r = (jpeg_reader *)cinfo->err;
    if (cinfo->err->msg_code == JERR_NO_BACKING_STORE) {
        r->status = GDR_ERROR_CAPACITY; /* the memory gdr allows the decoder, not the machine's */
        snprintf(r->message, sizeof r->message, "decoding needs more memory than counted for the image");
    } else {
        cinfo->err->format_message(cinfo, r->message);
    }
    longjmp(r->jump, 1);
}

/* Warnings: a file that ends early is an error (the missing part would be grey); other corrupt-data
 * warnings leave defined pixels and are not reported. Trace messages are dropped. */
static void on_message(j_common_ptr cinfo, int level)
{
    if (level < 0 && cinfo->err->msg_code == JWRN_JPEG_EOF) {
        jpeg_reader *r = (jpeg_reader *)cinfo->err;
        snprintf(r->message, sizeof r->message, "the file ends before the image data does (truncated)");
        longjmp(r->jump, 1);
    }
}

/* Called between every row of blocks as the scans are read: stops at the first scan past the limit. */
static void on_progress(j_common_ptr cinfo)
{
    j_decompress_ptr d = (j_decompress_ptr)cinfo;
    if (d->input_scan_number > GDR_IO_JPEG_MAX_SCANS) {
        jpeg_reader *r = (jpeg_reader *)cinfo->err;
        r->status = GDR_ERROR_UNSUPPORTED; /* a limit of gdr's, as the image size is */
        snprintf(r->message, sizeof r->message, "more than %d scans", GDR_IO_JPEG_MAX_SCANS);
        longjmp(r->jump, 1);
    }
}

static void reader_init(j_decompress_ptr cinfo, jpeg_reader *r, const uint8_t *data, size_t size)
{
    cinfo->err = jpeg_std_error(&r->pub);
    r->pub.error_exit = on_error_exit;
    r->pub.emit_message = on_message;
    r->status = GDR_ERROR_PARSE;
    r->message[0] = 0;
    jpeg_create_decompress(cinfo);
    r->progress.progress_monitor = on_progress;
    cinfo->progress = &r->progress;
    jpeg_mem_src(cinfo, data, (unsigned long)size);
}

/* The decoder's memory besides the result: a multi-scan (progressive) image keeps every block's
 * coefficients (64 of 2 bytes, per component, rounded up to whole MCUs as libjpeg allocates them);
 * rows and tables take a few rows of the image's width at most. */
static uint64_t work_bytes(j_decompress_ptr cinfo)
{
    uint64_t bytes = (4u << 20) + (uint64_t)cinfo->image_width * (uint64_t)cinfo->num_components * 64;
    if (!jpeg_has_multiple_scans(cinfo))
        return bytes;
    for (int i = 0; i < cinfo->num_components; i++) {
        const jpeg_component_info *c = &cinfo->comp_info[i];
        uint64_t h = (uint64_t)c->h_samp_factor, v = (uint64_t)c->v_samp_factor;
        uint64_t across = (c->width_in_blocks + h - 1) / h * h, down = (c->height_in_blocks + v - 1) / v * v;
        bytes += across * down * sizeof(JBLOCK);
    }
    return bytes;
}

/* The header part of the probe, between setjmp and the end: false on a libjpeg error. */
static bool read_header(j_decompress_ptr cinfo, jpeg_reader *r)
{
    if (setjmp(r->jump))
        return false;
    jpeg_read_header(cinfo, TRUE);
    return true;
}

gdr_status gdr_io_jpeg_probe(const uint8_t *data, size_t size, const char *name, gdr_io_image_info *info,
                             gdr_error *err)
{
    struct jpeg_decompress_struct cinfo;
    jpeg_reader r;
    reader_init(&cinfo, &r, data, size);
    gdr_status status = GDR_OK;
    if (!read_header(&cinfo, &r))
        status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: JPEG: %s", name, r.message);
    else if (cinfo.image_width > GDR_IO_IMAGE_MAX_SIDE || cinfo.image_height > GDR_IO_IMAGE_MAX_SIDE ||
             cinfo.image_width == 0 || cinfo.image_height == 0)
        status = gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: JPEG: image size %ux%u is out of range (1..%u)", name,
                               cinfo.image_width, cinfo.image_height, GDR_IO_IMAGE_MAX_SIDE);
    else
        *info = (gdr_io_image_info){.format = GDR_IO_IMAGE_JPEG, .width = cinfo.image_width,
                                    .height = cinfo.image_height, .work_bytes = work_bytes(&cinfo)};
    jpeg_destroy_decompress(&cinfo);
    return status;
}

/* Adobe's CMYK (and YCCK, which libjpeg turns into it) is stored inverted: a channel times black. */
static void cmyk_to_rgba(uint8_t *row, uint32_t width)
{
    for (uint32_t x = 0; x < width; x++) {
        uint8_t *p = row + 4 * (size_t)x;
        unsigned k = p[3];
        for (int c = 0; c < 3; c++) {
            unsigned t = p[c] * k + 128;
            p[c] = (uint8_t)((t + (t >> 8)) >> 8);
        }
        p[3] = 255;
    }
}

/* The decoding between setjmp and the end: false on a libjpeg error (r->message says it). */
static bool decode_rows(j_decompress_ptr cinfo, jpeg_reader *r, const gdr_io_image_info *info, uint8_t *rgba)
{
    if (setjmp(r->jump))
        return false;
    jpeg_read_header(cinfo, TRUE);
    bool cmyk = cinfo->jpeg_color_space == JCS_CMYK || cinfo->jpeg_color_space == JCS_YCCK;
    cinfo->out_color_space = cmyk ? JCS_CMYK : JCS_EXT_RGBA;
    cinfo->mem->max_memory_to_use = (long)info->work_bytes;
    jpeg_start_decompress(cinfo);
    if (cinfo->output_width != info->width || cinfo->output_height != info->height ||
        cinfo->output_components != 4) {
        snprintf(r->message, sizeof r->message, "the decoder's rows are not %ux%u RGBA", info->width, info->height);
        return false;
    }
    while (cinfo->output_scanline < cinfo->output_height) {
        uint8_t *row = rgba + (size_t)cinfo->output_scanline * info->width * 4;
        jpeg_read_scanlines(cinfo, &row, 1);
        if (cmyk)
            cmyk_to_rgba(row, info->width);
    }
    return true;
}

gdr_status gdr_io_jpeg_decode(const uint8_t *data, size_t size, const char *name, const gdr_io_image_info *info,
                              uint8_t *rgba, gdr_error *err)
{
    struct jpeg_decompress_struct cinfo;
    jpeg_reader r;
    reader_init(&cinfo, &r, data, size);
    bool decoded = decode_rows(&cinfo, &r, info, rgba);
    jpeg_destroy_decompress(&cinfo); /* also after an error: it frees whatever was allocated */
    if (!decoded)
        return gdr_error_set(err, r.status, "%s: JPEG: %s", name, r.message);
    return GDR_OK;
}
