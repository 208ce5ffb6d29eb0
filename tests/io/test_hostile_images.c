/* Hostile images (docs/SECURITY.md): files made here that once made the decoder allocate
 * gigabytes, work for minutes or decode formats glTF does not allow (one of them into
 * uninitialised memory). The costly cases run in a child process under an alarm, which measures
 * its own peak memory: a regression fails by the bound, not by exhausting the machine. */
#define _GNU_SOURCE
#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <jpeglib.h>
#include <zlib.h>

#include "gdr/io.h"
#include "io/io_internal.h"
#include "io/io_test_helpers.h"
#include "test_util.h"

static test_warnings warnings;
static gdr_error err;
static char dir[1024];

/* --- a growable buffer and PNG files ----------------------------------------------------------- */

typedef struct bytes {
    uint8_t *data;
    size_t size, capacity;
} bytes;

static void put(bytes *b, const void *data, size_t size)
{
    if (size == 0)
        return;
    if (b->size + size > b->capacity) {
        b->capacity = (b->size + size) * 2;
        b->data = realloc(b->data, b->capacity);
    }
    memcpy(b->data + b->size, data, size);
    b->size += size;
}

static void put_be32(bytes *b, uint32_t v)
{
    uint8_t p[4] = {(uint8_t)(v >> 24), (uint8_t)(v >> 16), (uint8_t)(v >> 8), (uint8_t)v};
    put(b, p, 4);
}

static void put_chunk(bytes *b, const char *type, const uint8_t *data, size_t size)
{
    put_be32(b, (uint32_t)size);
    size_t start = b->size;
    put(b, type, 4);
    put(b, data, size);
    put_be32(b, (uint32_t)crc32(0, b->data + start, (uInt)(size + 4)));
}

/* A PNG of the given header around `stream` (a zlib stream), in IDAT chunks of 64 KiB. */
static bytes png_file(uint32_t width, uint32_t height, uint8_t depth, uint8_t color_type, uint8_t interlace,
                      const uint8_t *palette, size_t palette_size, const bytes *stream)
{
    static const uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    bytes b = {0};
    put(&b, signature, 8);
    uint8_t ihdr[13] = {(uint8_t)(width >> 24), (uint8_t)(width >> 16), (uint8_t)(width >> 8), (uint8_t)width,
                        (uint8_t)(height >> 24), (uint8_t)(height >> 16), (uint8_t)(height >> 8), (uint8_t)height,
                        depth, color_type, 0, 0, interlace};
    put_chunk(&b, "IHDR", ihdr, sizeof ihdr);
    if (palette)
        put_chunk(&b, "PLTE", palette, palette_size);
    for (size_t at = 0; at < stream->size; at += 65536)
        put_chunk(&b, "IDAT", stream->data + at, stream->size - at < 65536 ? stream->size - at : 65536);
    put_chunk(&b, "IEND", NULL, 0);
    return b;
}

/* `rows` rows of `row_bytes` bytes each from make_row (the filter byte, 0, comes first), deflated
 * row by row so that the raw image never exists whole. */
static bytes deflate_rows(uint32_t rows, size_t row_bytes, void (*make_row)(uint32_t y, uint8_t *row))
{
    bytes out = {0};
    z_stream z = {0};
    deflateInit(&z, 6);
    uint8_t *row = calloc(1, row_bytes + 1), chunk[65536];
    for (uint32_t y = 0; y < rows; y++) {
        make_row(y, row + 1);
        z.next_in = row;
        z.avail_in = (uInt)(row_bytes + 1);
        int flush = y + 1 == rows ? Z_FINISH : Z_NO_FLUSH, ret;
        do {
            z.next_out = chunk;
            z.avail_out = sizeof chunk;
            ret = deflate(&z, flush);
            put(&out, chunk, sizeof chunk - z.avail_out);
        } while (z.avail_out == 0 || (flush == Z_FINISH && ret != Z_STREAM_END));
    }
    deflateEnd(&z);
    free(row);
    return out;
}

/* A zlib stream of `total` zero bytes (a multiple of 1 MiB) made without deflating them all: after
 * a full flush, deflating another MiB of zeros gives the same bytes, so they are repeated. Its
 * Adler-32 is left wrong, as a hostile file's may be. */
static bytes zero_stream(size_t total)
{
    enum { MIB = 1 << 20 };
    uint8_t *zeros = calloc(1, MIB), chunk[65536];
    bytes first = {0}, again = {0}, out = {0};
    z_stream z = {0};
    deflateInit(&z, 9);
    for (int pass = 0; pass < 3; pass++) {
        bytes *into = pass == 0 ? &first : pass == 1 ? &again : &out;
        z.next_in = zeros;
        z.avail_in = pass < 2 ? MIB : 0;
        do {
            z.next_out = chunk;
            z.avail_out = sizeof chunk;
            deflate(&z, pass < 2 ? Z_FULL_FLUSH : Z_FINISH);
            put(into, chunk, sizeof chunk - z.avail_out);
        } while (z.avail_out == 0);
    }
    deflateEnd(&z);
    bytes stream = {0};
    put(&stream, first.data, first.size);
    for (size_t i = 1; i < total / MIB; i++)
        put(&stream, again.data, again.size);
    put(&stream, out.data, out.size);
    free(zeros), free(first.data), free(again.data), free(out.data);
    return stream;
}

/* --- JPEG files -------------------------------------------------------------------------------- */

/* A JPEG of width x height from libjpeg: colour (0: grey, 3: RGB, 4: CMYK), progressive or not.
 * Pixels: x, y, (x + y) / 2 and 200, in the channels there are. */
static bytes jpeg_file(uint32_t width, uint32_t height, int channels, bool progressive)
{
    struct jpeg_compress_struct c;
    struct jpeg_error_mgr e;
    c.err = jpeg_std_error(&e);
    jpeg_create_compress(&c);
    unsigned char *out = NULL;
    unsigned long size = 0;
    jpeg_mem_dest(&c, &out, &size);
    c.image_width = width;
    c.image_height = height;
    c.input_components = channels ? channels : 1;
    c.in_color_space = channels == 0 ? JCS_GRAYSCALE : channels == 3 ? JCS_RGB : JCS_CMYK;
    jpeg_set_defaults(&c);
    jpeg_set_quality(&c, 100, TRUE);
    if (progressive)
        jpeg_simple_progression(&c);
    jpeg_start_compress(&c, TRUE);
    uint8_t *row = malloc((size_t)width * 4);
    while (c.next_scanline < height) {
        uint32_t y = c.next_scanline;
        for (uint32_t x = 0; x < width; x++) {
            uint8_t v[4] = {(uint8_t)x, (uint8_t)y, (uint8_t)((x + y) / 2), 200};
            memcpy(row + (size_t)x * (size_t)c.input_components, v, (size_t)c.input_components);
        }
        jpeg_write_scanlines(&c, &row, 1);
    }
    jpeg_finish_compress(&c);
    jpeg_destroy_compress(&c);
    free(row);
    bytes b = {0};
    put(&b, out, size);
    free(out);
    return b;
}

/* A progressive grey JPEG of side x side whose scans carry no data: a DC scan, then `refinements`
 * DC refinement scans of 10 bytes each. Every scan still visits every block. */
static bytes empty_scans_jpeg(uint32_t side, uint32_t refinements)
{
    static const uint8_t dc_scan[10] = {0xff, 0xda, 0, 8, 1, 1, 0, 0, 0, 0x00};
    static const uint8_t refine_scan[10] = {0xff, 0xda, 0, 8, 1, 1, 0, 0, 0, 0x10};
    bytes b = {0};
    put(&b, "\xff\xd8\xff\xdb\x00\x43\x00", 7);
    for (int i = 0; i < 64; i++)
        put(&b, "\x01", 1);
    uint8_t sof[13] = {0xff, 0xc2, 0, 11, 8, (uint8_t)(side >> 8), (uint8_t)side, (uint8_t)(side >> 8),
                       (uint8_t)side, 1, 1, 0x11, 0};
    put(&b, sof, sizeof sof);
    uint8_t dht[22] = {0xff, 0xc4, 0, 20, 0x00, 1}; /* one DC code, of length 1, for difference 0 */
    put(&b, dht, sizeof dht);
    put(&b, dc_scan, sizeof dc_scan);
    for (uint32_t i = 0; i < refinements; i++)
        put(&b, refine_scan, sizeof refine_scan);
    put(&b, "\xff\xd9", 2);
    return b;
}

/* --- running a case in a child ----------------------------------------------------------------- */

/* Runs fn(arg) in a child under an alarm of `seconds`; the child's peak memory beyond what it had
 * at the start goes to *grown_kib. True when fn returned true in time. */
static bool in_child(bool (*fn)(const void *arg), const void *arg, unsigned seconds, long *grown_kib)
{
    int pipe_fd[2];
    if (pipe(pipe_fd) != 0)
        return false;
    pid_t pid = fork();
    if (pid == 0) {
        close(pipe_fd[0]);
        struct rusage before, after;
        getrusage(RUSAGE_SELF, &before);
        alarm(seconds);
        bool ok = fn(arg);
        getrusage(RUSAGE_SELF, &after);
        long grown = after.ru_maxrss - before.ru_maxrss;
        if (write(pipe_fd[1], &grown, sizeof grown) != (ssize_t)sizeof grown)
            ok = false;
        _exit(ok ? 0 : 1);
    }
    close(pipe_fd[1]);
    *grown_kib = -1;
    if (read(pipe_fd[0], grown_kib, sizeof *grown_kib) != (ssize_t)sizeof *grown_kib)
        *grown_kib = -1;
    close(pipe_fd[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (WIFSIGNALED(status))
        fprintf(stderr, "child: signal %d%s\n", WTERMSIG(status),
                WTERMSIG(status) == SIGALRM ? " (took longer than its alarm)" : "");
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

/* gdr_image_decode of a `bytes`, expecting width x height (0 x 0: a refusal with `status`). */
typedef struct decode_case {
    const bytes *file;
    uint32_t width, height;
    gdr_status status;
} decode_case;

static bool decode_as_expected(const void *arg)
{
    const decode_case *d = arg;
    uint8_t *rgba = NULL;
    uint32_t w = 0, h = 0;
    gdr_error e = {0};
    gdr_status status = gdr_image_decode(d->file->data, d->file->size, "hostile", &rgba, &w, &h, &e);
    free(rgba);
    if (d->width == 0) {
        if (status != d->status || e.status != d->status)
            fprintf(stderr, "expected a refusal with %s, got %s: %s\n", gdr_status_name(d->status),
                    gdr_status_name(status), e.message);
        return status == d->status && e.status == d->status;
    }
    if (status != GDR_OK || w != d->width || h != d->height)
        fprintf(stderr, "expected %ux%u, got %d (%ux%u): %s\n", d->width, d->height, status, w, h, e.message);
    return status == GDR_OK && w == d->width && h == d->height;
}

/* --- the cases ---------------------------------------------------------------------------------- */

/* A 1 x 1 PNG whose data inflates to 512 MiB (from 512 kB): the image needs 5 bytes of it.
 * stb_image inflated all of it (a 2 GiB one took 13 s and 2.1 GB). */
static void test_png_inflate_bomb(void)
{
    bytes stream = zero_stream((size_t)512 << 20);
    bytes png = png_file(1, 1, 8, 6, 0, NULL, 0, &stream);
    decode_case d = {&png, 1, 1, GDR_OK};
    long grown = 0;
    CHECK(in_child(decode_as_expected, &d, 10, &grown));
    printf("PNG, 1x1, data inflating to 512 MiB (%zu bytes): peak grew %ld KiB\n", png.size, grown);
    CHECK(grown >= 0 && grown < 32 * 1024);
    free(stream.data), free(png.data);
}

static void deep_row(uint32_t y, uint8_t *row)
{
    for (uint32_t x = 0; x < 2048; x++) {
        uint8_t px[8] = {(uint8_t)x, 0xab, (uint8_t)y, 0xcd, 0x80, 0x00, 0xff, 0xff};
        memcpy(row + 8 * (size_t)x, px, 8);
    }
}

static bool deep_png_pixels(const void *arg)
{
    const bytes *png = arg;
    uint8_t *rgba = NULL;
    uint32_t w = 0, h = 0;
    gdr_error e = {0};
    if (gdr_image_decode(png->data, png->size, "deep.png", &rgba, &w, &h, &e) != GDR_OK || w != 2048 || h != 1024)
        return false;
    /* 16-bit channels keep their high byte. */
    const uint8_t *p = rgba + ((size_t)700 * 2048 + 300) * 4;
    bool ok = p[0] == (uint8_t)300 && p[1] == (uint8_t)700 && p[2] == 0x80 && p[3] == 0xff;
    free(rgba);
    return ok;
}

/* A 16-bit RGBA PNG of 2048 x 1024: stb_image held the inflated data, a 16-bit copy and an 8-bit one
 * (48 MiB besides the 8 MiB result; a 1 MB file of 16384 x 8192 peaked at 2.1 GB). Now rows are
 * converted as they are inflated: the result and a few rows. And in a glTF, the decoded bytes
 * budget counts the result, the mip chain and the decoder's rows. */
static void test_png_16_bit(void)
{
    bytes stream = deflate_rows(1024, 2048 * 8, deep_row);
    bytes png = png_file(2048, 1024, 16, 6, 0, NULL, 0, &stream);
    long grown = 0;
    CHECK(in_child(deep_png_pixels, &png, 20, &grown));
    printf("PNG, 2048x1024 16-bit RGBA (%zu bytes): peak grew %ld KiB (the result is 8192 KiB)\n", png.size, grown);
    CHECK(grown >= 0 && grown < 20 * 1024);

    char path[1200], gltf[1200];
    snprintf(path, sizeof path, "%s/deep.png", dir);
    snprintf(gltf, sizeof gltf, "%s/deep.gltf", dir);
    const char *text = "{\"asset\":{\"version\":\"2.0\"},\"images\":[{\"uri\":\"deep.png\"}],\"textures\":[{\"source\":0}],"
                       "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]}";
    CHECK(test_write_file(path, png.data, png.size) && test_write_file(gltf, text, strlen(text)));
    gdr_import_options o = {.warning = test_collect_warning, .warning_user = &warnings, .no_progress = 1,
                            .budget = {.decoded_bytes = 16u << 20}};
    gdr_scene *s = NULL;
    /* 2048 x 1024: 8 MiB of pixels, 10.7 MiB with its mip chain; 16 MiB is not enough. */
    CHECK_FAILS(gdr_import_gltf(gltf, &o, &s, NULL, &err), err, GDR_ERROR_BUDGET);
    CHECK(!s);
    CHECK_NAMES(err, "deep.gltf: images[0] (deep.png): ");
    CHECK_NAMES(err, "--budget bytes=N");
    o.budget.decoded_bytes = 24u << 20;
    CHECK(gdr_import_gltf(gltf, &o, &s, NULL, &err) == GDR_OK && s && s->texture_count == 1);
    gdr_scene_destroy(s);
    free(stream.data), free(png.data);
}

/* Palette, 1-bit grey and interlaced PNGs take libpng's transformations and its interlace passes. */
static void grey1_row(uint32_t y, uint8_t *row) { row[0] = y & 1 ? 0x55 : 0xaa; }
static void palette_row(uint32_t y, uint8_t *row) { for (int x = 0; x < 4; x++) row[x] = (uint8_t)((x + y) % 3); }
static void rgb_row(uint32_t y, uint8_t *row)
{
    for (uint32_t x = 0; x < 9; x++)
        row[3 * x] = (uint8_t)(10 * x), row[3 * x + 1] = (uint8_t)(10 * y), row[3 * x + 2] = 7;
}

static void test_png_kinds(void)
{
    uint8_t *rgba = NULL;
    uint32_t w, h;
    bytes stream = deflate_rows(2, 1, grey1_row), png = png_file(8, 2, 1, 0, 0, NULL, 0, &stream);
    CHECK(gdr_image_decode(png.data, png.size, "grey1.png", &rgba, &w, &h, &err) == GDR_OK && w == 8 && h == 2 &&
          rgba[0] == 255 && rgba[4] == 0 && rgba[8 * 4] == 0 && rgba[8 * 4 + 4] == 255 && rgba[3] == 255);
    free(rgba), free(stream.data), free(png.data);
    static const uint8_t palette[9] = {255, 0, 0, 0, 255, 0, 0, 0, 255};
    stream = deflate_rows(3, 4, palette_row), png = png_file(4, 3, 8, 3, 0, palette, sizeof palette, &stream);
    CHECK(gdr_image_decode(png.data, png.size, "palette.png", &rgba, &w, &h, &err) == GDR_OK && w == 4 && h == 3 &&
          rgba[0] == 255 && rgba[4 + 1] == 255 && rgba[(4 + 1) * 4] == 0 && rgba[(4 + 1) * 4 + 2] == 255);
    free(rgba), free(stream.data), free(png.data);
    /* The same 9 x 9 pixels, plain and interlaced (Adam7: seven passes of sub-images, rows combined
     * by libpng's progressive reader), decode alike. */
    stream = deflate_rows(9, 27, rgb_row), png = png_file(9, 9, 8, 2, 0, NULL, 0, &stream);
    uint8_t *plain = NULL;
    CHECK(gdr_image_decode(png.data, png.size, "rgb.png", &plain, &w, &h, &err) == GDR_OK && w == 9 && h == 9 &&
          plain[(4 * 9 + 5) * 4] == 50 && plain[(4 * 9 + 5) * 4 + 1] == 40 && plain[(4 * 9 + 5) * 4 + 3] == 255);
    free(stream.data), free(png.data);
    static const uint8_t adam7[7][4] = {{0, 0, 8, 8}, {4, 0, 8, 8}, {0, 4, 4, 8}, {2, 0, 4, 4},
                                        {0, 2, 2, 4}, {1, 0, 2, 2}, {0, 1, 1, 2}};
    uint8_t raw[1024];
    size_t n = 0;
    for (int pass = 0; pass < 7; pass++)
        for (uint32_t y = adam7[pass][1]; y < 9; y += adam7[pass][3]) {
            raw[n++] = 0;
            for (uint32_t x = adam7[pass][0]; x < 9; x += adam7[pass][2])
                raw[n++] = (uint8_t)(10 * x), raw[n++] = (uint8_t)(10 * y), raw[n++] = 7;
        }
    uLongf packed_size = compressBound(n);
    stream = (bytes){.data = malloc(packed_size)};
    CHECK(compress(stream.data, &packed_size, raw, n) == Z_OK);
    stream.size = packed_size;
    png = png_file(9, 9, 8, 2, 1, NULL, 0, &stream);
    CHECK(gdr_image_decode(png.data, png.size, "adam7.png", &rgba, &w, &h, &err) == GDR_OK && w == 9 && h == 9 &&
          plain && memcmp(rgba, plain, 9 * 9 * 4) == 0);
    free(plain);
    free(rgba), free(stream.data), free(png.data);
}

/* A progressive JPEG with 12,000 empty scans of a 4096 x 4096 image (120 kB): stb_image decoded
 * every scan over every block (an 8192^2 one took 164 s). Now the 65th scan is refused. */
static void test_jpeg_scans(void)
{
    bytes jpeg = empty_scans_jpeg(4096, 12000);
    decode_case d = {&jpeg, 0, 0, GDR_ERROR_UNSUPPORTED}; /* the only limit a file of scans meets */
    long grown = 0;
    CHECK(in_child(decode_as_expected, &d, 10, &grown));
    printf("JPEG, 4096x4096, 12,001 scans (%zu bytes): peak grew %ld KiB\n", jpeg.size, grown);
    free(jpeg.data);
    /* 64 scans are decoded: every block's DC is 0, mid-grey. */
    jpeg = empty_scans_jpeg(64, 63);
    uint8_t *rgba = NULL;
    uint32_t w, h;
    CHECK(gdr_image_decode(jpeg.data, jpeg.size, "64.jpg", &rgba, &w, &h, &err) == GDR_OK && w == 64 && h == 64 &&
          rgba[0] == 128 && rgba[1] == 128 && rgba[3] == 255);
    free(rgba), free(jpeg.data);
}

/* Real JPEGs: grey, RGB (baseline and progressive) and Adobe CMYK decode to the pixels written. */
static void test_jpeg_kinds(void)
{
    const struct { int channels; bool progressive; } kinds[] = {{0, false}, {3, false}, {3, true}, {4, true}};
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
        bytes jpeg = jpeg_file(64, 48, kinds[k].channels, kinds[k].progressive);
        uint8_t *rgba = NULL;
        uint32_t w = 0, h = 0;
        CHECK(gdr_image_decode(jpeg.data, jpeg.size, "kind.jpg", &rgba, &w, &h, &err) == GDR_OK && w == 64 && h == 48);
        if (rgba) {
            const uint8_t *p = rgba + ((size_t)30 * 64 + 40) * 4; /* x 40, y 30 */
            int c = kinds[k].channels;
            /* CMYK: channel times black (200 / 255). */
            int r = c == 4 ? 40 * 200 / 255 : 40, g = c == 0 ? 40 : c == 4 ? 30 * 200 / 255 : 30;
            CHECK_NEAR(p[0], r, 6);
            CHECK_NEAR(p[1], g, 6);
            CHECK(p[3] == 255);
        }
        free(rgba), free(jpeg.data);
    }
}

/* A progressive JPEG keeps every block's coefficients while its scans are read: that memory is
 * counted (gdr_io_image_info.work_bytes), enforced (libjpeg's max_memory_to_use), and charged to
 * the decoded bytes budget in a glTF. */
static void test_jpeg_memory(void)
{
    bytes jpeg = jpeg_file(1024, 1024, 3, true);
    gdr_io_image_info info;
    CHECK(gdr_io_image_probe(jpeg.data, jpeg.size, "p.jpg", &info, &err) == GDR_OK && info.width == 1024 &&
          info.work_bytes >= 3ull * 1024 * 1024 * 2);
    gdr_io_image_info tight = info;
    tight.work_bytes = 1u << 20;
    uint8_t *rgba = NULL;
    CHECK_FAILS(gdr_io_image_decode(jpeg.data, jpeg.size, "p.jpg", &tight, &rgba, &err), err, GDR_ERROR_CAPACITY);
    CHECK(!rgba);
    CHECK_NAMES(err, "p.jpg: JPEG: ");
    CHECK(gdr_io_image_decode(jpeg.data, jpeg.size, "p.jpg", &info, &rgba, &err) == GDR_OK && rgba);
    free(rgba);
    /* In a glTF: 4 MiB of pixels and 5.3 MiB with mips fit in 12 MiB, the coefficients (6 MiB) do not. */
    char path[1200], gltf[1200];
    snprintf(path, sizeof path, "%s/p.jpg", dir);
    snprintf(gltf, sizeof gltf, "%s/p.gltf", dir);
    const char *text = "{\"asset\":{\"version\":\"2.0\"},\"images\":[{\"uri\":\"p.jpg\"}],\"textures\":[{\"source\":0}],"
                       "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]}";
    CHECK(test_write_file(path, jpeg.data, jpeg.size) && test_write_file(gltf, text, strlen(text)));
    gdr_import_options o = {.no_progress = 1, .budget = {.decoded_bytes = 12u << 20}};
    gdr_scene *s = NULL;
    CHECK_FAILS(gdr_import_gltf(gltf, &o, &s, NULL, &err), err, GDR_ERROR_BUDGET);
    CHECK(!s);
    CHECK_NAMES(err, "p.gltf: images[0] (p.jpg): ");
    /* Truncated: refused, not decoded with a grey rest. */
    CHECK_FAILS(gdr_image_decode(jpeg.data, jpeg.size / 2, "cut.jpg", &rgba, &(uint32_t){0}, &(uint32_t){0}, &err),
                err, GDR_ERROR_PARSE);
    CHECK_NAMES(err, "cut.jpg: JPEG: ");
    CHECK(!rgba);
    free(jpeg.data);
}

/* Formats glTF does not allow: stb_image decoded them all, an 18-byte TGA header into uninitialised
 * memory that went into the cache. Now refused by signature, whatever the URI says. */
static void test_other_formats(void)
{
    static const uint8_t tga[18] = {0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 64, 0, 64, 0, 32, 8};
    static const uint8_t bmp[58] = {'B', 'M', 58, 0, 0, 0, 0, 0, 0, 0, 54, 0, 0, 0, 40, 0, 0, 0, 1, 0, 0, 0, 1, 0,
                                    0, 0, 1, 0, 24, 0, 0, 0, 0, 0, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
                                    0, 0, 0, 0, 1, 2, 3, 0};
    static const uint8_t gif[35] = {'G', 'I', 'F', '8', '9', 'a', 1, 0, 1, 0, 0x80, 0, 0, 0, 0, 0, 255, 255, 255,
                                    ',', 0, 0, 0, 0, 1, 0, 1, 0, 0, 2, 2, 0x44, 0x01, 0, ';'};
    static const char pnm[] = "P6\n2 1\n255\n\x01\x02\x03\x04\x05\x06";
    char hdr[256];
    int hdr_size = snprintf(hdr, sizeof hdr, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n");
    memcpy(hdr + hdr_size, "\x80\x80\x80\x81\x80\x80\x80\x81", 8);
    const struct { const void *data; size_t size; const char *message; } files[] = {
        {tga, sizeof tga, "not a PNG or JPEG image"}, {bmp, sizeof bmp, "a BMP image"},
        {gif, sizeof gif, "a GIF image"},             {pnm, sizeof pnm - 1, "a PNM image"},
        {hdr, (size_t)hdr_size + 8, "a HDR image"},
    };
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        uint8_t *rgba = NULL;
        uint32_t w, h;
        gdr_status status = gdr_image_decode(files[i].data, files[i].size, "x.png", &rgba, &w, &h, &err);
        CHECK(status == GDR_ERROR_UNSUPPORTED && !rgba);
        CHECK_NAMES(err, files[i].message); /* the format it is: what the user needs to convert it */
        free(rgba);
    }
    /* The TGA in a glTF (named .png, mimeType image/png): left out with a warning naming it. */
    char *uri = test_data_uri(tga, sizeof tga);
    char *text = malloc(strlen(uri) + 512);
    sprintf(text, "{\"asset\":{\"version\":\"2.0\"},\"images\":[{\"uri\":\"%s\",\"mimeType\":\"image/png\"}],"
                  "\"textures\":[{\"source\":0}],\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":"
                  "{\"index\":0}}}]}", uri);
    gdr_import_options o = {.warning = test_collect_warning, .warning_user = &warnings, .no_progress = 1};
    gdr_scene *s = NULL;
    memset(&warnings, 0, sizeof warnings);
    CHECK(gdr_import_gltf_memory(text, strlen(text), "tga.gltf", NULL, &o, &s, NULL, &err) == GDR_OK && s &&
          s->texture_count == 0 && warnings.count == 1 &&
          strstr(warnings.text, "tga.gltf: images[0] (a data: URI): not a PNG or JPEG image"));
    gdr_scene_destroy(s);
    free(uri), free(text);
    /* A PNG called a JPEG is decoded as the PNG it is. */
    bytes stream = deflate_rows(9, 27, rgb_row), png = png_file(9, 9, 8, 2, 0, NULL, 0, &stream);
    uint8_t *rgba = NULL;
    uint32_t w, h;
    CHECK(gdr_image_decode(png.data, png.size, "really.jpg", &rgba, &w, &h, &err) == GDR_OK && w == 9);
    free(rgba), free(stream.data), free(png.data);
}

int main(void)
{
    snprintf(dir, sizeof dir, "%s/hostile_images", GDR_IO_TEST_TMP);
    mkdir(dir, 0755);
    test_png_inflate_bomb(); /* the memory cases first, while this process is small */
    test_png_16_bit();
    test_jpeg_scans();
    test_png_kinds();
    test_jpeg_kinds();
    test_jpeg_memory();
    test_other_formats();
    return test_finish("test_hostile_images");
}
