/* The geometry pages of the scene cache (section 'PAGE') and the paged reader: every page decodes
 * to exactly the clusters, vertices and triangles of the scene (triangles up to the rotation the
 * index codec may apply); pages hold whole groups, coarsest first, page 0 the root; the DAG's edges
 * match the clusters; the open reads only the header, table, instances and index; a damaged page
 * (flipped byte, rewritten in place while open) is refused naming the file, mesh and page while
 * the others still read; a truncated file or a damaged index is refused at the open; pages read
 * from several threads decode to the same bytes; quantized vertices decode to the scene's own. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "test_util.h"
#include "io/cache_pages.h"
#include "io/loaders.h"

/* A vertex of the page and one of the mesh: the same bytes. */
static int same_vertex(const gdr_page_vertex *pv, const gdr_mesh *mesh, uint32_t v)
{
    return !memcmp(&pv->position, &mesh->positions[v], 12) && !memcmp(&pv->normal, &mesh->normals[v], 12) &&
           !memcmp(&pv->uv, &mesh->uvs[v], 8);
}

/* Decoded triangle t of cluster pc is the scene's triangle t of cluster sc, corner for corner up to
 * a rotation (the index codec may rotate a triangle; the winding stays). */
static int same_triangle(const gdr_mesh *mesh, const gdr_cluster *sc, const gdr_page *page,
                         const gdr_page_cluster *pc, uint32_t t)
{
    const uint8_t *d = &page->triangles[pc->triangle_offset + 3 * t];
    const uint8_t *x = &mesh->clusters.triangles[sc->triangle_offset + 3 * t];
    for (int r = 0; r < 3; r++) {
        int all = 1;
        for (int k = 0; k < 3; k++)
            all &= same_vertex(&page->vertices[pc->vertex_offset + d[(k + r) % 3]], mesh,
                               mesh->clusters.vertices[sc->vertex_offset + x[k]]);
        if (all)
            return 1;
    }
    return 0;
}

/* The decoded cluster is the scene's cluster `c` of mesh `mesh`: the same records, vertex count and
 * triangles (by their corners' vertex bytes; the local order of vertices is rebuilt by the reader). */
static int same_cluster(const gdr_mesh *mesh, uint32_t c, const gdr_page *page, const gdr_page_cluster *pc)
{
    const gdr_cluster *sc = &mesh->clusters.clusters[c];
    if (pc->group != sc->group || pc->refined_group != sc->refined_group || pc->vertex_count != sc->vertex_count ||
        pc->triangle_count != sc->triangle_count || memcmp(&pc->sphere, &sc->sphere, 16) ||
        memcmp(&pc->cone_apex, &sc->cone_apex, 12) || memcmp(&pc->cone_axis, &sc->cone_axis, 12) ||
        pc->cone_cutoff != sc->cone_cutoff || pc->triangle_offset % 4 != 0)
        return 0;
    for (uint32_t t = 0; t < sc->triangle_count; t++)
        if (!same_triangle(mesh, sc, page, pc, t))
            return 0;
    return 1;
}

/* Every page of every mesh decodes to the scene's clusters; groups in page order, coarsest first. */
static void check_pages_match(gdr_paged_cache *pc, const gdr_scene *scene)
{
    gdr_error err = {0};
    CHECK(gdr_paged_cache_mesh_count(pc) == scene->mesh_count);
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh *mesh = &scene->meshes[m];
        const gdr_paged_mesh *pm = gdr_paged_cache_mesh(pc, m);
        CHECK(pm->group_count == mesh->clusters.group_count && pm->page_count >= 2);
        CHECK(pm->pages[0].group_count >= 2);
        CHECK(pm->source_triangles == mesh->index_count / 3);
        uint32_t *seen = calloc(mesh->clusters.cluster_count, sizeof *seen);
        uint32_t last_depth = UINT32_MAX;
        for (uint32_t p = 0; p < pm->page_count; p++) {
            gdr_page page;
            CHECK(gdr_paged_cache_read_page(pc, m, p, &page, &err) == GDR_OK);
            uint32_t k = 0;
            for (uint32_t g = 0; g < pm->pages[p].group_count; g++) {
                uint32_t group = pm->page_groups[pm->pages[p].first + g];
                const gdr_cluster_group *sg = &mesh->clusters.groups[group];
                CHECK(pm->groups[group].page == p && pm->groups[group].depth == sg->depth);
                CHECK(!(p > 0 || g > 0) || sg->depth <= last_depth); /* coarsest first */
                CHECK(p > 0 || g > 0 || isinf(sg->error));            /* page 0 starts with the root */
                last_depth = sg->depth;
                for (uint32_t c = 0; c < sg->cluster_count && k < page.cluster_count; c++, k++) {
                    CHECK(same_cluster(mesh, sg->first_cluster + c, &page, &page.clusters[k]));
                    seen[sg->first_cluster + c]++;
                }
            }
            CHECK(k == page.cluster_count);
            gdr_page_free(&page);
        }
        for (uint32_t c = 0; c < mesh->clusters.cluster_count; c++)
            CHECK(seen[c] == 1);
        free(seen);
        /* The edges: every cluster's (refined group -> group) is listed, and nothing else. */
        uint32_t listed = 0;
        for (uint32_t c = 0; c < mesh->clusters.cluster_count; c++) {
            const gdr_cluster *sc = &mesh->clusters.clusters[c];
            if (sc->refined_group == GDR_NO_INDEX)
                continue;
            const gdr_page_group *r = &pm->groups[sc->refined_group];
            int found = 0;
            for (uint32_t e = r->parent_first; e < r->parent_first + r->parent_count; e++)
                found |= pm->parents[e] == sc->group;
            CHECK(found);
        }
        for (uint32_t g = 0; g < pm->group_count; g++)
            listed += pm->groups[g].parent_count;
        CHECK(listed == pm->parent_count);
    }
}

static void write_file(const char *path, const uint8_t *bytes, size_t size)
{
    FILE *f = fopen(path, "wb");
    CHECK(f && fwrite(bytes, 1, size, f) == size);
    if (f)
        fclose(f);
}

static uint8_t *read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    struct stat st;
    if (!f || stat(path, &st) != 0)
        return NULL;
    uint8_t *bytes = malloc((size_t)st.st_size);
    *size = fread(bytes, 1, (size_t)st.st_size, f);
    fclose(f);
    return bytes;
}

/* A flipped byte in page 1 of mesh 1: only that page is refused, by name. */
static void check_damaged_page(const char *path, const uint8_t *bytes, size_t size, const gdr_paged_cache *good)
{
    char damaged[1100];
    snprintf(damaged, sizeof damaged, "%s.flip.gdrc", path);
    const gdr_page_info *pi = &gdr_paged_cache_mesh(good, 1)->pages[1];
    uint8_t *copy = malloc(size);
    memcpy(copy, bytes, size);
    copy[pi->offset + pi->stored_size / 2] ^= 0x10;
    write_file(damaged, copy, size);
    free(copy);
    gdr_error err = {0};
    gdr_paged_cache *pc = NULL;
    CHECK(gdr_paged_cache_open(damaged, &pc, &err) == GDR_OK); /* the open does not read pages */
    if (!pc)
        return;
    gdr_page page;
    CHECK_FAILS(gdr_paged_cache_read_page(pc, 1, 1, &page, &err), err, GDR_ERROR_CORRUPT);
    CHECK_NAMES(err, damaged);
    CHECK_NAMES(err, "mesh 1 page 1");
    printf("damaged page: %s\n", err.message);
    CHECK(page.clusters == NULL && page.vertices == NULL);
    CHECK(gdr_paged_cache_read_page(pc, 1, 0, &page, &err) == GDR_OK);
    gdr_page_free(&page);
    CHECK(gdr_paged_cache_read_page(pc, 0, 1, &page, &err) == GDR_OK);
    gdr_page_free(&page);
    CHECK(gdr_paged_cache_read_page(pc, 1, 99999, &page, &err) == GDR_ERROR_INVALID_ARGUMENT);
    /* The same page rewritten in place while the file is open (another writer, no rename): refused. */
    FILE *f = fopen(damaged, "r+b");
    const gdr_page_info *p2 = &gdr_paged_cache_mesh(pc, 0)->pages[1];
    uint8_t byte = 0;
    CHECK(f && fseek(f, (long)(p2->offset + 40), SEEK_SET) == 0 && fread(&byte, 1, 1, f) == 1);
    byte ^= 0xff;
    CHECK(f && fseek(f, (long)(p2->offset + 40), SEEK_SET) == 0 && fwrite(&byte, 1, 1, f) == 1);
    if (f)
        fclose(f);
    CHECK_FAILS(gdr_paged_cache_read_page(pc, 0, 1, &page, &err), err, GDR_ERROR_CORRUPT);
    CHECK_NAMES(err, "mesh 0 page 1");
    gdr_paged_cache_close(pc);
    remove(damaged);
}

/* A truncated file, a damaged index or instance section, a cache without pages: refused at the open. */
static void check_refused_opens(const char *path, const uint8_t *bytes, size_t size, const gdr_paged_cache *good)
{
    char bad[1100];
    snprintf(bad, sizeof bad, "%s.bad.gdrc", path);
    gdr_error err = {0};
    gdr_paged_cache *pc = NULL;
    write_file(bad, bytes, size - 10);
    CHECK_FAILS(gdr_paged_cache_open(bad, &pc, &err), err, GDR_ERROR_CORRUPT);
    CHECK(pc == NULL);
    /* A byte of the index (just after the section header): the index checksum. */
    const gdr_page_info *first = &gdr_paged_cache_mesh(good, 0)->pages[0];
    uint8_t *copy = malloc(size);
    memcpy(copy, bytes, size);
    uint64_t index_start = first->offset - 8; /* the last 8 bytes of the index: page 0's.. of the last mesh */
    copy[index_start] ^= 1;
    write_file(bad, copy, size);
    CHECK_FAILS(gdr_paged_cache_open(bad, &pc, &err), err, GDR_ERROR_CORRUPT);
    CHECK_NAMES(err, "section 'PAGE'");
    printf("damaged index: %s\n", err.message);
    free(copy);
    remove(bad);
}

typedef struct reader_job {
    gdr_paged_cache *pc;
    uint32_t mesh, pages;
    uint64_t hash; /* of every decoded byte, in page order */
} reader_job;

static uint64_t mix(uint64_t h, const void *data, size_t n)
{
    const uint8_t *p = data;
    for (size_t i = 0; i < n; i++)
        h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

/* A page index whose groups' parent lists overlap (every level-0 group listing all the mesh's edges,
 * each of them to a deeper group, so every other check passes) is refused: a reader that gathers
 * the lists per page would write more edges than the mesh holds. */
static void check_overlapping_parents(const uint8_t *bytes, size_t size, const gdr_paged_cache *good)
{
    uint64_t pages_start = gdr_paged_cache_mesh(good, 0)->pages[0].offset, header = 0, index_size = 0;
    /* The section's header lies just before the index, which ends where the first page starts. */
    for (uint64_t p = 0; p + CACHE_PAGES_HEADER <= pages_start && !index_size; p++) {
        uint64_t n;
        memcpy(&n, bytes + p + 16, 8);
        if (p + CACHE_PAGES_HEADER + n == pages_start && n > 16)
            header = p, index_size = n;
    }
    CHECK(index_size > 0);
    if (!index_size)
        return;
    uint8_t *index = malloc(index_size);
    memcpy(index, bytes + header + CACHE_PAGES_HEADER, index_size);
    uint32_t groups, parents, overlapped = 0;
    memcpy(&groups, index, 4);
    memcpy(&parents, index + 12, 4);
    for (uint32_t g = 0; g < groups; g++) {
        uint8_t *record = index + 16 + (size_t)g * CACHE_PAGE_GROUP_RECORD;
        uint32_t depth, first = 0;
        memcpy(&depth, record + 20, 4);
        if (depth == 0) {
            memcpy(record + 32, &first, 4);
            memcpy(record + 36, &parents, 4);
            overlapped++;
        }
    }
    CHECK(overlapped > 1 && parents > 0);
    gdr_paged_mesh *meshes = NULL;
    gdr_error err = {0};
    CHECK_FAILS(cache_pages_parse_index("overlap.gdrc", index, index_size, gdr_paged_cache_mesh_count(good), header,
                                        size - header, &meshes, &err),
                err, GDR_ERROR_PARSE);
    CHECK_NAMES(err, "mesh 0");
    printf("overlapping parent lists: %s\n", err.message);
    if (meshes) /* accepted: the check is missing */
        cache_pages_free_index(meshes, gdr_paged_cache_mesh_count(good));
    free(index);
}

static void *read_all_pages(void *user)
{
    reader_job *job = user;
    job->hash = 14695981039346656037ull;
    for (uint32_t p = 0; p < job->pages; p++) {
        gdr_page page;
        gdr_error err = {0};
        if (gdr_paged_cache_read_page(job->pc, job->mesh, p, &page, &err) != GDR_OK)
            continue;
        job->hash = mix(job->hash, page.clusters, sizeof *page.clusters * page.cluster_count);
        job->hash = mix(job->hash, page.vertices, sizeof *page.vertices * page.vertex_count);
        job->hash = mix(job->hash, page.triangles, page.triangle_byte_count);
        gdr_page_free(&page);
    }
    return NULL;
}

/* Four threads read the same pages at once: the same bytes as one thread alone. */
static void check_threads(gdr_paged_cache *pc)
{
    reader_job alone = {pc, 0, gdr_paged_cache_mesh(pc, 0)->page_count, 0};
    read_all_pages(&alone);
    reader_job jobs[4];
    pthread_t threads[4];
    for (int t = 0; t < 4; t++) {
        jobs[t] = alone;
        pthread_create(&threads[t], NULL, read_all_pages, &jobs[t]);
    }
    for (int t = 0; t < 4; t++) {
        pthread_join(threads[t], NULL);
        CHECK(jobs[t].hash == alone.hash);
    }
}

int main(void)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load("unique-field:meshes=3,triangles=3000,seed=4", &load, &scene, &err) == GDR_OK);
    if (!scene)
        return test_finish("test_cache_pages");
    char path[1024];
    snprintf(path, sizeof path, "%s/pages.gdrc", GDR_IO_TEST_TMP);
    gdr_cache_write_options bad = {.page_bytes = GDR_PAGE_BYTES_MIN - 1};
    CHECK(gdr_cache_write(path, scene, &bad, &err) == GDR_ERROR_INVALID_ARGUMENT);
    /* Pages of about three groups: several pages per mesh, several groups per page. */
    gdr_cache_write_options write = {.page_bytes = 48u << 10};
    /* With the whole geometry beside the pages, the whole-file reader reads it (and checks the page
     * index); with the pages alone it refuses it, saying how to read it. */
    gdr_cache_write_options whole = {.page_bytes = 48u << 10, .whole_geometry = 1};
    CHECK(gdr_cache_write(path, scene, &whole, &err) == GDR_OK);
    gdr_scene *again = NULL;
    CHECK(gdr_cache_read(path, NULL, &again, NULL, &err) == GDR_OK);
    gdr_scene_destroy(again);
    CHECK(gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    again = NULL;
    CHECK_FAILS(gdr_cache_read(path, NULL, &again, NULL, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    CHECK(again == NULL && strstr(err.message, "pages alone") && strstr(err.message, "--geometry-budget"));

    size_t size = 0;
    uint8_t *bytes = read_file(path, &size);
    gdr_paged_cache *pc = NULL;
    CHECK(gdr_paged_cache_open(path, &pc, &err) == GDR_OK);
    if (pc && bytes) {
        printf("open read %llu of %zu bytes\n", (unsigned long long)gdr_paged_cache_bytes_read(pc), size);
        CHECK(gdr_paged_cache_bytes_read(pc) * 20 < size);
        uint32_t count = 0;
        const gdr_instance *instances = gdr_paged_cache_instances(pc, &count);
        CHECK(count == scene->instance_count && !memcmp(instances, scene->instances, sizeof *instances * count));
        check_pages_match(pc, scene);
        check_threads(pc);
        check_damaged_page(path, bytes, size, pc);
        check_refused_opens(path, bytes, size, pc);
        check_overlapping_parents(bytes, size, pc);
    }
    gdr_paged_cache_close(pc);
    /* Quantized vertices: the pages store them as integers and decode them to the scene's floats, bit
     * for bit, in much fewer bytes. */
    uint64_t float_bytes = 0, quantized_bytes = 0;
    pc = NULL;
    if (gdr_paged_cache_open(path, &pc, &err) == GDR_OK)
        float_bytes = gdr_paged_cache_page_bytes(pc);
    gdr_paged_cache_close(pc);
    CHECK(gdr_scene_quantize_vertices(scene, &err) == GDR_OK);
    CHECK(gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    pc = NULL;
    CHECK(gdr_paged_cache_open(path, &pc, &err) == GDR_OK);
    if (pc) {
        quantized_bytes = gdr_paged_cache_page_bytes(pc);
        check_pages_match(pc, scene);
    }
    gdr_paged_cache_close(pc);
    printf("pages: %llu bytes with float vertices, %llu quantized\n", (unsigned long long)float_bytes,
           (unsigned long long)quantized_bytes);
    CHECK(quantized_bytes > 0 && quantized_bytes * 10 < float_bytes * 7);
    /* A cache written without pages is refused by the paged reader, saying why. */
    CHECK(gdr_cache_write(path, scene, NULL, &err) == GDR_OK);
    pc = NULL;
    CHECK_FAILS(gdr_paged_cache_open(path, &pc, &err), err, GDR_ERROR_UNSUPPORTED);
    free(bytes);
    remove(path);
    gdr_scene_destroy(scene);
    return test_finish("test_cache_pages");
}
