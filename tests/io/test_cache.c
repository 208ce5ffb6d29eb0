/* The processed-scene cache: build -> load gives an identical scene; every truncation and many
 * random byte flips are refused cleanly; stale, foreign-version and unknown-section handling;
 * gdr_scene_load uses and rebuilds the cache next to the source; the optional precomputed
 * visibility section (PVIS): round trip, absent, truncated, flipped, mismatched. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <xxhash.h>

#include "gdr/geometry.h"
#include "gdr/procedural.h"
#include "gdr/cull.h"
#include "gdr/io.h"
#include "geometry/cluster_checks.h"
#include "io_test_helpers.h"
#include "test_util.h"
#include "io/loaders.h"

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
            memcmp(x->indices, y->indices, 4 * (size_t)x->index_count) || !same_clusters(&x->clusters, &y->clusters) ||
            !x->colors != !y->colors || (x->colors && memcmp(x->colors, y->colors, 16 * (size_t)x->vertex_count)))
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
            x->levels != y->levels || x->format != y->format ||
            memcmp(x->rgba, y->rgba, gdr_texture_format_level_offset(x->format, x->width, x->height, x->levels)))
            return 0;
    }
    return 1;
}

static void test_round_trip_and_corruption(const char *label, gdr_scene *scene)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.gdrc", GDR_IO_TEST_TMP, label);
    gdr_error err = {0};
    gdr_cache_write_options plain_options = {.source = {gdr_cache_build_options(), NULL}};
    CHECK(gdr_cache_write(path, scene, &plain_options, &err) == GDR_OK);
    gdr_scene *loaded = NULL;
    CHECK(gdr_cache_read(path, gdr_cache_build_options(), &loaded, NULL, &err) == GDR_OK);
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
        gdr_status status = gdr_cache_read_memory(data, cut, label, &s, NULL, &err);
        refused += status != GDR_OK;
        CHECK(status == GDR_ERROR_CORRUPT && s == NULL);
        CHECK_STATUS(err, GDR_ERROR_CORRUPT);
        CHECK_NAMES(err, label);
    }
    /* Random byte flips: the checksums catch every one. Only a flip in the magic (not a cache) or
     * the version (another format) is told apart from damage. */
    unsigned seed = 12345;
    uint8_t *copy = malloc(size);
    for (int trial = 0; trial < 2000; trial++) {
        memcpy(copy, data, size);
        int flips = 1 + trial % 3;
        size_t first = size;
        for (int f = 0; f < flips; f++) {
            size_t at = (size_t)(test_random(&seed) * (float)size) % size;
            copy[at] ^= (uint8_t)(1u + (unsigned)(test_random(&seed) * 254.0f));
            first = at < first ? at : first;
        }
        gdr_scene *s = NULL;
        gdr_status status = gdr_cache_read_memory(copy, size, label, &s, NULL, &err);
        if (status == GDR_OK) {
            /* Only possible if flips cancelled out. */
            CHECK(memcmp(copy, data, size) == 0);
            gdr_scene_destroy(s);
        } else if (first >= 12) {
            CHECK_STATUS(err, GDR_ERROR_CORRUPT);
        } else {
            CHECK(status == GDR_ERROR_CORRUPT || status == GDR_ERROR_PARSE || status == GDR_ERROR_UNSUPPORTED);
        }
    }
    /* A foreign version is named. */
    memcpy(copy, data, size);
    copy[8] = 99;
    gdr_scene *s = NULL;
    CHECK_FAILS(gdr_cache_read_memory(copy, size, label, &s, NULL, &err), err, GDR_ERROR_UNSUPPORTED);
    char expected[80];
    snprintf(expected, sizeof expected, "cache format version 99, this build reads %u", GDR_CACHE_FORMAT_VERSION);
    CHECK_NAMES(err, expected); /* both versions, so that the user knows which build wrote it */
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
    CHECK(gdr_cache_read_memory(data, size, "sections", &s, NULL, &err) == GDR_OK);
    CHECK(s && same_scene(s, scene));
    gdr_scene_destroy(s);
    uint32_t required = 1;
    memcpy(table + 4, &required, 4);
    h = XXH3_64bits(table, (size_t)count * 32);
    memcpy(data + 32, &h, 8);
    h = XXH3_64bits(data, 40);
    memcpy(data + 40, &h, 8);
    s = NULL;
    CHECK_FAILS(gdr_cache_read_memory(data, size, "sections", &s, NULL, &err), err, GDR_ERROR_UNSUPPORTED);
    CHECK_NAMES(err, "section 'LODX'");
    free(data);
}

/* gdr_scene_load with the cache next to the source (cache_dir "."): first load imports and writes
 * SOURCE.gdrc; the second reads it; touching
 * the source without changing it keeps it; changing the source rebuilds it. */
static void test_automatic_cache(void)
{
    char obj[1024], cache[1100];
    snprintf(obj, sizeof obj, "%s/auto.obj", GDR_IO_TEST_TMP);
    snprintf(cache, sizeof cache, "%s.gdrc", obj);
    const char *text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    CHECK(test_write_file(obj, text, strlen(text)));
    unlink(cache);
    gdr_load_options options = {.no_progress = 1, .cache_dir = "."}; /* ".": next to the source */
    gdr_error err = {0};
    gdr_scene *s = NULL;
    CHECK(gdr_scene_load(obj, &options, &s, &err) == GDR_OK);
    CHECK(access(cache, F_OK) == 0);
    gdr_scene_destroy(s);
    /* Replace the cache's geometry marker: a cache with 2 triangles proves the cache is read. */
    gdr_scene *two = NULL;
    CHECK(gdr_scene_load(obj, &(gdr_load_options){.no_cache = 1}, &two, &err) == GDR_OK);
    gdr_instance copy = two->instances[0];
    CHECK(gdr_scene_add_instance(two, &copy, &err) == GDR_OK);
    gdr_source_list sources = {0};
    gdr_import_options import = {.sources = &sources, .no_progress = 1};
    gdr_scene *tmp = NULL;
    CHECK(gdr_import_file(obj, &import, &tmp, NULL, &err) == GDR_OK);
    gdr_scene_destroy(tmp);
    gdr_cache_write_options plain_options = {.source = {gdr_cache_build_options(), &sources}};
    CHECK(gdr_cache_write(cache, two, &plain_options, &err) == GDR_OK);
    gdr_scene_destroy(two);
    s = NULL;
    CHECK(gdr_scene_load(obj, &options, &s, &err) == GDR_OK);
    CHECK(s && s->instance_count == 2); /* from the cache */
    gdr_scene_destroy(s);
    /* Same contents, new mtime: still fresh (the hash decides). */
    CHECK(test_write_file(obj, text, strlen(text)));
    s = NULL;
    CHECK(gdr_scene_load(obj, &options, &s, &err) == GDR_OK);
    CHECK(s && s->instance_count == 2);
    gdr_scene_destroy(s);
    /* Changed source: the cache is stale for the source and rebuilt automatically; read directly it
     * is read as it stands (its recorded sources are not opened). */
    const char *text2 = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
    CHECK(test_write_file(obj, text2, strlen(text2)));
    s = NULL;
    CHECK(gdr_cache_read(cache, gdr_cache_build_options(), &s, NULL, &err) == GDR_OK && s && s->instance_count == 2);
    gdr_scene_destroy(s);
    s = NULL;
    test_warnings stale_warnings = {0}; /* rebuilt without a word: a stale cache is no fault */
    options.warning = test_collect_warning;
    options.warning_user = &stale_warnings;
    CHECK(gdr_scene_load(obj, &options, &s, &err) == GDR_OK && stale_warnings.count == 0);
    options.warning = NULL;
    CHECK(s && s->instance_count == 1 && s->meshes[0].index_count == 6);
    gdr_scene_destroy(s);
    s = NULL;
    CHECK(gdr_cache_read(cache, gdr_cache_build_options(), &s, NULL, &err) == GDR_OK); /* rewritten */
    CHECK(s && s->meshes[0].index_count == 6);
    gdr_scene_destroy(s);
    /* A build with other options is stale. */
    s = NULL;
    CHECK_FAILS(gdr_cache_read(cache, "import=0", &s, NULL, &err), err, GDR_ERROR_STALE);
    /* A corrupted cache is reported and rebuilt. */
    size_t size;
    uint8_t *data = test_read_file(cache, &size);
    data[size / 2] ^= 0x55;
    CHECK(test_write_file(cache, data, size));
    free(data);
    test_warnings w = {0};
    options.warning = test_collect_warning;
    options.warning_user = &w;
    CHECK(gdr_scene_load(obj, &options, &s, &err) == GDR_OK);
    CHECK(w.count == 1 && strstr(w.text, "corrupted") && strstr(w.text, "rebuilding"));
    gdr_scene_destroy(s);
    /* A cache folder. */
    char dir[1100];
    snprintf(dir, sizeof dir, "%s/cache-dir", GDR_IO_TEST_TMP);
    options.cache_dir = dir;
    s = NULL;
    CHECK(gdr_scene_load(obj, &options, &s, &err) == GDR_OK);
    gdr_scene_destroy(s);
    char in_dir[1400];
    CHECK(gdr_cache_path_for(obj, dir, in_dir, sizeof in_dir) > 0);
    CHECK(access(in_dir, F_OK) == 0);
    gdr_source_list_free(&sources);
}

/* --- the PVIS section ------------------------------------------------------------------------- */

/* A room of boxes (a floor, a wall with a doorway, crates on both sides) and a quick bake of it. */
static gdr_scene *pvs_scene(void)
{
    gdr_scene *scene = NULL;
    gdr_error err;
    CHECK(gdr_scene_create(&scene, &err) == GDR_OK);
    gdr_vec3 p[8];
    for (int i = 0; i < 8; i++)
        p[i] = (gdr_vec3){(i & 1) ? 1.0f : -1.0f, (i & 2) ? 1.0f : -1.0f, (i & 4) ? 1.0f : -1.0f};
    uint32_t idx[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                        2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    uint32_t box;
    CHECK(gdr_scene_add_mesh(scene, "box", p, NULL, NULL, 8, idx, 36, &box, &err) == GDR_OK);
    gdr_vec3 boxes[][2] = {{{0, -0.5f, 0}, {12, 0.5f, 12}}, {{-7, 2, 0}, {5, 2, 0.25f}}, {{7, 2, 0}, {5, 2, 0.25f}}};
    for (int i = 0; i < 3 + 40; i++) {
        gdr_vec3 c, h;
        if (i < 3) {
            c = boxes[i][0];
            h = boxes[i][1];
        } else {
            int k = i - 3;
            c = (gdr_vec3){-10.0f + 2.5f * (float)(k % 9), 0.4f, (k / 9 % 2 ? 1.0f : -1.0f) * (3.0f + 2.0f * (float)(k / 18))};
            h = (gdr_vec3){0.4f, 0.4f, 0.4f};
        }
        gdr_instance inst = {gdr_mat4_from_trs(c, gdr_quat_identity(), h), box, GDR_NO_INDEX, {1, 1, 1, 1}};
        CHECK(gdr_scene_add_instance(scene, &inst, &err) == GDR_OK);
    }
    CHECK(gdr_scene_build_clusters(scene, NULL, &err) == GDR_OK);
    return scene;
}

static gdr_pvs *pvs_bake_quick(const gdr_scene *scene)
{
    gdr_pvs_bake_desc desc = {.scene = scene, .region_min = {-12, 0.2f, -12}, .region_max = {12, 3.4f, 12},
                              .cell_size = 3.0f, .samples_per_cell = 1, .cube_resolution = 16, .cells_per_chunk = 6,
                              .bucket_count_x = 4, .bucket_count_z = 4};
    gdr_pvs *pvs = NULL;
    gdr_error err;
    CHECK(gdr_pvs_bake(&desc, &pvs, NULL, &err) == GDR_OK);
    return pvs;
}

static uint8_t *pvs_bytes(const gdr_pvs *pvs, size_t *size)
{
    *size = gdr_pvs_serialized_size(pvs);
    uint8_t *blob = malloc(*size);
    gdr_error err;
    CHECK(blob && gdr_pvs_serialize(pvs, blob, *size, &err) == GDR_OK);
    return blob;
}

/* The entry of section `id` in the table (NULL if absent). */
static uint8_t *cache_entry(uint8_t *data, const char *id)
{
    uint32_t count;
    memcpy(&count, data + 16, 4);
    for (uint32_t i = 0; i < count; i++)
        if (memcmp(data + 64 + (size_t)i * 32, id, 4) == 0)
            return data + 64 + (size_t)i * 32;
    return NULL;
}

/* Recomputes every section checksum, the table's and the header's (after a deliberate edit). */
static void cache_fix_checksums(uint8_t *data, size_t size)
{
    uint64_t file_size = size, h;
    memcpy(data + 24, &file_size, 8);
    uint32_t count;
    memcpy(&count, data + 16, 4);
    for (uint32_t i = 0; i < count; i++) {
        uint8_t *e = data + 64 + (size_t)i * 32;
        uint64_t offset, length;
        memcpy(&offset, e + 8, 8);
        memcpy(&length, e + 16, 8);
        if (offset <= size && length <= size - offset) {
            h = XXH3_64bits(data + offset, (size_t)length);
            memcpy(e + 24, &h, 8);
        }
    }
    h = XXH3_64bits(data + 64, (size_t)count * 32);
    memcpy(data + 32, &h, 8);
    h = XXH3_64bits(data, 40);
    memcpy(data + 40, &h, 8);
}

/* The PVS blob's own checksum (FNV-1a 64 with its field at 72 taken as zero, docs/CULLING.md). */
static void pvs_fix_checksum(uint8_t *blob, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < n; i++)
        h = (h ^ ((i >= 72 && i < 80) ? 0 : blob[i])) * 0x100000001b3ull;
    memcpy(blob + 72, &h, 8);
}

/* Reads a damaged cache: must be refused with `expected`, no scene and no PVS, naming the file and
 * the place `where` (unless NULL). */
static void expect_refused(const uint8_t *data, size_t size, const char *where, gdr_status expected)
{
    gdr_scene *s = (gdr_scene *)(uintptr_t)1;
    gdr_pvs *pvs = (gdr_pvs *)(uintptr_t)1;
    gdr_error err = {0};
    gdr_status status = gdr_cache_read_memory(data, size, "pvs.gdrc", &s, &pvs, &err);
    CHECK(status == expected && s == NULL && pvs == NULL);
    CHECK_STATUS(err, expected);
    CHECK_NAMES(err, "pvs.gdrc");
    if (where)
        CHECK_NAMES(err, where);
    if (status == GDR_OK) {
        gdr_scene_destroy(s);
        gdr_pvs_destroy(pvs);
    }
}

/* Reads a damaged cache without PVS: refused with `expected`, no scene, naming the file and `where`. */
static void expect_read_refused(const uint8_t *data, size_t size, const char *where, gdr_status expected)
{
    gdr_scene *s = (gdr_scene *)(uintptr_t)1;
    gdr_error err = {0};
    gdr_status status = gdr_cache_read_memory(data, size, "blocks.gdrc", &s, NULL, &err);
    CHECK(status == expected && s == NULL);
    CHECK_STATUS(err, expected);
    CHECK_NAMES(err, "blocks.gdrc");
    CHECK_NAMES(err, where);
    if (status == GDR_OK)
        gdr_scene_destroy(s);
}

static void test_pvs_section(void)
{
    gdr_scene *scene = pvs_scene();
    gdr_pvs *pvs = pvs_bake_quick(scene);
    if (!scene || !pvs)
        return;
    size_t blob_size;
    uint8_t *blob = pvs_bytes(pvs, &blob_size);
    char path[1024], plain[1024];
    snprintf(path, sizeof path, "%s/pvs.gdrc", GDR_IO_TEST_TMP);
    snprintf(plain, sizeof plain, "%s/no-pvs.gdrc", GDR_IO_TEST_TMP);
    gdr_error err = {0};
    gdr_cache_write_options plain_options = {.source = {gdr_cache_build_options(), NULL}};
    gdr_cache_write_options with_pvs = {.source = plain_options.source, .pvs = pvs};

    /* Round trip: the same scene and, byte for byte, the same PVS. */
    CHECK(gdr_cache_write(path, scene, &with_pvs, &err) == GDR_OK);
    gdr_scene *loaded = NULL;
    gdr_pvs *back = NULL;
    CHECK(gdr_cache_read(path, gdr_cache_build_options(), &loaded, &back, &err) == GDR_OK);
    CHECK(loaded && same_scene(scene, loaded));
    CHECK(back != NULL);
    if (back) {
        size_t n;
        uint8_t *again = pvs_bytes(back, &n);
        CHECK(n == blob_size && memcmp(again, blob, n) == 0);
        CHECK(gdr_pvs_object_count(back) == scene->instance_count);
        free(again);
    }
    gdr_pvs_destroy(back);
    gdr_scene_destroy(loaded);
    /* Readers that do not ask for it still load the scene; so does gdr_scene_load_file. */
    loaded = NULL;
    CHECK(gdr_cache_read(path, gdr_cache_build_options(), &loaded, NULL, &err) == GDR_OK && loaded);
    gdr_scene_destroy(loaded);
    loaded = NULL;
    back = NULL;
    CHECK(gdr_scene_load_file(path, NULL, &loaded, &back, &err) == GDR_OK && loaded && back);
    CHECK(back && gdr_pvs_cell_count(back) == gdr_pvs_cell_count(pvs));
    gdr_pvs_destroy(back);
    gdr_scene_destroy(loaded);

    /* A cache without the section: loads, and says there is none. */
    CHECK(gdr_cache_write(plain, scene, &plain_options, &err) == GDR_OK);
    loaded = NULL;
    back = (gdr_pvs *)(uintptr_t)1;
    CHECK(gdr_cache_read(plain, NULL, &loaded, &back, &err) == GDR_OK && loaded && back == NULL);
    gdr_scene_destroy(loaded);

    /* A PVS baked for another scene is refused by the writer; nothing is written. */
    gdr_scene *other = pvs_scene();
    gdr_instance extra = other->instances[0];
    CHECK(gdr_scene_add_instance(other, &extra, &err) == GDR_OK);
    char wrong[1100];
    snprintf(wrong, sizeof wrong, "%s/wrong-pvs.gdrc", GDR_IO_TEST_TMP);
    unlink(wrong);
    CHECK_FAILS(gdr_cache_write(wrong, other, &with_pvs, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    CHECK(access(wrong, F_OK) != 0);
    gdr_scene_destroy(other);

    size_t size, plain_size;
    uint8_t *data = test_read_file(path, &size);
    uint8_t *without = test_read_file(plain, &plain_size);
    CHECK(data && without && size > plain_size);
    uint8_t *entry = data ? cache_entry(data, "PVIS") : NULL;
    CHECK(entry != NULL);
    if (!data || !without || !entry) {
        free(data);
        free(without);
        free(blob);
        gdr_pvs_destroy(pvs);
        gdr_scene_destroy(scene);
        return;
    }
    uint32_t flags;
    uint64_t offset, length;
    memcpy(&flags, entry + 4, 4);
    memcpy(&offset, entry + 8, 8);
    memcpy(&length, entry + 16, 8);
    CHECK(flags == 0);                  /* optional: older readers skip it */
    CHECK(offset + length == size);     /* the last section */
    CHECK(length == blob_size && memcmp(data + offset, blob, blob_size) == 0);
    uint8_t *bad = malloc(size);

    /* Every truncation of the file is refused. */
    unsigned truncations = 0;
    for (size_t cut = 0; cut < size; cut += cut < offset ? 97 : 1, truncations++)
        expect_refused(data, cut, NULL, GDR_ERROR_CORRUPT);
    /* Every alignment padding byte between sections flipped: no byte escapes the checks. */
    uint32_t section_count, paddings = 0;
    memcpy(&section_count, data + 16, 4);
    for (uint32_t i = 0; i < section_count; i++) {
        uint64_t at, n;
        memcpy(&at, data + 64 + (size_t)i * 32 + 8, 8);
        memcpy(&n, data + 64 + (size_t)i * 32 + 16, 8);
        for (uint64_t p = at + n; p % 8 != 0 && p < size; p++, paddings++) {
            memcpy(bad, data, size);
            bad[p] ^= 0x20;
            expect_refused(bad, size, NULL, GDR_ERROR_CORRUPT);
        }
    }
    CHECK(paddings > 0);
    /* Every byte of the section flipped: the section checksum names it. */
    for (uint64_t i = offset; i < size; i++) {
        memcpy(bad, data, size);
        bad[i] ^= (uint8_t)(1u << (i % 8));
        expect_refused(bad, size, "section 'PVIS'", GDR_ERROR_CORRUPT);
    }
    /* The same flips with the cache's checksums recomputed: the blob's own checks name it. */
    unsigned inner = 0;
    for (uint64_t i = offset; i < size; i += 1 + (i - offset) / 64) {
        memcpy(bad, data, size);
        bad[i] ^= (uint8_t)(1u << (i % 8));
        cache_fix_checksums(bad, size);
        expect_refused(bad, size, "section 'PVIS'", GDR_ERROR_PARSE);
        inner++;
    }
    /* The section cut short (its size in the table, checksums recomputed): the blob's size check. */
    for (uint64_t keep = 0; keep < length; keep += 1 + keep / 8) {
        memcpy(bad, data, size);
        uint8_t *e = cache_entry(bad, "PVIS");
        memcpy(e + 16, &keep, 8);
        cache_fix_checksums(bad, size);
        expect_refused(bad, size, "section 'PVIS'", GDR_ERROR_PARSE);
    }
    /* A valid blob for another object count (same bitset size, blob checksum fixed too). */
    memcpy(bad, data, size);
    uint32_t objects = (uint32_t)scene->instance_count - 1;
    memcpy(bad + offset + 16, &objects, 4);
    pvs_fix_checksum(bad + offset, (size_t)length);
    cache_fix_checksums(bad, size);
    expect_refused(bad, size, "section 'PVIS'", GDR_ERROR_PARSE);
    /* Two PVIS sections: the second entry points at the same bytes. */
    {
        size_t n = size + 32;
        uint8_t *two = malloc(n);
        uint32_t count;
        memcpy(&count, data + 16, 4);
        size_t table_end = 64 + (size_t)count * 32;
        memcpy(two, data, table_end);
        memcpy(two + table_end, entry, 32);
        memcpy(two + table_end + 32, data + table_end, size - table_end);
        count++;
        memcpy(two + 16, &count, 4);
        for (uint32_t i = 0; i < count; i++) { /* every offset moves by the new entry */
            uint64_t o;
            memcpy(&o, two + 64 + (size_t)i * 32 + 8, 8);
            o += 32;
            memcpy(two + 64 + (size_t)i * 32 + 8, &o, 8);
        }
        cache_fix_checksums(two, n);
        expect_refused(two, n, "section 'PVIS'", GDR_ERROR_PARSE);
        free(two);
    }
    printf("pvs section: %llu bytes; %u truncations, %llu flips, %u flips behind fixed checksums refused\n",
           (unsigned long long)length, truncations, (unsigned long long)length, inner);
    free(bad);
    free(data);
    free(without);
    free(blob);
    gdr_pvs_destroy(pvs);
    gdr_scene_destroy(scene);
}

/* A scene with a texture of every block format, sides not multiples of 4 (9 x 5: partial blocks,
 * levels below 4 x 4). */
static gdr_scene *block_texture_scene(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create_demo(&(gdr_demo_desc){.instances = 4}, &s, &err) == GDR_OK);
    uint8_t texels[9 * 5 * 4];
    for (uint32_t i = 0; i < sizeof texels; i++)
        texels[i] = (uint8_t)(i * 37u + (i >> 2) * 11u);
    gdr_material m = gdr_material_default();
    m.alpha_mode = GDR_ALPHA_MASK;
    gdr_texture_ref *uses[5] = {&m.base_color_texture, &m.emissive_texture, &m.normal_texture,
                                &m.metallic_roughness_texture, &m.occlusion_texture};
    for (uint32_t k = 0; k < 5; k++)
        CHECK(gdr_scene_add_texture(s, "t", 9, 5, texels, k < 2, &uses[k]->texture, &err) == GDR_OK);
    CHECK(gdr_scene_add_material(s, &m, NULL, &err) == GDR_OK);
    CHECK(gdr_scene_compress_textures(s, NULL, &err) == GDR_OK);
    const uint32_t formats[5] = {GDR_TEXTURE_BC3, GDR_TEXTURE_BC1, GDR_TEXTURE_BC5, GDR_TEXTURE_BC5_GB, GDR_TEXTURE_BC4};
    for (uint32_t k = 0; k < 5; k++)
        CHECK(s->textures[k].format == formats[k]);
    /* 9 x 5 -> 4 x 2 -> 2 x 1 -> 1 x 1: 3 x 2, 1, 1 and 1 blocks */
    CHECK(gdr_texture_format_level_offset(GDR_TEXTURE_BC1, 9, 5, 4) == 8 * (6 + 1 + 1 + 1));
    return s;
}

/* A cache's texture records and blocks damaged behind recomputed checksums: each refused with
 * GDR_ERROR_PARSE naming the file, the section or texture and what is wrong. */
static void test_block_textures(void)
{
    gdr_scene *scene = block_texture_scene();
    test_round_trip_and_corruption("blocks", scene);
    char path[1024];
    snprintf(path, sizeof path, "%s/blocks.gdrc", GDR_IO_TEST_TMP);
    size_t size;
    uint8_t *data = test_read_file(path, &size), *bad = malloc(size);
    CHECK(data && bad);
    if (!data || !bad)
        return;
    uint64_t texr, txpx, txpx_length;
    memcpy(&texr, cache_entry(data, "TEXR") + 8, 8);
    memcpy(&txpx, cache_entry(data, "TXPX") + 8, 8);
    memcpy(&txpx_length, cache_entry(data, "TXPX") + 16, 8);
    CHECK(txpx_length == 16 * 9 + 8 * 9 + 16 * 9 + 16 * 9 + 8 * 9); /* BC3, BC1, BC5, BC5_GB, BC4 */
    /* texture 2's format (its record: name, width, height, sRGB, format) out of range */
    memcpy(bad, data, size);
    uint32_t format = GDR_TEXTURE_FORMAT_COUNT;
    memcpy(bad + texr + 2 * (64 + 16) + 64 + 12, &format, 4);
    cache_fix_checksums(bad, size);
    expect_read_refused(bad, size, "texture 2: format 6", GDR_ERROR_PARSE);
    /* texture 1 claiming BC5 (16-byte blocks) where its 8-byte BC1 blocks are: the levels after it
     * no longer fit the section */
    memcpy(bad, data, size);
    format = GDR_TEXTURE_BC5;
    memcpy(bad + texr + 1 * (64 + 16) + 64 + 12, &format, 4);
    cache_fix_checksums(bad, size);
    expect_read_refused(bad, size, "run past section 'TXPX'", GDR_ERROR_PARSE);
    /* texture 0 claiming BC1 (8-byte blocks) where its 16-byte BC3 blocks are: bytes left over */
    memcpy(bad, data, size);
    format = GDR_TEXTURE_BC1;
    memcpy(bad + texr + 64 + 12, &format, 4);
    cache_fix_checksums(bad, size);
    expect_read_refused(bad, size, "section 'TXPX' has 72 bytes left over", GDR_ERROR_PARSE);
    /* the blocks cut short by one byte */
    memcpy(bad, data, size);
    uint64_t length = txpx_length - 1;
    memcpy(cache_entry(bad, "TXPX") + 16, &length, 8);
    cache_fix_checksums(bad, size);
    expect_read_refused(bad, size, "texture 4 (bc4, 9x5): its 72 bytes of levels run past section 'TXPX'",
                        GDR_ERROR_PARSE);
    /* a flipped bit in the blocks, checksums as written: the section's checksum names it */
    memcpy(bad, data, size);
    bad[txpx + 20] ^= 4;
    expect_read_refused(bad, size, "TXPX", GDR_ERROR_CORRUPT);
    printf("block textures: %llu bytes of blocks; damaged formats, sizes and blocks refused\n",
           (unsigned long long)txpx_length);
    free(bad);
    free(data);
    gdr_scene_destroy(scene);
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
    /* ... and a material using it with a transform, and vertex colours on one mesh. */
    gdr_material material = gdr_material_default();
    material.base_color_texture = (gdr_texture_ref){.texture = 0, .sampler = GDR_SAMPLER_WRAP_MIRROR,
                                                    .offset = {0.5f, 0.25f}, .scale = {2, 3}, .rotation = 0.5f};
    material.emissive = (gdr_vec3){1, 2, 3};
    CHECK(gdr_scene_add_material(demo, &material, NULL, &err) == GDR_OK);
    gdr_vec4 *colors = calloc(demo->meshes[1].vertex_count, sizeof *colors);
    for (uint32_t v = 0; colors && v < demo->meshes[1].vertex_count; v++)
        colors[v] = (gdr_vec4){(float)(v % 7) / 7.0f, 0.5f, 1.0f, (float)(v % 3) / 3.0f};
    CHECK(colors && gdr_scene_set_mesh_colors(demo, 1, colors, &err) == GDR_OK);
    free(colors);
    if (demo) {
        test_round_trip_and_corruption("demo", demo);
        test_unknown_sections(demo);
        test_block_textures();
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
    test_pvs_section();
    return test_finish("test_cache");
}
