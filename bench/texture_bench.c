/* Block compression of a glTF's textures: per texture and libsquish colour fit, the format
 * gdr_scene_compress_textures chooses (and for metallic-roughness both candidates, BC5_GB and BC1),
 * the encoding time of the whole mip chain on one thread and on the pool, and the PSNR of the
 * decoded level 0 against the uncompressed level 0 over the channels its uses read.
 *
 *   texture_bench FILE.gltf [--threads N]     (every fit for BC1/BC3, the one encoder of BC4/BC5)
 *
 * Prints a table and, at the end, one JSON line per row. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gdr/gdr.h"
#include "io/loaders.h"
#include "io/texture_codec.h"

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

/* The channels a texture's uses read (bits R 1, G 2, B 4, A 8), as the compressor counts them. */
static uint32_t channels_of(const gdr_scene *s, uint32_t texture)
{
    uint32_t c = 0;
    for (uint32_t i = 0; i < s->material_count; i++) {
        const gdr_material *m = &s->materials[i];
        c |= m->base_color_texture.texture == texture ? 7u | (m->alpha_mode != GDR_ALPHA_OPAQUE ? 8u : 0u) : 0u;
        c |= m->emissive_texture.texture == texture ? 7u : 0u;
        c |= m->metallic_roughness_texture.texture == texture ? 6u : 0u;
        c |= m->normal_texture.texture == texture ? 3u : 0u;
        c |= m->occlusion_texture.texture == texture ? 1u : 0u;
    }
    return c;
}

/* PSNR over the channels in `channels` of level 0. */
static double psnr(const uint8_t *a, const uint8_t *b, size_t texels, uint32_t channels)
{
    double se = 0;
    size_t n = 0;
    for (size_t i = 0; i < texels; i++)
        for (int k = 0; k < 4; k++)
            if (channels & (1u << k)) {
                double d = (double)a[i * 4 + k] - (double)b[i * 4 + k];
                se += d * d;
                n++;
            }
    return se == 0 ? INFINITY : 10 * log10(255.0 * 255.0 / (se / (double)n));
}

/* Encodes texture i of `source` as `format` with `fit` (a GDR_TEXTURE_FIT_*): a one-texture copy
 * of the scene through gdr_scene_compress_textures, timed; its level 0 decoded into `decoded`. */
static double encode(const gdr_texture *t, uint32_t format, uint32_t fit, uint32_t threads, uint8_t *decoded)
{
    gdr_scene *one = NULL;
    gdr_error err;
    if (gdr_scene_create(&one, &err) != GDR_OK ||
        gdr_scene_add_texture_levels(one, t->name, t->width, t->height, t->rgba, t->srgb, NULL, &err) != GDR_OK)
        return -1;
    gdr_material m = gdr_material_default();
    /* one use that makes the compressor pick `format` */
    gdr_texture_ref *use = format == GDR_TEXTURE_BC4 ? &m.occlusion_texture
                           : format == GDR_TEXTURE_BC5 ? &m.normal_texture
                           : format == GDR_TEXTURE_BC1 || format == GDR_TEXTURE_BC3 ? &m.base_color_texture
                                                                                     : &m.metallic_roughness_texture;
    use->texture = 0;
    m.alpha_mode = format == GDR_TEXTURE_BC3 ? GDR_ALPHA_BLEND : GDR_ALPHA_OPAQUE;
    gdr_scene_add_material(one, &m, NULL, &err);
    gdr_texture_compress_options o = {.fit = fit, .thread_count = threads,
                                      .metallic_roughness_format = format == GDR_TEXTURE_BC5_GB ? GDR_TEXTURE_BC5_GB
                                                                                                 : GDR_TEXTURE_BC1};
    double t0 = now_s();
    gdr_status status = gdr_scene_compress_textures(one, &o, &err);
    double seconds = now_s() - t0;
    if (status != GDR_OK || one->textures[0].format != format ||
        gdr_texture_decode_level(&one->textures[0], 0, decoded, &err) != GDR_OK)
        seconds = -1;
    gdr_scene_destroy(one);
    return seconds;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: texture_bench FILE.gltf [--threads N]\n");
        return 2;
    }
    uint32_t threads = 0;
    for (int i = 2; i + 1 < argc; i += 2)
        if (strcmp(argv[i], "--threads") == 0)
            threads = (uint32_t)atoi(argv[i + 1]);
    gdr_scene *s = NULL;
    gdr_error err;
    gdr_import_options options = {.no_progress = 1};
    if (gdr_import_gltf(argv[1], &options, &s, NULL, &err) != GDR_OK) {
        fprintf(stderr, "texture_bench: %s\n", err.message);
        return 1;
    }
    static const char *fit_names[] = {"", "range", "cluster", "iterative"};
    printf("%-28s %-7s %-9s %10s %10s %8s\n", "texture", "format", "fit", "1 thread s", "pool s", "PSNR dB");
    for (uint32_t i = 0; i < s->texture_count; i++) {
        const gdr_texture *t = &s->textures[i];
        uint32_t channels = channels_of(s, i);
        uint32_t chosen = gdr_io_texture_format_for(t, channels, GDR_TEXTURE_BC5_GB);
        uint32_t formats[2] = {chosen, chosen == GDR_TEXTURE_BC5_GB ? GDR_TEXTURE_BC1 : chosen};
        size_t texels = (size_t)t->width * t->height;
        uint8_t *decoded = malloc(texels * 4);
        for (int f = 0; f < (formats[1] != formats[0] ? 2 : 1); f++)
            for (uint32_t fit = 1; fit <= 3; fit++) {
                bool colour_fit = formats[f] == GDR_TEXTURE_BC1 || formats[f] == GDR_TEXTURE_BC3;
                if (!colour_fit && fit != 1)
                    continue; /* BC4 and BC5 have one encoder */
                double one = encode(t, formats[f], fit, 1, decoded);
                double pool = encode(t, formats[f], fit, threads, decoded);
                double db = psnr(t->rgba, decoded, texels, channels & ~8u);
                printf("%-28s %-7s %-9s %10.3f %10.3f %8.2f\n", t->name, gdr_texture_format_name(formats[f]),
                       colour_fit ? fit_names[fit] : "-", one, pool, db);
                printf("JSON {\"texture\":\"%s\",\"format\":\"%s\",\"fit\":\"%s\",\"one_thread_s\":%.4f,"
                       "\"pool_s\":%.4f,\"psnr_db\":%.3f}\n", t->name, gdr_texture_format_name(formats[f]),
                       colour_fit ? fit_names[fit] : "-", one, pool, db);
            }
        free(decoded);
    }
    gdr_scene_destroy(s);
    return 0;
}
