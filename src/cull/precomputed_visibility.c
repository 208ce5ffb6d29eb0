/* The precomputed-visibility bake: cells of empty space, camera points sampled in each, a
 * conservative depth cube per point (pvs_occlusion.c) deciding which objects it may see, one
 * visibility bitset per cell, cells hashed into 2D buckets, bitsets compressed with zstd in chunks
 * of cells. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>

#include "gdr/thread_pool.h"
#include "cull/cull_internal.h"

enum { CELL_UNTOUCHED = 0, CELL_BAKED = 1, CELL_OCCUPIED = 2 };

typedef struct bake_context {
    gdr_pvs_bake_desc desc; /* defaults applied */
    const gdr_bvh *bvh;
    pvs_geometry geometry;
    pvs_view_scratch **scratch; /* per worker */
    uint32_t object_count, words;
    gdr_vec3 origin;
    float cell;
    uint32_t grid[3];
    uint32_t *bits;         /* per grid cell: words */
    uint8_t *state;         /* per grid cell */
    gdr_vec3 *samples;      /* per grid cell: samples_per_cell, or NULL */
    uint64_t *tests;        /* per grid cell: objects tested against a depth cube */
    uint32_t *unproven;     /* per grid cell: samples too near geometry for the proof */
} bake_context;

static uint64_t splitmix(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static float rand01(uint64_t *s) { return (float)(splitmix(s) >> 40) * (1.0f / 16777216.0f); }

static void bake_cell(void *user, uint32_t index, uint32_t worker)
{
    bake_context *ctx = user;
    const gdr_pvs_bake_desc *d = &ctx->desc;
    uint32_t x = index % ctx->grid[0], y = index / ctx->grid[0] % ctx->grid[1], z = index / ctx->grid[0] / ctx->grid[1];
    float h = 0.5f * ctx->cell;
    gdr_vec3 lo = {ctx->origin.x + (float)x * ctx->cell, ctx->origin.y + (float)y * ctx->cell,
                   ctx->origin.z + (float)z * ctx->cell};
    gdr_vec3 hi = {lo.x + ctx->cell, lo.y + ctx->cell, lo.z + ctx->cell};
    if (gdr_bvh_overlaps_box(ctx->bvh, (gdr_vec3){lo.x + h, lo.y + h, lo.z + h}, (gdr_vec3){h, h, h})) {
        ctx->state[index] = CELL_OCCUPIED;
        return;
    }
    ctx->state[index] = CELL_BAKED;
    uint32_t *bits = &ctx->bits[(size_t)index * ctx->words];
    uint64_t rng = ((uint64_t)d->seed << 32) ^ index;
    splitmix(&rng);
    uint32_t strata = 1;
    while (strata * strata * strata < d->samples_per_cell)
        strata++;
    for (uint32_t s = 0; s < d->samples_per_cell; s++) {
        /* stratified and jittered, kept off the cell's faces */
        uint32_t sx = s % strata, sy = s / strata % strata, sz = s / strata / strata % strata;
        gdr_vec3 p = {lo.x + ctx->cell * (((float)sx + 0.02f + 0.96f * rand01(&rng)) / (float)strata),
                      lo.y + ctx->cell * (((float)sy + 0.02f + 0.96f * rand01(&rng)) / (float)strata),
                      lo.z + ctx->cell * (((float)sz + 0.02f + 0.96f * rand01(&rng)) / (float)strata)};
        if (ctx->samples)
            ctx->samples[(size_t)index * d->samples_per_cell + s] = p;
        /* The proof needs a small cube about p free of triangles: half the distance to the
         * (empty) cell's faces, checked again with the exact triangle/box test. */
        float delta = 0.5f * fminf(fminf(fminf(p.x - lo.x, hi.x - p.x), fminf(p.y - lo.y, hi.y - p.y)),
                                   fminf(p.z - lo.z, hi.z - p.z));
        if (!(delta > 0.0f) || gdr_bvh_overlaps_box(ctx->bvh, p, (gdr_vec3){delta, delta, delta})) {
            for (uint32_t o = 0; o < ctx->object_count; o++)
                if (ctx->geometry.first[o + 1] > ctx->geometry.first[o])
                    bits[o >> 5] |= 1u << (o & 31u);
            ctx->unproven[index]++;
            continue;
        }
        ctx->tests[index] += pvs_visible_from_point(&ctx->geometry, ctx->scratch[worker], p, delta, bits);
    }
}

/* Sorts the baked cells into buckets and compresses their bitsets in chunks. */
static gdr_status assemble(bake_context *ctx, gdr_pvs *pvs, gdr_error *err)
{
    uint32_t total = ctx->grid[0] * ctx->grid[1] * ctx->grid[2];
    uint32_t bucket_count = pvs->bucket_x * pvs->bucket_z;
    pvs->buckets = calloc(bucket_count, sizeof(pvs_bucket));
    uint32_t baked = 0;
    for (uint32_t i = 0; i < total; i++)
        baked += ctx->state[i] == CELL_BAKED;
    size_t cell_bytes = (size_t)ctx->words * 4;
    pvs->cell_count = baked;
    pvs->cells = calloc(baked ? baked : 1, sizeof(pvs_cell));
    uint32_t *grid_index = malloc((baked ? baked : 1) * sizeof(uint32_t));
    uint32_t max_chunks = baked; /* at most one chunk per cell */
    pvs->chunks = calloc(max_chunks ? max_chunks : 1, sizeof(pvs_chunk));
    uint8_t *raw = malloc(cell_bytes * ctx->desc.cells_per_chunk + 1);
    size_t bound = ZSTD_compressBound(cell_bytes * ctx->desc.cells_per_chunk);
    uint8_t *packed = malloc(bound);
    size_t data_capacity = 4096, data_size = 0;
    pvs->data = malloc(data_capacity);
    if (!pvs->buckets || !pvs->cells || !grid_index || !pvs->chunks || !raw || !packed || !pvs->data) {
        free(grid_index);
        free(raw);
        free(packed);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "pvs bake: out of memory assembling %u cells", baked);
    }
    for (uint32_t i = 0; i < total; i++)
        if (ctx->state[i] == CELL_BAKED)
            pvs->buckets[pvs_bucket_of(pvs, i % ctx->grid[0], i / ctx->grid[0] / ctx->grid[1])].cell_count++;
    uint32_t start = 0;
    for (uint32_t b = 0; b < bucket_count; b++) {
        pvs->buckets[b].first_cell = start;
        start += pvs->buckets[b].cell_count;
        pvs->buckets[b].cell_count = 0;
    }
    for (uint32_t i = 0; i < total; i++) {
        if (ctx->state[i] != CELL_BAKED)
            continue;
        uint32_t x = i % ctx->grid[0], y = i / ctx->grid[0] % ctx->grid[1], z = i / ctx->grid[0] / ctx->grid[1];
        pvs_bucket *b = &pvs->buckets[pvs_bucket_of(pvs, x, z)];
        uint32_t c = b->first_cell + b->cell_count++;
        pvs->cells[c] = (pvs_cell){x, y, z, 0, 0};
        grid_index[c] = i;
    }
    gdr_status st = GDR_OK;
    for (uint32_t b = 0; b < bucket_count && st == GDR_OK; b++) {
        const pvs_bucket *bucket = &pvs->buckets[b];
        for (uint32_t k = 0; k < bucket->cell_count && st == GDR_OK; k += ctx->desc.cells_per_chunk) {
            uint32_t n = bucket->cell_count - k < ctx->desc.cells_per_chunk ? bucket->cell_count - k
                                                                            : ctx->desc.cells_per_chunk;
            uint32_t chunk = pvs->chunk_count++;
            for (uint32_t j = 0; j < n; j++) {
                uint32_t c = bucket->first_cell + k + j;
                memcpy(raw + j * cell_bytes, &ctx->bits[(size_t)grid_index[c] * ctx->words], cell_bytes);
                pvs->cells[c].chunk = chunk;
                pvs->cells[c].offset = (uint32_t)(j * cell_bytes);
            }
            size_t raw_size = n * cell_bytes;
            size_t packed_size = ZSTD_compress(packed, bound, raw, raw_size, ctx->desc.zstd_level);
            bool use_zstd = !ZSTD_isError(packed_size) && packed_size < raw_size;
            const uint8_t *src = use_zstd ? packed : raw;
            size_t size = use_zstd ? packed_size : raw_size;
            while (data_size + size > data_capacity) {
                data_capacity *= 2;
                uint8_t *grown = realloc(pvs->data, data_capacity);
                if (!grown) {
                    st = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "pvs bake: out of memory for chunk data");
                    break;
                }
                pvs->data = grown;
            }
            if (st != GDR_OK)
                break;
            memcpy(pvs->data + data_size, src, size);
            pvs->chunks[chunk] = (pvs_chunk){data_size, (uint32_t)size, (uint32_t)raw_size,
                                             use_zstd ? PVS_CHUNK_ZSTD : 0u};
            data_size += size;
            if (raw_size > pvs->max_chunk_bytes)
                pvs->max_chunk_bytes = (uint32_t)raw_size;
        }
    }
    pvs->data_size = data_size;
    if (st == GDR_OK && ctx->samples) {
        uint32_t spc = ctx->desc.samples_per_cell;
        pvs->samples = malloc((size_t)(baked ? baked : 1) * spc * sizeof(gdr_vec3));
        if (!pvs->samples)
            st = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "pvs bake: out of memory for samples");
        for (uint32_t c = 0; c < baked && st == GDR_OK; c++)
            memcpy(&pvs->samples[(size_t)c * spc], &ctx->samples[(size_t)grid_index[c] * spc], spc * sizeof(gdr_vec3));
        pvs->samples_per_cell = spc;
    }
    free(grid_index);
    free(raw);
    free(packed);
    return st;
}

static void bake_context_free(bake_context *ctx, uint32_t workers)
{
    pvs_geometry_free(&ctx->geometry);
    if (ctx->scratch)
        for (uint32_t w = 0; w < workers; w++)
            pvs_view_scratch_destroy(ctx->scratch[w]);
    free(ctx->scratch);
    free(ctx->bits);
    free(ctx->state);
    free(ctx->samples);
    free(ctx->tests);
    free(ctx->unproven);
}

/* The desc with every zero field given its default. */
static gdr_pvs_bake_desc pvs_bake_desc_defaults(const gdr_pvs_bake_desc *in)
{
    gdr_pvs_bake_desc d = *in;
    d.samples_per_cell = d.samples_per_cell ? d.samples_per_cell : 8;
    d.cube_resolution = d.cube_resolution ? d.cube_resolution : 64;
    d.cells_per_chunk = d.cells_per_chunk ? d.cells_per_chunk : 16;
    d.bucket_count_x = d.bucket_count_x ? d.bucket_count_x : 16;
    d.bucket_count_z = d.bucket_count_z ? d.bucket_count_z : 16;
    d.zstd_level = d.zstd_level ? d.zstd_level : 3;
    d.seed = d.seed ? d.seed : 1;
    return d;
}

gdr_status gdr_pvs_bake(const gdr_pvs_bake_desc *desc_in, gdr_pvs **out, gdr_pvs_bake_report *report, gdr_error *err)
{
    *out = NULL;
    if (!desc_in || !desc_in->scene)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "pvs bake: scene is NULL");
    bake_context ctx = {0};
    gdr_pvs_bake_desc d = pvs_bake_desc_defaults(desc_in);
    if (d.bucket_count_x > PVS_MAX_BUCKETS_PER_AXIS || d.bucket_count_z > PVS_MAX_BUCKETS_PER_AXIS)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "pvs bake: more than %u buckets along an axis",
                             PVS_MAX_BUCKETS_PER_AXIS);
    if (d.cube_resolution < 4 || d.cube_resolution > 1024)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "pvs bake: cube_resolution %u is outside 4..1024",
                             d.cube_resolution);
    if (d.samples_per_cell > 4096 || d.cells_per_chunk > 4096)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "pvs bake: samples_per_cell and cells_per_chunk "
                                                              "must be at most 4096");
    if (d.scene->instance_count > PVS_MAX_OBJECTS)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "pvs bake: %u objects is too many", d.scene->instance_count);
    ctx.object_count = d.scene->instance_count;
    ctx.words = gdr_cull_word_count(ctx.object_count);
    /* a chunk holds at most PVS_MAX_CHUNK_BYTES (what the loader accepts) */
    uint64_t cell_bytes = (uint64_t)ctx.words * 4;
    if (cell_bytes && d.cells_per_chunk * cell_bytes > PVS_MAX_CHUNK_BYTES)
        d.cells_per_chunk = (uint32_t)(PVS_MAX_CHUNK_BYTES / cell_bytes);
    ctx.desc = d;

    gdr_bvh *bvh;
    gdr_status st = gdr_bvh_create_from_scene(d.scene, &bvh, err);
    if (st != GDR_OK)
        return st;
    ctx.bvh = bvh;

    gdr_vec3 lo = d.region_min, hi = d.region_max;
    bool no_region = lo.x == 0 && lo.y == 0 && lo.z == 0 && hi.x == 0 && hi.y == 0 && hi.z == 0;
    if (no_region) {
        if (gdr_bvh_triangle_count(bvh) == 0) {
            gdr_bvh_destroy(bvh);
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "pvs bake: no triangles and no region");
        }
        cull_bvh_bounds(bvh, &lo, &hi);
    }
    gdr_vec3 size = gdr_vec3_sub(hi, lo);
    float largest = fmaxf(size.x, fmaxf(size.y, size.z));
    float cell = d.cell_size > 0.0f ? d.cell_size : largest / 16.0f;
    if (!(size.x >= 0 && size.y >= 0 && size.z >= 0) || !isfinite(largest) || !(cell > 0.0f) || !isfinite(cell) ||
        !isfinite(lo.x) || !isfinite(lo.y) || !isfinite(lo.z)) {
        gdr_bvh_destroy(bvh);
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "pvs bake: bad region or cell size %g", (double)cell);
    }
    double cells = 1.0;
    float sizes[3] = {size.x, size.y, size.z};
    for (int a = 0; a < 3; a++) {
        double n = fmax(1.0, ceil((double)sizes[a] / cell));
        cells *= n;
        ctx.grid[a] = n <= (double)PVS_MAX_GRID_CELLS ? (uint32_t)n : PVS_MAX_GRID_CELLS;
    }
    if (cells > (double)PVS_MAX_GRID_CELLS) {
        gdr_bvh_destroy(bvh);
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "pvs bake: %.0f cells exceed %u; use a larger cell_size", cells,
                             PVS_MAX_GRID_CELLS);
    }
    uint32_t total = ctx.grid[0] * ctx.grid[1] * ctx.grid[2];
    ctx.origin = lo;
    ctx.cell = cell;
    ctx.bits = calloc((size_t)total * ctx.words + 1, sizeof(uint32_t));
    ctx.state = calloc(total, 1);
    ctx.tests = calloc(total, sizeof(uint64_t));
    ctx.unproven = calloc(total, sizeof(uint32_t));
    if (d.keep_samples)
        ctx.samples = calloc((size_t)total * d.samples_per_cell, sizeof(gdr_vec3));
    uint32_t workers = gdr_thread_pool_thread_count(d.pool);
    ctx.scratch = calloc(workers, sizeof(pvs_view_scratch *));
    gdr_pvs *pvs = calloc(1, sizeof(*pvs));
    if (!ctx.bits || !ctx.state || !ctx.tests || !ctx.unproven || (d.keep_samples && !ctx.samples) ||
        !ctx.scratch || !pvs)
        st = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "pvs bake: out of memory for %u cells", total);
    if (st == GDR_OK)
        st = pvs_geometry_build(&ctx.geometry, bvh, ctx.object_count, err);
    for (uint32_t w = 0; w < workers && st == GDR_OK; w++)
        st = pvs_view_scratch_create(d.cube_resolution, ctx.geometry.max_triangles, ctx.object_count, &ctx.scratch[w],
                                    err);
    if (st == GDR_OK) {
        gdr_thread_pool_run(d.pool, total, bake_cell, &ctx);
        pvs->object_count = ctx.object_count;
        memcpy(pvs->grid, ctx.grid, sizeof(pvs->grid));
        pvs->origin = lo;
        pvs->cell_size = cell;
        pvs->bucket_x = d.bucket_count_x;
        pvs->bucket_z = d.bucket_count_z;
        st = assemble(&ctx, pvs, err);
    }
    if (st == GDR_OK && report) {
        gdr_pvs_bake_report r = {0};
        memcpy(r.grid, ctx.grid, sizeof(r.grid));
        r.cells_total = total;
        for (uint32_t i = 0; i < total; i++) {
            r.cells_baked += ctx.state[i] == CELL_BAKED;
            r.cells_occupied += ctx.state[i] == CELL_OCCUPIED;
            r.object_tests += ctx.tests[i];
            r.unproven_samples += ctx.unproven[i];
            if (ctx.state[i] == CELL_BAKED)
                for (uint32_t w = 0; w < ctx.words; w++)
                    r.visible_pairs += (uint64_t)__builtin_popcount(ctx.bits[(size_t)i * ctx.words + w]);
        }
        r.samples_used = (uint64_t)r.cells_baked * d.samples_per_cell;
        r.compressed_bytes = (size_t)pvs->data_size;
        r.uncompressed_bytes = (size_t)r.cells_baked * ctx.words * 4;
        *report = r;
    }
    bake_context_free(&ctx, workers);
    gdr_bvh_destroy(bvh);
    if (st != GDR_OK) {
        gdr_pvs_destroy(pvs);
        return st;
    }
    *out = pvs;
    return GDR_OK;
}
