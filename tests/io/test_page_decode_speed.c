/* Decoding a geometry page costs little beyond what no reader can skip (docs/STREAMING.md, "Decoding
 * a page"): every page of a quantized paged cache is decoded from memory on one thread, and the time
 * is compared, in the same run, with the time of the page's checksum and inflating its zstd body
 * alone, both as CPU time of this thread, best of several rounds (a ratio, as CPU figures on a
 * shared machine must be). Decoding with an ldexpf per coordinate, a memcmp per corner comparison
 * and a branch per corner took 8 times that floor here; the decoder now takes about 4 times it.
 * The bound, 6, leaves room for noise either way. Run alone, in the normal build only. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <zstd.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "io/cache_pages.h"
#include "io/io_internal.h"
#include "io_test_helpers.h"
#include "test_util.h"

#define ROUNDS 7
#define MOST_TIMES_THE_FLOOR 6.0

static double cpu_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef struct stored_pages {
    const gdr_paged_mesh *meshes;
    uint32_t mesh_count;
    uint8_t *file;
    size_t size;
} stored_pages;

/* Every page decoded once; returns the pages that failed. */
static uint32_t decode_all(const stored_pages *sp)
{
    uint32_t failed = 0;
    for (uint32_t m = 0; m < sp->mesh_count; m++)
        for (uint32_t p = 0; p < sp->meshes[m].page_count; p++) {
            const gdr_page_info *pi = &sp->meshes[m].pages[p];
            gdr_page page;
            gdr_error err = {0};
            failed += cache_page_decode("speed", m, p, &sp->meshes[m], sp->file + pi->offset, pi->stored_size, &page,
                                        &err) != GDR_OK;
            gdr_page_free(&page);
        }
    return failed;
}

/* What every reader of a page does whatever its decoder: the checksum, and zstd over a compressed
 * body (one behind the page header). Returns the bytes inflated, so that nothing is optimised out. */
static uint64_t floor_all(const stored_pages *sp, ZSTD_DCtx *dctx, uint8_t *scratch, size_t scratch_size)
{
    uint64_t total = 0;
    for (uint32_t m = 0; m < sp->mesh_count; m++)
        for (uint32_t p = 0; p < sp->meshes[m].page_count; p++) {
            const gdr_page_info *pi = &sp->meshes[m].pages[p];
            const uint8_t *bytes = sp->file + pi->offset;
            total += gdr_io_hash(bytes, pi->stored_size) & 1;
            unsigned long long content =
                ZSTD_getFrameContentSize(bytes + CACHE_PAGE_HEADER, pi->stored_size - CACHE_PAGE_HEADER);
            if (content <= scratch_size) {
                size_t n = ZSTD_decompressDCtx(dctx, scratch, scratch_size, bytes + CACHE_PAGE_HEADER,
                                               pi->stored_size - CACHE_PAGE_HEADER);
                total += ZSTD_isError(n) ? 0 : n;
            }
        }
    return total;
}

int main(void)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1, .no_cache = 1};
    CHECK(gdr_scene_load("unique-field:meshes=2,triangles=200000,seed=7", &load, &scene, &err) == GDR_OK);
    if (!scene)
        return test_finish("test_page_decode_speed");
    CHECK(gdr_scene_quantize_vertices(scene, &err) == GDR_OK);
    char path[1024];
    snprintf(path, sizeof path, "%s/page_decode_speed.gdrc", GDR_IO_TEST_TMP);
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_DEFAULT};
    CHECK(gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    gdr_scene_destroy(scene);
    gdr_paged_cache *pc = NULL;
    CHECK(gdr_paged_cache_open(path, &pc, &err) == GDR_OK);
    stored_pages sp = {0};
    sp.file = test_read_file(path, &sp.size);
    size_t scratch_size = CACHE_PAGE_MAX_RAW;
    uint8_t *scratch = malloc(scratch_size);
    ZSTD_DCtx *dctx = ZSTD_createDCtx();
    if (pc && sp.file && scratch && dctx) {
        sp.mesh_count = gdr_paged_cache_mesh_count(pc);
        sp.meshes = gdr_paged_cache_mesh(pc, 0);
        double decode = 1e30, floor = 1e30;
        uint64_t inflated = 0;
        CHECK(decode_all(&sp) == 0);
        for (int r = 0; r < ROUNDS; r++) {
            double t0 = cpu_s();
            CHECK(decode_all(&sp) == 0);
            double t1 = cpu_s();
            inflated = floor_all(&sp, dctx, scratch, scratch_size);
            double t2 = cpu_s();
            decode = t1 - t0 < decode ? t1 - t0 : decode;
            floor = t2 - t1 < floor ? t2 - t1 : floor;
        }
        printf("decoding every page: %.4f s of CPU; its checksum and zstd alone: %.4f s (%llu bytes inflated): "
               "%.2f times\n", decode, floor, (unsigned long long)inflated, decode / floor);
        CHECK(inflated > 0 && decode <= MOST_TIMES_THE_FLOOR * floor);
    }
    ZSTD_freeDCtx(dctx);
    free(scratch);
    free(sp.file);
    gdr_paged_cache_close(pc);
    remove(path);
    return test_finish("test_page_decode_speed");
}
