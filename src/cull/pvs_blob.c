/* The precomputed-visibility blob (docs/CULLING.md): write, and load as untrusted input. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>

#include "cull/cull_internal.h"

#define PVS_MAGIC "GDRPVS\r\n"
#define PVS_VERSION 1u
#define PVS_HEADER_SIZE 80u
#define PVS_BUCKET_SIZE 8u
#define PVS_CELL_SIZE 20u
#define PVS_CHUNK_SIZE 24u
#define PVS_CHECKSUM_OFFSET 72u

static void put32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}
static void put64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}
static void putf(uint8_t *p, float f)
{
    uint32_t v;
    memcpy(&v, &f, 4);
    put32(p, v);
}
static uint32_t get32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static uint64_t get64(const uint8_t *p) { return (uint64_t)get32(p) | (uint64_t)get32(p + 4) << 32; }
static float getf(const uint8_t *p)
{
    uint32_t v = get32(p);
    float f;
    memcpy(&f, &v, 4);
    return f;
}

/* FNV-1a, 64 bits, over the blob with the checksum field taken as zero. */
static uint64_t blob_checksum(const uint8_t *data, size_t size)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < size; i++) {
        uint8_t byte = (i >= PVS_CHECKSUM_OFFSET && i < PVS_CHECKSUM_OFFSET + 8) ? 0 : data[i];
        h = (h ^ byte) * 0x100000001b3ull;
    }
    return h;
}

/* Size of a blob with these counts, or 0 on overflow. */
static uint64_t blob_size(uint64_t buckets, uint64_t cells, uint64_t chunks, uint64_t data)
{
    if (buckets > UINT32_MAX || cells > UINT32_MAX || chunks > UINT32_MAX || data > (UINT64_MAX >> 2))
        return 0;
    return PVS_HEADER_SIZE + buckets * PVS_BUCKET_SIZE + cells * PVS_CELL_SIZE + chunks * PVS_CHUNK_SIZE + data;
}

size_t gdr_pvs_serialized_size(const gdr_pvs *pvs)
{
    return (size_t)blob_size((uint64_t)pvs->bucket_x * pvs->bucket_z, pvs->cell_count, pvs->chunk_count,
                             pvs->data_size);
}

gdr_status gdr_pvs_serialize(const gdr_pvs *pvs, void *destination, size_t capacity, gdr_error *err)
{
    size_t size = gdr_pvs_serialized_size(pvs);
    if (!destination || capacity < size)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "pvs serialize: %zu bytes needed, %zu given", size,
                             capacity);
    uint8_t *p = destination;
    memset(p, 0, PVS_HEADER_SIZE);
    memcpy(p, PVS_MAGIC, 8);
    put32(p + 8, PVS_VERSION);
    put32(p + 12, PVS_HEADER_SIZE);
    put32(p + 16, pvs->object_count);
    for (int a = 0; a < 3; a++)
        put32(p + 20 + 4 * a, pvs->grid[a]);
    putf(p + 32, pvs->origin.x);
    putf(p + 36, pvs->origin.y);
    putf(p + 40, pvs->origin.z);
    putf(p + 44, pvs->cell_size);
    put32(p + 48, pvs->bucket_x);
    put32(p + 52, pvs->bucket_z);
    put32(p + 56, pvs->cell_count);
    put32(p + 60, pvs->chunk_count);
    put64(p + 64, pvs->data_size);
    uint8_t *q = p + PVS_HEADER_SIZE;
    for (uint32_t b = 0; b < pvs->bucket_x * pvs->bucket_z; b++, q += PVS_BUCKET_SIZE) {
        put32(q, pvs->buckets[b].first_cell);
        put32(q + 4, pvs->buckets[b].cell_count);
    }
    for (uint32_t c = 0; c < pvs->cell_count; c++, q += PVS_CELL_SIZE) {
        const pvs_cell *cell = &pvs->cells[c];
        put32(q, cell->x);
        put32(q + 4, cell->y);
        put32(q + 8, cell->z);
        put32(q + 12, cell->chunk);
        put32(q + 16, cell->offset);
    }
    for (uint32_t k = 0; k < pvs->chunk_count; k++, q += PVS_CHUNK_SIZE) {
        const pvs_chunk *chunk = &pvs->chunks[k];
        put64(q, chunk->data_offset);
        put32(q + 8, chunk->compressed_size);
        put32(q + 12, chunk->uncompressed_size);
        put32(q + 16, chunk->flags);
        put32(q + 20, 0);
    }
    if (pvs->data_size)
        memcpy(q, pvs->data, (size_t)pvs->data_size);
    put64(p + PVS_CHECKSUM_OFFSET, blob_checksum(p, size));
    return GDR_OK;
}

#define REFUSE(...) gdr_error_set(err, GDR_ERROR_PARSE, __VA_ARGS__)

static gdr_status parse_header(const uint8_t *p, size_t size, gdr_pvs *pvs, gdr_error *err)
{
    if (size < PVS_HEADER_SIZE)
        return REFUSE("pvs blob: %zu bytes is shorter than the %u-byte header", size, PVS_HEADER_SIZE);
    if (memcmp(p, PVS_MAGIC, 8) != 0)
        return REFUSE("pvs blob: bad magic");
    if (get32(p + 8) != PVS_VERSION)
        return REFUSE("pvs blob: version %u, expected %u", get32(p + 8), PVS_VERSION);
    if (get32(p + 12) != PVS_HEADER_SIZE)
        return REFUSE("pvs blob: header_size %u, expected %u", get32(p + 12), PVS_HEADER_SIZE);
    pvs->object_count = get32(p + 16);
    if (pvs->object_count > PVS_MAX_OBJECTS)
        return REFUSE("pvs blob: object_count %u exceeds %u", pvs->object_count, PVS_MAX_OBJECTS);
    uint64_t cells = 1;
    for (int a = 0; a < 3; a++) {
        pvs->grid[a] = get32(p + 20 + 4 * a);
        if (pvs->grid[a] == 0 || pvs->grid[a] > PVS_MAX_GRID_CELLS)
            return REFUSE("pvs blob: grid[%d] = %u is out of range", a, pvs->grid[a]);
        cells *= pvs->grid[a];
        if (cells > PVS_MAX_GRID_CELLS)
            return REFUSE("pvs blob: the grid has more than %u cells", PVS_MAX_GRID_CELLS);
    }
    pvs->origin = (gdr_vec3){getf(p + 32), getf(p + 36), getf(p + 40)};
    pvs->cell_size = getf(p + 44);
    if (!isfinite(pvs->origin.x) || !isfinite(pvs->origin.y) || !isfinite(pvs->origin.z) ||
        !isfinite(pvs->cell_size) || !(pvs->cell_size > 0.0f))
        return REFUSE("pvs blob: origin or cell_size is not a finite positive value");
    pvs->bucket_x = get32(p + 48);
    pvs->bucket_z = get32(p + 52);
    if (pvs->bucket_x == 0 || pvs->bucket_x > PVS_MAX_BUCKETS_PER_AXIS || pvs->bucket_z == 0 ||
        pvs->bucket_z > PVS_MAX_BUCKETS_PER_AXIS)
        return REFUSE("pvs blob: bucket grid %u x %u is out of range", pvs->bucket_x, pvs->bucket_z);
    pvs->cell_count = get32(p + 56);
    pvs->chunk_count = get32(p + 60);
    pvs->data_size = get64(p + 64);
    if (pvs->cell_count > cells)
        return REFUSE("pvs blob: cell_count %u exceeds the grid's %llu cells", pvs->cell_count,
                      (unsigned long long)cells);
    if (pvs->chunk_count > pvs->cell_count)
        return REFUSE("pvs blob: chunk_count %u exceeds cell_count %u", pvs->chunk_count, pvs->cell_count);
    uint64_t expected = blob_size((uint64_t)pvs->bucket_x * pvs->bucket_z, pvs->cell_count, pvs->chunk_count,
                                  pvs->data_size);
    if (expected == 0 || expected != size)
        return REFUSE("pvs blob: size %zu, the header describes %llu bytes", size, (unsigned long long)expected);
    if (get64(p + PVS_CHECKSUM_OFFSET) != blob_checksum(p, size))
        return REFUSE("pvs blob: checksum mismatch");
    return GDR_OK;
}

/* Reads the bucket, cell and chunk tables and checks them against each other. A chunk holds
 * exactly the bitsets of the cells that refer to it, one each: its uncompressed size must be
 * (its cell count) x (bytes per bitset), and its cells' offsets must tile it. So the size of
 * every buffer the loader and the lookup cache allocate follows from the object count and the
 * cell table, never from a size field alone. */
static gdr_status parse_tables(const uint8_t *p, gdr_pvs *pvs, uint32_t *scratch, gdr_error *err)
{
    uint32_t bucket_count = pvs->bucket_x * pvs->bucket_z;
    uint64_t cell_bytes = (uint64_t)gdr_cull_word_count(pvs->object_count) * 4;
    const uint8_t *q = p + PVS_HEADER_SIZE;
    uint32_t next_cell = 0;
    for (uint32_t b = 0; b < bucket_count; b++, q += PVS_BUCKET_SIZE) {
        pvs_bucket *bucket = &pvs->buckets[b];
        bucket->first_cell = get32(q);
        bucket->cell_count = get32(q + 4);
        /* buckets partition the cell table in order */
        if (bucket->first_cell != next_cell || bucket->cell_count > pvs->cell_count - next_cell)
            return REFUSE("pvs blob: buckets[%u] covers cells [%u, +%u), expected to start at %u", b,
                          bucket->first_cell, bucket->cell_count, next_cell);
        next_cell += bucket->cell_count;
    }
    if (next_cell != pvs->cell_count)
        return REFUSE("pvs blob: buckets cover %u of %u cells", next_cell, pvs->cell_count);
    const uint8_t *cells = q;
    q += (size_t)pvs->cell_count * PVS_CELL_SIZE;
    for (uint32_t k = 0; k < pvs->chunk_count; k++, q += PVS_CHUNK_SIZE) {
        pvs_chunk *chunk = &pvs->chunks[k];
        chunk->data_offset = get64(q);
        chunk->compressed_size = get32(q + 8);
        chunk->uncompressed_size = get32(q + 12);
        chunk->flags = get32(q + 16);
        if (chunk->data_offset > pvs->data_size || chunk->compressed_size > pvs->data_size - chunk->data_offset)
            return REFUSE("pvs blob: chunks[%u] data [%llu, +%u) exceeds the %llu data bytes", k,
                          (unsigned long long)chunk->data_offset, chunk->compressed_size,
                          (unsigned long long)pvs->data_size);
        if ((chunk->flags & ~PVS_CHUNK_ZSTD) || get32(q + 20) != 0)
            return REFUSE("pvs blob: chunks[%u] has unknown flags 0x%x", k, chunk->flags);
        if (!(chunk->flags & PVS_CHUNK_ZSTD) && chunk->compressed_size != chunk->uncompressed_size)
            return REFUSE("pvs blob: stored chunks[%u] has %u bytes, expected %u", k, chunk->compressed_size,
                          chunk->uncompressed_size);
    }
    /* scratch[k]: cells of chunk k (first pass), then the first tile of chunk k (second pass) */
    memset(scratch, 0, sizeof(uint32_t) * pvs->chunk_count);
    for (uint32_t c = 0; c < pvs->cell_count; c++) {
        const uint8_t *e = cells + (size_t)c * PVS_CELL_SIZE;
        pvs_cell *cell = &pvs->cells[c];
        *cell = (pvs_cell){get32(e), get32(e + 4), get32(e + 8), get32(e + 12), get32(e + 16)};
        if (cell->x >= pvs->grid[0] || cell->y >= pvs->grid[1] || cell->z >= pvs->grid[2])
            return REFUSE("pvs blob: cells[%u] (%u, %u, %u) is outside the grid", c, cell->x, cell->y, cell->z);
        const pvs_bucket *bucket = &pvs->buckets[pvs_bucket_of(pvs, cell->x, cell->z)];
        if (c < bucket->first_cell || c >= bucket->first_cell + bucket->cell_count)
            return REFUSE("pvs blob: cells[%u] is not in its bucket", c);
        if (cell->chunk >= pvs->chunk_count)
            return REFUSE("pvs blob: cells[%u].chunk %u exceeds %u", c, cell->chunk, pvs->chunk_count);
        scratch[cell->chunk]++;
    }
    /* the exact size of each chunk, before anything is decompressed or allocated for it */
    uint32_t tiles = 0;
    for (uint32_t k = 0; k < pvs->chunk_count; k++) {
        pvs_chunk *chunk = &pvs->chunks[k];
        uint64_t exact = scratch[k] * cell_bytes;
        if (scratch[k] == 0)
            return REFUSE("pvs blob: chunks[%u] holds no cell", k);
        if (exact > PVS_MAX_CHUNK_BYTES)
            return REFUSE("pvs blob: chunks[%u] holds %u cells of %llu bytes, more than %u bytes", k, scratch[k],
                          (unsigned long long)cell_bytes, PVS_MAX_CHUNK_BYTES);
        if (chunk->uncompressed_size != exact)
            return REFUSE("pvs blob: chunks[%u] uncompressed_size %u, its %u cells of %u objects need %llu", k,
                          chunk->uncompressed_size, scratch[k], pvs->object_count, (unsigned long long)exact);
        if (chunk->uncompressed_size > pvs->max_chunk_bytes)
            pvs->max_chunk_bytes = chunk->uncompressed_size;
        uint32_t count = scratch[k];
        scratch[k] = tiles;
        tiles += count;
    }
    /* each cell of a chunk owns one tile of it: offset = tile * cell_bytes, no tile shared */
    uint32_t *owner = scratch + pvs->chunk_count; /* per tile: cell + 1, or 0 */
    memset(owner, 0, sizeof(uint32_t) * pvs->cell_count);
    for (uint32_t c = 0; c < pvs->cell_count; c++) {
        const pvs_cell *cell = &pvs->cells[c];
        const pvs_chunk *chunk = &pvs->chunks[cell->chunk];
        uint64_t tile = cell_bytes ? cell->offset / cell_bytes : 0;
        if ((cell_bytes ? cell->offset % cell_bytes : cell->offset) != 0 ||
            (uint64_t)cell->offset + cell_bytes > chunk->uncompressed_size)
            return REFUSE("pvs blob: cells[%u] bitset at %u (+%llu) is not a bitset of chunk %u of %u bytes", c,
                          cell->offset, (unsigned long long)cell_bytes, cell->chunk, chunk->uncompressed_size);
        if (cell_bytes == 0)
            continue; /* no objects: every bitset is empty */
        uint32_t *slot = &owner[scratch[cell->chunk] + tile];
        if (*slot)
            return REFUSE("pvs blob: cells[%u] and cells[%u] share the bitset at %u of chunk %u", *slot - 1, c,
                          cell->offset, cell->chunk);
        *slot = c + 1;
    }
    return GDR_OK;
}

/* Every compressed chunk is one zstd frame that states exactly the chunk's size (checked for all
 * chunks before the buffer is allocated) and decompresses to exactly that size. */
static gdr_status check_chunks(gdr_pvs *pvs, gdr_error *err)
{
    for (uint32_t k = 0; k < pvs->chunk_count; k++) {
        const pvs_chunk *chunk = &pvs->chunks[k];
        if (!(chunk->flags & PVS_CHUNK_ZSTD))
            continue;
        const uint8_t *src = pvs->data + chunk->data_offset;
        size_t frame = ZSTD_findFrameCompressedSize(src, chunk->compressed_size);
        if (ZSTD_isError(frame) || frame != chunk->compressed_size)
            return REFUSE("pvs blob: chunks[%u] is not one zstd frame of %u bytes", k, chunk->compressed_size);
        unsigned long long stated = ZSTD_getFrameContentSize(src, chunk->compressed_size);
        if (stated != chunk->uncompressed_size)
            return REFUSE("pvs blob: chunks[%u] zstd frame states %s bytes, the chunk has %u", k,
                          stated == ZSTD_CONTENTSIZE_UNKNOWN ? "no size" : stated == ZSTD_CONTENTSIZE_ERROR
                                                                               ? "a damaged header and no"
                                                                               : "another number of",
                          chunk->uncompressed_size);
    }
    uint8_t *buffer = malloc(pvs->max_chunk_bytes ? pvs->max_chunk_bytes : 1);
    if (!buffer)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "pvs blob: out of memory");
    gdr_status st = GDR_OK;
    for (uint32_t k = 0; k < pvs->chunk_count && st == GDR_OK; k++) {
        const pvs_chunk *chunk = &pvs->chunks[k];
        if (!(chunk->flags & PVS_CHUNK_ZSTD))
            continue;
        /* capacity = the exact size: a frame that would write more fails instead */
        size_t n = ZSTD_decompress(buffer, chunk->uncompressed_size, pvs->data + chunk->data_offset,
                                   chunk->compressed_size);
        if (ZSTD_isError(n) || n != chunk->uncompressed_size)
            st = REFUSE("pvs blob: chunks[%u] does not decompress to its %u bytes: %s", k, chunk->uncompressed_size,
                        ZSTD_isError(n) ? ZSTD_getErrorName(n) : "fewer bytes");
    }
    free(buffer);
    return st;
}

gdr_status gdr_pvs_load(const void *data, size_t size, gdr_pvs **out, gdr_error *err)
{
    *out = NULL;
    if (!data && size)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "pvs blob: data is NULL");
    const uint8_t *p = data;
    gdr_pvs *pvs = calloc(1, sizeof(*pvs));
    if (!pvs)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "pvs blob: out of memory");
    uint32_t *scratch = NULL;
    gdr_status st = parse_header(p, size, pvs, err);
    if (st == GDR_OK) {
        /* sizes are now bounded by the blob's own size */
        pvs->buckets = calloc((size_t)pvs->bucket_x * pvs->bucket_z, sizeof(pvs_bucket));
        pvs->cells = calloc(pvs->cell_count ? pvs->cell_count : 1, sizeof(pvs_cell));
        pvs->chunks = calloc(pvs->chunk_count ? pvs->chunk_count : 1, sizeof(pvs_chunk));
        pvs->data = malloc(pvs->data_size ? (size_t)pvs->data_size : 1);
        scratch = malloc(sizeof(uint32_t) * ((size_t)pvs->chunk_count + pvs->cell_count + 1));
        if (!pvs->buckets || !pvs->cells || !pvs->chunks || !pvs->data || !scratch)
            st = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "pvs blob: out of memory");
    }
    if (st == GDR_OK) {
        if (pvs->data_size)
            memcpy(pvs->data, p + size - pvs->data_size, (size_t)pvs->data_size);
        st = parse_tables(p, pvs, scratch, err);
    }
    free(scratch);
    if (st == GDR_OK)
        st = check_chunks(pvs, err);
    if (st != GDR_OK) {
        gdr_pvs_destroy(pvs);
        return st;
    }
    *out = pvs;
    return GDR_OK;
}
