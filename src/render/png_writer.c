/* PNG output: stb_image_write encodes into memory, gdr_write_file_atomic puts it in place. */
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image_write.h>

#include "gdr/renderer.h"

typedef struct png_buffer {
    unsigned char *data;
    size_t size, capacity;
    bool failed;
} png_buffer;

static void append_png_bytes(void *context, void *bytes, int count)
{
    png_buffer *b = context;
    if (b->failed || count <= 0)
        return;
    if (b->size + (size_t)count > b->capacity) {
        size_t capacity = b->capacity ? b->capacity * 2 : 1 << 16;
        while (capacity < b->size + (size_t)count)
            capacity *= 2;
        unsigned char *grown = realloc(b->data, capacity);
        if (!grown) {
            b->failed = true;
            return;
        }
        b->data = grown;
        b->capacity = capacity;
    }
    memcpy(b->data + b->size, bytes, (size_t)count);
    b->size += (size_t)count;
}

gdr_status gdr_write_png(const char *path, const uint8_t *rgba, uint32_t width, uint32_t height, gdr_error *err)
{
    if (width == 0 || height == 0 || width > 65535 || height > 65535)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: image size %ux%u is not writable", path, width, height);
    png_buffer buffer = {0};
    int encoded = stbi_write_png_to_func(append_png_bytes, &buffer, (int)width, (int)height, 4, rgba, (int)width * 4);
    gdr_status status;
    if (!encoded || buffer.failed)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: PNG encoding failed (out of memory)", path);
    else
        status = gdr_write_file_atomic(path, buffer.data, buffer.size, err);
    free(buffer.data);
    return status;
}
