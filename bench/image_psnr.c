/* PSNR of one image against another of the same size (PNG or JPEG, read by gdr's own decoder).
 * usage: image_psnr REFERENCE.png TEST.png
 * Prints one line of JSON:
 *   psnr          over the whole image: every pixel counts, the background too; the mean squared
 *                 error of the R, G and B channels (8-bit sRGB values as stored, alpha ignored),
 *                 10 log10(255^2 / MSE); "inf" where the images are equal;
 *   psnr_covered  the same over the pixels that differ from the background in either image (the
 *                 background colour is the reference's top-left pixel: gdr clears to one colour);
 *   covered       that share of the image's pixels (psnr = psnr_covered - 10 log10(1 / covered));
 *   differing     how many pixels differ at all.
 * Exit status 1 with a message for an unreadable image or images of different sizes, 2 for bad
 * arguments. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/io.h"

#define MAX_IMAGE_BYTES ((size_t)512 << 20)

typedef struct image {
    uint8_t *rgba;
    uint32_t width, height;
} image;

static int load(const char *path, image *out)
{
    gdr_error err = {0};
    char *data = NULL;
    size_t size = 0;
    gdr_status status = gdr_read_file(path, MAX_IMAGE_BYTES, &data, &size, &err);
    if (status == GDR_OK)
        status = gdr_image_decode(data, size, path, &out->rgba, &out->width, &out->height, &err);
    free(data);
    if (status != GDR_OK) {
        fprintf(stderr, "image_psnr: %s\n", err.message);
        return 0;
    }
    return 1;
}

static double squared_error(const uint8_t *a, const uint8_t *b)
{
    double sum = 0.0;
    for (int k = 0; k < 3; k++) {
        double d = (double)a[k] - (double)b[k];
        sum += d * d;
    }
    return sum;
}

static void print_psnr(const char *key, double sum, size_t pixels)
{
    double mse = pixels > 0 ? sum / (3.0 * (double)pixels) : 0.0;
    if (mse > 0.0)
        printf("\"%s\": %.4f", key, 10.0 * log10(255.0 * 255.0 / mse));
    else
        printf("\"%s\": \"inf\"", key);
}

static void compare(const image *a, const image *b)
{
    size_t pixels = (size_t)a->width * a->height, covered = 0, differing = 0;
    double sum = 0.0;
    const uint8_t *background = a->rgba;
    for (size_t p = 0; p < pixels; p++) {
        const uint8_t *pa = a->rgba + 4 * p, *pb = b->rgba + 4 * p;
        double e = squared_error(pa, pb);
        sum += e;
        differing += e > 0.0;
        covered += memcmp(pa, background, 3) != 0 || memcmp(pb, background, 3) != 0;
    }
    printf("{");
    print_psnr("psnr", sum, pixels);
    printf(", ");
    print_psnr("psnr_covered", sum, covered);
    printf(", \"covered\": %.6f, \"differing\": %zu, \"width\": %u, \"height\": %u}\n",
           pixels > 0 ? (double)covered / (double)pixels : 0.0, differing, a->width, a->height);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: image_psnr REFERENCE.png TEST.png\n");
        return 2;
    }
    image a = {0}, b = {0};
    int ok = load(argv[1], &a) && load(argv[2], &b);
    if (ok && (a.width != b.width || a.height != b.height)) {
        fprintf(stderr, "image_psnr: %s is %ux%u, %s is %ux%u: not the same size\n", argv[1], a.width, a.height,
                argv[2], b.width, b.height);
        ok = 0;
    }
    if (ok)
        compare(&a, &b);
    free(a.rgba);
    free(b.rgba);
    return ok ? 0 : 1;
}
