/* The memory of a paged cache written mesh by mesh (gdr_cache_build_paged) follows the meshes in
 * flight, not the scene: the peak heap (every allocation counted by wrapping the allocator,
 * bench/heap_count.c) of the unique field with 8 meshes is within 1.25 times that of 2 meshes of the
 * same size, on one thread. The premise is checked too: the same two scenes made whole and written
 * with gdr_cache_write with the whole geometry beside the pages (the path before) take at least twice the heap for 4 times the meshes,
 * so the measure tells the two apart. */
#include <stdio.h>
#include <unistd.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "heap_count.h"
#include "test_util.h"

#define TRIANGLES 20000u

static double by_mesh(uint32_t meshes, const char *path)
{
    char spec[128];
    snprintf(spec, sizeof spec, "unique-field:meshes=%u,triangles=%u", meshes, TRIANGLES);
    gdr_error err = {0};
    gdr_paged_build_options o = {.thread_count = 1, .no_progress = 1};
    long long base = heap_peak_reset();
    CHECK(gdr_cache_build_paged(spec, path, &o, &err) == GDR_OK);
    return (double)(heap_peak() - base);
}

static double whole(uint32_t meshes, const char *path)
{
    char spec[128];
    snprintf(spec, sizeof spec, "unique-field:meshes=%u,triangles=%u", meshes, TRIANGLES);
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    long long base = heap_peak_reset();
    gdr_scene *scene = NULL;
    CHECK(gdr_scene_load(spec, &load, &scene, &err) == GDR_OK);
    CHECK(scene && gdr_scene_quantize_vertices(scene, &err) == GDR_OK);
    /* The file written before format 11: the whole geometry beside the pages. */
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_DEFAULT, .whole_geometry = 1};
    CHECK(scene && gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    gdr_scene_destroy(scene);
    return (double)(heap_peak() - base);
}

int main(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/meshes-memory.gdrc", GDR_IO_TEST_TMP);
    double small = by_mesh(2, path), large = by_mesh(8, path);
    double old_small = whole(2, path), old_large = whole(8, path);
    printf("peak heap, %u-triangle meshes: mesh by mesh %.1f MB (2 meshes) %.1f MB (8), %.2fx; whole scene %.1f MB "
           "%.1f MB, %.2fx\n", TRIANGLES, small / 1e6, large / 1e6, large / small, old_small / 1e6, old_large / 1e6,
           old_large / old_small);
    printf("peak heap per source triangle at 8 meshes: mesh by mesh %.1f bytes, whole scene %.1f bytes\n",
           large / (8.0 * TRIANGLES), old_large / (8.0 * TRIANGLES));
    CHECK(old_large > 2.0 * old_small);
    CHECK(large < 1.25 * small);
    unlink(path);
    return test_finish("test_cache_meshes_memory");
}
