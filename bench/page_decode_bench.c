/* Decoding alone (docs/STREAMING.md, "Decoding a page"): every page of a paged cache read into
 * memory once, then checked and decoded on one thread `--rounds` times, without the file system or
 * the loader's threads in the way; prints MB/s of stored and of decoded bytes per second of the
 * thread's CPU time (less disturbed than wall time by other work on a shared machine), and a hash
 * of every decoded byte (clusters, vertices, triangles, in page order) so that two builds can be
 * shown to decode the same pages to the same bytes.
 *     page_decode_bench CACHE.gdrc [--rounds N]
 * CPU figures on a shared machine: compare builds within one session, run after run. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gdr/paged_cache.h"
#include "io/cache_pages.h"
#include "io/io_internal.h"

static double clock_s(clockid_t clock)
{
    struct timespec t;
    clock_gettime(clock, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The whole file in memory; NULL when it cannot be read. */
static uint8_t *read_whole(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    uint8_t *bytes = NULL;
    long n = -1;
    if (f && fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) > 0 && fseek(f, 0, SEEK_SET) == 0)
        bytes = malloc((size_t)n);
    if (bytes && fread(bytes, 1, (size_t)n, f) != (size_t)n) {
        free(bytes);
        bytes = NULL;
    }
    if (f)
        fclose(f);
    *size = bytes ? (size_t)n : 0;
    return bytes;
}

typedef struct decode_totals {
    uint64_t stored, decoded, pages, failed, hash;
} decode_totals;

/* Every page once; with `hash`, the decoded bytes folded into totals->hash. */
static void decode_all(gdr_paged_cache *pc, const uint8_t *file, size_t file_size, int hash, decode_totals *t)
{
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(pc); m++) {
        const gdr_paged_mesh *pm = gdr_paged_cache_mesh(pc, m);
        for (uint32_t p = 0; p < pm->page_count; p++) {
            const gdr_page_info *pi = &pm->pages[p];
            gdr_page page;
            gdr_error err = {0};
            if (pi->offset > file_size || pi->stored_size > file_size - pi->offset ||
                cache_page_decode("page_decode_bench", m, p, pm, file + pi->offset, pi->stored_size, &page, &err) !=
                    GDR_OK) {
                if (t->failed++ == 0)
                    fprintf(stderr, "page_decode_bench: %s\n", err.message);
                continue;
            }
            t->stored += pi->stored_size, t->pages++;
            t->decoded += sizeof *page.clusters * page.cluster_count + sizeof *page.vertices * page.vertex_count +
                          page.triangle_byte_count;
            if (hash) {
                uint64_t h[4] = {t->hash, gdr_io_hash(page.clusters, sizeof *page.clusters * page.cluster_count),
                                 gdr_io_hash(page.vertices, sizeof *page.vertices * page.vertex_count),
                                 gdr_io_hash(page.triangles, page.triangle_byte_count)};
                t->hash = gdr_io_hash(h, sizeof h);
            }
            gdr_page_free(&page);
        }
    }
}

int main(int argc, char **argv)
{
    const char *path = NULL;
    unsigned long rounds = 3;
    for (int i = 1; i < argc; i++) {
        char *end = NULL;
        if (!strcmp(argv[i], "--rounds") && i + 1 < argc) {
            rounds = strtoul(argv[++i], &end, 10);
            if (*end || rounds == 0 || rounds > 1000) {
                fprintf(stderr, "page_decode_bench: --rounds: '%s' is not 1..1000\n", argv[i]);
                return 2;
            }
        } else if (argv[i][0] != '-' && !path) {
            path = argv[i];
        } else {
            fprintf(stderr, "usage: page_decode_bench CACHE.gdrc [--rounds N]\n");
            return 2;
        }
    }
    if (!path) {
        fprintf(stderr, "usage: page_decode_bench CACHE.gdrc [--rounds N]\n");
        return 2;
    }
    gdr_error err = {0};
    gdr_paged_cache *pc = NULL;
    if (gdr_paged_cache_open(path, &pc, &err) != GDR_OK) {
        fprintf(stderr, "page_decode_bench: %s\n", err.message);
        return 1;
    }
    size_t size = 0;
    uint8_t *file = read_whole(path, &size);
    if (!file) {
        fprintf(stderr, "page_decode_bench: %s: cannot be read\n", path);
        gdr_paged_cache_close(pc);
        return 1;
    }
    decode_totals first = {.hash = 0};
    decode_all(pc, file, size, 1, &first);
    printf("%s: %llu pages, %.1f MB stored, %.1f MB decoded, %llu failed, decoded bytes hash %016llx\n", path,
           (unsigned long long)first.pages, 1e-6 * (double)first.stored, 1e-6 * (double)first.decoded,
           (unsigned long long)first.failed, (unsigned long long)first.hash);
    double best = 0.0;
    for (unsigned long r = 0; r < rounds; r++) {
        decode_totals t = {0};
        double t0 = clock_s(CLOCK_MONOTONIC), c0 = clock_s(CLOCK_THREAD_CPUTIME_ID);
        decode_all(pc, file, size, 0, &t);
        double s = clock_s(CLOCK_MONOTONIC) - t0, cpu = clock_s(CLOCK_THREAD_CPUTIME_ID) - c0;
        printf("round %lu: %.3f s (%.3f s of CPU): %.1f MB/s stored, %.1f MB/s decoded per CPU second\n", r + 1, s,
               cpu, 1e-6 * (double)t.stored / cpu, 1e-6 * (double)t.decoded / cpu);
        best = best == 0.0 || cpu < best ? cpu : best;
    }
    printf("best: %.1f MB/s stored, %.1f MB/s decoded per CPU second\n", 1e-6 * (double)first.stored / best,
           1e-6 * (double)first.decoded / best);
    free(file);
    gdr_paged_cache_close(pc);
    return first.failed ? 1 : 0;
}
