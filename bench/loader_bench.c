/* The page loader against the disk (docs/STREAMING.md, "The loader thread"): every page of a paged
 * cache read, checked and decoded through gdr_page_loader, against a plain sequential read of the
 * same bytes, each from a cold page cache where the kernel lets it be dropped (posix_fadvise
 * DONTNEED on the file; whether it was is said), then warm (decoding alone).
 *     loader_bench CACHE.gdrc [--threads N,N,...] [--json FILE]
 * Reports MB/s of file bytes (and of decoded bytes) per second of wall time. --threads: the loader's
 * worker counts to run (default 1 and the renderer's default). CPU figures on a shared machine:
 * compare within one run. */
#define _DEFAULT_SOURCE /* mincore */
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include "gdr/paged_cache.h"
#include "stream/page_loader.h"

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Drops the file's cached pages; returns the share of the range [offset, offset + size) still in
 * memory afterwards (0: a cold read follows), or -1 where that cannot be told. */
static double drop_cache(const char *path, uint64_t offset, uint64_t size)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return -1.0;
    fdatasync(fd);
    posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
    double share = -1.0;
    long page = sysconf(_SC_PAGESIZE);
    uint64_t start = offset / (uint64_t)page * (uint64_t)page, length = offset + size - start;
    void *map = length ? mmap(NULL, length, PROT_READ, MAP_SHARED, fd, (off_t)start) : MAP_FAILED;
    size_t pages = (length + (uint64_t)page - 1) / (uint64_t)page;
    unsigned char *in = map != MAP_FAILED ? malloc(pages) : NULL;
    if (in && mincore(map, length, in) == 0) {
        size_t resident = 0;
        for (size_t i = 0; i < pages; i++)
            resident += in[i] & 1;
        share = (double)resident / (double)pages;
    }
    free(in);
    if (map != MAP_FAILED)
        munmap(map, length);
    close(fd);
    return share;
}

/* The page section read front to back in 4 MiB preads. Returns MB/s, 0 on failure. */
static double sequential_read(const char *path, uint64_t offset, uint64_t size)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    size_t chunk = 4u << 20;
    char *buffer = malloc(chunk);
    if (fd < 0 || !buffer) {
        free(buffer);
        if (fd >= 0)
            close(fd);
        return 0.0;
    }
    double t0 = now_s();
    uint64_t done = 0;
    while (done < size) {
        size_t want = size - done < chunk ? (size_t)(size - done) : chunk;
        ssize_t got = pread(fd, buffer, want, (off_t)(offset + done));
        if (got <= 0)
            break;
        done += (uint64_t)got;
    }
    double seconds = now_s() - t0;
    free(buffer);
    close(fd);
    return done == size && seconds > 0.0 ? 1e-6 * (double)size / seconds : 0.0;
}

typedef struct loader_run {
    uint32_t threads;
    double wall_s, busy_s;
    uint64_t bytes_read, bytes_decoded, pages, failed;
} loader_run;

/* Every page through a loader of `threads` workers, submitted at once, collected in order. */
static int load_all(gdr_paged_cache *pc, uint32_t threads, loader_run *run)
{
    gdr_error err = {0};
    gdr_page_loader *loader = NULL;
    uint64_t total = 0;
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(pc); m++)
        total += gdr_paged_cache_mesh(pc, m)->page_count;
    gdr_stream_load *loads = malloc(sizeof *loads * (total ? total : 1));
    if (!loads || gdr_page_loader_create(pc, threads, &loader, &err) != GDR_OK) {
        fprintf(stderr, "loader_bench: %s\n", loads ? err.message : "out of memory");
        free(loads);
        return 0;
    }
    uint32_t n = 0;
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(pc); m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(pc, m)->page_count; p++, n++)
            loads[n] = (gdr_stream_load){m, p, n}; /* the slot is not used: nothing goes to a pool */
    *run = (loader_run){0};
    double t0 = now_s();
    int ok = gdr_page_loader_submit(loader, loads, n, &err) == GDR_OK;
    gdr_page_result result;
    for (uint32_t i = 0; ok && i < n; i++) {
        if (gdr_page_loader_collect(loader, 1, &result, 1) != 1)
            break;
        run->failed += result.status != GDR_OK;
        gdr_page_free(&result.page);
    }
    run->wall_s = now_s() - t0;
    gdr_page_loader_stats st = gdr_page_loader_get_stats(loader);
    run->threads = st.threads, run->busy_s = st.busy_s, run->bytes_read = st.bytes_read;
    run->bytes_decoded = st.bytes_decoded, run->pages = st.pages_read;
    gdr_page_loader_destroy(loader);
    free(loads);
    return ok;
}

static void print_run(FILE *out, const char *what, const loader_run *r, double cached, int json, int last)
{
    double mb = 1e-6 * (double)r->bytes_read, decoded = 1e-6 * (double)r->bytes_decoded;
    if (!json) {
        fprintf(out, "%-6s loader, %u threads: %llu pages, %.1f MB read (%.1f MB decoded) in %.3f s: %.1f MB/s read, "
                "%.1f MB/s decoded, %.1f MB/s per busy second%s\n", what, r->threads, (unsigned long long)r->pages, mb,
                decoded, r->wall_s, mb / r->wall_s, decoded / r->wall_s, r->busy_s > 0 ? mb / r->busy_s : 0.0,
                r->failed ? " (pages failed)" : "");
        return;
    }
    fprintf(out, "    {\"cache\": \"%s\", \"threads\": %u, \"pages\": %llu, \"bytes_read\": %llu, \"bytes_decoded\": %llu, "
            "\"wall_s\": %.6f, \"busy_s\": %.6f, \"mb_s\": %.2f, \"decoded_mb_s\": %.2f, \"resident_before\": %.3f}%s\n",
            what, r->threads, (unsigned long long)r->pages, (unsigned long long)r->bytes_read,
            (unsigned long long)r->bytes_decoded, r->wall_s, r->busy_s, mb / r->wall_s, decoded / r->wall_s, cached,
            last ? "" : ",");
}

int main(int argc, char **argv)
{
    const char *path = NULL, *json_path = NULL, *thread_list = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--json") && i + 1 < argc)
            json_path = argv[++i];
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            thread_list = argv[++i];
        else if (argv[i][0] != '-' && !path)
            path = argv[i];
        else {
            fprintf(stderr, "usage: loader_bench CACHE.gdrc [--threads N,N,...] [--json FILE]\n");
            return 2;
        }
    }
    uint32_t threads[8] = {1, 0}, thread_count = 2;
    if (thread_list) {
        thread_count = 0;
        for (const char *p = thread_list; *p && thread_count < 8; p += strcspn(p, ","), p += *p == ',') {
            char *end;
            unsigned long n = strtoul(p, &end, 10);
            if (end == p || n > GDR_PAGE_LOADER_MAX_THREADS || (*end && *end != ',')) {
                fprintf(stderr, "loader_bench: --threads: '%s' is not a list of 0..%d\n", thread_list,
                        GDR_PAGE_LOADER_MAX_THREADS);
                return 2;
            }
            threads[thread_count++] = (uint32_t)n;
        }
    }
    if (!path) {
        fprintf(stderr, "usage: loader_bench CACHE.gdrc [--threads N,N,...] [--json FILE]\n");
        return 2;
    }
    gdr_error err = {0};
    gdr_paged_cache *pc = NULL;
    if (gdr_paged_cache_open(path, &pc, &err) != GDR_OK) {
        fprintf(stderr, "loader_bench: %s\n", err.message);
        return 1;
    }
    /* The pages lie together in the page section: from the first page's offset to the last one's end. */
    uint64_t first = UINT64_MAX, end = 0;
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(pc); m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(pc, m)->page_count; p++) {
            const gdr_page_info *info = &gdr_paged_cache_mesh(pc, m)->pages[p];
            first = info->offset < first ? info->offset : first;
            end = info->offset + info->stored_size > end ? info->offset + info->stored_size : end;
        }
    uint64_t size = end > first ? end - first : 0;
    double cached = drop_cache(path, first, size);
    double cold_seq = sequential_read(path, first, size);
    double warm_seq = sequential_read(path, first, size);
    printf("%s: pages %.1f MB; sequential read %.1f MB/s cold (%.0f%% cached before), %.1f MB/s warm\n", path,
           1e-6 * (double)size, cold_seq, 100.0 * cached, warm_seq);
    FILE *json = json_path ? fopen(json_path, "w") : NULL;
    if (json)
        fprintf(json, "{\n  \"file\": \"%s\", \"page_bytes\": %llu, \"sequential_cold_mb_s\": %.2f, "
                "\"sequential_warm_mb_s\": %.2f, \"resident_before_cold\": %.3f,\n  \"loader\": [\n", path,
                (unsigned long long)size, cold_seq, warm_seq, cached);
    int ok = cold_seq > 0.0;
    for (uint32_t t = 0; t < thread_count; t++) {
        loader_run cold, warm;
        double before = drop_cache(path, first, size);
        ok = ok && load_all(pc, threads[t], &cold) && load_all(pc, threads[t], &warm);
        if (!ok)
            break;
        print_run(stdout, "cold", &cold, before, 0, 0);
        print_run(stdout, "warm", &warm, 1.0, 0, 0);
        if (json) {
            print_run(json, "cold", &cold, before, 1, 0);
            print_run(json, "warm", &warm, 1.0, 1, t + 1 == thread_count);
        }
    }
    if (json) {
        fprintf(json, "  ]\n}\n");
        ok = fclose(json) == 0 && ok;
    }
    gdr_paged_cache_close(pc);
    return ok ? 0 : 1;
}
