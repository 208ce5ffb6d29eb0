/* A paged cache written mesh by mesh (gdr_cache_write_meshes, gdr_cache_build_paged): the file is
 * byte for byte the one gdr_cache_write writes for the whole scene quantized, for the unique field
 * made one mesh at a time and for scenes made whole (lod-field, demo), with 1, 2 and 4 threads; the
 * paged cache that gdr_scene_load builds for streaming a built-in scene is the same file; it opens
 * and every page decodes; a mesh that fails stops the build, its error names the mesh, and nothing
 * is written (no file, no temporary file left in the folder); a cache without pages is refused. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "gdr/procedural.h"
#include "io_test_helpers.h"
#include "test_util.h"

/* The two files hold the same bytes. */
static int same_file(const char *a, const char *b)
{
    size_t na, nb;
    uint8_t *x = test_read_file(a, &na), *y = test_read_file(b, &nb);
    int same = x && y && na == nb && memcmp(x, y, na) == 0;
    if (!same)
        fprintf(stderr, "%s (%zu bytes) and %s (%zu bytes) differ\n", a, na, b, nb);
    free(x), free(y);
    return same;
}

/* What gdr build --pages wrote before: the whole scene made, quantized, gdr_cache_write. */
static void write_whole(const char *spec, const char *path, uint32_t page_bytes, int whole_geometry)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load(spec, &load, &scene, &err) == GDR_OK);
    CHECK(scene && gdr_scene_quantize_vertices(scene, &err) == GDR_OK);
    gdr_source_list none = {0};
    gdr_cache_write_options write = {.source = {gdr_cache_build_options(), &none}, .page_bytes = page_bytes,
                                     .whole_geometry = whole_geometry};
    CHECK(scene && gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    gdr_scene_destroy(scene);
}

/* Every page of the file opens and decodes. */
static void check_pages_read(const char *path)
{
    gdr_error err = {0};
    gdr_paged_cache *pc = NULL;
    CHECK(gdr_paged_cache_open(path, &pc, &err) == GDR_OK);
    uint32_t pages = 0;
    for (uint32_t m = 0; pc && m < gdr_paged_cache_mesh_count(pc); m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(pc, m)->page_count; p++, pages++) {
            gdr_page page;
            CHECK(gdr_paged_cache_read_page(pc, m, p, &page, &err) == GDR_OK);
            gdr_page_free(&page);
        }
    CHECK(pages > 0);
    gdr_paged_cache_close(pc);
}

/* One layout of the file written mesh by mesh with 1, 2 and 4 threads: each equals the whole-scene one. */
static void check_equal_layout(const char *spec, uint32_t page_bytes, int whole_geometry)
{
    char whole[1024], meshes[1024];
    snprintf(whole, sizeof whole, "%s/meshes-whole.gdrc", GDR_IO_TEST_TMP);
    snprintf(meshes, sizeof meshes, "%s/meshes-by-mesh.gdrc", GDR_IO_TEST_TMP);
    write_whole(spec, whole, page_bytes, whole_geometry);
    static const uint32_t threads[] = {1, 2, 4};
    for (int t = 0; t < 3; t++) {
        gdr_error err = {0};
        unlink(meshes);
        gdr_paged_build_options o = {.page_bytes = page_bytes, .thread_count = threads[t], .no_progress = 1,
                                     .whole_geometry = whole_geometry};
        CHECK(gdr_cache_build_paged(spec, meshes, &o, &err) == GDR_OK);
        if (!same_file(whole, meshes))
            fprintf(stderr, "%s, %u threads, whole geometry %d: not the whole scene's file\n", spec, threads[t],
                    whole_geometry);
        CHECK(same_file(whole, meshes));
    }
    check_pages_read(meshes);
}

/* The spec written mesh by mesh with 1, 2 and 4 threads: each file equals the whole-scene one, with
 * the geometry in the pages alone and with the whole geometry beside them. */
static void check_equal(const char *spec, uint32_t page_bytes)
{
    for (int whole_geometry = 0; whole_geometry <= 1; whole_geometry++)
        check_equal_layout(spec, page_bytes, whole_geometry);
}

/* gdr_scene_load for streaming a built-in scene builds its paged cache in the cache folder: the file
 * gdr_cache_write writes for the whole scene with the default pages. */
static void check_load_paged(void)
{
    char folder[1024], whole[1024], cache_path[4096] = "";
    snprintf(folder, sizeof folder, "%s/meshes-cache", GDR_IO_TEST_TMP);
    snprintf(whole, sizeof whole, "%s/meshes-whole.gdrc", GDR_IO_TEST_TMP);
    const char *spec = "unique-field:meshes=4,triangles=6000,seed=9";
    write_whole(spec, whole, GDR_PAGE_BYTES_DEFAULT, 0);
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_load_options load = {.no_progress = 1, .geometry_in_pages = 1, .cache_dir = folder,
                             .cache_path = cache_path, .cache_path_size = sizeof cache_path};
    CHECK(gdr_scene_load(spec, &load, &scene, &err) == GDR_OK);
    CHECK(scene && scene->geometry_in_pages && scene->mesh_count == 4);
    CHECK(cache_path[0] && same_file(whole, cache_path));
    gdr_scene_destroy(scene);
    if (cache_path[0])
        unlink(cache_path);
}

/* A source whose mesh 2 fails. */
static gdr_status failing_mesh(void *user, uint32_t index, uint32_t threads, gdr_scene **out, gdr_error *err)
{
    (void)threads;
    const gdr_unique_field_desc *d = user;
    if (index == 2)
        return gdr_error_set(err, GDR_ERROR_PARSE, "made to fail");
    gdr_status status = gdr_scene_create_unique_field_mesh(d, index, out, err);
    gdr_lod_options lod = {.no_progress = 1, .thread_count = 1};
    if (status == GDR_OK && (status = gdr_scene_build_lod(*out, &lod, NULL, err)) != GDR_OK) {
        gdr_scene_destroy(*out);
        *out = NULL;
    }
    return status;
}

/* Names in the test folder starting with `prefix`. */
static int count_names(const char *prefix)
{
    DIR *dir = opendir(GDR_IO_TEST_TMP);
    int n = 0;
    for (struct dirent *e; dir && (e = readdir(dir));)
        n += strncmp(e->d_name, prefix, strlen(prefix)) == 0;
    if (dir)
        closedir(dir);
    return n;
}

static void check_failures(void)
{
    gdr_unique_field_desc d = {.meshes = 5, .triangles = 2000, .seed = 3};
    gdr_scene *skeleton = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create_unique_field_skeleton(&d, &skeleton, &err) == GDR_OK);
    char path[1024];
    snprintf(path, sizeof path, "%s/meshes-failed.gdrc", GDR_IO_TEST_TMP);
    unlink(path);
    int before = count_names("meshes-failed.gdrc") + count_names(".gdr-spool");
    for (uint32_t threads = 1; threads <= 3; threads += 2) {
        gdr_cache_mesh_source source = {.make = failing_mesh, .user = &d, .thread_count = threads, .no_progress = 1};
        gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_DEFAULT};
        CHECK_FAILS(gdr_cache_write_meshes(path, skeleton, &source, &write, &err), err, GDR_ERROR_PARSE);
        CHECK(strstr(err.message, "meshes[2]: made to fail") != NULL);
        CHECK(access(path, F_OK) != 0);
        CHECK(count_names("meshes-failed.gdrc") + count_names(".gdr-spool") == before);
        /* Without pages: refused before anything is made. */
        gdr_cache_write_options plain = {0};
        CHECK_FAILS(gdr_cache_write_meshes(path, skeleton, &source, &plain, &err), err, GDR_ERROR_INVALID_ARGUMENT);
        CHECK(strstr(err.message, "needs pages") != NULL);
    }
    /* A folder that does not exist: refused by name, nothing made. */
    gdr_paged_build_options o = {.thread_count = 2, .no_progress = 1};
    CHECK_FAILS(gdr_cache_build_paged("unique-field:meshes=2,triangles=2000", "/nonexistent-gdr-folder/x.gdrc", &o,
                                      &err), err, GDR_ERROR_IO);
    CHECK(strstr(err.message, "/nonexistent-gdr-folder/x.gdrc") != NULL);
    CHECK_FAILS(gdr_cache_build_paged("unique-field:meshes=0", path, &o, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    CHECK_FAILS(gdr_cache_build_paged("scene.gltf", path, &o, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    gdr_scene_destroy(skeleton);
}

int main(void)
{
    check_equal("unique-field:meshes=5,triangles=8000,seed=4", 32u << 10);
    check_equal("lod-field:instances=3,triangles=6000", GDR_PAGE_BYTES_DEFAULT);
    check_equal("demo:instances=20", GDR_PAGE_BYTES_DEFAULT);
    check_load_paged();
    check_failures();
    return test_finish("test_cache_meshes");
}
