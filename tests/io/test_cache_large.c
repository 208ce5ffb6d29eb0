/* A paged cache past 4 GiB (docs/CACHE_FORMAT.md, "Caches over 4 GiB"): a small paged cache is
 * rewritten as a sparse file whose PAGE section starts 4 GiB + 4 KiB into it, behind an optional
 * section of zeros (a hole: no disk is used) that a reader skips. Its checksums, file size and
 * offsets are made as the writer makes them. The paged reader opens it, every page lies past 4 GiB
 * and decodes to exactly the bytes of the same page of the small file, the read for streaming takes
 * the same scene, and the whole reader, which holds a file in memory, refuses it by name and size.
 * Skipped (77) where the file system cannot make the sparse file.
 * The writer past the whole reader's limit, scaled down (the limit lowered to 64 KiB): a cache with
 * pages is written (section by section) and streams; one without is refused, nothing left. */
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <xxhash.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "io/io_internal.h"
#include "io/loaders.h"
#include "test_util.h"

#define HEADER 64u
#define ENTRY 32u
#define PAD ((4ull << 30) + 4096u)
#define PAGE_ID ((uint32_t)'P' | (uint32_t)'A' << 8 | (uint32_t)'G' << 16 | (uint32_t)'E' << 24)
#define PAD_ID ((uint32_t)'Z' | (uint32_t)'P' << 8 | (uint32_t)'A' << 16 | (uint32_t)'D' << 24)

typedef struct entry {
    uint32_t id, flags;
    uint64_t offset, size, checksum;
} entry;

static uint64_t get64(const uint8_t *p) { uint64_t v; memcpy(&v, p, 8); return v; }
static uint32_t get32(const uint8_t *p) { uint32_t v; memcpy(&v, p, 4); return v; }

/* XXH3-64 of `size` zero bytes, in pieces. */
static uint64_t zeros_hash(uint64_t size)
{
    static uint8_t zeros[1 << 20];
    XXH3_state_t *state = XXH3_createState();
    XXH3_64bits_reset(state);
    for (uint64_t done = 0; done < size; done += sizeof zeros)
        XXH3_64bits_update(state, zeros, size - done < sizeof zeros ? (size_t)(size - done) : sizeof zeros);
    uint64_t h = XXH3_64bits_digest(state);
    XXH3_freeState(state);
    return h;
}

/* The small file's sections with the zero section before PAGE, at offsets as the writer lays them
 * (8-byte aligned after the table). Returns 0 when the sparse file cannot be made. */
static int make_large(const char *small, const char *large)
{
    FILE *in = fopen(small, "rb");
    uint8_t head[HEADER];
    if (!in || fread(head, 1, HEADER, in) != HEADER)
        return in ? fclose(in), 0 : 0;
    uint32_t count = get32(head + 16);
    uint8_t *table = malloc((size_t)count * ENTRY);
    entry *e = calloc(count + 1, sizeof *e);
    int ok = table && e && fread(table, 1, (size_t)count * ENTRY, in) == (size_t)count * ENTRY;
    uint32_t n = 0;
    for (uint32_t i = 0; ok && i < count; i++) {
        const uint8_t *t = table + (size_t)i * ENTRY;
        entry s = {get32(t), get32(t + 4), get64(t + 8), get64(t + 16), get64(t + 24)};
        if (s.id == PAGE_ID)
            e[n++] = (entry){PAD_ID, 0, 0, PAD, zeros_hash(PAD)};
        e[n++] = s;
    }
    int fd = open(large, O_RDWR | O_CREAT | O_TRUNC, 0644);
    uint64_t at = HEADER + (uint64_t)n * ENTRY;
    for (uint32_t i = 0; ok && fd >= 0 && i < n; i++) {
        at = (at + 7) & ~7ull;
        uint64_t from = e[i].offset;
        e[i].offset = at;
        if (e[i].id != PAD_ID) {
            uint8_t *bytes = malloc(e[i].size ? e[i].size : 1);
            ok = bytes && fseek(in, (long)from, SEEK_SET) == 0 && fread(bytes, 1, e[i].size, in) == e[i].size &&
                 pwrite(fd, bytes, e[i].size, (off_t)at) == (ssize_t)e[i].size;
            free(bytes);
        }
        at += e[i].size;
    }
    ok = ok && fd >= 0 && ftruncate(fd, (off_t)at) == 0; /* the hole's zeros, and no byte past the end */
    uint8_t *out = calloc(1, HEADER + (size_t)n * ENTRY);
    for (uint32_t i = 0; ok && out && i < n; i++) {
        uint8_t *t = out + HEADER + (size_t)i * ENTRY;
        memcpy(t, &e[i].id, 4), memcpy(t + 4, &e[i].flags, 4), memcpy(t + 8, &e[i].offset, 8);
        memcpy(t + 16, &e[i].size, 8), memcpy(t + 24, &e[i].checksum, 8);
    }
    if (ok && out) {
        memcpy(out, head, 40);
        memcpy(out + 16, &n, 4);
        memcpy(out + 24, &at, 8);
        uint64_t table_hash = XXH3_64bits(out + HEADER, (size_t)n * ENTRY);
        memcpy(out + 32, &table_hash, 8);
        uint64_t header_hash = XXH3_64bits(out, 40);
        memcpy(out + 40, &header_hash, 8);
        ok = pwrite(fd, out, HEADER + (size_t)n * ENTRY, 0) == (ssize_t)(HEADER + (size_t)n * ENTRY);
    }
    if (fd >= 0)
        close(fd);
    fclose(in);
    free(table), free(e), free(out);
    return ok && out;
}

static int same_page(const gdr_page *a, const gdr_page *b)
{
    return a->cluster_count == b->cluster_count && a->vertex_count == b->vertex_count &&
           a->triangle_byte_count == b->triangle_byte_count &&
           memcmp(a->clusters, b->clusters, sizeof *a->clusters * a->cluster_count) == 0 &&
           memcmp(a->vertices, b->vertices, sizeof *a->vertices * a->vertex_count) == 0 &&
           memcmp(a->triangles, b->triangles, a->triangle_byte_count) == 0;
}

static void check_large(const char *small, const char *large)
{
    gdr_error err = {0};
    gdr_paged_cache *a = NULL, *b = NULL;
    CHECK(gdr_paged_cache_open(small, &a, &err) == GDR_OK);
    CHECK(gdr_paged_cache_open(large, &b, &err) == GDR_OK);
    if (!b)
        fprintf(stderr, "open: %s\n", err.message);
    uint32_t pages = 0, past = 0, same = 0;
    for (uint32_t m = 0; a && b && m < gdr_paged_cache_mesh_count(a); m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(a, m)->page_count; p++, pages++) {
            gdr_page pa = {0}, pb = {0};
            past += gdr_paged_cache_mesh(b, m)->pages[p].offset > (4ull << 30);
            if (gdr_paged_cache_read_page(a, m, p, &pa, &err) == GDR_OK &&
                gdr_paged_cache_read_page(b, m, p, &pb, &err) == GDR_OK)
                same += same_page(&pa, &pb);
            gdr_page_free(&pa), gdr_page_free(&pb);
        }
    printf("%u pages: %u past 4 GiB, %u decode as in the small file\n", pages, past, same);
    CHECK(pages > 0 && past == pages && same == pages);
    gdr_paged_cache_close(a), gdr_paged_cache_close(b);

    gdr_scene *sa = NULL, *sb = NULL;
    CHECK(gdr_cache_read_for_streaming(small, NULL, &sa, NULL, NULL, &err) == GDR_OK);
    CHECK(gdr_cache_read_for_streaming(large, NULL, &sb, NULL, NULL, &err) == GDR_OK);
    CHECK(sa && sb && sa->mesh_count == sb->mesh_count && sa->instance_count == sb->instance_count);
    for (uint32_t m = 0; sa && sb && m < sa->mesh_count; m++)
        CHECK(sa->meshes[m].clusters.cluster_count == sb->meshes[m].clusters.cluster_count &&
              sa->meshes[m].clusters.group_count == sb->meshes[m].clusters.group_count);
    gdr_scene_destroy(sa), gdr_scene_destroy(sb);

    gdr_scene *whole = NULL;
    CHECK_FAILS(gdr_cache_read(large, NULL, &whole, NULL, &err), err, GDR_ERROR_UNSUPPORTED);
    printf("whole read: %s\n", err.message);
    CHECK(strstr(err.message, large) != NULL && strstr(err.message, "bytes") != NULL);
}

/* The limit scaled down: a paged cache past it is written and streams; a plain one is refused. */
static void past_the_limit(const gdr_scene *scene, const char *path)
{
    gdr_error err = {0};
    uint64_t limit = gdr_io_max_file_size;
    gdr_io_max_file_size = 64u << 10;
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_MIN};
    CHECK(gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    if (err.message[0])
        printf("paged write past the limit: %s\n", err.message);
    FILE *f = fopen(path, "rb");
    long size = f && fseek(f, 0, SEEK_END) == 0 ? ftell(f) : 0;
    if (f)
        fclose(f);
    gdr_paged_cache *cache = NULL;
    gdr_scene *streamed = NULL, *whole = NULL;
    CHECK(size > (long)(64u << 10) && gdr_paged_cache_open(path, &cache, &err) == GDR_OK);
    CHECK(gdr_cache_read_for_streaming(path, NULL, &streamed, NULL, NULL, &err) == GDR_OK);
    CHECK_FAILS(gdr_cache_read(path, NULL, &whole, NULL, &err), err, GDR_ERROR_UNSUPPORTED);
    uint32_t pages = 0, decoded = 0;
    for (uint32_t m = 0; cache && m < gdr_paged_cache_mesh_count(cache); m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(cache, m)->page_count; p++, pages++) {
            gdr_page page = {0};
            decoded += gdr_paged_cache_read_page(cache, m, p, &page, &err) == GDR_OK;
            gdr_page_free(&page);
        }
    printf("limit %llu bytes: a paged cache of %ld bytes written, %u of %u pages read back\n",
           (unsigned long long)gdr_io_max_file_size, size, decoded, pages);
    CHECK(pages > 0 && decoded == pages);
    gdr_paged_cache_close(cache);
    gdr_scene_destroy(streamed);
    unlink(path);
    CHECK_FAILS(gdr_cache_write(path, scene, NULL, &err), err, GDR_ERROR_CAPACITY);
    printf("without pages: %s\n", err.message);
    CHECK(access(path, F_OK) != 0);
    gdr_io_max_file_size = limit;
}

int main(void)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load("unique-field:meshes=2,triangles=4000,seed=2", &load, &scene, &err) == GDR_OK);
    CHECK(scene && gdr_scene_quantize_vertices(scene, &err) == GDR_OK);
    char small[256], large[256];
    snprintf(small, sizeof small, "%s/cache_large_%ld.gdrc", GDR_IO_TEST_TMP, (long)getpid());
    snprintf(large, sizeof large, "%s/cache_large_%ld.sparse.gdrc", GDR_IO_TEST_TMP, (long)getpid());
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_MIN};
    CHECK(scene && gdr_cache_write(small, scene, &write, &err) == GDR_OK);
    if (scene)
        past_the_limit(scene, large);
    gdr_scene_destroy(scene);
    int made = make_large(small, large);
    if (made)
        check_large(small, large);
    else
        printf("the file system made no sparse file of %llu bytes: skipped\n", (unsigned long long)PAD);
    unlink(small), unlink(large);
    if (!made)
        return 77;
    return test_finish("test_cache_large");
}
