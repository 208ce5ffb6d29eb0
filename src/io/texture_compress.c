/* Block compression of a scene's textures (gdr_scene_compress_textures): each texture's format is
 * chosen by what the materials read of it, every level of its mip chain (built before, from the
 * full-resolution image) is encoded with libsquish on a thread pool, in bands of block rows. */
#include <stdlib.h>
#include <string.h>

#include "gdr/io.h"
#include "gdr/thread_pool.h"
#include "io/texture_codec.h"
#include "io/texture_squish.h"

enum { CH_R = 1, CH_G = 2, CH_B = 4, CH_A = 8 };
enum { BAND_BLOCK_ROWS = 16 }; /* one task: 16 rows of blocks (64 texel rows) of one level */

static gdr_squish_kind squish_kind(uint32_t format)
{
    switch (format) {
    case GDR_TEXTURE_BC1:
        return GDR_SQUISH_BC1;
    case GDR_TEXTURE_BC3:
        return GDR_SQUISH_BC3;
    case GDR_TEXTURE_BC4:
        return GDR_SQUISH_BC4;
    default:
        return GDR_SQUISH_BC5;
    }
}

/* Whether any texel of level 0 is not opaque. */
static int has_alpha(const gdr_texture *t)
{
    size_t texels = (size_t)t->width * t->height;
    for (size_t i = 0; i < texels; i++)
        if (t->rgba[i * 4 + 3] != 255)
            return 1;
    return 0;
}

/* The channels each texture's uses read: colour RGB (and A where a MASK or BLEND material reads
 * the base colour's alpha), a normal map RG, metallic-roughness GB, occlusion R. */
static void channels_used(const gdr_scene *scene, uint32_t *channels)
{
    memset(channels, 0, scene->texture_count * sizeof *channels);
    for (uint32_t i = 0; i < scene->material_count; i++) {
        const gdr_material *m = &scene->materials[i];
        const gdr_texture_ref *refs[5] = {&m->base_color_texture, &m->metallic_roughness_texture, &m->normal_texture,
                                          &m->occlusion_texture, &m->emissive_texture};
        const uint32_t reads[5] = {CH_R | CH_G | CH_B | (m->alpha_mode != GDR_ALPHA_OPAQUE ? CH_A : 0u),
                                   CH_G | CH_B, CH_R | CH_G, CH_R, CH_R | CH_G | CH_B};
        for (int k = 0; k < 5; k++)
            if (refs[k]->texture < scene->texture_count)
                channels[refs[k]->texture] |= reads[k];
    }
}

uint32_t gdr_io_texture_format_for(const gdr_texture *t, uint32_t channels, uint32_t metallic_roughness_format)
{
    if (channels == 0 || t->format != GDR_TEXTURE_RGBA8)
        return t->format; /* unused, or already compressed */
    if ((channels & CH_A) && has_alpha(t))
        return GDR_TEXTURE_BC3;
    if (channels == CH_R)
        return GDR_TEXTURE_BC4;
    if ((channels & ~(uint32_t)(CH_R | CH_G)) == 0)
        return GDR_TEXTURE_BC5;
    if ((channels & ~(uint32_t)(CH_G | CH_B)) == 0)
        return metallic_roughness_format;
    return GDR_TEXTURE_BC1;
}

/* The 16 texels of block (bx, by) of a w x h RGBA8 level, edges repeated past the level's border,
 * rearranged for the format: BC1 opaque, BC5_GB's G and B moved into R and G. */
static void gather_block(const uint8_t *level, uint32_t w, uint32_t h, uint32_t bx, uint32_t by, uint32_t format,
                         uint8_t out[64])
{
    for (uint32_t y = 0; y < 4; y++) {
        uint32_t sy = by * 4 + y < h ? by * 4 + y : h - 1;
        for (uint32_t x = 0; x < 4; x++) {
            uint32_t sx = bx * 4 + x < w ? bx * 4 + x : w - 1;
            const uint8_t *s = level + ((size_t)sy * w + sx) * 4;
            uint8_t *d = out + (y * 4 + x) * 4;
            memcpy(d, s, 4);
            if (format == GDR_TEXTURE_BC1)
                d[3] = 255;
            if (format == GDR_TEXTURE_BC5_GB) {
                d[0] = s[1];
                d[1] = s[2];
            }
        }
    }
}

void gdr_io_texture_encode_rows(const uint8_t *level, uint32_t w, uint32_t h, uint32_t format, uint32_t fit,
                                uint32_t first_block_row, uint32_t block_rows, uint8_t *blocks)
{
    uint32_t blocks_x = (w + 3) / 4, block_bytes = gdr_texture_block_bytes(format);
    for (uint32_t by = first_block_row; by < first_block_row + block_rows; by++)
        for (uint32_t bx = 0; bx < blocks_x; bx++) {
            uint8_t texels[64];
            gather_block(level, w, h, bx, by, format, texels);
            gdr_squish_compress_block(texels, blocks + ((size_t)by * blocks_x + bx) * block_bytes,
                                      squish_kind(format), (gdr_squish_fit)fit);
        }
}

/* One task: a band of block rows of one level of one texture. */
typedef struct encode_task {
    const uint8_t *level; /* RGBA8 */
    uint8_t *blocks;      /* the level's blocks */
    uint32_t width, height, format, first_block_row, block_rows;
} encode_task;

typedef struct encode_job {
    encode_task *tasks;
    uint32_t fit;
} encode_job;

static void run_encode_task(void *user, uint32_t index, uint32_t worker)
{
    (void)worker;
    const encode_job *job = user;
    const encode_task *t = &job->tasks[index];
    gdr_io_texture_encode_rows(t->level, t->width, t->height, t->format, job->fit, t->first_block_row, t->block_rows,
                               t->blocks);
}

/* Appends the tasks of every level of texture t, to be encoded as `format` into `chain`. */
static uint32_t add_tasks(const gdr_texture *t, uint32_t format, uint8_t *chain, encode_task *tasks)
{
    uint32_t n = 0;
    for (uint32_t l = 0; l < t->levels; l++) {
        uint32_t w = t->width >> l ? t->width >> l : 1, h = t->height >> l ? t->height >> l : 1;
        uint32_t rows = (h + 3) / 4;
        for (uint32_t r = 0; r < rows; r += BAND_BLOCK_ROWS) {
            if (tasks)
                tasks[n] = (encode_task){.level = t->rgba + gdr_texture_level_offset(t->width, t->height, l),
                                         .blocks = chain + gdr_texture_format_level_offset(format, t->width, t->height, l),
                                         .width = w, .height = h, .format = format, .first_block_row = r,
                                         .block_rows = rows - r < BAND_BLOCK_ROWS ? rows - r : BAND_BLOCK_ROWS};
            n++;
        }
    }
    return n;
}

/* The new chains of the textures whose format changes (NULL for the others), their tasks counted,
 * allocated and filled; then encoded, and each texture's chain replaced. */
static gdr_status encode_all(gdr_scene *scene, const uint32_t *formats, uint8_t **chains, gdr_thread_pool *pool,
                             uint32_t fit, gdr_error *err)
{
    uint32_t task_count = 0;
    for (uint32_t i = 0; i < scene->texture_count; i++) {
        const gdr_texture *t = &scene->textures[i];
        if (formats[i] == t->format)
            continue;
        chains[i] = malloc(gdr_texture_format_level_offset(formats[i], t->width, t->height, t->levels));
        if (!chains[i])
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "texture '%s': out of memory for its blocks", t->name);
        task_count += add_tasks(t, formats[i], chains[i], NULL);
    }
    encode_task *tasks = malloc((task_count ? task_count : 1) * sizeof *tasks);
    if (!tasks)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "textures: out of memory for %u encoding tasks", task_count);
    uint32_t n = 0;
    for (uint32_t i = 0; i < scene->texture_count; i++)
        if (chains[i])
            n += add_tasks(&scene->textures[i], formats[i], chains[i], tasks + n);
    encode_job job = {.tasks = tasks, .fit = fit};
    gdr_thread_pool_run(pool, task_count, run_encode_task, &job);
    free(tasks);
    for (uint32_t i = 0; i < scene->texture_count; i++)
        if (chains[i]) {
            free(scene->textures[i].rgba);
            scene->textures[i].rgba = chains[i];
            scene->textures[i].format = formats[i];
            chains[i] = NULL;
        }
    return GDR_OK;
}

gdr_status gdr_scene_compress_textures(gdr_scene *scene, const gdr_texture_compress_options *options, gdr_error *err)
{
    gdr_texture_compress_options o = options ? *options : (gdr_texture_compress_options){0};
    uint32_t fit = o.fit ? o.fit - 1 : GDR_TEXTURE_FIT_DEFAULT - 1;
    uint32_t mr = o.metallic_roughness_format ? o.metallic_roughness_format : GDR_TEXTURE_BC5_GB;
    if (fit > GDR_SQUISH_ITERATIVE_CLUSTER_FIT || (mr != GDR_TEXTURE_BC5_GB && mr != GDR_TEXTURE_BC1))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "texture compression: fit %u or format %u is not one of "
                             "the choices", o.fit, o.metallic_roughness_format);
    if (scene->texture_count == 0)
        return GDR_OK;
    uint32_t *formats = calloc(scene->texture_count, sizeof *formats);
    uint8_t **chains = calloc(scene->texture_count, sizeof *chains);
    gdr_thread_pool *pool = NULL;
    gdr_status status = formats && chains ? GDR_OK
                                          : gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "textures: out of memory");
    if (status == GDR_OK) {
        channels_used(scene, formats);
        for (uint32_t i = 0; i < scene->texture_count; i++)
            formats[i] = gdr_io_texture_format_for(&scene->textures[i], formats[i], mr);
        status = gdr_thread_pool_create(o.thread_count, &pool, err);
    }
    if (status == GDR_OK)
        status = encode_all(scene, formats, chains, pool, fit, err);
    for (uint32_t i = 0; chains && i < scene->texture_count; i++)
        free(chains[i]);
    gdr_thread_pool_destroy(pool);
    free(chains);
    free(formats);
    return status;
}
