/* Geometry pages (docs/CACHE_FORMAT.md, "Page size"): for each page size, the bytes per source
 * triangle the pages take on disk, how much of the raw size the codecs and zstd keep, the open's
 * read, and the time to read, check and decode every page on one thread (MB/s of decoded bytes).
 *     page_bench [SCENE] [--sizes KIB,KIB,...] [--json FILE]
 * SCENE defaults to unique-field:meshes=8,triangles=100000. CPU figures: compare sizes within one
 * run (the machine is shared). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "gdr/io.h"
#include "gdr/paged_cache.h"

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef struct page_row {
    uint32_t kib, pages;
    double bytes_per_triangle, stored_share, decode_mb_s, groups_per_page;
    uint64_t open_bytes, page_bytes;
    double open_ms, pinned_ms; /* the open, then every mesh's page 0: what a first frame needs */
} page_row;

static int measure(const gdr_scene *scene, const char *path, uint32_t kib, page_row *row)
{
    gdr_error err = {0};
    gdr_cache_write_options write = {.page_bytes = kib * 1024u};
    gdr_paged_cache *pc = NULL;
    if (gdr_cache_write(path, scene, &write, &err) != GDR_OK) {
        fprintf(stderr, "page_bench: %s\n", err.message);
        return 0;
    }
    double t_open = now_s();
    if (gdr_paged_cache_open(path, &pc, &err) != GDR_OK) {
        fprintf(stderr, "page_bench: %s\n", err.message);
        return 0;
    }
    double t_pinned = now_s();
    uint64_t open_bytes = gdr_paged_cache_bytes_read(pc);
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(pc); m++) {
        gdr_page page;
        if (gdr_paged_cache_mesh(pc, m)->page_count && gdr_paged_cache_read_page(pc, m, 0, &page, &err) == GDR_OK)
            gdr_page_free(&page);
    }
    double t_done = now_s();
    *row = (page_row){.kib = kib, .open_bytes = open_bytes, .page_bytes = gdr_paged_cache_page_bytes(pc),
                      .open_ms = 1e3 * (t_pinned - t_open), .pinned_ms = 1e3 * (t_done - t_pinned)};
    uint64_t triangles = 0, raw = 0, stored = 0, decoded = 0, groups = 0;
    double t0 = now_s();
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(pc); m++) {
        const gdr_paged_mesh *pm = gdr_paged_cache_mesh(pc, m);
        triangles += pm->source_triangles;
        groups += pm->group_count;
        for (uint32_t p = 0; p < pm->page_count; p++) {
            const gdr_page_info *pi = &pm->pages[p];
            raw += (uint64_t)pi->cluster_count * 56 + (uint64_t)pi->vertex_count * 32 + (uint64_t)pi->triangle_count * 3;
            stored += pi->stored_size;
            gdr_page page;
            if (gdr_paged_cache_read_page(pc, m, p, &page, &err) != GDR_OK) {
                fprintf(stderr, "page_bench: %s\n", err.message);
                gdr_paged_cache_close(pc);
                return 0;
            }
            decoded += (uint64_t)page.cluster_count * sizeof *page.clusters +
                       (uint64_t)page.vertex_count * sizeof *page.vertices + page.triangle_byte_count;
            gdr_page_free(&page);
            row->pages++;
        }
    }
    double seconds = now_s() - t0;
    row->bytes_per_triangle = (double)row->page_bytes / (double)triangles;
    row->stored_share = (double)stored / (double)raw;
    row->decode_mb_s = (double)decoded / 1e6 / seconds;
    row->groups_per_page = (double)groups / (double)row->pages;
    gdr_paged_cache_close(pc);
    return 1;
}

int main(int argc, char **argv)
{
    const char *spec = "unique-field:meshes=8,triangles=100000", *json = NULL, *sizes = "4,16,64,128,256,1024";
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--sizes") == 0 && i + 1 < argc)
            sizes = argv[++i];
        else if (strcmp(argv[i], "--json") == 0 && i + 1 < argc)
            json = argv[++i];
        else if (argv[i][0] != '-')
            spec = argv[i];
        else {
            fprintf(stderr, "usage: page_bench [SCENE] [--sizes KIB,KIB,...] [--json FILE]\n");
            return 2;
        }
    }
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    if (gdr_scene_load(spec, &load, &scene, &err) != GDR_OK) {
        fprintf(stderr, "page_bench: %s\n", err.message);
        return 1;
    }
    char path[64];
    snprintf(path, sizeof path, "/tmp/page_bench.%ld.gdrc", (long)getpid());
    page_row rows[32];
    int n = 0;
    char list[256];
    snprintf(list, sizeof list, "%s", sizes);
    printf("scene %s\n%8s %8s %12s %10s %10s %12s %10s %9s %10s\n", spec, "KiB", "pages", "groups/page", "B/tri",
           "stored", "decode MB/s", "open B", "open ms", "pinned ms");
    for (char *save = NULL, *item = strtok_r(list, ",", &save); item && n < 32; item = strtok_r(NULL, ",", &save)) {
        if (!measure(scene, path, (uint32_t)strtoul(item, NULL, 10), &rows[n]))
            break;
        page_row *r = &rows[n++];
        printf("%8u %8u %12.1f %10.2f %9.1f%% %12.0f %10llu %9.2f %10.2f\n", r->kib, r->pages, r->groups_per_page,
               r->bytes_per_triangle, 100.0 * r->stored_share, r->decode_mb_s, (unsigned long long)r->open_bytes,
               r->open_ms, r->pinned_ms);
    }
    FILE *out = json ? fopen(json, "w") : NULL;
    if (out) {
        fprintf(out, "{\"scene\": \"%s\", \"rows\": [", spec);
        for (int i = 0; i < n; i++)
            fprintf(out, "%s{\"page_kib\": %u, \"pages\": %u, \"bytes_per_source_triangle\": %.3f, \"stored_share\": %.4f, "
                         "\"decode_mb_s\": %.1f, \"open_bytes\": %llu, \"open_ms\": %.3f, \"pinned_ms\": %.3f}", i ? ", " : "",
                    rows[i].kib, rows[i].pages, rows[i].bytes_per_triangle, rows[i].stored_share, rows[i].decode_mb_s,
                    (unsigned long long)rows[i].open_bytes, rows[i].open_ms, rows[i].pinned_ms);
        fprintf(out, "]}\n");
        fclose(out);
    }
    remove(path);
    gdr_scene_destroy(scene);
    return 0;
}
