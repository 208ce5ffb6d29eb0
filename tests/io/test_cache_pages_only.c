/* A paged cache whose geometry lives in its pages alone (docs/CACHE_FORMAT.md, "Geometry in the
 * pages alone"): the same quantized scene written with the whole geometry beside its pages and
 * without it. The file without has header flag 1 and no 'GEOM', 'VCOL' or 'CLGM'; every section it
 * has holds the bytes of the same section of the other file, so it is smaller by exactly those
 * three. Read for streaming, both give the same scene (records, groups, hierarchy, instances) and
 * every page decodes to the same clusters, vertices and triangles. The whole read refuses it by
 * name, saying how to read it; gdr_scene_load reads it for streaming only.
 * Hostile copies: unknown header flags, the flag cleared (the whole geometry is then missing), the
 * flag set on a file with the whole geometry, the flag without pages, the previous format version,
 * truncations and random byte flips: each is refused with an error naming the file, or (a flip the
 * reads never look at) reads exactly as the original. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <xxhash.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "io/loaders.h"
#include "io_test_helpers.h"
#include "test_util.h"

#define FLAGS_AT 20u
#define PAGES_ONLY 1u

static void write_file(const char *path, const uint8_t *bytes, size_t size)
{
    FILE *f = fopen(path, "wb");
    CHECK(f && fwrite(bytes, 1, size, f) == size);
    if (f)
        fclose(f);
}

static uint32_t get32(const uint8_t *p) { uint32_t v; memcpy(&v, p, 4); return v; }
static uint64_t get64(const uint8_t *p) { uint64_t v; memcpy(&v, p, 8); return v; }

/* The table entry of section `id` (NULL when the file has none). */
static const uint8_t *entry_of(const uint8_t *data, const char *id)
{
    uint32_t count = get32(data + 16);
    for (uint32_t i = 0; i < count; i++)
        if (memcmp(data + 64 + (size_t)i * 32, id, 4) == 0)
            return data + 64 + (size_t)i * 32;
    return NULL;
}

/* The table's and the header's checksums after a deliberate edit of either. */
static void fix_header(uint8_t *data)
{
    uint32_t count = get32(data + 16);
    uint64_t h = XXH3_64bits(data + 64, (size_t)count * 32);
    memcpy(data + 32, &h, 8);
    h = XXH3_64bits(data, 40);
    memcpy(data + 40, &h, 8);
}

/* Every section of `only` holds the bytes of the same section of `full`; `full` has exactly the
 * whole geometry more. */
static void check_sections(const uint8_t *only, size_t only_size, const uint8_t *full, size_t full_size)
{
    static const char *const geometry[] = {"GEOM", "VCOL", "CLGM", "CLDT"};
    CHECK(get32(only + FLAGS_AT) == PAGES_ONLY && get32(full + FLAGS_AT) == 0);
    CHECK(entry_of(only, "PAGE") != NULL && entry_of(full, "PAGE") != NULL);
    uint64_t geometry_bytes = 0;
    for (int k = 0; k < 4; k++) {
        CHECK(entry_of(only, geometry[k]) == NULL);
        const uint8_t *e = entry_of(full, geometry[k]);
        CHECK(e != NULL);
        geometry_bytes += e ? get64(e + 16) : 0;
    }
    uint32_t count = get32(only + 16);
    CHECK(count + 4 == get32(full + 16));
    for (uint32_t i = 0; i < count; i++) {
        const uint8_t *e = only + 64 + (size_t)i * 32;
        char id[5] = {0};
        memcpy(id, e, 4);
        const uint8_t *f = entry_of(full, id);
        CHECK(f && get64(e + 16) == get64(f + 16) && get64(e + 24) == get64(f + 24));
        if (f && get64(e + 16) == get64(f + 16))
            CHECK(memcmp(only + get64(e + 8), full + get64(f + 8), (size_t)get64(e + 16)) == 0);
    }
    /* The file is its sections, the table and under 8 bytes of padding each, nothing more. */
    CHECK(full_size - only_size >= geometry_bytes + 4 * 32 && full_size - only_size < geometry_bytes + 4 * 40);
    printf("pages alone: %zu bytes, with the whole geometry %zu (its sections %llu)\n", only_size, full_size,
           (unsigned long long)geometry_bytes);
}

static int same_records(const gdr_scene *a, const gdr_scene *b)
{
    if (a->mesh_count != b->mesh_count || a->instance_count != b->instance_count ||
        memcmp(a->instances, b->instances, sizeof *a->instances * a->instance_count) != 0)
        return 0;
    for (uint32_t m = 0; m < a->mesh_count; m++) {
        const gdr_mesh *x = &a->meshes[m], *y = &b->meshes[m];
        const gdr_mesh_clusters *p = &x->clusters, *q = &y->clusters;
        if (x->vertex_count != y->vertex_count || x->index_count != y->index_count ||
            memcmp(&x->bounds, &y->bounds, sizeof x->bounds) != 0 ||
            memcmp(&x->quantization, &y->quantization, sizeof x->quantization) != 0 ||
            p->cluster_count != q->cluster_count || p->group_count != q->group_count ||
            p->lod_node_count != q->lod_node_count ||
            (p->clusters || q->clusters) != 0 || p->refinement_count != q->refinement_count ||
            memcmp(p->size_classes, q->size_classes, sizeof p->size_classes) != 0 ||
            memcmp(p->refinements, q->refinements, sizeof *p->refinements * p->refinement_count) != 0 ||
            memcmp(p->group_bounds, q->group_bounds, sizeof *p->group_bounds * p->group_count) != 0 ||
            memcmp(p->groups, q->groups, sizeof *p->groups * p->group_count) != 0 ||
            memcmp(p->lod_nodes, q->lod_nodes, sizeof *p->lod_nodes * p->lod_node_count) != 0)
            return 0;
    }
    return 1;
}

/* Every page of both files decodes to the same bytes. Returns the pages compared (0 on a failure). */
static uint32_t same_pages(gdr_paged_cache *a, gdr_paged_cache *b)
{
    uint32_t pages = 0;
    gdr_error err = {0};
    if (gdr_paged_cache_mesh_count(a) != gdr_paged_cache_mesh_count(b))
        return 0;
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(a); m++) {
        if (gdr_paged_cache_mesh(a, m)->page_count != gdr_paged_cache_mesh(b, m)->page_count)
            return 0;
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(a, m)->page_count; p++, pages++) {
            gdr_page x, y;
            gdr_status sx = gdr_paged_cache_read_page(a, m, p, &x, &err);
            gdr_status sy = gdr_paged_cache_read_page(b, m, p, &y, &err);
            int same = sx == GDR_OK && sy == GDR_OK && x.cluster_count == y.cluster_count &&
                       x.vertex_count == y.vertex_count && x.triangle_byte_count == y.triangle_byte_count &&
                       !memcmp(x.clusters, y.clusters, sizeof *x.clusters * x.cluster_count) &&
                       !memcmp(x.vertices, y.vertices, sizeof *x.vertices * x.vertex_count) &&
                       !memcmp(x.triangles, y.triangles, x.triangle_byte_count);
            if (sx == GDR_OK)
                gdr_page_free(&x);
            if (sy == GDR_OK)
                gdr_page_free(&y);
            if (!same)
                return 0;
        }
    }
    return pages;
}

/* Both files read for streaming: the same scene and the same pages. */
static void check_streamed(const char *only, const char *full)
{
    gdr_error err = {0};
    gdr_scene *a = NULL, *b = NULL;
    uint64_t read_a = 0, read_b = 0;
    CHECK(gdr_cache_read_for_streaming(only, NULL, &a, NULL, &read_a, &err) == GDR_OK);
    CHECK(gdr_cache_read_for_streaming(full, NULL, &b, NULL, &read_b, &err) == GDR_OK);
    CHECK(a && b && a->geometry_in_pages && same_records(a, b));
    /* The same reads but four table entries: none of the whole geometry, no cluster record (CLDT). */
    CHECK(read_a + 4 * 32 == read_b);
    /* No per-cluster record in the scene or among the bytes read: the pages hold them. */
    uint64_t clusters = 0, without = 0;
    for (uint32_t m = 0; a && m < a->mesh_count; m++) {
        const gdr_mesh_clusters *c = &a->meshes[m].clusters;
        clusters += c->cluster_count;
        without += c->cluster_count > 0 && !c->clusters && c->group_bounds && c->refinements;
    }
    printf("read for streaming: %llu bytes for %llu clusters, %llu of %u meshes without their records\n",
           (unsigned long long)read_a, (unsigned long long)clusters, (unsigned long long)without,
           a ? a->mesh_count : 0);
    CHECK(a && clusters > 0 && without == a->mesh_count && read_a < 72 * clusters);
    gdr_scene_destroy(a);
    gdr_scene_destroy(b);
    gdr_paged_cache *pa = NULL, *pb = NULL;
    CHECK(gdr_paged_cache_open(only, &pa, &err) == GDR_OK && gdr_paged_cache_open(full, &pb, &err) == GDR_OK);
    CHECK(pa && pb && gdr_paged_cache_pages_only(pa) == 1 && gdr_paged_cache_pages_only(pb) == 0);
    CHECK(pa && pb && same_pages(pa, pb) > 0);
    gdr_paged_cache_close(pa);
    gdr_paged_cache_close(pb);
}

/* What needs the whole geometry refuses the file by name, saying how to read it. */
static void check_whole_refused(const char *only)
{
    gdr_error err = {0};
    gdr_scene *s = NULL;
    CHECK_FAILS(gdr_cache_read(only, NULL, &s, NULL, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    CHECK_NAMES(err, only);
    CHECK(s == NULL && strstr(err.message, "pages alone") && strstr(err.message, "--geometry-budget") &&
          strstr(err.message, "--whole-geometry"));
    CHECK_FAILS(gdr_scene_load(only, &(gdr_load_options){.no_progress = 1}, &s, &err), err,
                GDR_ERROR_INVALID_ARGUMENT);
    CHECK(s == NULL);
    gdr_load_options streamed = {.no_progress = 1, .geometry_in_pages = 1};
    CHECK(gdr_scene_load(only, &streamed, &s, &err) == GDR_OK && s && s->geometry_in_pages);
    /* A scene read so holds no geometry to write again. */
    char again[1100];
    snprintf(again, sizeof again, "%s.again.gdrc", only);
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_DEFAULT};
    if (s)
        CHECK_FAILS(gdr_cache_write(again, s, &write, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    CHECK(access(again, F_OK) != 0);
    gdr_scene_destroy(s);
}

/* A copy of the file, edited: every read refuses it with `code`, naming the file and `what`. */
static void expect_refused(const char *path, const uint8_t *bytes, size_t size, gdr_status code, const char *what)
{
    write_file(path, bytes, size);
    gdr_error err = {0};
    gdr_scene *s = NULL;
    CHECK_FAILS(gdr_cache_read_for_streaming(path, NULL, &s, NULL, NULL, &err), err, code);
    CHECK_NAMES(err, path);
    CHECK_NAMES(err, what);
    CHECK(s == NULL);
    CHECK_FAILS(gdr_cache_read(path, NULL, &s, NULL, &err), err, code);
    CHECK_NAMES(err, what);
    CHECK(s == NULL);
}

static void check_header_edits(const char *bad, const uint8_t *only, size_t only_size, const uint8_t *full,
                               size_t full_size)
{
    uint8_t *copy = malloc(only_size > full_size ? only_size : full_size);
    /* A flag this build does not know. */
    memcpy(copy, only, only_size);
    copy[FLAGS_AT] |= 2;
    fix_header(copy);
    expect_refused(bad, copy, only_size, GDR_ERROR_PARSE, "header flags 0x3");
    /* The flag cleared: a file that says it has the whole geometry and lacks it. */
    memcpy(copy, only, only_size);
    copy[FLAGS_AT] = 0;
    fix_header(copy);
    expect_refused(bad, copy, only_size, GDR_ERROR_PARSE, "section 'GEOM' is missing");
    /* The flag set on a file with the whole geometry. */
    memcpy(copy, full, full_size);
    copy[FLAGS_AT] = PAGES_ONLY;
    fix_header(copy);
    expect_refused(bad, copy, full_size, GDR_ERROR_PARSE, "in a cache whose header says its geometry is in its pages");
    /* The flag, and the pages renamed into a section this build does not know (optional: skipped). */
    memcpy(copy, only, only_size);
    uint8_t *page = (uint8_t *)entry_of(copy, "PAGE");
    CHECK(page != NULL);
    if (page)
        memcpy(page, "PAGX", 4);
    fix_header(copy);
    expect_refused(bad, copy, only_size, GDR_ERROR_PARSE, "has no section 'PAGE'");
    /* The format before this one (pages beside the whole geometry, no flag): rebuild it. */
    memcpy(copy, only, only_size);
    uint32_t old = GDR_CACHE_FORMAT_VERSION - 1;
    memcpy(copy + 8, &old, 4);
    fix_header(copy);
    char expected[96];
    snprintf(expected, sizeof expected, "cache format version %u, this build reads %u; rebuild it", old,
             GDR_CACHE_FORMAT_VERSION);
    expect_refused(bad, copy, only_size, GDR_ERROR_UNSUPPORTED, expected);
    free(copy);
}

/* The copy reads, for streaming and page by page, exactly as the original; or it is refused naming
 * the file. Returns 1 when refused. */
static int refused_or_same(const char *bad, gdr_scene *original, gdr_paged_cache *original_pages)
{
    gdr_error err = {0};
    gdr_scene *s = NULL;
    gdr_status status = gdr_cache_read_for_streaming(bad, NULL, &s, NULL, NULL, &err);
    if (status != GDR_OK) {
        CHECK(s == NULL && strstr(err.message, bad) != NULL);
        return 1;
    }
    gdr_paged_cache *pc = NULL;
    status = gdr_paged_cache_open(bad, &pc, &err);
    if (status != GDR_OK) {
        CHECK(pc == NULL && strstr(err.message, bad) != NULL);
        gdr_scene_destroy(s);
        return 1;
    }
    int refused = 0;
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(pc) && !refused; m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(pc, m)->page_count && !refused; p++) {
            gdr_page page;
            if (gdr_paged_cache_read_page(pc, m, p, &page, &err) != GDR_OK) {
                CHECK(strstr(err.message, bad) != NULL);
                refused = 1;
            } else {
                gdr_page_free(&page);
            }
        }
    if (!refused) {
        CHECK(same_records(s, original));
        CHECK(same_pages(pc, original_pages) > 0);
    }
    gdr_paged_cache_close(pc);
    gdr_scene_destroy(s);
    return refused;
}

static void check_damage(const char *only, const char *bad, const uint8_t *bytes, size_t size)
{
    gdr_error err = {0};
    gdr_scene *original = NULL;
    gdr_paged_cache *pages = NULL;
    CHECK(gdr_cache_read_for_streaming(only, NULL, &original, NULL, NULL, &err) == GDR_OK);
    CHECK(gdr_paged_cache_open(only, &pages, &err) == GDR_OK);
    if (!original || !pages)
        return;
    uint8_t *copy = malloc(size);
    uint32_t truncations = 0, flips = 0, refused = 0;
    for (size_t cut = 0; cut < size; cut += size / 61 + 1, truncations++) {
        write_file(bad, bytes, cut);
        CHECK(refused_or_same(bad, original, pages) == 1); /* a shorter file is never the same file */
    }
    unsigned seed = 2026;
    for (int trial = 0; trial < 400; trial++, flips++) {
        memcpy(copy, bytes, size);
        for (int f = 0; f < 1 + trial % 3; f++) {
            size_t at = (size_t)(test_random(&seed) * (float)size) % size;
            copy[at] ^= (uint8_t)(1u + (unsigned)(test_random(&seed) * 254.0f));
        }
        write_file(bad, copy, size);
        refused += (uint32_t)refused_or_same(bad, original, pages);
    }
    printf("%u truncations refused; %u of %u damaged copies refused, the rest read as the original\n", truncations,
           refused, flips);
    CHECK(refused * 10 > flips * 9); /* nearly every byte is under a checksum that some read checks */
    free(copy);
    gdr_scene_destroy(original);
    gdr_paged_cache_close(pages);
}

/* What 'CLGR' gives a scene read for streaming, against the clusters it was written from: the groups,
 * each group's cluster bounds (the enclosing sphere of its clusters' spheres, to the bit), its
 * refinements (refined groups in order of first use, with their clusters) and the size classes. */
static void check_groups_from_clusters(const gdr_scene *scene, const char *path)
{
    gdr_error err = {0};
    gdr_scene *s = NULL;
    CHECK(gdr_cache_read_for_streaming(path, NULL, &s, NULL, NULL, &err) == GDR_OK && s);
    uint32_t wrong = 0, refinements = 0;
    for (uint32_t m = 0; s && m < scene->mesh_count; m++) {
        const gdr_mesh_clusters *c = &scene->meshes[m].clusters, *r = &s->meshes[m].clusters;
        uint32_t classes[GDR_CLUSTER_SIZE_CLASSES] = {0}, k = 0;
        for (uint32_t i = 0; i < c->cluster_count; i++)
            classes[gdr_cluster_size_class(c->clusters[i].vertex_count, c->clusters[i].triangle_count)]++;
        wrong += memcmp(classes, r->size_classes, sizeof classes) != 0;
        wrong += memcmp(c->groups, r->groups, sizeof *c->groups * c->group_count) != 0;
        for (uint32_t g = 0; g < c->group_count; g++) {
            const gdr_cluster_group *gr = &c->groups[g];
            gdr_vec4 spheres[256];
            uint32_t refined[256], counts[256], n = 0;
            for (uint32_t i = 0; i < gr->cluster_count && i < 256; i++) {
                const gdr_cluster *cl = &c->clusters[gr->first_cluster + i];
                spheres[i] = cl->sphere;
                uint32_t j = 0;
                while (j < n && refined[j] != cl->refined_group)
                    j++;
                if (cl->refined_group != GDR_NO_INDEX && j == n)
                    refined[n] = cl->refined_group, counts[n++] = 0;
                if (cl->refined_group != GDR_NO_INDEX)
                    counts[j]++;
            }
            gdr_vec4 bounds = gdr_lod_enclosing_sphere(spheres, gr->cluster_count < 256 ? gr->cluster_count : 256);
            wrong += memcmp(&bounds, &r->group_bounds[g], sizeof bounds) != 0;
            for (uint32_t j = 0; j < n; j++, k++)
                wrong += k >= r->refinement_count || r->refinements[k].group != g ||
                         r->refinements[k].refined_group != refined[j] || r->refinements[k].cluster_count != counts[j];
        }
        wrong += k != r->refinement_count;
        refinements += r->refinement_count;
    }
    printf("CLGR against the clusters: %u refinements, %u differences\n", refinements, wrong);
    CHECK(s && refinements > 0 && wrong == 0);
    gdr_scene_destroy(s);
}

int main(void)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_load("unique-field:meshes=3,triangles=3000,seed=4", &(gdr_load_options){.no_progress = 1},
                         &scene, &err) == GDR_OK);
    CHECK(scene && gdr_scene_quantize_vertices(scene, &err) == GDR_OK);
    if (!scene)
        return test_finish("test_cache_pages_only");
    char only[1024], full[1024], bad[1024];
    snprintf(only, sizeof only, "%s/pages-only.gdrc", GDR_IO_TEST_TMP);
    snprintf(full, sizeof full, "%s/pages-full.gdrc", GDR_IO_TEST_TMP);
    snprintf(bad, sizeof bad, "%s/pages-only-bad.gdrc", GDR_IO_TEST_TMP);
    gdr_source_list none = {0};
    gdr_cache_write_options write = {.source = {gdr_cache_build_options(), &none}, .page_bytes = 16u << 10};
    gdr_cache_write_options whole = write;
    whole.whole_geometry = 1;
    CHECK(gdr_cache_write(only, scene, &write, &err) == GDR_OK);
    CHECK(gdr_cache_write(full, scene, &whole, &err) == GDR_OK);
    check_groups_from_clusters(scene, only);
    gdr_scene_destroy(scene);
    size_t only_size = 0, full_size = 0;
    uint8_t *only_bytes = test_read_file(only, &only_size), *full_bytes = test_read_file(full, &full_size);
    CHECK(only_bytes && full_bytes);
    if (only_bytes && full_bytes) {
        check_sections(only_bytes, only_size, full_bytes, full_size);
        check_streamed(only, full);
        check_whole_refused(only);
        check_header_edits(bad, only_bytes, only_size, full_bytes, full_size);
        check_damage(only, bad, only_bytes, only_size);
    }
    free(only_bytes);
    free(full_bytes);
    remove(bad);
    return test_finish("test_cache_pages_only");
}
