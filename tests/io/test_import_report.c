/* What an import says about a file, and where its cache goes: one warning per unsupported feature
 * at its first place; a missing buffer said before any image is decoded; a decode warning naming
 * the image's buffer view; the warnings kept in the cache (section 'REPT') and said again, escaped
 * and bounded; the cache folder ($XDG_CACHE_HOME/gdr, else ~/.cache/gdr, mode 0700) and its
 * least-recently-used eviction, which removes only caches gdr wrote. */
#define _DEFAULT_SOURCE
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>


#include "cache_checksums.h"

#include "gdr/gdr.h"
#include "io/io_internal.h"
#include "io/loaders.h"
#include "io/io_test_helpers.h"
#include "test_util.h"

static char dir[1024];
static gdr_error err;

/* Occurrences of `needle` in `text`. */
static unsigned occurrences(const char *text, const char *needle)
{
    unsigned n = 0;
    for (const char *p = strstr(text, needle); p; p = strstr(p + 1, needle))
        n++;
    return n;
}

/* A triangle's positions (36 bytes) as a data: URI buffer, the rest of the document after it. */
static char *triangle_gltf(const char *buffer_uri, const char *rest)
{
    float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    char *uri = buffer_uri ? NULL : test_data_uri(positions, sizeof positions);
    size_t size = strlen(rest) + 4096;
    char *json = malloc(size);
    snprintf(json, size,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"%s\",\"byteLength\":36}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]}]%s}",
             buffer_uri ? buffer_uri : uri, rest);
    free(uri);
    return json;
}

/* Skins on two nodes, morph targets on two primitives, two animations, clearcoat on two materials,
 * specular-glossiness on one and emissive strength (applied): exactly one warning per feature. */
static void test_unsupported_features(void)
{
    const char *rest =
        ",\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0,\"targets\":[{\"POSITION\":0}]},"
        "{\"attributes\":{\"POSITION\":0},\"material\":1,\"targets\":[{\"POSITION\":0}]}]}],"
        "\"materials\":[{\"extensions\":{\"KHR_materials_clearcoat\":{\"clearcoatFactor\":1}}},"
        "{\"extensions\":{\"KHR_materials_clearcoat\":{},\"KHR_materials_pbrSpecularGlossiness\":{},"
        "\"KHR_materials_emissive_strength\":{\"emissiveStrength\":2}}}],"
        "\"skins\":[{\"joints\":[2]}],"
        "\"nodes\":[{\"mesh\":0},{\"mesh\":0,\"skin\":0},{\"skin\":0}],"
        "\"animations\":[{\"channels\":[],\"samplers\":[]},{\"channels\":[],\"samplers\":[]}],"
        "\"scenes\":[{\"nodes\":[0,1,2]}],\"scene\":0";
    char *json = triangle_gltf(NULL, rest);
    test_warnings w = {0};
    gdr_import_options options = {.warning = test_collect_warning, .warning_user = &w, .no_progress = 1};
    gdr_scene *s = NULL;
    CHECK(gdr_import_gltf_memory(json, strlen(json), "features.gltf", NULL, &options, &s, NULL, &err) == GDR_OK);
    CHECK(w.count == 5);
    CHECK(occurrences(w.text, "skins are not supported") == 1 && strstr(w.text, "nodes[1].skin: skins") &&
          strstr(w.text, "(2 nodes use one)"));
    CHECK(occurrences(w.text, "morph targets are not supported") == 1 &&
          strstr(w.text, "meshes[0].primitives[0].targets: morph") && strstr(w.text, "(2 primitives have them)"));
    CHECK(occurrences(w.text, "animation is not supported") == 1 && strstr(w.text, "animations[0]: animation") &&
          strstr(w.text, "(2 animations)"));
    CHECK(occurrences(w.text, "KHR_materials_clearcoat is not supported") == 1 &&
          strstr(w.text, "materials[0].extensions.KHR_materials_clearcoat: ") &&
          strstr(w.text, "(2 materials use it)"));
    CHECK(occurrences(w.text, "KHR_materials_pbrSpecularGlossiness is not supported") == 1 &&
          strstr(w.text, "materials[1].extensions.KHR_materials_pbrSpecularGlossiness: "));
    CHECK(!strstr(w.text, "emissive_strength"));
    if (w.count != 5)
        fprintf(stderr, "warnings:\n%s", w.text);
    gdr_scene_destroy(s);
    free(json);
    /* Without any of them: no warning. */
    json = triangle_gltf(NULL, ",\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                               "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]");
    memset(&w, 0, sizeof w);
    s = NULL;
    CHECK(gdr_import_gltf_memory(json, strlen(json), "plain.gltf", NULL, &options, &s, NULL, &err) == GDR_OK);
    CHECK(w.count == 0);
    gdr_scene_destroy(s);
    free(json);
}

/* A missing .bin is the import's error, said before any image is decoded (the code before decoded
 * every material's images first: their warnings came before the error). The decode warning of an
 * image in a buffer view names the view and the image's name. */
static void test_buffers_before_images(void)
{
    char path[1200], bin[1200];
    snprintf(path, sizeof path, "%s/nobin.gltf", dir);
    snprintf(bin, sizeof bin, "%s/nobin.bin", dir);
    unlink(bin);
    const char *image = "this is not a PNG or a JPEG";
    char *bad = test_data_uri(image, strlen(image));
    char rest[2048];
    snprintf(rest, sizeof rest,
             ",\"images\":[{\"uri\":\"%s\"}],\"textures\":[{\"source\":0}],"
             "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]", bad);
    free(bad);
    char *json = triangle_gltf("nobin.bin", rest);
    CHECK(test_write_file(path, json, strlen(json)));
    free(json);
    test_warnings w = {0};
    gdr_import_options options = {.warning = test_collect_warning, .warning_user = &w, .no_progress = 1};
    gdr_scene *s = NULL;
    CHECK_FAILS(gdr_import_gltf(path, &options, &s, NULL, &err), err, GDR_ERROR_IO);
    CHECK(strstr(err.message, "buffers[0].uri") && strstr(err.message, "nobin.bin"));
    CHECK(w.count == 0); /* no image decoded (and so none warned about) before the buffer's error */
    if (w.count)
        fprintf(stderr, "warned before the missing buffer:\n%s", w.text);

    /* An image in a buffer view, named: its warning says which view. */
    const uint8_t bytes[36] = "not an image at all, 36 bytes long.";
    char *uri = test_data_uri(bytes, sizeof bytes);
    char doc[4096];
    snprintf(doc, sizeof doc,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"%s\",\"byteLength\":36}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
             "\"images\":[{\"bufferView\":0,\"mimeType\":\"image/png\",\"name\":\"albedo\"}],"
             "\"textures\":[{\"source\":0}],"
             "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]}", uri);
    free(uri);
    memset(&w, 0, sizeof w);
    CHECK(gdr_import_gltf_memory(doc, strlen(doc), "view.gltf", NULL, &options, &s, NULL, &err) == GDR_OK);
    CHECK(w.count == 1 && strstr(w.text, "images[0] 'albedo' (bufferView 0)") && strstr(w.text, "texture left out"));
    if (w.count != 1 || !strstr(w.text, "bufferView 0"))
        fprintf(stderr, "decode warning: %s", w.text);
    gdr_scene_destroy(s);
}

/* The entry of section `id` in a cache's table (NULL if absent). */
static uint8_t *cache_entry(uint8_t *data, const char *id)
{
    uint32_t count;
    memcpy(&count, data + 16, 4);
    for (uint32_t i = 0; i < count; i++)
        if (memcmp(data + 64 + (size_t)i * 32, id, 4) == 0)
            return data + 64 + (size_t)i * 32;
    return NULL;
}


/* A cache keeps the import's warnings: read again, they are said again, with control characters
 * escaped; a section out of its limits is refused by name. */
static void test_report_section(void)
{
    char obj[1200], cache[1300];
    snprintf(obj, sizeof obj, "%s/report.obj", dir);
    snprintf(cache, sizeof cache, "%s/report.gdrc", dir);
    /* An OBJ statement gdr ignores, with an escape sequence in it, gives a warning. */
    const char *text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\x1b]0;owned\x07 x\n";
    CHECK(test_write_file(obj, text, strlen(text)));
    test_warnings first = {0}, again = {0};
    gdr_import_report report = {0};
    gdr_load_options options = {.no_progress = 1, .cache_dir = dir, .warning = test_collect_warning,
                                .warning_user = &first, .report = &report};
    gdr_scene *s = NULL;
    CHECK(gdr_scene_load(obj, &options, &s, &err) == GDR_OK);
    CHECK(first.count == 1 && !strchr(first.text, 0x1b) && strstr(first.text, "\\x1b"));
    CHECK(report.cache_state == GDR_CACHE_WRITTEN && report.warning_count == 1);
    gdr_scene_destroy(s);
    gdr_import_report_free(&report);
    options.warning_user = &again;
    CHECK(gdr_scene_load(obj, &options, &s, &err) == GDR_OK);
    CHECK(report.cache_state == GDR_CACHE_READ && again.count == 1 && strcmp(first.text, again.text) == 0);
    gdr_scene_destroy(s);
    gdr_import_report_free(&report);
    /* A report with a raw escape sequence (as a hostile cache could hold) is escaped when read. */
    gdr_scene *plain = NULL;
    CHECK(gdr_scene_load(obj, &(gdr_load_options){.no_cache = 1, .no_progress = 1,
                                                  .warning = test_collect_warning, .warning_user = &first},
                         &plain, &err) == GDR_OK);
    char *raw = "\x1b[2J\x1b]52;c;cHduZWQ=\x07 hello \xc2\x9b";
    gdr_import_report hostile = {.warnings = &raw, .warning_count = 1, .warning_total = 1};
    gdr_cache_write_options write = {.source = {gdr_cache_build_options(), NULL}, .report = &hostile};
    CHECK(gdr_cache_write(cache, plain, &write, &err) == GDR_OK);
    memset(&again, 0, sizeof again);
    gdr_import_report read_back = {0};
    gdr_status loaded = gdr_scene_load(cache, &(gdr_load_options){.warning = test_collect_warning, .warning_user = &again,
                                                    .report = &read_back}, &s, &err);
    if (loaded != GDR_OK)
        fprintf(stderr, "%s\n", err.message);
    CHECK(loaded == GDR_OK);
    CHECK(again.count == 1 && !strchr(again.text, 0x1b) && !strchr(again.text, 0x07) && !strstr(again.text, "\xc2\x9b"));
    CHECK(strstr(again.text, "\\x1b[2J\\x1b]52;c;cHduZWQ=\\x07 hello \\xc2\\x9b"));
    gdr_scene_destroy(s);
    gdr_import_report_free(&read_back);
    /* Out of its limits: a warning longer than 511 bytes, more kept warnings than the section holds. */
    size_t size;
    uint8_t *bytes = test_read_file(cache, &size);
    uint8_t *entry = bytes ? cache_entry(bytes, "REPT") : NULL;
    CHECK(entry != NULL);
    if (entry) {
        uint64_t offset;
        memcpy(&offset, entry + 8, 8);
        uint32_t length = 600, kept = 1000000;
        uint8_t *copy = malloc(size);
        memcpy(copy, bytes, size);
        memcpy(copy + offset + 12, &length, 4);
        test_cache_fix_checksums(copy, size);
        CHECK_FAILS(gdr_cache_read_memory(copy, size, "long.gdrc", &s, NULL, &err), err, GDR_ERROR_PARSE);
        CHECK(strstr(err.message, "long.gdrc: section 'REPT': warning 0"));
        memcpy(copy, bytes, size);
        memcpy(copy + offset + 4, &kept, 4);
        memcpy(copy + offset + 8, &kept, 4);
        test_cache_fix_checksums(copy, size);
        CHECK_FAILS(gdr_cache_read_memory(copy, size, "many.gdrc", &s, NULL, &err), err, GDR_ERROR_PARSE);
        CHECK(strstr(err.message, "many.gdrc: section 'REPT': 1000000 warnings kept"));
        /* A flipped byte without fixed checksums: corrupted. */
        memcpy(copy, bytes, size);
        copy[offset + 16] ^= 0x20;
        CHECK_FAILS(gdr_cache_read_memory(copy, size, "flip.gdrc", &s, NULL, &err), err, GDR_ERROR_CORRUPT);
        CHECK(strstr(err.message, "'REPT'"));
        free(copy);
    }
    free(bytes);
    gdr_scene_destroy(plain);
}

/* The per-user folder: $XDG_CACHE_HOME/gdr when it is absolute, else $HOME/.cache/gdr. */
static void test_default_dir(void)
{
    char out[1400], expected[1400];
    const char *saved_xdg = getenv("XDG_CACHE_HOME");
    char xdg_copy[1024] = "";
    if (saved_xdg)
        snprintf(xdg_copy, sizeof xdg_copy, "%s", saved_xdg);
    setenv("XDG_CACHE_HOME", "/somewhere/xdg", 1);
    CHECK(gdr_cache_default_dir(out, sizeof out) && strcmp(out, "/somewhere/xdg/gdr") == 0);
    setenv("XDG_CACHE_HOME", "relative/xdg", 1); /* the XDG rule: relative values are ignored */
    setenv("HOME", "/home/someone", 1);
    CHECK(gdr_cache_default_dir(out, sizeof out) && strcmp(out, "/home/someone/.cache/gdr") == 0);
    unsetenv("XDG_CACHE_HOME");
    CHECK(gdr_cache_default_dir(out, sizeof out) && strcmp(out, "/home/someone/.cache/gdr") == 0);
    unsetenv("HOME");
    CHECK(gdr_cache_default_dir(out, sizeof out) == 0);
    /* The folder is made 0700; one others may write to is refused. */
    char home[1200];
    snprintf(home, sizeof home, "%s/home", dir);
    mkdir(home, 0755);
    setenv("HOME", home, 1);
    char obj[1300];
    snprintf(obj, sizeof obj, "%s/default.obj", dir);
    const char *triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    CHECK(test_write_file(obj, triangle, strlen(triangle)));
    gdr_import_report report = {0};
    gdr_scene *s = NULL;
    CHECK(gdr_scene_load(obj, &(gdr_load_options){.no_progress = 1, .report = &report}, &s, &err) == GDR_OK);
    snprintf(expected, sizeof expected, "%s/.cache/gdr/", home);
    CHECK(report.cache_state == GDR_CACHE_WRITTEN && report.cache_path &&
          strncmp(report.cache_path, expected, strlen(expected)) == 0);
    struct stat st;
    expected[strlen(expected) - 1] = 0;
    CHECK(stat(expected, &st) == 0 && (st.st_mode & 0777) == 0700);
    gdr_scene_destroy(s);
    gdr_import_report_free(&report);
    chmod(expected, 0777);
    test_warnings w = {0};
    CHECK(gdr_scene_load(obj, &(gdr_load_options){.no_progress = 1, .report = &report, .warning = test_collect_warning,
                                                  .warning_user = &w}, &s, &err) == GDR_OK);
    CHECK(report.cache_state == GDR_CACHE_NONE && w.count == 1 && strstr(w.text, "others may write to it"));
    gdr_scene_destroy(s);
    gdr_import_report_free(&report);
    if (xdg_copy[0])
        setenv("XDG_CACHE_HOME", xdg_copy, 1);
}

/* n bytes of a file that starts like a cache, used `age` seconds ago. */
static void fake_cache(const char *path, size_t n, int age)
{
    char *bytes = calloc(n, 1);
    memcpy(bytes, "GDRCACHE", 8);
    CHECK(test_write_file(path, bytes, n));
    free(bytes);
    struct timespec times[2];
    clock_gettime(CLOCK_REALTIME, &times[0]);
    times[0].tv_sec -= age;
    times[1] = times[0];
    utimensat(AT_FDCWD, path, times, 0);
}

/* Least recently used first, down to the limit; never the one kept, never what gdr did not write. */
static void test_eviction(void)
{
    char folder[1200], p[6][1400];
    snprintf(folder, sizeof folder, "%s/evict", dir);
    mkdir(folder, 0700);
    const char *names[6] = {"a.gltf-0000000000000001.gdrc", "b.gltf-0000000000000002.gdrc",
                            "c.gltf-0000000000000003.gdrc", "notes.gdrc", "d.obj-00000000000000ff.gdrc",
                            "e.obj-0123456789abcdef.gdrc"};
    for (int i = 0; i < 6; i++)
        snprintf(p[i], sizeof p[i], "%s/%s", folder, names[i]);
    fake_cache(p[0], 1000, 300); /* the oldest */
    fake_cache(p[1], 1000, 100);
    fake_cache(p[2], 1000, 200);
    fake_cache(p[3], 5000, 900);                          /* not a name gdr gives */
    CHECK(test_write_file(p[4], "not a cache at all", 18)); /* gdr's name, not its contents */
    fake_cache(p[5], 1000, 1000);                         /* the oldest, but the one just written */
    CHECK(gdr_io_cache_evict(folder, 2000, p[5]) == 2);
    CHECK(access(p[0], F_OK) != 0 && access(p[2], F_OK) != 0); /* 300 s and 200 s old: gone */
    CHECK(access(p[1], F_OK) == 0 && access(p[5], F_OK) == 0);
    CHECK(access(p[3], F_OK) == 0 && access(p[4], F_OK) == 0);
    uint32_t removed = 0;
    CHECK(gdr_cache_clear(folder, &removed, NULL, &err) == GDR_OK && removed == 2);
    CHECK(access(p[3], F_OK) == 0 && access(p[4], F_OK) == 0 && access(p[1], F_OK) != 0);
    /* The limit: the option, else GDR_CACHE_MAX_MIB, else the default. */
    CHECK(gdr_io_cache_limit(123) == 123);
    setenv("GDR_CACHE_MAX_MIB", "7", 1);
    CHECK(gdr_io_cache_limit(0) == 7u << 20);
    setenv("GDR_CACHE_MAX_MIB", "seven", 1);
    CHECK(gdr_io_cache_limit(0) == GDR_CACHE_DEFAULT_MAX_BYTES);
    unsetenv("GDR_CACHE_MAX_MIB");
}

int main(void)
{
    snprintf(dir, sizeof dir, "%s/import_report", GDR_IO_TEST_TMP);
    char clean[1200];
    snprintf(clean, sizeof clean, "rm -rf '%s'", dir); /* caches of an earlier run would be read */
    CHECK(system(clean) == 0);
    mkdir(dir, 0755);
    test_unsupported_features();
    test_buffers_before_images();
    test_report_section();
    test_eviction();
    test_default_dir();
    return test_finish("test_import_report");
}
