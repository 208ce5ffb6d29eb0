/* Hostile scene and cache files (docs/SECURITY.md): each case is a file a few bytes to a few kB
 * long that once crashed gdr, made it hang, read files outside the scene's folder, rendered a
 * stale cache or allocated gigabytes; each must now load or be refused with a message. */
#define _GNU_SOURCE /* mkfifo, symlink, utimensat */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "geometry/cluster_checks.h"
#include <xxhash.h>
#include <zlib.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "io/io_test_helpers.h"
#include "test_util.h"
#include "io/loaders.h"

static test_warnings warnings;
static gdr_error err;
static char dir[1024];

static gdr_scene *obj_text(const char *text, const gdr_budget *budget)
{
    gdr_import_options o = {.warning = test_collect_warning, .warning_user = &warnings, .no_progress = 1};
    if (budget)
        o.budget = *budget;
    gdr_scene *s = NULL;
    memset(&warnings, 0, sizeof warnings);
    memset(&err, 0, sizeof err);
    gdr_import_obj_memory(text, strlen(text), "hostile.obj", &o, &s, NULL, &err);
    return s;
}

static gdr_scene *gltf_file(const char *path, const gdr_budget *budget, int allow_outside)
{
    gdr_import_options o = {.warning = test_collect_warning, .warning_user = &warnings, .no_progress = 1,
                            .allow_outside_files = allow_outside};
    if (budget)
        o.budget = *budget;
    gdr_scene *s = NULL;
    memset(&warnings, 0, sizeof warnings);
    memset(&err, 0, sizeof err);
    gdr_import_gltf(path, &o, &s, NULL, &err);
    return s;
}

static gdr_scene *gltf_text(const char *text, const gdr_budget *budget)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/t.gltf", dir);
    CHECK(test_write_file(path, text, strlen(text)));
    return gltf_file(path, budget, 0);
}

/* A glTF of one triangle list whose positions are `positions` (a data: URI). */
static char *triangle_gltf(const float *positions, uint32_t vertices)
{
    char *uri = test_data_uri(positions, sizeof(float) * 3 * vertices);
    size_t size = strlen(uri) + 1024;
    char *text = malloc(size);
    snprintf(text, size,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%u,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":%u}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}],"
             "\"scenes\":[{\"nodes\":[0]}]}",
             (unsigned)(12 * vertices), uri, (unsigned)(12 * vertices), vertices);
    free(uri);
    return text;
}

/* Huge finite coordinates: meshoptimizer made no meshlet (and gdr read meshlets[-1]) or asserted. */
static void test_huge_coordinates(void)
{
    gdr_scene *s = obj_text("v 0x1p127 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n", NULL);
    CHECK(!s);
    CHECK_STATUS(err, GDR_ERROR_PARSE);
    CHECK_NAMES(err, "hostile.obj:1: v: '0x1p127'");
    s = obj_text("v 1e19 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n", NULL);
    CHECK(!s);
    CHECK_STATUS(err, GDR_ERROR_PARSE);
    CHECK_NAMES(err, "hostile.obj:1:");
    const float values[] = {1e19f, 1e20f, -3e38f};
    for (int k = 0; k < 3; k++) {
        float p[9] = {values[k], 0, 0, 0, 1, 0, 0, 0, 1};
        char *text = triangle_gltf(p, 3);
        s = gltf_text(text, NULL);
        free(text);
        CHECK(!s);
        CHECK_STATUS(err, GDR_ERROR_PARSE);
        CHECK_NAMES(err, "meshes[0].primitives[0].attributes.POSITION: vertex 0");
    }
    /* The same numbers handed to the library directly (a cache, an application). */
    gdr_vec3 p[3] = {{1e19f, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    uint32_t idx[3] = {0, 1, 2};
    gdr_scene *scene = NULL;
    CHECK(gdr_scene_create(&scene, &err) == GDR_OK);
    CHECK_FAILS(gdr_scene_add_mesh(scene, "huge", p, NULL, NULL, 3, idx, 3, NULL, &err), err,
                GDR_ERROR_INVALID_ARGUMENT);
    gdr_mesh mesh = {.vertex_count = 3, .positions = p, .index_count = 3, .indices = idx};
    gdr_mesh_clusters clusters = {0};
    CHECK_FAILS(gdr_meshlets_build(&mesh, NULL, &clusters, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    gdr_scene_destroy(scene);
    /* 1e11 is allowed and builds meshlets. */
    s = obj_text("v 1e11 0 0\nv 0 1e11 0\nv 0 0 1e11\nf 1 2 3\n", NULL);
    CHECK(s && s->mesh_count == 1);
    gdr_scene_destroy(s);
}

/* Duplicate and degenerate triangles are dropped at import, with a warning. */
static void test_degenerate_and_duplicate(void)
{
    char text[4096] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 0\nv 2 0 0\n";
    for (int i = 0; i < 40; i++)
        strcat(text, "f 1 2 3\n");
    strcat(text, "f 3 1 2\n"); /* the same face, rotated */
    strcat(text, "f 1 3 2\n"); /* its back face: kept */
    strcat(text, "f 4 2 3\n"); /* vertex 4 is at vertex 1's position: a duplicate */
    strcat(text, "f 1 2 5\n"); /* zero area */
    strcat(text, "f 1 4 3\n"); /* two corners at one position */
    gdr_scene *s = obj_text(text, NULL);
    CHECK(s && s->mesh_count == 1 && s->meshes[0].index_count == 6);
    CHECK(strstr(warnings.text, "43 of 45 faces dropped (2 degenerate, 41 duplicate)") != NULL);
    gdr_scene_destroy(s);
    /* A POSITION accessor without a bufferView: every triangle has zero area, nothing is left. */
    const char *zeros = "{\"asset\":{\"version\":\"2.0\"},\"accessors\":[{\"componentType\":5126,\"count\":3000,"
                        "\"type\":\"VEC3\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                        "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}";
    s = gltf_text(zeros, NULL);
    CHECK(s && s->mesh_count == 0 && s->instance_count == 0);
    CHECK(strstr(warnings.text, "1000 of 1000 triangles dropped (1000 degenerate, 0 duplicate); no triangles left"));
    gdr_scene_destroy(s);
}

/* A vertex shared by thousands of triangles (a fan) is split into copies of at most 128 uses. */
static void test_fan_split(void)
{
    enum { N = 1000 };
    char *text = malloc(64 * (N + 2) * 2);
    size_t n = (size_t)sprintf(text, "v 0 0 0\n");
    for (int i = 0; i <= N; i++)
        n += (size_t)sprintf(text + n, "v %d 1 0\n", i);
    for (int i = 0; i < N; i++)
        n += (size_t)sprintf(text + n, "f 1 %d %d\n", i + 3, i + 2);
    gdr_scene *s = obj_text(text, NULL);
    free(text);
    CHECK(s && s->mesh_count == 1 && s->meshes[0].index_count == 3 * N);
    if (s) {
        const gdr_mesh *m = &s->meshes[0];
        uint32_t *uses = calloc(m->vertex_count, sizeof(uint32_t)), most = 0, centre = 0;
        for (uint32_t i = 0; i < m->index_count; i++)
            most = ++uses[m->indices[i]] > most ? uses[m->indices[i]] : most;
        for (uint32_t v = 0; v < m->vertex_count; v++)
            centre += m->positions[v].x == 0 && m->positions[v].y == 0;
        CHECK(most <= 128 && centre == (N + 127) / 128);
        CHECK(m->clusters.cluster_count > 0 || gdr_scene_build_clusters(s, NULL, &err) == GDR_OK);
        free(uses);
    }
    gdr_scene_destroy(s);
}

/* A soup of separate triangles and one far away: meshoptimizer's kd-tree cannot split them, so
 * meshlets are built in chunks; they must still follow the whole cluster contract. */
static void test_soup_with_outlier(void)
{
    enum { N = 9000 };
    gdr_vec3 *p = malloc(sizeof(gdr_vec3) * 3 * (N + 1));
    uint32_t *idx = malloc(sizeof(uint32_t) * 3 * (N + 1));
    unsigned state = 3;
    for (uint32_t i = 0; i < N; i++) {
        gdr_vec3 a = {test_random(&state), test_random(&state), test_random(&state)};
        p[3 * i] = a;
        p[3 * i + 1] = (gdr_vec3){a.x + 0.01f, a.y, a.z};
        p[3 * i + 2] = (gdr_vec3){a.x, a.y + 0.01f, a.z};
    }
    p[3 * N] = (gdr_vec3){1e9f, 0, 0};
    p[3 * N + 1] = (gdr_vec3){1e9f, 1, 0};
    p[3 * N + 2] = (gdr_vec3){1e9f, 0, 1};
    for (uint32_t i = 0; i < 3 * (N + 1); i++)
        idx[i] = i;
    gdr_mesh mesh = {.name = "soup", .vertex_count = 3 * (N + 1), .positions = p, .index_count = 3 * (N + 1),
                     .indices = idx};
    gdr_mesh_clusters mc = {0};
    CHECK(gdr_meshlets_build(&mesh, NULL, &mc, &err) == GDR_OK);
    CHECK(check_cluster_layout(&mesh, &mc, GDR_CLUSTER_MAX_VERTICES, GDR_CLUSTER_MAX_TRIANGLES));
    CHECK(check_cluster_coverage(&mesh, &mc));
    CHECK(check_cluster_spheres(&mesh, &mc));
    gdr_mesh_clusters_free(&mc);
    free(p);
    free(idx);
}

/* URIs leaving the scene's folder are refused unless allowed. */
static void test_uri_confinement(void)
{
    char path[1400], scene_dir[1100], outside[1100], secret[1200];
    snprintf(scene_dir, sizeof scene_dir, "%s/scene", dir);
    snprintf(outside, sizeof outside, "%s/outside", dir);
    mkdir(scene_dir, 0755);
    mkdir(outside, 0755);
    mkdir(strcat(strcpy(path, scene_dir), "/sub"), 0755);
    float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    snprintf(secret, sizeof secret, "%s/secret.bin", outside);
    CHECK(test_write_file(secret, p, sizeof p));
    snprintf(path, sizeof path, "%s/sub/inside.bin", scene_dir);
    CHECK(test_write_file(path, p, sizeof p));
    snprintf(path, sizeof path, "%s/link.bin", scene_dir);
    unlink(path);
    CHECK(symlink(secret, path) == 0);
    struct { const char *uri; bool refused; } cases[] = {
        {"../outside/secret.bin", true}, {"%2e%2e/outside/secret.bin", true}, {"sub/../../outside/secret.bin", true},
        {"link.bin", true},              {"/etc/passwd", true},               {"%2fetc%2fpasswd", true},
        {"sub/inside.bin", false},       {"sub/./inside.bin", false},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[1024], file[1200];
        snprintf(text, sizeof text,
                 "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"%s\"}],"
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,"
                 "\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],\"meshes\":[{\"primitives\":[{\"attributes\":"
                 "{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
                 cases[i].uri);
        snprintf(file, sizeof file, "%s/t.gltf", scene_dir);
        CHECK(test_write_file(file, text, strlen(text)));
        gdr_scene *s = gltf_file(file, NULL, 0);
        if (cases[i].refused) {
            CHECK(!s);
            CHECK_STATUS(err, GDR_ERROR_OUTSIDE_FOLDER);
            CHECK_NAMES(err, "buffers[0].uri");
            CHECK(!strstr(err.message, "root:")); /* no byte of /etc/passwd in the message */
            if (strcmp(cases[i].uri, "/etc/passwd") != 0 && strcmp(cases[i].uri, "%2fetc%2fpasswd") != 0) {
                gdr_scene_destroy(s);
                s = gltf_file(file, NULL, 1); /* the caller's opt-in */
                CHECK(s && s->mesh_count == 1);
            }
        } else {
            CHECK(s && s->mesh_count == 1);
        }
        gdr_scene_destroy(s);
    }
}

/* URIs that name no file: called so (both were "resolves outside the scene's folder (a symbolic
 * link)"): no file at all is malformed, the scene's folder is not a file. */
static void test_uri_messages(void)
{
    struct { const char *uri; gdr_status status; } cases[] = {
        {"", GDR_ERROR_PARSE},
        {".", GDR_ERROR_NOT_A_FILE},
        {"./", GDR_ERROR_NOT_A_FILE},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[1024], file[1200];
        snprintf(text, sizeof text,
                 "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"%s\"}],"
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,"
                 "\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],\"meshes\":[{\"primitives\":[{\"attributes\":"
                 "{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
                 cases[i].uri);
        snprintf(file, sizeof file, "%s/scene/t.gltf", dir);
        CHECK(test_write_file(file, text, strlen(text)));
        gdr_scene *s = gltf_file(file, NULL, 0);
        CHECK(!s);
        CHECK_STATUS(err, cases[i].status);
        CHECK_NAMES(err, "buffers[0].uri");
        gdr_scene_destroy(s);
    }
}

static void on_alarm(int signal)
{
    (void)signal;
    static const char message[] = "test_hostile: hung opening a FIFO\n";
    (void)!write(2, message, sizeof message - 1);
    _exit(1);
}

/* A FIFO as a buffer, as a cache, or in a cache's source list: refused at once, never waited on. */
static void test_fifo(void)
{
    char fifo[1200], file[1200];
    snprintf(fifo, sizeof fifo, "%s/scene/fifo.bin", dir);
    unlink(fifo);
    CHECK(mkfifo(fifo, 0600) == 0);
    signal(SIGALRM, on_alarm);
    alarm(20);
    const char *text = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"fifo.bin\"}],"
                       "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,"
                       "\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],\"meshes\":[{\"primitives\":[{"
                       "\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}";
    snprintf(file, sizeof file, "%s/scene/t.gltf", dir);
    CHECK(test_write_file(file, text, strlen(text)));
    gdr_scene *s = gltf_file(file, NULL, 0);
    CHECK(!s);
    CHECK_STATUS(err, GDR_ERROR_NOT_A_FILE);
    CHECK_NAMES(err, "fifo.bin");
    CHECK_FAILS(gdr_cache_read(fifo, NULL, &s, NULL, &err), err, GDR_ERROR_NOT_A_FILE);
    /* A cache whose source list names the FIFO (with another mtime: its contents would be read). */
    char cache[1200];
    snprintf(cache, sizeof cache, "%s/fifo_list.gdrc", dir);
    s = obj_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", NULL);
    gdr_source_file f = {fifo, 0, 1, 42};
    gdr_source_list list = {&f, 1, 1};
    gdr_cache_write_options write = {.source = {gdr_cache_build_options(), &list}};
    CHECK(s && gdr_cache_write(cache, s, &write, &err) == GDR_OK);
    gdr_scene_destroy(s);
    s = NULL;
    CHECK(gdr_cache_read(cache, gdr_cache_build_options(), &s, NULL, &err) == GDR_OK);
    gdr_scene_destroy(s);
    alarm(0);
    unlink(fifo);
}

/* Writes `s` as the cache of `source` (its first entry, fresh), listing `spellings` names of `big`
 * (recorded with another mtime: their contents are compared). */
static void write_listing_cache(const char *cache, const gdr_scene *s, const char *source, const char *big,
                                uint32_t spellings)
{
    struct stat st_source, st_big;
    CHECK(stat(source, &st_source) == 0 && stat(big, &st_big) == 0);
    size_t size;
    uint8_t *contents = test_read_file(big, &size);
    uint64_t hash = contents ? XXH3_64bits(contents, size) : 0;
    free(contents);
    char absolute[PATH_MAX];
    CHECK(realpath(source, absolute) != NULL);
    gdr_source_file *files = calloc(spellings + 1, sizeof *files);
    char (*names)[PATH_MAX] = calloc(spellings, PATH_MAX);
    files[0] = (gdr_source_file){absolute, (uint64_t)st_source.st_size,
                                 (int64_t)st_source.st_mtim.tv_sec * 1000000000ll + st_source.st_mtim.tv_nsec, 0};
    /* `//dir/./big.bin`, `/dir/././big.bin`, ...: one file, many strings. */
    for (uint32_t i = 0; i < spellings; i++) {
        int n = snprintf(names[i], PATH_MAX, "%s%s", i % 2 ? "/" : "", big);
        char *slash = strrchr(names[i], '/');
        memmove(slash + 2 * (i / 2), slash, strlen(slash) + 1);
        for (uint32_t k = 0; k < i / 2; k++)
            memcpy(slash + 2 * k, "/.", 2);
        CHECK(n > 0 && strlen(names[i]) < PATH_MAX - 2);
        files[i + 1] = (gdr_source_file){names[i], (uint64_t)st_big.st_size, 1, hash};
    }
    gdr_source_list list = {files, spellings + 1, spellings + 1};
    gdr_cache_write_options write = {.source = {gdr_cache_build_options(), &list}};
    CHECK(gdr_cache_write(cache, s, &write, &err) == GDR_OK);
    free(files);
    free(names);
}

/* A source list naming one file many times, under many spellings: the file is read and hashed once,
 * not per entry nor per string. */
static void test_source_list_repeats(void)
{
    char big[1200], source[1200], cache[1300];
    snprintf(big, sizeof big, "%s/big.bin", dir);
    snprintf(source, sizeof source, "%s/repeats.obj", dir);
    snprintf(cache, sizeof cache, "%s.gdrc", source);
    size_t size = 16u << 20;
    uint8_t *bytes = calloc(size, 1);
    CHECK(bytes && test_write_file(big, bytes, size));
    free(bytes);
    const char *one = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    CHECK(test_write_file(source, one, strlen(one)));
    /* The cache holds two triangles, the source one: a scene of two came from the cache. */
    gdr_scene *s = obj_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n", NULL);
    double seconds[2];
    uint32_t counts[2] = {1, 243};
    /* next to the source ("."), where a copied folder carries its cache */
    gdr_load_options o = {.no_progress = 1, .warning = test_collect_warning, .warning_user = &warnings,
                          .cache_dir = "."};
    for (int k = 0; k < 2; k++) {
        write_listing_cache(cache, s, source, big, counts[k]);
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        gdr_scene *loaded = NULL;
        CHECK(gdr_scene_load_file(source, &o, &loaded, NULL, &err) == GDR_OK);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        CHECK(loaded && loaded->meshes[0].index_count == 6); /* every entry fresh: the cache was used */
        seconds[k] = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
        gdr_scene_destroy(loaded);
    }
    /* Once per string, 243 spellings take about 243 times as long; once per file, about the same. */
    printf("source list: 1 entry %.2f ms, 243 spellings of one file %.2f ms\n", seconds[0] * 1e3, seconds[1] * 1e3);
    CHECK(seconds[1] < 8 * seconds[0] + 0.05);
    /* Read as it stands (a .gdrc given directly), the cache opens none of its recorded files: one
     * whose contents differ from the record, or a FIFO, changes nothing. */
    CHECK(test_write_file(big, "other contents", 14));
    gdr_scene *loaded = NULL;
    CHECK(gdr_cache_read(cache, gdr_cache_build_options(), &loaded, NULL, &err) == GDR_OK && loaded &&
          loaded->meshes[0].index_count == 6);
    gdr_scene_destroy(loaded);
    loaded = NULL;
    CHECK(gdr_scene_load_file(cache, &o, &loaded, NULL, &err) == GDR_OK && loaded &&
          loaded->meshes[0].index_count == 6);
    gdr_scene_destroy(loaded);
    /* Read for its source, the changed file makes it stale: rebuilt from the source. */
    loaded = NULL;
    CHECK(gdr_scene_load_file(source, &o, &loaded, NULL, &err) == GDR_OK && loaded &&
          loaded->meshes[0].index_count == 3);
    gdr_scene_destroy(loaded);
    gdr_scene_destroy(s);
    unlink(big);
}

static void copy_file(const char *from, const char *to)
{
    size_t size;
    uint8_t *data = test_read_file(from, &size);
    CHECK(data && test_write_file(to, data, size));
    free(data);
}

/* The cache of scene A copied with A's folder to B, and B edited: B must not render A's geometry. */
static void test_cache_knows_its_source(void)
{
    char a[1200], b[1200], a_obj[1300], b_obj[1300], a_cache[1400], b_cache[1400];
    snprintf(a, sizeof a, "%s/A", dir);
    snprintf(b, sizeof b, "%s/B", dir);
    mkdir(a, 0755);
    mkdir(b, 0755);
    snprintf(a_obj, sizeof a_obj, "%s/s.obj", a);
    snprintf(b_obj, sizeof b_obj, "%s/s.obj", b);
    snprintf(a_cache, sizeof a_cache, "%s.gdrc", a_obj);
    snprintf(b_cache, sizeof b_cache, "%s.gdrc", b_obj);
    const char *one = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    const char *two = "v 0 0 0\nv 2 0 0\nv 0 2 0\nf 1 2 3\n"; /* same size, other contents */
    const char *three = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
    unlink(a_cache);
    CHECK(test_write_file(a_obj, one, strlen(one)));
    /* next to the source ("."), where a copied folder carries its cache */
    gdr_load_options o = {.no_progress = 1, .warning = test_collect_warning, .warning_user = &warnings,
                          .cache_dir = "."};
    gdr_scene *s = NULL;
    CHECK(gdr_scene_load_file(a_obj, &o, &s, NULL, &err) == GDR_OK && access(a_cache, F_OK) == 0);
    gdr_scene_destroy(s);
    for (int edit = 0; edit < 2; edit++) {
        copy_file(a_cache, b_cache);
        const char *text = edit == 0 ? two : three;
        CHECK(test_write_file(b_obj, text, strlen(text)));
        /* Even with A's modification time (as `cp -a` and an edit within the same second leave it). */
        struct stat st;
        CHECK(stat(a_obj, &st) == 0);
        struct timespec times[2] = {st.st_atim, st.st_mtim};
        CHECK(utimensat(AT_FDCWD, b_obj, times, 0) == 0);
        s = NULL;
        CHECK(gdr_scene_load_file(b_obj, &o, &s, NULL, &err) == GDR_OK);
        float extent = s ? s->meshes[0].positions[1].x : 0;
        CHECK(s && s->meshes[0].index_count == (edit == 0 ? 3u : 6u) && extent == (edit == 0 ? 2.0f : 1.0f));
        gdr_scene_destroy(s);
    }
    /* A's own cache is still used for A. */
    s = NULL;
    CHECK(gdr_scene_load_file(a_obj, &o, &s, NULL, &err) == GDR_OK && s && s->meshes[0].positions[1].x == 1.0f);
    gdr_scene_destroy(s);
}

/* Image pixels: a budget over the whole scene, checked from the header before decoding. */
static size_t png_header(uint8_t *out, uint32_t width, uint32_t height)
{
    static const uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    memcpy(out, signature, 8);
    uint8_t ihdr[25] = {0, 0, 0, 13, 'I', 'H', 'D', 'R', (uint8_t)(width >> 24), (uint8_t)(width >> 16),
                        (uint8_t)(width >> 8), (uint8_t)width, (uint8_t)(height >> 24), (uint8_t)(height >> 16),
                        (uint8_t)(height >> 8), (uint8_t)height, 8, 6, 0, 0, 0, 0, 0, 0, 0};
    uint32_t crc = (uint32_t)crc32(0, ihdr + 4, 17);
    for (int i = 0; i < 4; i++)
        ihdr[21 + i] = (uint8_t)(crc >> (24 - 8 * i));
    memcpy(out + 8, ihdr, sizeof ihdr);
    return 8 + sizeof ihdr;
}

static char *textured_gltf(uint32_t images, uint32_t side)
{
    uint8_t png[64];
    char *uri = test_data_uri(png, png_header(png, side, side));
    size_t size = 4096 + images * (strlen(uri) + 200);
    char *text = malloc(size);
    size_t n = (size_t)snprintf(text, size, "{\"asset\":{\"version\":\"2.0\"},\"images\":[");
    for (uint32_t i = 0; i < images; i++)
        n += (size_t)snprintf(text + n, size - n, "%s{\"uri\":\"%s\"}", i ? "," : "", uri);
    n += (size_t)snprintf(text + n, size - n, "],\"textures\":[");
    for (uint32_t i = 0; i < images; i++)
        n += (size_t)snprintf(text + n, size - n, "%s{\"source\":%u}", i ? "," : "", i);
    n += (size_t)snprintf(text + n, size - n, "],\"materials\":[");
    for (uint32_t i = 0; i < images; i++)
        n += (size_t)snprintf(text + n, size - n, "%s{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":%u}}}",
                              i ? "," : "", i);
    snprintf(text + n, size - n, "]}");
    free(uri);
    return text;
}

static void test_texture_pixels(void)
{
    char *text = textured_gltf(1, 16384);
    gdr_scene *s = gltf_text(text, NULL);
    free(text);
    CHECK(!s);
    CHECK_STATUS(err, GDR_ERROR_BUDGET);
    CHECK_NAMES(err, "images[0]");
    CHECK_NAMES(err, "--budget pixels=N"); /* how to raise it, as docs/SECURITY.md promises */
    /* Two 8192^2 images fill the default budget; the third is refused. */
    text = textured_gltf(3, 8192);
    s = gltf_text(text, NULL);
    CHECK(!s);
    CHECK_STATUS(err, GDR_ERROR_BUDGET);
    CHECK_NAMES(err, "images[2]");
    /* Raised, they pass the budget (and, being headers only, are left out with a warning). */
    gdr_budget raised = {.texture_pixels = 3ull << 26};
    s = gltf_text(text, &raised);
    free(text);
    CHECK(s && s->texture_count == 0 && warnings.count == 3 && strstr(warnings.text, "images[2] (a data: URI): PNG: ") &&
          strstr(warnings.text, "(truncated)"));
    gdr_scene_destroy(s);
    /* The cache writer refuses what its reader would refuse. */
    s = obj_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", NULL);
    uint8_t *row = calloc(32769, 4);
    CHECK(s && row && gdr_scene_add_texture(s, "wide", 32768, 1, row, 0, NULL, &err) == GDR_OK);
    s->textures[0].width = 32769; /* what gdr_scene_add_texture would refuse, as a bug elsewhere might leave */
    char cache[1200];
    snprintf(cache, sizeof cache, "%s/wide.gdrc", dir);
    unlink(cache);
    CHECK_FAILS(gdr_cache_write(cache, s, NULL, &err), err, GDR_ERROR_CAPACITY);
    CHECK_NAMES(err, "texture 0");
    CHECK(access(cache, F_OK) != 0);
    s->textures[0].width = 32768;
    free(row);
    gdr_scene_destroy(s);
}

/* EXT_mesh_gpu_instancing accessors without a bufferView: 16.7 M instances from 800 bytes. */
static void test_instance_budget(void)
{
    char text[2048];
    const char *format =
        "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\"],\"buffers\":[{\"byteLength\":"
        "36,\"uri\":\"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,"
        "\"count\":3,\"type\":\"VEC3\"},{\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\"}],\"meshes\":[{"
        "\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0,\"extensions\":{"
        "\"EXT_mesh_gpu_instancing\":{\"attributes\":{\"TRANSLATION\":1}}}}],\"scenes\":[{\"nodes\":[0]}]}";
    snprintf(text, sizeof text, format, 16777216u);
    gdr_scene *s = gltf_text(text, NULL);
    CHECK(!s);
    CHECK_STATUS(err, GDR_ERROR_BUDGET);
    CHECK_NAMES(err, "EXT_mesh_gpu_instancing");
    CHECK_NAMES(err, "--budget instances=N");
    gdr_budget small = {.instances = 100};
    snprintf(text, sizeof text, format, 100u);
    s = gltf_text(text, &small);
    CHECK(s && s->instance_count == 100);
    gdr_scene_destroy(s);
    snprintf(text, sizeof text, format, 101u);
    s = gltf_text(text, &small);
    CHECK(!s);
    CHECK_STATUS(err, GDR_ERROR_BUDGET);
}

/* Triangles and decoded bytes: refused before the memory is allocated. */
static void test_other_budgets(void)
{
    gdr_budget small = {.triangles = 2};
    gdr_scene *s = obj_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nf 1 2 4 3\n", &small);
    CHECK(!s);
    CHECK_STATUS(err, GDR_ERROR_BUDGET);
    CHECK_NAMES(err, "hostile.obj:7:");
    CHECK_NAMES(err, "--budget triangles=N");
    float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    char *text = triangle_gltf(p, 3);
    gdr_budget one = {.triangles = 1}, bytes = {.decoded_bytes = 16};
    s = gltf_text(text, &one);
    CHECK(s && s->mesh_count == 1);
    gdr_scene_destroy(s);
    s = gltf_text(text, &bytes);
    free(text);
    CHECK(!s);
    CHECK_STATUS(err, GDR_ERROR_BUDGET);
    CHECK_NAMES(err, "buffers[0]");
    CHECK_NAMES(err, "--budget bytes=N");
}

/* Messages that say what is wrong. */
static void test_messages(void)
{
    char text[4096] = "{\"asset\":{\"version\":\"2.0\"},\"extras\":";
    for (int i = 0; i < 1100; i++)
        strcat(text, "[");
    gdr_scene *s = gltf_text(text, NULL);
    CHECK(!s);
    CHECK_STATUS(err, GDR_ERROR_PARSE);
    CHECK_NAMES(err, "JSON nested deeper than 1000 arrays and objects"); /* the wording is what is tested */
    uint8_t png[64];
    size_t n = png_header(png, 4, 4);
    uint8_t *rgba = NULL;
    uint32_t w, h;
    CHECK_FAILS(gdr_image_decode(png, n, "cut.png", &rgba, &w, &h, &err), err, GDR_ERROR_PARSE);
    CHECK_NAMES(err, "cut.png: PNG: the file ends before its IEND chunk (truncated)");
    free(rgba);
}

/* A glTF of one triangle with the material `material` (JSON text). */
static gdr_scene *material_gltf(const char *material)
{
    static const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    char *uri = test_data_uri(corners, sizeof corners);
    char text[2048];
    snprintf(text, sizeof text,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,"
             "\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],\"materials\":[%s],\"meshes\":[{"
             "\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],\"nodes\":[{\"mesh\":0}],"
             "\"scenes\":[{\"nodes\":[0]}]}",
             uri, material);
    free(uri);
    return gltf_text(text, NULL);
}

/* Material values a cache cannot hold: refused at import, by the API and by the writer, with the
 * reader's own rule (a factor of 1e300 was written as +inf, and the reader then refused the cache). */
static void test_material_values(void)
{
    static const char *const bad[] = {
        "{\"pbrMetallicRoughness\":{\"metallicFactor\":1e300}}",
        "{\"pbrMetallicRoughness\":{\"roughnessFactor\":-1e39}}",
        "{\"alphaCutoff\":1e300}",
        "{\"normalTexture\":{\"index\":0,\"scale\":1e300}}",
        "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1e300]}}",
        ("{\"emissiveFactor\":[3e38,0,0],\"extensions\":{\"KHR_materials_emissive_strength\":"
         "{\"emissiveStrength\":1e6}}}"),
    };
    static const char *const where[] = {"materials[0].pbrMetallicRoughness.metallicFactor",
                                        "materials[0].pbrMetallicRoughness.roughnessFactor", "materials[0].alphaCutoff",
                                        "materials[0].normalTexture.scale",
                                        "materials[0].pbrMetallicRoughness.baseColorFactor[3]",
                                        "materials[0]: emissive factor"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        gdr_scene *s = material_gltf(bad[i]);
        CHECK(!s);
        CHECK_STATUS(err, GDR_ERROR_PARSE);
        CHECK_NAMES(err, "t.gltf");
        CHECK_NAMES(err, where[i]);
        gdr_scene_destroy(s);
    }
    gdr_scene *s = material_gltf("{\"pbrMetallicRoughness\":{\"metallicFactor\":0.25}}");
    CHECK(s && s->material_count == 1 && s->materials[0].metallic_factor == 0.25f);
    /* Through the API, and a material poked into the scene's array: the writer refuses it. */
    gdr_material m = gdr_material_default();
    m.roughness_factor = 1.0f / 0.0f;
    CHECK(s);
    if (s)
        CHECK_FAILS(gdr_scene_add_material(s, &m, NULL, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    char cache[1200];
    snprintf(cache, sizeof cache, "%s/inf_material.gdrc", dir);
    unlink(cache);
    if (s)
        s->materials[0].occlusion_strength = 1.0f / 0.0f;
    if (s) {
        CHECK_FAILS(gdr_cache_write(cache, s, NULL, &err), err, GDR_ERROR_INVALID_ARGUMENT);
        CHECK_NAMES(err, "material 0");
    }
    CHECK(access(cache, F_OK) != 0);
    gdr_scene_destroy(s);
}

/* Primitives reading the same accessors share one mesh (each primitive its own instance, with its
 * own material); other indices make another mesh. Each primitive was a mesh and a DAG of its own. */
static void test_shared_accessors(void)
{
    static const float corners[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    static const uint32_t quads[9] = {0, 1, 2, 1, 3, 2, 0, 1, 3};
    uint8_t bytes[sizeof corners + sizeof quads];
    memcpy(bytes, corners, sizeof corners);
    memcpy(bytes + sizeof corners, quads, sizeof quads);
    char *uri = test_data_uri(bytes, sizeof bytes);
    char text[4096];
    const char *same = "{\"attributes\":{\"POSITION\":0},\"indices\":1";
    snprintf(text, sizeof text,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":84,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"},"
             "{\"bufferView\":1,\"byteOffset\":24,\"componentType\":5125,\"count\":3,\"type\":\"SCALAR\"}],"
             "\"materials\":[{},{}],\"meshes\":[{\"primitives\":[%s},%s,\"material\":1},%s,\"mode\":4},"
             "{\"attributes\":{\"POSITION\":0},\"indices\":2}]},{\"primitives\":[%s,\"material\":0}]}],"
             "\"nodes\":[{\"mesh\":0},{\"mesh\":1,\"translation\":[5,0,0]}],\"scenes\":[{\"nodes\":[0,1]}]}",
             uri, same, same, same, same);
    free(uri);
    gdr_scene *s = gltf_text(text, NULL);
    CHECK(s && s->mesh_count == 2 && s->instance_count == 5);
    uint32_t uses[2] = {0, 0};
    for (uint32_t i = 0; s && i < s->instance_count; i++)
        uses[s->instances[i].mesh < 2 ? s->instances[i].mesh : 0]++;
    CHECK(s && uses[0] + uses[1] == 5 && (uses[0] == 4 || uses[1] == 4));
    CHECK(s && s->instances[0].material != s->instances[1].material && s->instances[1].material == 1);
    if (s)
        printf("shared accessors: %u meshes, %u instances\n", s->mesh_count, s->instance_count);
    gdr_scene_destroy(s);
}

/* Output files: links followed, devices written in place, FIFOs without a reader refused. */
static void test_output_targets(void)
{
    char target[1200], link[1200], fifo[1200];
    snprintf(target, sizeof target, "%s/target.json", dir);
    snprintf(link, sizeof link, "%s/link.json", dir);
    snprintf(fifo, sizeof fifo, "%s/out.fifo", dir);
    unlink(target), unlink(link), unlink(fifo);
    CHECK(test_write_file(target, "old", 3) && symlink(target, link) == 0);
    CHECK(gdr_write_file_atomic(link, "new!", 4, &err) == GDR_OK);
    struct stat st;
    CHECK(lstat(link, &st) == 0 && S_ISLNK(st.st_mode) && stat(target, &st) == 0 && st.st_size == 4);
    /* Devices of the test's own (root can make them): a regression must not replace the system's
     * /dev/null. */
    char null_device[1200], full_device[1200];
    snprintf(null_device, sizeof null_device, "%s/null", dir);
    snprintf(full_device, sizeof full_device, "%s/full", dir);
    unlink(null_device), unlink(full_device);
    if (mknod(null_device, S_IFCHR | 0666, makedev(1, 3)) == 0 && mknod(full_device, S_IFCHR | 0666, makedev(1, 7)) == 0) {
        CHECK(gdr_write_file_atomic(null_device, "x", 1, &err) == GDR_OK);
        CHECK(stat(null_device, &st) == 0 && S_ISCHR(st.st_mode));
        CHECK_FAILS(gdr_write_file_atomic(full_device, "x", 1, &err), err, GDR_ERROR_IO);
        CHECK(stat(full_device, &st) == 0 && S_ISCHR(st.st_mode));
    } else {
        printf("devices: not root, written to /dev/stdout only\n");
    }
    /* What /dev/stdout is: a link to the process's descriptor 1, whatever that is (a pipe here). */
    char stdout_link[1200];
    snprintf(stdout_link, sizeof stdout_link, "%s/stdout", dir);
    unlink(stdout_link);
    CHECK(symlink("/proc/self/fd/1", stdout_link) == 0);
    CHECK(gdr_write_file_atomic(stdout_link, "", 0, &err) == GDR_OK);
    CHECK(lstat(stdout_link, &st) == 0 && S_ISLNK(st.st_mode));
    unlink(null_device), unlink(full_device), unlink(stdout_link);
    CHECK(mkfifo(fifo, 0600) == 0);
    alarm(20);
    CHECK_FAILS(gdr_write_file_atomic(fifo, "x", 1, &err), err, GDR_ERROR_IO);
    alarm(0);
    CHECK(stat(fifo, &st) == 0 && S_ISFIFO(st.st_mode));
    CHECK_FAILS(gdr_write_file_atomic(dir, "x", 1, &err), err, GDR_ERROR_NOT_A_FILE);
    unlink(link);
    CHECK(symlink("/nonexistent/dir/file", link) == 0);
    CHECK_FAILS(gdr_write_file_atomic(link, "x", 1, &err), err, GDR_ERROR_IO);
    unlink(target), unlink(link), unlink(fifo);
}

/* A transform that places a mesh beyond the limit on coordinates (a node scale of 3e38 on a unit
 * triangle): refused at import naming the file and the node; the CPU pipeline refused it at render
 * time without a file while the GPU pipelines drew nothing. The limit is mesh space's. */
static void test_world_extent(void)
{
    static const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    gdr_scene *s = NULL;
    const char *scales[2] = {"3e38", "1e13"};
    for (int k = 0; k < 2; k++) {
        char *text = triangle_gltf(corners, 3);
        char *node = strstr(text, "{\"mesh\":0}");
        char edited[4096];
        CHECK(node != NULL);
        if (!node)
            break;
        snprintf(edited, sizeof edited, "%.*s{\"mesh\":0,\"scale\":[%s,%s,%s]}%s", (int)(node - text), text, scales[k],
                 scales[k], scales[k], node + strlen("{\"mesh\":0}"));
        free(text);
        s = gltf_text(edited, NULL);
        CHECK(!s);
        CHECK_STATUS(err, GDR_ERROR_PARSE);
        CHECK_NAMES(err, "t.gltf: nodes[0]");
        gdr_scene_destroy(s);
    }
    s = obj_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", NULL);
    gdr_instance far = {.transform = gdr_mat4_from_trs((gdr_vec3){1e13f, 0, 0}, gdr_quat_identity(), (gdr_vec3){1, 1, 1}), .mesh = 0,
                        .material = GDR_NO_INDEX, .color = {1, 1, 1, 1}};
    CHECK(s);
    if (s)
        CHECK_FAILS(gdr_scene_add_instance(s, &far, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    far.transform = gdr_mat4_from_trs((gdr_vec3){1e11f, 0, 0}, gdr_quat_identity(), (gdr_vec3){1, 1, 1});
    CHECK(s && gdr_scene_add_instance(s, &far, &err) == GDR_OK);
    gdr_scene_destroy(s);
}

/* Temporary files left by writers killed by a signal (PATH.tmp.PID): removed by the next write of
 * PATH when their process no longer runs; a running writer's, and other names, are kept. */
static void test_stale_temporaries(void)
{
    pid_t child = fork();
    if (child == 0)
        _exit(0);
    CHECK(child > 0 && waitpid(child, NULL, 0) == child); /* its pid now runs nothing */
    char target[1200], stale[1300], live[1300], other[1300], odd[1300];
    snprintf(target, sizeof target, "%s/written.bin", dir);
    snprintf(stale, sizeof stale, "%s.tmp.%ld", target, (long)child);
    snprintf(live, sizeof live, "%s.tmp.%ld", target, (long)getppid());
    snprintf(other, sizeof other, "%s/another.bin.tmp.%ld", dir, (long)child);
    snprintf(odd, sizeof odd, "%s.tmp.%ldx", target, (long)child);
    const char *files[4] = {stale, live, other, odd};
    for (int i = 0; i < 4; i++)
        CHECK(test_write_file(files[i], "left", 4));
    CHECK(gdr_write_file_atomic(target, "new", 3, &err) == GDR_OK);
    CHECK(access(stale, F_OK) != 0);
    CHECK(access(live, F_OK) == 0 && access(other, F_OK) == 0 && access(odd, F_OK) == 0);
    for (int i = 0; i < 4; i++)
        unlink(files[i]);
    unlink(target);
}

int main(void)
{
    snprintf(dir, sizeof dir, "%s/hostile", GDR_IO_TEST_TMP);
    mkdir(dir, 0755);
    test_huge_coordinates();
    test_degenerate_and_duplicate();
    test_fan_split();
    test_soup_with_outlier();
    test_uri_confinement();
    test_uri_messages();
    test_fifo();
    test_source_list_repeats();
    test_cache_knows_its_source();
    test_texture_pixels();
    test_instance_budget();
    test_other_budgets();
    test_messages();
    test_material_values();
    test_shared_accessors();
    test_output_targets();
    test_stale_temporaries();
    test_world_extent();
    return test_finish("test_hostile");
}
