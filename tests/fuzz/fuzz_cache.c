/* libFuzzer target: the .gdrc cache reader. Checksums would reject nearly every mutation before
 * the section parsers, so a flag in the first byte (when odd) recomputes them first, the
 * precomputed-visibility blob's own checksum inside section 'PVIS' included: both the container
 * checks and the parsers behind them get exercised. A PVS that loads must match the scene and
 * serialise back to the section's bytes. The seed corpus/cache/pvs.gdrc is a flag byte 1 and
 * the output of `gdr build tri.obj -o a.gdrc --pvs; gdr build a.gdrc -o pvs.gdrc` (corpus/obj;
 * the second build keeps the PVS and drops the source path). The same bytes are also read as a
 * file for streaming (gdr_cache_read_for_streaming, through a memfd): what it accepts must agree
 * with the whole read's cluster records wherever both accept the file. The seeds nodes.gdrc,
 * quad.gdrc and paged.gdrc come from corpus/gltf/nodes.gltf, corpus/obj/quad.obj and
 * `gdr build unique-field:meshes=2,triangles=1000 --pages=4` (tests/fuzz/make_cache_seeds.sh). */
#define _GNU_SOURCE /* memfd_create */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include <xxhash.h>

#include "gdr/cull.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "fuzz_geometry.h"
#include "io/io_internal.h"

/* FNV-1a 64 over a PVS blob with its checksum field (offset 72) taken as zero (docs/CULLING.md). */
static void fix_pvs_checksum(uint8_t *blob, size_t size)
{
    if (size < 80)
        return;
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < size; i++)
        h = (h ^ ((i >= 72 && i < 80) ? 0 : blob[i])) * 0x100000001b3ull;
    memcpy(blob + 72, &h, 8);
}

/* The bytes of section 'PVIS' of a cache that loaded (so its table is sound). */
static const uint8_t *pvs_section(const uint8_t *data, size_t *length)
{
    uint32_t count;
    memcpy(&count, data + 16, 4);
    for (uint32_t i = 0; i < count; i++) {
        const uint8_t *e = data + 64 + (size_t)i * 32;
        uint64_t offset, n;
        memcpy(&offset, e + 8, 8);
        memcpy(&n, e + 16, 8);
        if (memcmp(e, "PVIS", 4) == 0) {
            *length = (size_t)n;
            return data + offset;
        }
    }
    return NULL;
}

/* What streaming relies on in a page the reader accepted: the counts of its index entry, every
 * cluster's group, vertices and triangles inside the page, every vertex finite. */
static void check_page(const gdr_paged_mesh *pm, const gdr_page_info *info, const gdr_page *page)
{
    if (page->cluster_count != info->cluster_count || page->vertex_count != info->vertex_count)
        __builtin_trap();
    for (uint32_t c = 0; c < page->cluster_count; c++) {
        const gdr_page_cluster *pc = &page->clusters[c];
        if (pc->group >= pm->group_count || pc->vertex_offset > page->vertex_count ||
            pc->vertex_count > page->vertex_count - pc->vertex_offset ||
            pc->triangle_offset > page->triangle_byte_count ||
            3 * pc->triangle_count > page->triangle_byte_count - pc->triangle_offset)
            __builtin_trap();
        for (uint32_t t = 0; t < 3 * pc->triangle_count; t++)
            if (page->triangles[pc->triangle_offset + t] >= pc->vertex_count)
                __builtin_trap();
    }
    for (uint32_t v = 0; v < page->vertex_count; v++)
        if (!isfinite(page->vertices[v].position.x) || !isfinite(page->vertices[v].position.y) ||
            !isfinite(page->vertices[v].position.z))
            __builtin_trap();
}

/* The rest of the streaming open (gdr_streaming_open), without a GPU: the paged reader opens the same
 * file, is checked against the scene read for streaming, and its pages are read (at most 32, so that
 * an input runs in milliseconds). A refusal at any step stops there, as streaming does. */
static void open_pages(const char *path, const gdr_scene *paged)
{
    gdr_paged_cache *cache = NULL;
    gdr_error err;
    if (gdr_paged_cache_open(path, &cache, &err) != GDR_OK)
        return;
    if (gdr_paged_cache_check_scene(cache, paged, path, &err) == GDR_OK) {
        uint32_t budget = 32;
        for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(cache) && budget; m++) {
            const gdr_paged_mesh *pm = gdr_paged_cache_mesh(cache, m);
            for (uint32_t p = 0; p < pm->page_count && budget; p++, budget--) {
                gdr_page page;
                if (gdr_paged_cache_read_page(cache, m, p, &page, &err) != GDR_OK)
                    continue;
                check_page(pm, &pm->pages[p], &page);
                gdr_page_free(&page);
            }
        }
    }
    gdr_paged_cache_close(cache);
}

/* The streaming read of the same bytes, from a file in memory; where the whole read accepted them
 * too (whole != NULL), every mesh's counts and group records must be the same, and the streamed
 * scene holds no cluster record (the pages do). Then the
 * paged reader, as the streaming open uses it. */
static void read_for_streaming(const uint8_t *data, size_t size, const gdr_scene *whole)
{
    int fd = memfd_create("fuzz.gdrc", 0);
    if (fd < 0)
        return;
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    gdr_scene *paged = NULL;
    gdr_error err;
    if (write(fd, data, size) == (ssize_t)size && gdr_cache_read_for_streaming(path, NULL, &paged, NULL, NULL, &err) == GDR_OK) {
        if (!paged->geometry_in_pages)
            __builtin_trap();
        for (uint32_t m = 0; whole && m < whole->mesh_count; m++) {
            const gdr_mesh_clusters *a = &whole->meshes[m].clusters, *b = &paged->meshes[m].clusters;
            if (paged->mesh_count != whole->mesh_count || a->cluster_count != b->cluster_count ||
                a->group_count != b->group_count || a->lod_node_count != b->lod_node_count ||
                (a->cluster_count && b->clusters) || /* the pages hold a streamed scene's cluster records */
                (a->group_count && memcmp(a->groups, b->groups, sizeof *a->groups * a->group_count)))
                __builtin_trap();
        }
        open_pages(path, paged);
        gdr_scene_destroy(paged);
    }
    close(fd);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    int fix = data[0] & 1;
    data++;
    size--;
    uint8_t *copy = malloc(size ? size : 1);
    if (!copy)
        return 0;
    memcpy(copy, data, size);
    if (fix && size >= 64) {
        uint64_t file_size = size;
        memcpy(copy + 24, &file_size, 8);
        uint32_t count;
        memcpy(&count, copy + 16, 4);
        if (count <= 1024 && 64 + (size_t)count * 32 <= size) {
            for (uint32_t i = 0; i < count; i++) {
                uint8_t *e = copy + 64 + (size_t)i * 32;
                uint64_t offset, length;
                memcpy(&offset, e + 8, 8);
                memcpy(&length, e + 16, 8);
                if (offset <= size && length <= size - offset) {
                    if (memcmp(e, "PVIS", 4) == 0)
                        fix_pvs_checksum(copy + offset, (size_t)length);
                    uint64_t h = XXH3_64bits(copy + offset, (size_t)length);
                    memcpy(e + 24, &h, 8);
                }
            }
            uint64_t h = XXH3_64bits(copy + 64, (size_t)count * 32);
            memcpy(copy + 32, &h, 8);
        }
        uint64_t h = XXH3_64bits(copy, 40);
        memcpy(copy + 40, &h, 8);
    }
    gdr_scene *scene = NULL;
    gdr_pvs *pvs = NULL;
    gdr_error err;
    gdr_status whole = gdr_cache_read_memory(copy, size, "fuzz.gdrc", &scene, &pvs, &err);
    read_for_streaming(copy, size, whole == GDR_OK ? scene : NULL);
    if (whole == GDR_OK) {
        if (pvs) {
            size_t n = gdr_pvs_serialized_size(pvs), length = 0;
            const uint8_t *section = pvs_section(copy, &length);
            uint8_t *again = malloc(n ? n : 1);
            if (gdr_pvs_object_count(pvs) != scene->instance_count || !again || !section || length != n ||
                gdr_pvs_serialize(pvs, again, n, &err) != GDR_OK || memcmp(section, again, n) != 0)
                __builtin_trap();
            free(again);
        }
        gdr_pvs_destroy(pvs);
        /* What loading a cache does next (import.c), then the DAG as `gdr build` would. */
        if (gdr_io_clean_unclustered_meshes(scene, "fuzz.gdrc", &err) == GDR_OK)
            fuzz_build_geometry(scene);
        gdr_scene_destroy(scene);
    }
    free(copy);
    return 0;
}
