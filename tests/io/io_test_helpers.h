/* Helpers for the io tests: base64, writing files, collecting warnings. */
#ifndef GDR_IO_TEST_HELPERS_H
#define GDR_IO_TEST_HELPERS_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef ASSIMP_GLTF2_DIR
#define ASSIMP_GLTF2_DIR "/usr/share/assimp/models/glTF2"
#endif

typedef struct test_warnings {
    unsigned count;
    char text[8192];
} test_warnings;

static inline void test_collect_warning(void *user, const char *message)
{
    test_warnings *w = user;
    w->count++;
    size_t used = strlen(w->text);
    snprintf(w->text + used, sizeof w->text - used, "%s\n", message);
}

/* malloc'ed "data:application/octet-stream;base64,..." for bytes. */
static inline char *test_data_uri(const void *bytes, size_t size)
{
    static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const char *prefix = "data:application/octet-stream;base64,";
    size_t prefix_length = strlen(prefix);
    char *out = malloc(prefix_length + (size + 2) / 3 * 4 + 1);
    memcpy(out, prefix, prefix_length);
    char *p = out + prefix_length;
    const uint8_t *in = bytes;
    for (size_t i = 0; i < size; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < size ? (uint32_t)in[i + 1] << 8 : 0) |
                     (i + 2 < size ? in[i + 2] : 0);
        *p++ = alphabet[v >> 18 & 63];
        *p++ = alphabet[v >> 12 & 63];
        *p++ = i + 1 < size ? alphabet[v >> 6 & 63] : '=';
        *p++ = i + 2 < size ? alphabet[v & 63] : '=';
    }
    *p = 0;
    return out;
}

static inline int test_write_file(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    size_t written = fwrite(data, 1, size, f);
    return fclose(f) == 0 && written == size;
}

/* A whole file's bytes (malloc'ed, one byte to spare; *size set), or NULL (*size 0). */
static inline uint8_t *test_read_file(const char *path, size_t *size)
{
    *size = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *data = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (data)
        *size = fread(data, 1, (size_t)n, f);
    fclose(f);
    return data;
}

/* A byte buffer that test cases append binary data to. */
typedef struct test_bytes {
    uint8_t data[65536];
    size_t size;
} test_bytes;

static inline size_t test_append(test_bytes *b, const void *data, size_t size)
{
    while (b->size % 4)
        b->data[b->size++] = 0;
    size_t offset = b->size;
    memcpy(b->data + b->size, data, size);
    b->size += size;
    return offset;
}

#endif
