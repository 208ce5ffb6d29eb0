/* Clusters in the .gdrc cache (sections CLUS, CLDT and CLGM): a round trip gives every field and array
 * back bit for bit (LOD groups included) without rebuilding; a cluster section corrupted behind
 * valid checksums is refused with a message naming the file, the section and the record; a
 * version-1 file is refused by version. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cluster_checks.h"
#include "gdr/io.h"
#include "gdr/procedural.h"
#include "gdr/geometry.h"
#include "gdr/scene.h"
#include "io/io_internal.h"
#include "procedural/procedural_meshes.h"
#include "test_util.h"

static uint8_t *read_whole(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *data = malloc((size_t)n + 1);
    *size = fread(data, 1, (size_t)n, f);
    fclose(f);
    return data;
}

static void path_for(char *out, size_t size, const char *label)
{
    snprintf(out, size, "%s/%s.gdrc", GDR_GEOMETRY_TEST_TMP, label);
}

/* Gives mesh `m` a made-up LOD DAG (groups, coarser clusters, a depth), so that every field of
 * gdr_mesh_clusters has data to lose. The shapes are what the format must carry, not a real DAG. */
static void add_fake_dag(gdr_mesh *mesh)
{
    gdr_mesh_clusters *c = &mesh->clusters;
    uint32_t extra = 2, n = c->cluster_count;
    c->clusters = realloc(c->clusters, sizeof(gdr_cluster) * (n + extra));
    for (uint32_t i = 0; i < extra; i++) {
        c->clusters[n + i] = c->clusters[i];
        c->clusters[n + i].refined_group = 0;
        c->clusters[n + i].group = 1;
    }
    for (uint32_t i = 0; i < n; i++)
        c->clusters[i].group = 0;
    c->cluster_count = n + extra;
    c->groups = malloc(sizeof(gdr_cluster_group) * 2);
    c->groups[0] = (gdr_cluster_group){{0.5f, 0.25f, -1.0f, 3.0f}, 0.01f, 0, 0, n};
    c->groups[1] = (gdr_cluster_group){{0.0f, 0.5f, 0.0f, 4.0f}, INFINITY, 1, n, extra};
    c->group_count = 2;
    c->dag_depth = 1;
    gdr_error err = {0};
    CHECK(gdr_mesh_clusters_build_hierarchy(c, &err) == GDR_OK); /* of the made-up DAG */
}

static gdr_scene *make_scene(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create_demo(&(gdr_demo_desc){.instances = 20}, &s, &err) == GDR_OK);
    /* A mesh without triangles and a mesh whose clusters were never built. */
    gdr_vec3 p[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    uint32_t idx[3] = {0, 1, 2};
    CHECK(gdr_scene_add_mesh(s, "empty", p, NULL, NULL, 3, idx, 0, NULL, &err) == GDR_OK);
    CHECK(gdr_scene_add_mesh(s, "unbuilt", p, NULL, NULL, 3, idx, 3, NULL, &err) == GDR_OK);
    add_fake_dag(&s->meshes[1]);
    return s;
}

static void test_round_trip(void)
{
    gdr_scene *s = make_scene();
    char path[1024];
    path_for(path, sizeof path, "clusters");
    gdr_error err = {0};
    CHECK(gdr_cache_write(path, s, &(gdr_cache_write_options){.source = {gdr_cache_build_options(), NULL}}, &err) == GDR_OK);
    gdr_scene *loaded = NULL;
    CHECK(gdr_cache_read(path, gdr_cache_build_options(), &loaded, NULL, &err) == GDR_OK);
    CHECK(loaded && loaded->mesh_count == s->mesh_count);
    for (uint32_t i = 0; loaded && i < s->mesh_count; i++) {
        CHECK(same_clusters(&s->meshes[i].clusters, &loaded->meshes[i].clusters));
        CHECK(same_bytes(s->meshes[i].positions, loaded->meshes[i].positions, 12 * (size_t)s->meshes[i].vertex_count));
        CHECK(same_bytes(s->meshes[i].indices, loaded->meshes[i].indices, 4 * (size_t)s->meshes[i].index_count));
    }
    /* "no groups" stays NULL, as the header promises; the unbuilt mesh comes back unbuilt. */
    CHECK(loaded && loaded->meshes[0].clusters.groups == NULL && loaded->meshes[0].clusters.cluster_count > 0);
    CHECK(loaded && loaded->meshes[s->mesh_count - 1].clusters.cluster_count == 0);
    gdr_scene_destroy(loaded);

    /* Loading the file through gdr_scene_load keeps what the cache holds and builds only what
     * it lacks. */
    loaded = NULL;
    CHECK(gdr_scene_load(path, &(gdr_load_options){.no_progress = 1}, &loaded, &err) == GDR_OK);
    for (uint32_t i = 0; loaded && i + 1 < s->mesh_count; i++)
        CHECK(same_clusters(&s->meshes[i].clusters, &loaded->meshes[i].clusters));
    const gdr_mesh *unbuilt = loaded ? &loaded->meshes[loaded->mesh_count - 1] : NULL;
    CHECK(unbuilt && unbuilt->clusters.cluster_count == 1 && check_cluster_coverage(unbuilt, &unbuilt->clusters));
    gdr_scene_destroy(loaded);
    gdr_scene_destroy(s);
}

/* --- corrupted cluster sections ---------------------------------------------------------------- */

typedef struct section {
    uint8_t *entry; /* its table entry */
    uint8_t *data;
    uint64_t size;
} section;

static section find_section(uint8_t *file, const char *id)
{
    uint32_t count;
    memcpy(&count, file + 16, 4);
    for (uint32_t i = 0; i < count; i++) {
        uint8_t *e = file + 64 + 32 * (size_t)i;
        if (memcmp(e, id, 4) == 0) {
            uint64_t offset, size;
            memcpy(&offset, e + 8, 8);
            memcpy(&size, e + 16, 8);
            return (section){e, file + offset, size};
        }
    }
    return (section){0};
}

/* Recomputes every checksum, so that the reader gets past them to the section parsers. */
static void fix_checksums(uint8_t *file)
{
    uint32_t count;
    memcpy(&count, file + 16, 4);
    for (uint32_t i = 0; i < count; i++) {
        uint8_t *e = file + 64 + 32 * (size_t)i;
        uint64_t offset, size;
        memcpy(&offset, e + 8, 8);
        memcpy(&size, e + 16, 8);
        uint64_t h = gdr_io_hash(file + offset, (size_t)size);
        memcpy(e + 24, &h, 8);
    }
    uint64_t h = gdr_io_hash(file + 64, (size_t)count * 32);
    memcpy(file + 32, &h, 8);
    h = gdr_io_hash(file, 40);
    memcpy(file + 40, &h, 8);
}

static void put32(uint8_t *p, uint32_t v) { memcpy(p, &v, 4); }
static uint32_t get32(const uint8_t *p)
{
    uint32_t v;
    memcpy(&v, p, 4);
    return v;
}

enum { CLUSTER_BYTES = 72, GROUP_BYTES = 48 }; /* docs/CACHE_FORMAT.md: a cluster record in CLDT, a group's in CLGR */
#define NODE(i) (8 + 48 * (i))  /* LODH: node i of the first mesh */

typedef struct corruption {
    const char *what;     /* expected in the message */
    const char *section;  /* "CLUS", "CLGR", "CLDT", "CLGM" or "LODH" */
    uint32_t at;          /* byte offset in the section */
    uint32_t value;       /* written as u32, or as the low byte when byte is set */
    int byte;
} corruption;

/* Applies each corruption to a copy of `good` and expects the reader to refuse it: first by
 * checksum, then, with the checksums recomputed, by the cluster checks with the given message. */
static void run_cases(const uint8_t *good, uint8_t *bad, size_t size, const corruption *cases, size_t count)
{
    gdr_error err = {0};
    for (size_t i = 0; i < count; i++) {
        const corruption *k = &cases[i];
        memcpy(bad, good, size);
        section sec = find_section(bad, k->section);
        CHECK(sec.data != NULL && k->at + 4 <= sec.size);
        if (!sec.data || k->at + 4 > sec.size)
            continue;
        if (k->byte)
            sec.data[k->at] = (uint8_t)k->value;
        else
            put32(sec.data + k->at, k->value);
        gdr_scene *out = NULL;
        CHECK_FAILS(gdr_cache_read_memory(bad, size, "corrupt.gdrc", &out, NULL, &err), err, GDR_ERROR_CORRUPT);
        CHECK(out == NULL);
        fix_checksums(bad);
        CHECK_FAILS(gdr_cache_read_memory(bad, size, "corrupt.gdrc", &out, NULL, &err), err, GDR_ERROR_PARSE);
        CHECK(out == NULL && strncmp(err.message, "corrupt.gdrc: ", 14) == 0);
        CHECK_NAMES(err, k->what); /* each check of the reader, by the record it names and what is wrong */
        gdr_scene_destroy(out);
    }
}

/* The LOD groups' records, on a mesh with a made-up DAG (24 clusters, then 2 groups). */
static void test_group_corruption(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create(&s, &err) == GDR_OK);
    CHECK(gdr_procedural_ground(s, 4.0f, 32, NULL, &err) == GDR_OK);
    CHECK(gdr_scene_build_clusters(s, NULL, &err) == GDR_OK);
    add_fake_dag(&s->meshes[0]);
    char path[1024];
    path_for(path, sizeof path, "corrupt-groups");
    CHECK(gdr_cache_write(path, s, NULL, &err) == GDR_OK);
    size_t size = 0;
    uint8_t *good = read_whole(path, &size), *bad = malloc(size);
    /* CLGR (docs/CACHE_FORMAT.md): 8 size classes, then 48-byte groups, then the refinements: group 1's
     * two clusters were made from group 0, one 12-byte entry. */
    uint32_t g = 4 * 8, f = g + 2 * GROUP_BYTES;
    const corruption cases[] = {
        {"section 'CLGR': mesh 0 group 0: sphere, bounds or error is not a number", "CLGR", g + 16, 0x7fc00000u, 0},
        {"section 'CLGR': mesh 0 group 1: sphere, bounds or error is not a number", "CLGR", g + GROUP_BYTES + 12,
         0xbf800000u, 0},
        {"section 'CLGR': mesh 0 group 0: sphere, bounds or error is not a number", "CLGR", g + 32, 0x7f800000u, 0},
        {"section 'CLGR': mesh 0 group 1: clusters 22 (+3) lie outside the mesh's 24", "CLGR", g + GROUP_BYTES + 28, 3,
         0},
        {"section 'CLGR': mesh 0 group 0: clusters 4294967295 (+22)", "CLGR", g + 24, UINT32_MAX, 0},
        {"section 'CLGR': mesh 0: 1000000000 refinements run past the section", "CLGR", f, 1000000000u, 0},
        {"section 'CLGR': mesh 0 refinement 0: group 1, refined group 1, 2 clusters", "CLGR", f + 8, 1, 0},
        {"section 'CLGR': mesh 0 refinement 0: group 1, refined group 0, 3 clusters", "CLGR", f + 12, 3, 0},
        {"section 'CLGR': mesh 0 refinement 0: group 2, refined group 0", "CLGR", f + 4, 2, 0},
        {"section 'CLDT': mesh 0 cluster 23: group 2 / refined group 0 does not exist (2 groups)", "CLDT",
         23 * CLUSTER_BYTES + 60, 2, 0},
        /* The hierarchy (docs/CACHE_FORMAT.md, LODH): node count, levels, then 48-byte nodes: the root
         * (node 0) over the leaves of group 1 (node 1) and group 0 (node 2). */
        {"section 'LODH': mesh 0: 1000000000 nodes for 24 clusters", "LODH", 0, 1000000000u, 0},
        {"section 'LODH': mesh 0: 2 levels, the mesh says 5", "LODH", 4, 5, 0},
        {"section 'LODH': mesh 0: node 0: does not contain child 1's sphere", "LODH", NODE(0) + 12, 0x3f800000u, 0},
        {"section 'LODH': mesh 0: node 0: error bounds do not contain child 1's", "LODH", NODE(0) + 16, 0, 0},
        {"section 'LODH': mesh 0: node 0: children 7 (+2) are not 1 to 8 nodes after it", "LODH", NODE(0) + 24, 7, 0},
        {"section 'LODH': mesh 0: node 2: group 1 is missing or named twice", "LODH", NODE(2) + 32, 1, 0},
        {"section 'LODH': mesh 0: node 2: does not contain its group 0's sphere or error", "LODH", NODE(2) + 16,
         0x3c000000u, 0},
        {"section 'LODH': mesh 0: node 0: bounds not finite", "LODH", NODE(0), 0x7fc00000u, 0},
    };
    CHECK(s->meshes[0].clusters.cluster_count == 24 && good && bad);
    if (good && bad)
        run_cases(good, bad, size, cases, sizeof cases / sizeof cases[0]);
    free(good);
    free(bad);
    gdr_scene_destroy(s);
}

static void test_corruption(void)
{
    /* One mesh (the ground grid: 22 clusters) keeps the offsets below simple. */
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create(&s, &err) == GDR_OK);
    CHECK(gdr_procedural_ground(s, 4.0f, 32, NULL, &err) == GDR_OK);
    CHECK(gdr_scene_build_clusters(s, NULL, &err) == GDR_OK);
    const gdr_mesh_clusters *c = &s->meshes[0].clusters;
    char path[1024];
    path_for(path, sizeof path, "corrupt");
    CHECK(gdr_cache_write(path, s, NULL, &err) == GDR_OK);
    size_t size = 0;
    uint8_t *good = read_whole(path, &size), *bad = malloc(size);
    CHECK(good != NULL && bad != NULL && c->cluster_count >= 2);
    if (!good || !bad || c->cluster_count < 2)
        return;
    uint32_t vertices_at = 0, triangles_at = 4 * c->vertex_count; /* in CLGM */
    uint32_t c1 = CLUSTER_BYTES; /* cluster 1 */
    char text[2][160];
    snprintf(text[0], sizeof text[0], "section 'CLGM': mesh 0 cluster vertex 3: mesh vertex %u does not exist (%u vertices)",
             s->meshes[0].vertex_count + 5, s->meshes[0].vertex_count);
    snprintf(text[1], sizeof text[1], "section 'CLDT': mesh 0: level-0 clusters hold %u triangles, the mesh %u",
             s->meshes[0].index_count / 3 - 1, s->meshes[0].index_count / 3);
    const corruption cases[] = {
        {"section 'CLDT': mesh 0 cluster 1: 65 vertices and", "CLDT", c1 + 8, 65, 0},
        {"section 'CLDT': mesh 0 cluster 1: 0 vertices and", "CLDT", c1 + 8, 0, 0},
        {"section 'CLDT': mesh 0 cluster 1: ", "CLDT", c1 + 12, 125, 0},
        {"section 'CLDT': mesh 0 cluster 1: triangle bytes at 2 (", "CLDT", c1 + 4, 2, 0},
        {"section 'CLDT': mesh 0 cluster 1: triangle bytes at 4000000000", "CLDT", c1 + 4, 4000000000u, 0},
        {"section 'CLDT': mesh 0 cluster 1: vertices 4294967295..", "CLDT", c1 + 0, UINT32_MAX, 0},
        {"section 'CLDT': mesh 0 cluster 0: bounds are not finite", "CLDT", 16 + 12, 0x7fc00000u, 0},
        {"section 'CLDT': mesh 0 cluster 0: bounds are not finite", "CLDT", 16 + 12, 0xbf800000u, 0}, /* r = -1 */
        {"section 'CLDT': mesh 0 cluster 1: bounds are not finite", "CLDT", c1 + 44, 0x7f800000u, 0}, /* axis */
        {"section 'CLDT': mesh 0 cluster 0: group 0 / refined group 4294967295 does not exist (0 groups)", "CLDT",
         60, 0, 0},
        {"section 'CLDT': mesh 0 cluster 1: group 4294967295 / refined group 7 does not exist", "CLDT", c1 + 64, 7, 0},
        {"section 'CLGM': mesh 0 cluster 0 triangle 0: local vertex 200, the cluster has", "CLGM", triangles_at, 200, 1},
        {text[0], "CLGM", vertices_at + 12, s->meshes[0].vertex_count + 5, 0},
        {text[1], "CLDT", 12, c->clusters[0].triangle_count - 1, 0},
        {"section 'CLUS': mesh 0: 22 clusters (23 of level 0)", "CLUS", 4, c->cluster_count + 1, 0},
        {"section 'CLUS': mesh 0: 0 clusters (22 of level 0)", "CLUS", 0, 0, 0},
        {"section 'CLUS': mesh 0: 22 clusters (0 of level 0)", "CLUS", 4, 0, 0},
        {"section 'CLGR': mesh 0: its size classes hold 22 clusters, the mesh 1000000000", "CLUS", 0, 1000000000u, 0},
        {"section 'CLGR': mesh 0: 1 groups run past the section", "CLUS", 16, 1, 0},
        {"section 'CLGR': mesh 0: its size classes hold 23 clusters, the mesh 22", "CLGR", 0, 1, 0}, /* none of size 1 */
        {"section 'CLDT': mesh 0 cluster 21: vertices", "CLUS", 8, c->vertex_count - 1, 0},
        {"section 'CLDT': mesh 0 cluster 21: triangle bytes at", "CLUS", 12, c->triangle_byte_count - 4, 0},
    };
    CHECK(c->cluster_count == 22);
    run_cases(good, bad, size, cases, sizeof cases / sizeof cases[0]);
    /* A cluster section is required: renamed to an unknown optional id, it is missing. */
    memcpy(bad, good, size);
    section sec = find_section(bad, "CLDT");
    memcpy(sec.entry, "CLDX", 4);
    put32(sec.entry + 4, 0);
    fix_checksums(bad);
    gdr_scene *out = NULL;
    CHECK_FAILS(gdr_cache_read_memory(bad, size, "corrupt.gdrc", &out, NULL, &err), err, GDR_ERROR_PARSE);
    CHECK_NAMES(err, "corrupt.gdrc: section 'CLDT'");
    /* A version-1 file (no clusters) is refused by version: rebuilt by the loader. */
    memcpy(bad, good, size);
    put32(bad + 8, 1);
    fix_checksums(bad);
    CHECK_FAILS(gdr_cache_read_memory(bad, size, "corrupt.gdrc", &out, NULL, &err), err, GDR_ERROR_UNSUPPORTED);
    /* The untouched file still reads, and the edits above really did go through the parser. */
    CHECK(gdr_cache_read_memory(good, size, "corrupt.gdrc", &out, NULL, &err) == GDR_OK);
    CHECK(out && same_clusters(&out->meshes[0].clusters, c));
    CHECK(get32(find_section(good, "CLUS").data) == c->cluster_count);
    gdr_scene_destroy(out);
    free(good);
    free(bad);
    gdr_scene_destroy(s);
}

int main(void)
{
    test_round_trip();
    test_corruption();
    test_group_corruption();
    return test_finish("test_cluster_cache");
}
