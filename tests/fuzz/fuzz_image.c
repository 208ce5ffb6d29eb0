/* libFuzzer target: the input as the one image of a minimal GLB (a bufferView, used as base colour
 * and as normal map, so decoded as sRGB and linear), imported with the fuzz budgets: the signature
 * check, libpng and libjpeg-turbo under their limits, the budgets, the mip chain. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/io.h"
#include "gdr/scene.h"
#include "io/loaders.h"

/* fuzz_geometry.h's budgets for pixels and decoded bytes: an image of up to about 600,000 pixels
 * (RGBA, mip chain and decoder memory within 8 MiB). */
static const gdr_budget image_budget = {.texture_pixels = 1u << 20, .decoded_bytes = 8u << 20};

static void ignore_warning(void *user, const char *message)
{
    (void)user;
    (void)message;
}

static volatile unsigned checksum; /* where the texels read go, so that the reads stay */

static void put_le32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > (1u << 24))
        return 0;
    char json[512];
    int json_length = snprintf(json, sizeof json,
        "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[{\"buffer\":0,"
        "\"byteLength\":%zu}],\"images\":[{\"bufferView\":0,\"mimeType\":\"image/png\"}],\"textures\":[{\"source\":0}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}},\"normalTexture\":"
        "{\"index\":0}}]}", size, size);
    size_t json_padded = ((size_t)json_length + 3) & ~(size_t)3, bin_padded = (size + 3) & ~(size_t)3;
    size_t total = 12 + 8 + json_padded + 8 + bin_padded;
    uint8_t *glb = calloc(1, total);
    if (!glb)
        return 0;
    memcpy(glb, "glTF", 4);
    put_le32(glb + 4, 2);
    put_le32(glb + 8, (uint32_t)total);
    put_le32(glb + 12, (uint32_t)json_padded);
    memcpy(glb + 16, "JSON", 4);
    memset(glb + 20, ' ', json_padded);
    memcpy(glb + 20, json, (size_t)json_length);
    uint8_t *bin = glb + 20 + json_padded;
    put_le32(bin, (uint32_t)bin_padded);
    memcpy(bin + 4, "BIN\0", 4);
    if (size)
        memcpy(bin + 8, data, size);
    gdr_import_options options = {.warning = ignore_warning, .no_progress = 1, .budget = image_budget};
    gdr_scene *scene = NULL;
    gdr_error err;
    gdr_status status = gdr_import_gltf_memory(glb, total, "fuzz.glb", NULL, &options, &scene, NULL, &err);
    free(glb);
    if (status == GDR_OK) {
        /* A texture that was made holds its whole chain: every byte is read (ASan checks the bounds). */
        unsigned sum = 0;
        for (uint32_t t = 0; t < scene->texture_count; t++) {
            const gdr_texture *tex = &scene->textures[t];
            size_t bytes = gdr_texture_level_offset(tex->width, tex->height, tex->levels);
            for (size_t i = 0; i < bytes; i++)
                sum += tex->rgba[i];
        }
        checksum = sum;
        gdr_scene_destroy(scene);
    } else if (!err.message[0]) {
        abort(); /* a refusal must say why */
    }
    return 0;
}
