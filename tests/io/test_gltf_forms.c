/* Generated glTF cases, one per accessor form and extension: component types, normalized,
 * byteStride, sparse, data: URIs, GLB, external files, strips and fans, node transforms, shared
 * meshes, EXT_mesh_gpu_instancing, cameras, textures, KHR_mesh_quantization and
 * EXT_meshopt_compression; and errors that must name the place. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>
#include <stb/stb_image_write.h>

#include "gdr/io.h"
#include "io_test_helpers.h"
#include "test_util.h"
#include "io/loaders.h"

static char json[65536];
static test_warnings warnings;
static gdr_error err;

static gdr_scene *import_text(const char *text, const char *base_dir)
{
    memset(&warnings, 0, sizeof warnings);
    memset(&err, 0, sizeof err);
    gdr_import_options options = {.warning = test_collect_warning, .warning_user = &warnings, .no_progress = 1};
    gdr_scene *scene = NULL;
    if (gdr_import_gltf_memory(text, strlen(text), "test.gltf", base_dir, &options, &scene, NULL, &err) != GDR_OK)
        return NULL;
    return scene;
}

static const float quad_positions[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};

/* Quantized attributes (KHR_mesh_quantization): normalized short/byte/ushort, ubyte indices. */
static void test_component_types(void)
{
    test_bytes b = {0};
    int16_t positions[16] = {0, 0, 0, 0, 32767, 0, 0, 0, 32767, 32767, 0, 0, 0, 32767, 0, 0}; /* VEC3 + pad */
    int8_t normals[16] = {0, 0, 127, 0, 0, 0, 127, 0, 0, 0, -128, 0, 0, 0, 127, 0};
    uint16_t uvs[8] = {0, 0, 65535, 0, 65535, 65535, 0, 65535};
    uint8_t indices[6] = {0, 1, 2, 0, 2, 3};
    size_t op = test_append(&b, positions, sizeof positions), on = test_append(&b, normals, sizeof normals);
    size_t ou = test_append(&b, uvs, sizeof uvs), oi = test_append(&b, indices, sizeof indices);
    char *uri = test_data_uri(b.data, b.size);
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_mesh_quantization\"],"
             "\"extensionsRequired\":[\"KHR_mesh_quantization\"],"
             "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":32,\"byteStride\":8},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":16,\"byteStride\":4},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":16},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":6}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5122,\"normalized\":true,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5120,\"normalized\":true,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":2,\"componentType\":5123,\"normalized\":true,\"count\":4,\"type\":\"VEC2\"},"
             "{\"bufferView\":3,\"componentType\":5121,\"count\":6,\"type\":\"SCALAR\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":3}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0}",
             uri, b.size, op, on, ou, oi);
    free(uri);
    gdr_scene *s = import_text(json, NULL);
    CHECK(s != NULL);
    if (!s) {
        fprintf(stderr, "component types: %s\n", err.message);
        return;
    }
    CHECK(s->mesh_count == 1 && s->instance_count == 1);
    gdr_mesh *m = &s->meshes[0];
    CHECK(m->vertex_count == 4 && m->index_count == 6);
    for (int i = 0; i < 12; i++)
        CHECK_NEAR((&m->positions[0].x)[i], quad_positions[i], 1e-6);
    CHECK_NEAR(m->normals[2].z, -1.0, 1e-6); /* -128 clamps to -1 */
    CHECK_NEAR(m->normals[0].z, 1.0, 1e-6);
    CHECK_NEAR(m->uvs[2].x, 1.0, 1e-6);
    CHECK_NEAR(m->uvs[2].y, 1.0, 1e-6);
    CHECK(m->indices[5] == 3);
    CHECK(s->extensions && strcmp(s->extensions, "KHR_mesh_quantization") == 0);
    gdr_scene_destroy(s);
}

/* Interleaved float positions/normals (byteStride 24), uint indices, sparse positions. */
static void test_stride_and_sparse(void)
{
    test_bytes b = {0};
    float interleaved[24];
    for (int v = 0; v < 4; v++) {
        memcpy(interleaved + v * 6, quad_positions + v * 3, 12);
        float n[3] = {0, 0, 2}; /* not unit: normalised on import */
        memcpy(interleaved + v * 6 + 3, n, 12);
    }
    uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
    uint16_t sparse_indices[2] = {1, 3};
    float sparse_values[6] = {5, 0, 0, 0, 7, 0};
    size_t ov = test_append(&b, interleaved, sizeof interleaved), oi = test_append(&b, indices, sizeof indices);
    size_t osi = test_append(&b, sparse_indices, sizeof sparse_indices);
    size_t osv = test_append(&b, sparse_values, sizeof sparse_values);
    char *uri = test_data_uri(b.data, b.size);
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":96,\"byteStride\":24},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":24},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":4},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":24}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
             "\"sparse\":{\"count\":2,\"indices\":{\"bufferView\":2,\"componentType\":5123},\"values\":{\"bufferView\":3}}},"
             "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"},"
             "{\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
             "\"sparse\":{\"count\":2,\"indices\":{\"bufferView\":2,\"componentType\":5123},\"values\":{\"bufferView\":3}}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]},"
             "{\"primitives\":[{\"attributes\":{\"POSITION\":3},\"mode\":0}]}],"
             "\"nodes\":[{\"mesh\":0},{\"mesh\":1}],\"scenes\":[{\"nodes\":[0,1]}]}",
             uri, b.size, ov, oi, osi, osv);
    free(uri);
    gdr_scene *s = import_text(json, NULL);
    CHECK(s != NULL);
    if (!s) {
        fprintf(stderr, "stride/sparse: %s\n", err.message);
        return;
    }
    CHECK(s->mesh_count == 1 && s->instance_count == 1);
    CHECK(warnings.count == 1 && strstr(warnings.text, "meshes[1].primitives[0]: mode 0 (points) skipped"));
    gdr_mesh *m = &s->meshes[0];
    CHECK_NEAR(m->positions[1].x, 5.0, 0);
    CHECK_NEAR(m->positions[3].y, 7.0, 0);
    CHECK_NEAR(m->positions[2].x, 1.0, 0);
    CHECK_NEAR(m->normals[3].z, 1.0, 1e-6);
    gdr_scene_destroy(s);
}

/* Strips and fans without indices; generated normals. */
static void test_topologies(void)
{
    char *uri = test_data_uri(quad_positions, sizeof quad_positions);
    for (int mode = 5; mode <= 6; mode++) {
        snprintf(json, sizeof json,
                 "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"%s\",\"byteLength\":48}],"
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":%d}]}],"
                 "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
                 uri, mode);
        gdr_scene *s = import_text(json, NULL);
        CHECK(s != NULL);
        if (!s)
            continue;
        gdr_mesh *m = &s->meshes[0];
        CHECK(m->index_count == 6);
        /* Both triangles face +Z for a fan 0-1-2-3; for a strip 0,1,2,3 the second flips back. */
        for (uint32_t t = 0; t < m->index_count; t += 3) {
            gdr_vec3 a = m->positions[m->indices[t]], bb = m->positions[m->indices[t + 1]];
            gdr_vec3 c = m->positions[m->indices[t + 2]];
            gdr_vec3 n = gdr_vec3_cross(gdr_vec3_sub(bb, a), gdr_vec3_sub(c, a));
            if (mode == 6)
                CHECK(n.z > 0);
            else
                CHECK(fabsf(n.z) > 0);
        }
        if (mode == 5) {
            CHECK(m->indices[0] == 0 && m->indices[1] == 1 && m->indices[2] == 2);
            CHECK(m->indices[3] == 1 && m->indices[4] == 3 && m->indices[5] == 2);
        }
        CHECK_NEAR(fabsf(m->normals[0].z), 1.0, 1e-6);
        gdr_scene_destroy(s);
    }
    free(uri);
}

/* Node hierarchy (TRS under a parent, a matrix node), one mesh shared by three nodes,
 * EXT_mesh_gpu_instancing and a perspective camera. */
static void test_nodes_instancing_cameras(void)
{
    test_bytes b = {0};
    float translations[9] = {10, 0, 0, 20, 0, 0, 30, 0, 0};
    size_t op = test_append(&b, quad_positions, sizeof quad_positions);
    size_t ot = test_append(&b, translations, sizeof translations);
    char *uri = test_data_uri(b.data, b.size);
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\"],"
             "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":48},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
             "\"meshes\":[{\"name\":\"quad\",\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":null,"
             "\"mode\":6}]}],"
             "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,\"znear\":0.1,\"aspectRatio\":1.5}}],"
             "\"nodes\":[{\"translation\":[1,2,3],\"rotation\":[0,0.70710678,0,0.70710678],\"children\":[1,3]},"
             "{\"scale\":[2,2,2],\"mesh\":0},"
             "{\"matrix\":[1,0,0,0, 0,1,0,0, 0,0,1,0, 5,6,7,1],\"mesh\":0},"
             "{\"translation\":[0,0,5],\"camera\":0},"
             "{\"mesh\":0,\"extensions\":{\"EXT_mesh_gpu_instancing\":{\"attributes\":{\"TRANSLATION\":1}}}}],"
             "\"scenes\":[{\"nodes\":[0,2,4]}]}",
             uri, b.size, op, ot);
    free(uri);
    gdr_scene *s = import_text(json, NULL);
    /* "indices": null is a wrong JSON type and must be refused with its place. */
    CHECK(s == NULL);
    CHECK_STATUS(err, GDR_ERROR_PARSE);
    CHECK_NAMES(err, "meshes[0].primitives[0].indices");
    gdr_scene_destroy(s);
    char *null_at = strstr(json, "\"indices\":null,");
    memmove(null_at, null_at + 15, strlen(null_at + 15) + 1);
    s = import_text(json, NULL);
    CHECK(s != NULL);
    if (!s) {
        fprintf(stderr, "nodes: %s\n", err.message);
        return;
    }
    CHECK(s->mesh_count == 1);
    CHECK(s->instance_count == 5);
    CHECK(s->camera_count == 1);
    /* Instance 0: parent T(1,2,3) R(90 deg about Y), child S(2): local x axis -> world -z, scaled. */
    gdr_vec3 p = gdr_mat4_transform_point(s->instances[0].transform, (gdr_vec3){1, 0, 0});
    CHECK_NEAR(p.x, 1.0, 1e-5);
    CHECK_NEAR(p.y, 2.0, 1e-5);
    CHECK_NEAR(p.z, 1.0, 1e-5);
    p = gdr_mat4_transform_point(s->instances[1].transform, (gdr_vec3){0, 0, 0});
    CHECK_NEAR(p.x, 5.0, 0);
    CHECK_NEAR(p.z, 7.0, 0);
    for (int i = 0; i < 3; i++) {
        p = gdr_mat4_transform_point(s->instances[2 + i].transform, (gdr_vec3){0, 0, 0});
        CHECK_NEAR(p.x, 10.0 * (i + 1), 1e-6);
    }
    gdr_camera *cam = &s->cameras[0];
    /* Camera at parent * T(0,0,5): (1,2,3) + R(0,0,5) = (6,2,3). */
    CHECK_NEAR(cam->position.x, 6.0, 1e-5);
    CHECK_NEAR(cam->position.y, 2.0, 1e-5);
    CHECK_NEAR(cam->position.z, 3.0, 1e-5);
    CHECK_NEAR(fabsf(cam->rotation.y), 0.70710678, 1e-5);
    CHECK_NEAR(cam->yfov, 0.8, 1e-6);
    CHECK_NEAR(cam->aspect, 1.5, 1e-6);
    CHECK(cam->zfar == 0.0f);
    gdr_scene_destroy(s);
}

static void png_to_bytes(void *context, void *data, int size)
{
    test_bytes *b = context;
    memcpy(b->data + b->size, data, (size_t)size);
    b->size += (size_t)size;
}

/* GLB with a binary chunk holding geometry and a PNG (texture from a buffer view), plus
 * the same as .gltf with an external .bin and .png next to it. */
static void test_glb_and_files(void)
{
    uint8_t pixels[4 * 4 * 4];
    for (int i = 0; i < 64; i++)
        pixels[i] = (uint8_t)(i * 4);
    test_bytes png = {0};
    stbi_write_png_to_func(png_to_bytes, &png, 4, 4, 4, pixels, 16);
    test_bytes bin = {0};
    uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
    size_t op = test_append(&bin, quad_positions, sizeof quad_positions);
    size_t oi = test_append(&bin, indices, sizeof indices);
    size_t oimg = test_append(&bin, png.data, png.size);
    while (bin.size % 4)
        bin.data[bin.size++] = 0;
    const char *common =
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":48},"
        "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":12},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
        "{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}],"
        "\"materials\":[{\"name\":\"m\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0.5,0.25,1],"
        "\"baseColorTexture\":{\"index\":0},\"metallicFactor\":0.25},\"normalTexture\":{\"index\":1},"
        "\"alphaMode\":\"MASK\",\"doubleSided\":true}],"
        "\"textures\":[{\"source\":0},{\"source\":1}],";
    char middle[2048];
    snprintf(middle, sizeof middle, common, op, oi, oimg, png.size);
    const char *tail = "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":0}]}],"
                       "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}";

    /* GLB: images from the buffer view. */
    int n = snprintf(json, sizeof json,
                     "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu}],%s"
                     "\"images\":[{\"bufferView\":2,\"mimeType\":\"image/png\"},{\"bufferView\":2,"
                     "\"mimeType\":\"image/png\"}],%s",
                     bin.size, middle, tail);
    while (n % 4)
        json[n++] = ' ';
    size_t total = 12 + 8 + (size_t)n + 8 + bin.size;
    uint8_t *glb = malloc(total);
    uint32_t header[3] = {0x46546C67u, 2, (uint32_t)total}, chunk[2] = {(uint32_t)n, 0x4E4F534Au};
    uint32_t bin_chunk[2] = {(uint32_t)bin.size, 0x004E4942u};
    memcpy(glb, header, 12);
    memcpy(glb + 12, chunk, 8);
    memcpy(glb + 20, json, (size_t)n);
    memcpy(glb + 20 + n, bin_chunk, 8);
    memcpy(glb + 28 + n, bin.data, bin.size);
    char path[1024];
    snprintf(path, sizeof path, "%s/forms.glb", GDR_IO_TEST_TMP);
    CHECK(test_write_file(path, glb, total));
    gdr_scene *s = NULL;
    gdr_import_options options = {.no_progress = 1};
    CHECK(gdr_import_gltf(path, &options, &s, NULL, &err) == GDR_OK);
    if (s) {
        CHECK(s->instance_count == 1 && s->material_count == 1 && s->texture_count == 2);
        gdr_material *m = &s->materials[0];
        CHECK(m->base_color_texture.texture == 0 && m->normal_texture.texture == 1 &&
              m->metallic_roughness_texture.texture == GDR_NO_INDEX);
        CHECK_NEAR(m->base_color.y, 0.5, 0);
        CHECK_NEAR(m->metallic_factor, 0.25, 0);
        CHECK(m->alpha_mode == GDR_ALPHA_MASK && m->double_sided == 1);
        CHECK(s->textures[0].width == 4 && s->textures[0].height == 4 && s->textures[0].srgb == 1);
        CHECK(s->textures[1].srgb == 0);
        CHECK(memcmp(s->textures[0].rgba, pixels, sizeof pixels) == 0);
        CHECK(s->instances[0].material == 0);
        gdr_scene_destroy(s);
    } else {
        fprintf(stderr, "glb: %s\n", err.message);
    }
    /* Every truncation of the GLB is refused or loads; never a crash (ASan watches). */
    for (size_t cut = 0; cut < total; cut += 7) {
        s = NULL;
        gdr_import_options quiet = {.warning = test_collect_warning, .warning_user = &warnings, .no_progress = 1};
        memset(&warnings, 0, sizeof warnings);
        gdr_status status = gdr_import_gltf_memory(glb, cut, "cut.glb", NULL, &quiet, &s, NULL, &err);
        CHECK(status != GDR_OK || cut >= total - 3);
        gdr_scene_destroy(s);
    }
    free(glb);

    /* .gltf with external forms.bin (a percent-encoded name) and forms image.png. */
    snprintf(path, sizeof path, "%s/forms data.bin", GDR_IO_TEST_TMP);
    CHECK(test_write_file(path, bin.data, bin.size));
    snprintf(path, sizeof path, "%s/forms image.png", GDR_IO_TEST_TMP);
    CHECK(test_write_file(path, png.data, png.size));
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"forms%%20data.bin\",\"byteLength\":%zu}],%s"
             "\"images\":[{\"uri\":\"forms image.png\"},{\"uri\":\"missing.png\"}],%s",
             bin.size, middle, tail);
    snprintf(path, sizeof path, "%s/forms.gltf", GDR_IO_TEST_TMP);
    CHECK(test_write_file(path, json, strlen(json)));
    gdr_source_list sources = {0};
    memset(&warnings, 0, sizeof warnings);
    gdr_import_options with_sources = {.warning = test_collect_warning, .warning_user = &warnings, .no_progress = 1,
                                       .sources = &sources};
    s = NULL;
    CHECK(gdr_import_gltf(path, &with_sources, &s, NULL, &err) == GDR_OK);
    if (s) {
        CHECK(s->texture_count == 1 && s->materials[0].base_color_texture.texture == 0);
        CHECK(s->materials[0].normal_texture.texture == GDR_NO_INDEX);
        CHECK(warnings.count == 1 && strstr(warnings.text, "images[1].uri") && strstr(warnings.text, "missing.png"));
        /* the .gltf, the .bin and the .png read, and missing.png looked for: a cache is rebuilt when it appears */
        CHECK(sources.count == 4);
        CHECK(sources.count == 4 && sources.files[3].state == GDR_SOURCE_ABSENT && strstr(sources.files[3].path, "/missing.png") &&
              sources.files[3].path[0] == '/');
        gdr_scene_destroy(s);
    } else {
        fprintf(stderr, "gltf files: %s\n", err.message);
    }
    gdr_source_list_free(&sources);
}

/* EXT_meshopt_compression: vertex codec + octahedral filter, triangle index codec; the buffer
 * the views point at is a fallback without data. */
static void test_meshopt(void)
{
    float positions[4 * 4]; /* padded to 16 bytes: the vertex codec wants a multiple of 4 */
    for (int v = 0; v < 4; v++) {
        memcpy(positions + v * 4, quad_positions + v * 3, 12);
        positions[v * 4 + 3] = 0;
    }
    float normal_floats[16] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0.6f, 0, 0.8f, 0};
    int8_t normals[16];
    meshopt_encodeFilterOct(normals, 4, 4, 8, normal_floats);
    uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
    test_bytes b = {0};
    uint8_t encoded[1024];
    size_t np = meshopt_encodeVertexBuffer(encoded, sizeof encoded, positions, 4, 16);
    size_t op = test_append(&b, encoded, np);
    size_t nn = meshopt_encodeVertexBuffer(encoded, sizeof encoded, normals, 4, 4);
    size_t on = test_append(&b, encoded, nn);
    size_t ni = meshopt_encodeIndexBuffer(encoded, sizeof encoded, indices, 6);
    size_t oi = test_append(&b, encoded, ni);
    char *uri = test_data_uri(b.data, b.size);
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},"
             "\"extensionsRequired\":[\"EXT_meshopt_compression\",\"KHR_mesh_quantization\"],"
             "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu},"
             "{\"byteLength\":128,\"extensions\":{\"EXT_meshopt_compression\":{\"fallback\":true}}}],"
             "\"bufferViews\":["
             "{\"buffer\":1,\"byteLength\":64,\"byteStride\":16,\"extensions\":{\"EXT_meshopt_compression\":"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":16,\"count\":4,\"mode\":\"ATTRIBUTES\"}}},"
             "{\"buffer\":1,\"byteLength\":16,\"byteStride\":4,\"extensions\":{\"EXT_meshopt_compression\":"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":4,\"count\":4,\"mode\":\"ATTRIBUTES\","
             "\"filter\":\"OCTAHEDRAL\"}}},"
             "{\"buffer\":1,\"byteLength\":24,\"extensions\":{\"EXT_meshopt_compression\":"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":4,\"count\":6,\"mode\":\"TRIANGLES\"}}}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5120,\"normalized\":true,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":2,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
             uri, b.size, op, np, on, nn, oi, ni);
    free(uri);
    gdr_scene *s = import_text(json, NULL);
    CHECK(s != NULL);
    if (!s) {
        fprintf(stderr, "meshopt: %s\n", err.message);
        return;
    }
    gdr_mesh *m = &s->meshes[0];
    CHECK(m->vertex_count == 4 && m->index_count == 6);
    for (int v = 0; v < 4; v++)
        for (int k = 0; k < 3; k++)
            CHECK_NEAR((&m->positions[v].x)[k], quad_positions[v * 3 + k], 0);
    for (int i = 0; i < 6; i++)
        CHECK(m->indices[i] == indices[i]);
    CHECK_NEAR(m->normals[2].y, 1.0, 0.02);
    CHECK_NEAR(m->normals[3].x, 0.6, 0.02);
    CHECK_NEAR(m->normals[3].z, 0.8, 0.02);
    gdr_scene_destroy(s);

    /* Using the fallback buffer directly is an error that says so. */
    char *view = strstr(json, "\"extensions\":{\"EXT_meshopt_compression\":{\"buffer\":0");
    memcpy(view, "\"extensionz", 11);
    s = import_text(json, NULL);
    CHECK(s == NULL);
    CHECK_STATUS(err, GDR_ERROR_PARSE);
    gdr_scene_destroy(s);
}

/* Broken documents: each error names the place. */
static void test_errors(void)
{
    static const struct { const char *json; gdr_status status; const char *place; } cases[] = {
        {"{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"data:application/octet-stream;base64,AAAAAAAAAAAAAAAA\","
         "\"byteLength\":12}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":12}],"
         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":100,\"type\":\"VEC3\"}],"
         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}],"
         "\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_PARSE, "test.gltf: accessors[0].count"},
        {"{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"data:application/octet-stream;base64,AAAA\","
         "\"byteLength\":12}]}",
         GDR_OK, NULL},
        {"{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"data:application/octet-stream;base64,AAAA\","
         "\"byteLength\":12}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":12}],"
         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":1,\"type\":\"VEC3\"}],"
         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}],"
         "\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_PARSE, "buffers[0].byteLength"},
        {"{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"data:application/octet-stream;base64,AA*A\","
         "\"byteLength\":1}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":1}],"
         "\"images\":[{\"bufferView\":0}],\"textures\":[{\"source\":0}],"
         "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]}",
         GDR_OK, NULL}, /* an image that fails is a warning */
        {"{\"asset\":{\"version\":\"2.0\"},\"extensionsRequired\":[\"KHR_texture_basisu\"]}",
         GDR_ERROR_UNSUPPORTED, "extensionsRequired: KHR_texture_basisu"},
        {"{\"asset\":{\"version\":\"1.0\"}}", GDR_ERROR_UNSUPPORTED, "asset.version"},
        {"{\"scenes\":[]}", GDR_ERROR_PARSE, "(root).asset"},
        {"[1,2]", GDR_ERROR_PARSE, "(root)"},
        {"{\"asset\":{\"version\":\"2.0\"},\n\"nodes\":[{\"mesh\":0}\n", GDR_ERROR_PARSE, "line 2"},
        {"{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_PARSE, "nodes[0].mesh"},
        {"{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"children\":[7]}],\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_PARSE, "nodes[0].children[0]"},
        {"{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"children\":[0]}],\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_PARSE, "nodes[0].children[0]: node 0"},
        {"{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"rotation\":[0,0,0,0]}],\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_PARSE, "nodes[0].rotation"},
        {"{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"translation\":[0,1e39,0]}],\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_PARSE, "nodes[0].translation[1]"},
        {"{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"camera\":0}],\"cameras\":[{\"type\":\"perspective\","
         "\"perspective\":{\"yfov\":-1,\"znear\":0.1}}],\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_PARSE, "cameras[0].perspective"},
        {"{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"camera\":0}],\"cameras\":[{\"type\":\"orthographic\","
         "\"orthographic\":{\"xmag\":1,\"ymag\":0,\"znear\":0,\"zfar\":10}}],\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_PARSE, "cameras[0].orthographic: xmag 1, ymag 0"},
        {"{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"camera\":0}],\"cameras\":[{\"type\":\"orthographic\","
         "\"orthographic\":{\"xmag\":1,\"ymag\":1,\"znear\":0}}],\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_PARSE, "cameras[0].orthographic: xmag 1, ymag 1, znear 0, zfar nan"},
        {"{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"http://example.com/a.bin\",\"byteLength\":4}],"
         "\"bufferViews\":[{\"buffer\":0,\"byteLength\":4}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,"
         "\"count\":1,\"type\":\"VEC3\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
         "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_UNSUPPORTED, "buffers[0].uri"},
        {"{\"asset\":{\"version\":\"2.0\"},\"accessors\":[{\"componentType\":5126,\"count\":3,\"type\":\"MAT4\"}],"
         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}],"
         "\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_UNSUPPORTED, "accessors[0].type"},
        {"{\"asset\":{\"version\":\"2.0\"},\"accessors\":[{\"componentType\":5126,\"count\":4000000000,"
         "\"type\":\"VEC3\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
         "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_UNSUPPORTED, "accessors[0].count"},
        {"{\"asset\":{\"version\":\"2.0\"},\"accessors\":[{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
         "{\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}],"
         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1}}]}],\"nodes\":[{\"mesh\":0}],"
         "\"scenes\":[{\"nodes\":[0]}]}",
         GDR_ERROR_PARSE, "attributes.NORMAL"},
        {"{\"asset\":{\"version\":\"2.0\"},\"meshes\":[{\"primitives\":[{\"attributes\":{}}]}],"
         "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
         GDR_OK, NULL}, /* no POSITION: warned and skipped */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        gdr_scene *s = import_text(cases[i].json, NULL);
        if (cases[i].place) {
            CHECK_STATUS(err, cases[i].status);
            if (s || !strstr(err.message, cases[i].place)) {
                fprintf(stderr, "error case %zu: expected '%s', got '%s'\n", i, cases[i].place,
                        s ? "(success)" : err.message);
                test_failure_count++;
            }
        } else if (i == 1) {
            CHECK(s != NULL); /* an unused short buffer is never loaded */
        } else {
            CHECK(s != NULL && warnings.count == 1);
        }
        gdr_scene_destroy(s);
    }
}

int main(void)
{
    test_component_types();
    test_stride_and_sparse();
    test_topologies();
    test_nodes_instancing_cameras();
    test_glb_and_files();
    test_meshopt();
    test_errors();
    return test_finish("test_gltf_forms");
}
