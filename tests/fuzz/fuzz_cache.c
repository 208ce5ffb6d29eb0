/* libFuzzer target: the .gdrc cache reader. Checksums would reject nearly every mutation before
 * the section parsers, so a flag in the first byte (when odd) recomputes them first: both the
 * container checks and the parsers behind them get exercised. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <xxhash.h>

#include "gdr/io.h"

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
    if (fix && size >= 64) {
        uint64_t file_size = size;
        memcpy(copy + 24, &file_size, 8);
        uint32_t count;
        memcpy(&count, copy + 16, 4);
        if (count <= 1024 && 64 + (size_t)count * 32 <= size) {
            for (uint32_t i = 0; i < count; i++) {
                uint8_t *e = copy + 64 + (size_t)i * 32;
                uint64_t offset, length;
                memcpy(&offset, e + 8, 8);
                memcpy(&length, e + 16, 8);
                if (offset <= size && length <= size - offset) {
                    uint64_t h = XXH3_64bits(copy + offset, (size_t)length);
                    memcpy(e + 24, &h, 8);
                }
            }
            uint64_t h = XXH3_64bits(copy + 64, (size_t)count * 32);
            memcpy(copy + 32, &h, 8);
        }
        uint64_t h = XXH3_64bits(copy, 40);
        memcpy(copy + 40, &h, 8);
    }
    gdr_scene *scene = NULL;
    gdr_error err;
    if (gdr_cache_read_memory(copy, size, "fuzz.gdrc", &scene, &err) == GDR_OK)
        gdr_scene_destroy(scene);
    free(copy);
    return 0;
}
