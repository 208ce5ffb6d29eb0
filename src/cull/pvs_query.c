/* Precomputed visibility at run time: point -> cell through the 2D buckets, and the cache of the
 * last decompressed chunk. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>

#include "cull/cull_internal.h"

struct gdr_pvs_cache {
    const gdr_pvs *pvs;
    uint32_t chunk; /* the chunk in buffer, or UINT32_MAX */
    uint8_t *buffer;
    uint64_t decompressions;
};

void gdr_pvs_destroy(gdr_pvs *pvs)
{
    if (!pvs)
        return;
    free(pvs->buckets);
    free(pvs->cells);
    free(pvs->chunks);
    free(pvs->data);
    free(pvs->samples);
    free(pvs);
}

uint32_t gdr_pvs_object_count(const gdr_pvs *pvs) { return pvs->object_count; }
uint32_t gdr_pvs_cell_count(const gdr_pvs *pvs) { return pvs->cell_count; }

void gdr_pvs_cell_bounds(const gdr_pvs *pvs, uint32_t cell, gdr_vec3 *min, gdr_vec3 *max)
{
    const pvs_cell *c = &pvs->cells[cell];
    *min = (gdr_vec3){pvs->origin.x + (float)c->x * pvs->cell_size, pvs->origin.y + (float)c->y * pvs->cell_size,
                      pvs->origin.z + (float)c->z * pvs->cell_size};
    *max = (gdr_vec3){min->x + pvs->cell_size, min->y + pvs->cell_size, min->z + pvs->cell_size};
}

const gdr_vec3 *gdr_pvs_samples(const gdr_pvs *pvs, uint32_t cell, uint32_t *count)
{
    if (!pvs->samples || cell >= pvs->cell_count) {
        *count = 0;
        return NULL;
    }
    *count = pvs->samples_per_cell;
    return &pvs->samples[(size_t)cell * pvs->samples_per_cell];
}

gdr_status gdr_pvs_cache_create(const gdr_pvs *pvs, gdr_pvs_cache **out, gdr_error *err)
{
    *out = NULL;
    gdr_pvs_cache *c = calloc(1, sizeof(*c));
    if (c)
        c->buffer = malloc(pvs->max_chunk_bytes ? pvs->max_chunk_bytes : 1);
    if (!c || !c->buffer) {
        free(c);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "pvs cache: out of memory");
    }
    c->pvs = pvs;
    c->chunk = UINT32_MAX;
    *out = c;
    return GDR_OK;
}

void gdr_pvs_cache_destroy(gdr_pvs_cache *cache)
{
    if (!cache)
        return;
    free(cache->buffer);
    free(cache);
}

const gdr_pvs *gdr_pvs_cache_pvs(const gdr_pvs_cache *cache) { return cache->pvs; }
uint64_t gdr_pvs_cache_decompressions(const gdr_pvs_cache *cache) { return cache->decompressions; }

/* Grid coordinate along one axis, or false when outside the grid (or NaN). */
static bool grid_coordinate(float p, float origin, float cell, uint32_t count, uint32_t *out)
{
    float f = floorf((p - origin) / cell);
    if (!(f >= 0.0f && f < (float)count))
        return false;
    *out = (uint32_t)f;
    return *out < count;
}

const uint32_t *gdr_pvs_lookup(gdr_pvs_cache *cache, gdr_vec3 point)
{
    const gdr_pvs *p = cache->pvs;
    uint32_t x, y, z;
    if (!grid_coordinate(point.x, p->origin.x, p->cell_size, p->grid[0], &x) ||
        !grid_coordinate(point.y, p->origin.y, p->cell_size, p->grid[1], &y) ||
        !grid_coordinate(point.z, p->origin.z, p->cell_size, p->grid[2], &z))
        return NULL;
    const pvs_bucket *b = &p->buckets[pvs_bucket_of(p, x, z)];
    for (uint32_t i = b->first_cell; i < b->first_cell + b->cell_count; i++) {
        const pvs_cell *c = &p->cells[i];
        if (c->x != x || c->y != y || c->z != z)
            continue;
        if (cache->chunk != c->chunk) {
            const pvs_chunk *chunk = &p->chunks[c->chunk];
            const uint8_t *src = p->data + chunk->data_offset;
            if (chunk->flags & PVS_CHUNK_ZSTD) {
                size_t n = ZSTD_decompress(cache->buffer, p->max_chunk_bytes, src, chunk->compressed_size);
                if (ZSTD_isError(n) || n != chunk->uncompressed_size) {
                    cache->chunk = UINT32_MAX; /* cannot happen for a validated blob */
                    return NULL;
                }
            } else {
                memcpy(cache->buffer, src, chunk->uncompressed_size);
            }
            cache->chunk = c->chunk;
            cache->decompressions++;
        }
        return (const uint32_t *)(cache->buffer + c->offset);
    }
    return NULL;
}
