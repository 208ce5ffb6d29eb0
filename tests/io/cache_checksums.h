/* Tests that damage a cache file on purpose: the checksums made right again (every section's, the
 * section table's, the header's), so that the reader meets the damage itself rather than a checksum
 * mismatch. Sections whose table entry points outside the file keep their old checksum. Needs
 * libxxhash. */
#ifndef GDR_TEST_CACHE_CHECKSUMS_H
#define GDR_TEST_CACHE_CHECKSUMS_H

#include <stdint.h>
#include <string.h>
#include <xxhash.h>

static inline void test_cache_fix_checksums(uint8_t *data, size_t size)
{
    uint32_t count;
    memcpy(&count, data + 16, 4);
    for (uint32_t i = 0; i < count; i++) {
        uint8_t *e = data + 64 + (size_t)i * 32;
        uint64_t offset, length, h;
        memcpy(&offset, e + 8, 8);
        memcpy(&length, e + 16, 8);
        if (offset <= size && length <= size - offset) {
            h = XXH3_64bits(data + offset, (size_t)length);
            memcpy(e + 24, &h, 8);
        }
    }
    uint64_t h = XXH3_64bits(data + 64, (size_t)count * 32);
    memcpy(data + 32, &h, 8);
    h = XXH3_64bits(data, 40);
    memcpy(data + 40, &h, 8);
}

#endif
