/* The processed-scene cache: build -> load gives an identical scene; every truncation and many
 * random byte flips are refused cleanly; stale, foreign-version and unknown-section handling;
 * gdr_scene_load_ex uses and rebuilds the cache next to the source. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <xxhash.h>

#include "gdr/io.h"
#include "geometry/cluster_checks.h"
#include "io_test_helpers.h"
#include "test_util.h"

static int same_scene(const gdr_scene *a, const gdr_scene *b)
{
    if (a->mesh_count != b->mesh_count || a->material_count != b->material_count ||
        a->instance_count != b->instance_count || a->camera_count != b->camera_count ||
        a->texture_count != b->texture_count)
        return 0;
    if ((a->extensions == NULL) != (b->extensions == NULL) ||
        (a->extensions && strcmp(a->extensions, b->extensions) != 0))
        return 0;
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        const gdr_mesh *x = &a->meshes[i], *y = &b->meshes[i];
        if (strcmp(x->name, y->name) || x->vertex_count != y->vertex_count || x->index_count != y->index_count ||
            memcmp(&x->bounds, &y->bounds, sizeof x->bounds) ||
            memcmp(x->positions, y->positions, 12 * (size_t)x->vertex_count) ||
            memcmp(x->normals, y->normals, 12 * (size_t)x->vertex_count) ||
            memcmp(x->uvs, y->uvs, 8 * (size_t)x->vertex_count) ||
            memcmp(x->indices, y->indices, 4 * (size_t)x->index_count) || !same_clusters(&x->clusters, &y->clusters))
            return 0;
    }
    for (uint32_t i = 0; i < a->material_count; i++)
        if (memcmp(&a->materials[i], &b->materials[i], sizeof(gdr_material)))
            return 0;
    for (uint32_t i = 0; i < a->instance_count; i++)
        if (memcmp(&a->instances[i], &b->instances[i], sizeof(gdr_instance)))
            return 0;
    for (uint32_t i = 0; i < a->camera_count; i++)
        if (memcmp(&a->cameras[i], &b->cameras[i], sizeof(gdr_camera)))
            return 0;
    for (uint32_t i = 0; i < a->texture_count; i++) {
        const gdr_texture *x = &a->textures[i], *y = &b->textures[i];
        if (strcmp(x->name, y->name) || x->width != y->width || x->height != y->height || x->srgb != y->srgb ||
            memcmp(x->rgba, y->rgba, (size_t)x->width * x->height * 4))
            return 0;
    }
    return 1;
}

static void test_round_trip_and_corruption(const char *label, gdr_scene *scene)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.gdrc", GDR_IO_TEST_TMP, label);
    gdr_error err = {0};
    gdr_cache_source source = {gdr_cache_build_options(), NULL};
    CHECK(gdr_cache_write(path, scene, &source, &err) == GDR_OK);
    gdr_scene *loaded = NULL;
    CHECK(gdr_cache_read(path, gdr_cache_build_options(), &loaded, &err) == GDR_OK);
    CHECK(loaded && same_scene(scene, loaded));
    gdr_scene_destroy(loaded);

    size_t size;
    uint8_t *data = test_read_file(path, &size);
    CHECK(data != NULL);
    if (!data)
        return;
    /* Every truncation (every byte for small files, a stride for large ones). */
    size_t step = size > 20000 ? size / 5000 : 1;
    unsigned refused = 0;
    for (size_t cut = 0; cut < size; cut += step) {
        gdr_scene *s = NULL;
        gdr_status status = gdr_cache_read_memory(data, cut, label, &s, &err);
        refused += status != GDR_OK;
        CHECK(status != GDR_OK && s == NULL);
        CHECK(strstr(err.message, label) != NULL);
    }
    /* Random byte flips: the checksums catch every one. */
    unsigned seed = 12345;
    uint8_t *copy = malloc(size);
    for (int trial = 0; trial < 2000; trial++) {
        memcpy(copy, data, size);
        int flips = 1 + trial % 3;
        for (int f = 0; f < flips; f++) {
            size_t at = (size_t)(test_random(&seed) * (float)size) % size;
            copy[at] ^= (uint8_t)(1u + (unsigned)(test_random(&seed) * 254.0f));
        }
        gdr_scene *s = NULL;
        gdr_status status = gdr_cache_read_memory(copy, size, label, &s, &err);
        if (status == GDR_OK) {
            /* Only possible if flips cancelled out. */
            CHECK(memcmp(copy, data, size) == 0);
            gdr_scene_destroy(s);
        } else {
            CHECK(strstr(err.message, "corrupted") || strstr(err.message, "bad magic") ||
                  strstr(err.message, "version") || strstr(err.message, "truncated"));
        }
    }
    /* A foreign version is named. */
    memcpy(copy, data, size);
    copy[8] = 99;
    gdr_scene *s = NULL;
    CHECK(gdr_cache_read_memory(copy, size, label, &s, &err) == GDR_ERROR_UNSUPPORTED);
    char expected[80];
    snprintf(expected, sizeof expected, "cache format version 99, this build reads %u", GDR_CACHE_FORMAT_VERSION);
    CHECK(strstr(err.message, expected) != NULL);
    free(copy);
    free(data);
    printf("%s: %zu bytes, %u truncations refused, 2000 corruptions refused\n", label, size, refused);
}

/* A later version's optional section is skipped; a required one is refused by name. */
static void test_unknown_sections(gdr_scene *scene)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/sections.gdrc", GDR_IO_TEST_TMP);
    gdr_error err = {0};
    CHECK(gdr_cache_write(path, scene, NULL, &err) == GDR_OK);
    size_t size;
    uint8_t *data = test_read_file(path, &size);
    if (!data)
        return;
    /* Rename the first section (SRCE, optional) to an unknown id and fix the checksums. */
    uint8_t *table = data + 64;
    memcpy(table, "LODX", 4);
    uint32_t count;
    memcpy(&count, data + 16, 4);
    uint64_t h = XXH3_64bits(table, (size_t)count * 32);
    memcpy(data + 32, &h, 8);
    h = XXH3_64bits(data, 40);
    memcpy(data + 40, &h, 8);
    gdr_scene *s = NULL;
    CHECK(gdr_cache_read_memory(data, size, "sections", &s, &err) == GDR_OK);
    CHECK(s && same_scene(s, scene));
    gdr_scene_destroy(s);
    uint32_t required = 1;
    memcpy(table + 4, &required, 4);
    h = XXH3_64bits(table, (size_t)count * 32);
    memcpy(data + 32, &h, 8);
    h = XXH3_64bits(data, 40);
    memcpy(data + 40, &h, 8);
    s = NULL;
    CHECK(gdr_cache_read_memory(data, size, "sections", &s, &err) == GDR_ERROR_UNSUPPORTED);
    CHECK(strstr(err.message, "requires section 'LODX'") != NULL);
    free(data);
}

/* gdr_scene_load_ex: first load imports and writes SOURCE.gdrc; the second reads it; touching
 * the source without changing it keeps it; changing the source rebuilds it. */
static void test_automatic_cache(void)
{
    char obj[1024], cache[1100];
    snprintf(obj, sizeof obj, "%s/auto.obj", GDR_IO_TEST_TMP);
    snprintf(cache, sizeof cache, "%s.gdrc", obj);
    const char *text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    CHECK(test_write_file(obj, text, strlen(text)));
    unlink(cache);
    gdr_load_options options = {.no_progress = 1};
    gdr_error err = {0};
    gdr_scene *s = NULL;
    CHECK(gdr_scene_load_ex(obj, &options, &s, &err) == GDR_OK);
    CHECK(access(cache, F_OK) == 0);
    gdr_scene_destroy(s);
    /* Replace the cache's geometry marker: a cache with 2 triangles proves the cache is read. */
    gdr_scene *two = NULL;
    CHECK(gdr_scene_load_ex(obj, &(gdr_load_options){.no_cache = 1}, &two, &err) == GDR_OK);
    gdr_instance copy = two->instances[0];
    CHECK(gdr_scene_add_instance(two, &copy, &err) == GDR_OK);
    gdr_source_list sources = {0};
    gdr_import_options import = {.sources = &sources, .no_progress = 1};
    gdr_scene *tmp = NULL;
    CHECK(gdr_import_file(obj, &import, &tmp, NULL, &err) == GDR_OK);
    gdr_scene_destroy(tmp);
    gdr_cache_source source = {gdr_cache_build_options(), &sources};
    CHECK(gdr_cache_write(cache, two, &source, &err) == GDR_OK);
    gdr_scene_destroy(two);
    s = NULL;
    CHECK(gdr_scene_load_ex(obj, &options, &s, &err) == GDR_OK);
    CHECK(s && s->instance_count == 2); /* from the cache */
    gdr_scene_destroy(s);
    /* Same contents, new mtime: still fresh (the hash decides). */
    CHECK(test_write_file(obj, text, strlen(text)));
    s = NULL;
    CHECK(gdr_scene_load_ex(obj, &options, &s, &err) == GDR_OK);
    CHECK(s && s->instance_count == 2);
    gdr_scene_destroy(s);
    /* Changed source: the cache is stale, refused when read directly, rebuilt automatically. */
    const char *text2 = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
    CHECK(test_write_file(obj, text2, strlen(text2)));
    s = NULL;
    CHECK(gdr_cache_read(cache, gdr_cache_build_options(), &s, &err) != GDR_OK);
    CHECK(strstr(err.message, "stale") != NULL);
    CHECK(gdr_scene_load_ex(obj, &options, &s, &err) == GDR_OK);
    CHECK(s && s->instance_count == 1 && s->meshes[0].index_count == 6);
    gdr_scene_destroy(s);
    s = NULL;
    CHECK(gdr_cache_read(cache, gdr_cache_build_options(), &s, &err) == GDR_OK); /* rewritten */
    CHECK(s && s->meshes[0].index_count == 6);
    gdr_scene_destroy(s);
    /* A build with other options is stale. */
    s = NULL;
    CHECK(gdr_cache_read(cache, "import=0", &s, &err) != GDR_OK && strstr(err.message, "stale: built with options"));
    /* A corrupted cache is reported and rebuilt. */
    size_t size;
    uint8_t *data = test_read_file(cache, &size);
    data[size / 2] ^= 0x55;
    CHECK(test_write_file(cache, data, size));
    free(data);
    test_warnings w = {0};
    options.warning = test_collect_warning;
    options.warning_user = &w;
    CHECK(gdr_scene_load_ex(obj, &options, &s, &err) == GDR_OK);
    CHECK(w.count == 1 && strstr(w.text, "corrupted") && strstr(w.text, "rebuilding"));
    gdr_scene_destroy(s);
    /* A cache folder. */
    char dir[1100];
    snprintf(dir, sizeof dir, "%s/cache-dir", GDR_IO_TEST_TMP);
    options.cache_dir = dir;
    s = NULL;
    CHECK(gdr_scene_load_ex(obj, &options, &s, &err) == GDR_OK);
    gdr_scene_destroy(s);
    char in_dir[1400];
    CHECK(gdr_cache_path_for(obj, dir, in_dir, sizeof in_dir) > 0);
    CHECK(access(in_dir, F_OK) == 0);
    gdr_source_list_free(&sources);
}

int main(void)
{
    gdr_error err = {0};
    gdr_scene *demo = NULL;
    CHECK(gdr_scene_create_demo(&(gdr_demo_desc){.instances = 50}, &demo, &err) == GDR_OK);
    /* Give the demo scene a texture and an extension list, so every section has data. */
    uint8_t pixels[2 * 2 * 4] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16};
    CHECK(gdr_scene_add_texture(demo, "t", 2, 2, pixels, 1, NULL, &err) == GDR_OK);
    CHECK(gdr_scene_set_extensions(demo, "EXT_test", &err) == GDR_OK);
    if (demo) {
        test_round_trip_and_corruption("demo", demo);
        test_unknown_sections(demo);
        gdr_scene_destroy(demo);
    }
    char path[1024];
    snprintf(path, sizeof path, "%s/ClearCoat-glTF/ClearCoatTest.gltf", ASSIMP_GLTF2_DIR);
    gdr_scene *gltf = NULL;
    if (gdr_import_gltf(path, &(gdr_import_options){.no_progress = 1}, &gltf, NULL, &err) == GDR_OK) {
        test_round_trip_and_corruption("clearcoat", gltf);
        gdr_scene_destroy(gltf);
    } else {
        printf("%s\n", err.message);
    }
    test_automatic_cache();
    return test_finish("test_cache");
}
