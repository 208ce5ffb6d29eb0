/* glTF materials into the scene model: every texture reference with its sampler and
 * KHR_texture_transform, normal scale, occlusion strength, KHR_materials_emissive_strength, a
 * texture coordinate set other than 0 (left out with a warning), COLOR_0 in its three component
 * types, glTF's default material for primitives without one; the mip chains gdr_scene_add_texture
 * builds (against box averages computed here); and all of it through the cache. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image_write.h>

#include "gdr/io.h"
#include "io_test_helpers.h"
#include "test_util.h"
#include "io/loaders.h"

static char json[65536];
static test_warnings warnings;
static gdr_error err;

static void png_to_bytes(void *context, void *data, int size)
{
    test_bytes *b = context;
    memcpy(b->data + b->size, data, (size_t)size);
    b->size += (size_t)size;
}

static const float quad[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
static const uint16_t quad_indices[6] = {0, 1, 2, 0, 2, 3};

/* Three primitives over one quad: material 0 with float RGBA colours, no material with unorm8 RGB
 * colours, material 1 with unorm16 RGBA colours. */
static gdr_scene *import_materials(void)
{
    uint8_t pixels[4 * 2 * 4];
    for (int i = 0; i < 32; i++)
        pixels[i] = (uint8_t)(i * 8);
    test_bytes png = {0};
    stbi_write_png_to_func(png_to_bytes, &png, 4, 2, 4, pixels, 16);
    char *image = test_data_uri(png.data, png.size);
    test_bytes b = {0};
    const float colors_f[16] = {1, 0, 0, 1, 0, 1, 0, 0.5f, 0, 0, 1, 0.25f, 1, 1, 1, 0};
    const uint8_t colors_u8[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 51, 102, 204};
    const uint16_t colors_u16[16] = {65535, 0, 0, 65535, 0, 65535, 0, 65535, 0, 0, 65535, 65535, 13107, 0, 0, 0};
    size_t op = test_append(&b, quad, sizeof quad), oi = test_append(&b, quad_indices, sizeof quad_indices);
    size_t of = test_append(&b, colors_f, sizeof colors_f), o8 = test_append(&b, colors_u8, sizeof colors_u8);
    size_t o16 = test_append(&b, colors_u16, sizeof colors_u16);
    char *buffer = test_data_uri(b.data, b.size);
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},"
             "\"extensionsUsed\":[\"KHR_texture_transform\",\"KHR_materials_emissive_strength\"],"
             "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":48},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":12},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":64},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":12},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":32}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"},"
             "{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"VEC4\"},"
             "{\"bufferView\":3,\"componentType\":5121,\"normalized\":true,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":4,\"componentType\":5123,\"normalized\":true,\"count\":4,\"type\":\"VEC4\"}],"
             "\"images\":[{\"uri\":\"%s\"}],"
             "\"samplers\":[{\"magFilter\":9728,\"minFilter\":9985,\"wrapS\":33071,\"wrapT\":33648},{}],"
             "\"textures\":[{\"source\":0,\"sampler\":0},{\"source\":0,\"sampler\":1}],"
             "\"materials\":[{\"name\":\"full\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,"
             "\"extensions\":{\"KHR_texture_transform\":{\"offset\":[0.25,0.5],\"rotation\":0.5,\"scale\":[2,3]}}},"
             "\"metallicRoughnessTexture\":{\"index\":1},\"metallicFactor\":0.3,\"roughnessFactor\":0.6},"
             "\"normalTexture\":{\"index\":1,\"scale\":0.7},\"occlusionTexture\":{\"index\":1,\"strength\":0.4},"
             "\"emissiveTexture\":{\"index\":0},\"emissiveFactor\":[1,0.5,0.25],"
             "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4}}},"
             "{\"name\":\"second set\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"texCoord\":1},"
             "\"metallicRoughnessTexture\":{\"index\":1,\"extensions\":{\"KHR_texture_transform\":{\"texCoord\":1}}}}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"COLOR_0\":2},\"indices\":1,\"material\":0},"
             "{\"attributes\":{\"POSITION\":0,\"COLOR_0\":3},\"indices\":1},"
             "{\"attributes\":{\"POSITION\":0,\"COLOR_0\":4},\"indices\":1,\"material\":1}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
             buffer, b.size, op, oi, of, o8, o16, image);
    free(buffer);
    free(image);
    memset(&warnings, 0, sizeof warnings);
    gdr_import_options options = {.warning = test_collect_warning, .warning_user = &warnings, .no_progress = 1};
    gdr_scene *scene = NULL;
    if (gdr_import_gltf_memory(json, strlen(json), "materials.gltf", NULL, &options, &scene, NULL, &err) != GDR_OK)
        fprintf(stderr, "materials.gltf: %s\n", err.message);
    return scene;
}

static void check_materials(const gdr_scene *s)
{
    CHECK(s->material_count == 3 && s->instance_count == 3 && s->texture_count == 2);
    const gdr_material *m = &s->materials[0];
    CHECK(m->base_color_texture.texture != GDR_NO_INDEX && s->textures[m->base_color_texture.texture].srgb == 1);
    CHECK(m->base_color_texture.sampler == (GDR_SAMPLER_WRAP_CLAMP | GDR_SAMPLER_WRAP_MIRROR << 2 |
                                            GDR_SAMPLER_MAG_NEAREST | GDR_SAMPLER_MIP_NEAREST));
    CHECK_NEAR(m->base_color_texture.offset.x, 0.25, 0);
    CHECK_NEAR(m->base_color_texture.offset.y, 0.5, 0);
    CHECK_NEAR(m->base_color_texture.rotation, 0.5, 1e-7);
    CHECK_NEAR(m->base_color_texture.scale.x, 2, 0);
    CHECK_NEAR(m->base_color_texture.scale.y, 3, 0);
    CHECK(m->metallic_roughness_texture.sampler == 0 && s->textures[m->metallic_roughness_texture.texture].srgb == 0);
    CHECK_NEAR(m->metallic_roughness_texture.scale.x, 1, 0);
    CHECK(m->normal_texture.texture == m->metallic_roughness_texture.texture);
    CHECK(m->occlusion_texture.texture == m->metallic_roughness_texture.texture);
    CHECK(m->emissive_texture.texture == m->base_color_texture.texture);
    CHECK_NEAR(m->normal_scale, 0.7, 1e-7);
    CHECK_NEAR(m->occlusion_strength, 0.4, 1e-7);
    CHECK_NEAR(m->emissive.x, 4, 0);
    CHECK_NEAR(m->emissive.y, 2, 0);
    CHECK_NEAR(m->emissive.z, 1, 0);
    CHECK_NEAR(m->metallic_factor, 0.3, 1e-7);
    /* Texture coordinate set 1, named by the textureInfo or by the transform: left out. */
    CHECK(s->materials[1].base_color_texture.texture == GDR_NO_INDEX);
    CHECK(s->materials[1].metallic_roughness_texture.texture == GDR_NO_INDEX);
    /* The primitive without a material: glTF's default one, added after the file's. */
    CHECK(strcmp(s->materials[2].name, "default") == 0 && s->materials[2].metallic_factor == 1.0f &&
          s->materials[2].base_color_texture.texture == GDR_NO_INDEX);
    CHECK(s->instances[0].material == 0 && s->instances[1].material == 2 && s->instances[2].material == 1);
}

static void check_colors(const gdr_scene *s)
{
    const gdr_mesh *f = &s->meshes[s->instances[0].mesh], *u8 = &s->meshes[s->instances[1].mesh];
    const gdr_mesh *u16 = &s->meshes[s->instances[2].mesh];
    CHECK(f->colors && u8->colors && u16->colors);
    if (!f->colors || !u8->colors || !u16->colors)
        return;
    CHECK_NEAR(f->colors[1].w, 0.5, 0);
    CHECK_NEAR(f->colors[2].z, 1, 0);
    CHECK_NEAR(u8->colors[3].x, 0.2, 1e-6);
    CHECK_NEAR(u8->colors[3].z, 0.8, 1e-6);
    CHECK_NEAR(u8->colors[3].w, 1, 0); /* RGB: alpha 1 */
    CHECK_NEAR(u16->colors[3].x, 0.2, 1e-6);
    CHECK_NEAR(u16->colors[3].w, 0, 0);
}

/* A flipped byte in the last mip level of the texture data: the cache is refused, naming the section. */
static void test_damaged_pixels(const char *path)
{
    FILE *f = fopen(path, "rb");
    CHECK(f != NULL);
    if (!f)
        return;
    static uint8_t data[1 << 20];
    size_t size = fread(data, 1, sizeof data, f);
    fclose(f);
    uint32_t sections = 0;
    memcpy(&sections, data + 16, 4);
    uint64_t offset = 0, length = 0;
    for (uint32_t i = 0; i < sections && 64 + (size_t)i * 32 + 32 <= size; i++)
        if (memcmp(data + 64 + (size_t)i * 32, "TXPX", 4) == 0) {
            memcpy(&offset, data + 64 + (size_t)i * 32 + 8, 8);
            memcpy(&length, data + 64 + (size_t)i * 32 + 16, 8);
        }
    CHECK(length == 2 * gdr_texture_level_offset(4, 2, 3) && offset + length <= size);
    if (!length || offset + length > size)
        return;
    data[offset + length - 2] ^= 0x10; /* the 1 x 1 level of the second texture */
    gdr_scene *s = NULL;
    CHECK_FAILS(gdr_cache_read_memory(data, size, "materials.gdrc", &s, NULL, &err), err, GDR_ERROR_CORRUPT);
    CHECK(s == NULL);
    CHECK_NAMES(err, "materials.gdrc");
    CHECK_NAMES(err, "'TXPX'");
}

static void test_import_and_cache(void)
{
    gdr_scene *s = import_materials();
    CHECK(s != NULL);
    if (!s)
        return;
    check_materials(s);
    check_colors(s);
    CHECK(warnings.count == 2 && strstr(warnings.text, "texture coordinate set 1"));
    /* The cache keeps all of it, and the mip chains as they are. */
    char path[1024];
    snprintf(path, sizeof path, "%s/materials.gdrc", GDR_IO_TEST_TMP);
    CHECK(gdr_cache_write(path, s, NULL, &err) == GDR_OK);
    gdr_scene *r = NULL;
    CHECK(gdr_cache_read(path, NULL, &r, NULL, &err) == GDR_OK);
    if (r) {
        check_materials(r);
        check_colors(r);
        for (uint32_t i = 0; i < s->material_count; i++)
            CHECK(memcmp(&s->materials[i], &r->materials[i], sizeof(gdr_material)) == 0);
        for (uint32_t i = 0; i < s->texture_count; i++)
            CHECK(r->textures[i].levels == 3 &&
                  memcmp(r->textures[i].rgba, s->textures[i].rgba, gdr_texture_level_offset(4, 2, 3)) == 0);
        gdr_scene_destroy(r);
    }
    gdr_scene_destroy(s);
    test_damaged_pixels(path);
}

/* A 4 x 2 texture's levels 1 (2 x 1) and 2 (1 x 1) against box averages: of the values for linear
 * data, of the decoded values (sRGB) for colour data; alpha is a plain average. */
static double decode(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }
static double encode(double c) { return c <= 0.0031308 ? c * 12.92 : 1.055 * pow(c, 1.0 / 2.4) - 0.055; }

static void test_mip_chain(void)
{
    uint8_t texels[4 * 2 * 4];
    for (int i = 0; i < 32; i++)
        texels[i] = (uint8_t)((i * 37 + 11) % 256);
    for (int i = 0; i < 8; i++)
        texels[i * 4 + 3] = 255; /* opaque: the alpha weighting changes nothing */
    gdr_scene *s = NULL;
    CHECK(gdr_scene_create(&s, &err) == GDR_OK);
    CHECK(gdr_scene_add_texture(s, "linear", 4, 2, texels, 0, NULL, &err) == GDR_OK);
    CHECK(gdr_scene_add_texture(s, "srgb", 4, 2, texels, 1, NULL, &err) == GDR_OK);
    for (uint32_t t = 0; s && t < 2; t++) {
        const gdr_texture *tex = &s->textures[t];
        CHECK(tex->levels == 3 && gdr_texture_level_offset(4, 2, 3) == (8 + 2 + 1) * 4);
        const uint8_t *l1 = tex->rgba + gdr_texture_level_offset(4, 2, 1), *l2 = tex->rgba + gdr_texture_level_offset(4, 2, 2);
        for (int k = 0; k < 3; k++) {
            double sum2 = 0.0;
            for (int x = 0; x < 2; x++) {
                double sum = 0.0;
                for (int dy = 0; dy < 2; dy++)
                    for (int dx = 0; dx < 2; dx++) {
                        double v = texels[(dy * 4 + 2 * x + dx) * 4 + k] / 255.0;
                        sum += t ? decode(v) : v;
                    }
                double expected = t ? encode(sum / 4) : sum / 4;
                CHECK(fabs(l1[x * 4 + k] / 255.0 - expected) <= 1.0 / 255.0);
                sum2 += sum;
            }
            double expected2 = t ? encode(sum2 / 8) : sum2 / 8;
            CHECK(fabs(l2[k] / 255.0 - expected2) <= 1.5 / 255.0);
        }
        CHECK(l1[3] == 255 && l2[3] == 255);
    }
    gdr_scene_destroy(s);
}

int main(void)
{
    test_import_and_cache();
    test_mip_chain();
    return test_finish("test_gltf_materials");
}
