/* libFuzzer target: the precomputed-visibility blob loader (gdr_pvs_load, docs/CULLING.md).
 * A checksum covers the whole blob and would reject nearly every mutation, so a flag in the first
 * byte (when odd) recomputes it first: the table and chunk checks behind it get exercised too.
 * A blob that loads must serialise back to the same bytes, and lookups in every cell and at odd
 * points must stay in bounds (every word of each returned bitset is read). The seeds in
 * corpus/pvs come from `test_cull_pvs --write-seeds DIR`. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/cull.h"

#define CHECKSUM_OFFSET 72u

/* FNV-1a 64 over the blob with the checksum field taken as zero (the format's definition). */
static uint64_t blob_checksum(const uint8_t *data, size_t size)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < size; i++) {
        uint8_t byte = (i >= CHECKSUM_OFFSET && i < CHECKSUM_OFFSET + 8) ? 0 : data[i];
        h = (h ^ byte) * 0x100000001b3ull;
    }
    return h;
}

static uint32_t read_bitset(const uint32_t *bits, uint32_t words)
{
    uint32_t acc = 0;
    for (uint32_t w = 0; bits && w < words; w++)
        acc ^= bits[w];
    return acc;
}

static void exercise(const gdr_pvs *pvs, const uint8_t *blob, size_t size)
{
    gdr_error err;
    size_t n = gdr_pvs_serialized_size(pvs);
    uint8_t *again = malloc(n ? n : 1);
    if (!again)
        return;
    /* the format is canonical: what loads writes back byte for byte */
    if (n != size || gdr_pvs_serialize(pvs, again, n, &err) != GDR_OK || memcmp(again, blob, n) != 0)
        __builtin_trap();
    free(again);

    gdr_pvs_cache *cache;
    if (gdr_pvs_cache_create(pvs, &cache, &err) != GDR_OK)
        return;
    uint32_t words = gdr_cull_word_count(gdr_pvs_object_count(pvs));
    volatile uint32_t sink = 0;
    for (uint32_t c = 0; c < gdr_pvs_cell_count(pvs); c++) {
        gdr_vec3 lo, hi;
        gdr_pvs_cell_bounds(pvs, c, &lo, &hi);
        gdr_vec3 points[3] = {{0.5f * (lo.x + hi.x), 0.5f * (lo.y + hi.y), 0.5f * (lo.z + hi.z)}, lo, hi};
        for (int k = 0; k < 3; k++)
            sink ^= read_bitset(gdr_pvs_lookup(cache, points[k]), words);
    }
    gdr_vec3 odd[] = {{0, 0, 0}, {NAN, 0, 0}, {0, INFINITY, 0}, {-INFINITY, 0, 0}, {3e38f, -3e38f, 1e-38f}};
    for (size_t k = 0; k < sizeof(odd) / sizeof(odd[0]); k++)
        sink ^= read_bitset(gdr_pvs_lookup(cache, odd[k]), words);
    (void)gdr_pvs_cache_decompressions(cache);
    gdr_pvs_cache_destroy(cache);
    (void)sink;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    int fix = data[0] & 1;
    data++;
    size--;
    uint8_t *copy = malloc(size ? size : 1);
    if (!copy)
        return 0;
    memcpy(copy, data, size);
    if (fix && size >= CHECKSUM_OFFSET + 8) {
        uint64_t h = blob_checksum(copy, size);
        for (int i = 0; i < 8; i++)
            copy[CHECKSUM_OFFSET + (size_t)i] = (uint8_t)(h >> (8 * i));
    }
    gdr_pvs *pvs = NULL;
    gdr_error err;
    if (gdr_pvs_load(copy, size, &pvs, &err) == GDR_OK) {
        exercise(pvs, copy, size);
        gdr_pvs_destroy(pvs);
    }
    free(copy);
    return 0;
}
