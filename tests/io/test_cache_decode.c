/* The cluster records (CLDT) and hierarchies (LODH) decoded on several threads (src/io/cache_decode.c)
 * give the scene the serial decode gives, and a damaged file the same refusal:
 * - five meshes of `unique-field` written whole and read back from memory with one thread and with
 *   four: every mesh's counts, clusters, groups and hierarchy nodes byte for byte equal, and equal to
 *   those written;
 * - records damaged in meshes 1 and 3 (a cluster of no vertices, checksums made right again): both
 *   decodes refuse the file naming mesh 1, the first in mesh order, with the same message; damaged
 *   in mesh 3 alone, both name mesh 3; likewise a hierarchy node whose children lie past the mesh's
 *   nodes in meshes 1 and 3, then 3. */
#include <stdlib.h>
#include <string.h>


#include "cache_checksums.h"

#include "gdr/io.h"
#include "io/cache_decode.h"
#include "io/loaders.h"
#include "test_util.h"

#define CLUSTER_RECORD 72 /* bytes of a cluster's record in CLDT (docs/CACHE_FORMAT.md) */
#define NODE_RECORD 48    /* bytes of a hierarchy node's in LODH, after each mesh's 8 bytes of counts */

static uint8_t *read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    CHECK(f != NULL);
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    *size = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *data = malloc(*size);
    CHECK(data && fread(data, 1, *size, f) == *size);
    fclose(f);
    return data;
}


static uint64_t section_offset(const uint8_t *data, const char *id)
{
    uint32_t count;
    memcpy(&count, data + 16, 4);
    for (uint32_t i = 0; i < count; i++)
        if (memcmp(data + 64 + (size_t)i * 32, id, 4) == 0) {
            uint64_t offset;
            memcpy(&offset, data + 64 + (size_t)i * 32 + 8, 8);
            return offset;
        }
    CHECK(!"section present");
    return 0;
}

static gdr_status read_with(uint32_t threads, const uint8_t *data, size_t size, gdr_scene **out, gdr_error *err)
{
    cache_set_decode_threads(threads);
    gdr_status status = gdr_cache_read_memory(data, size, "u.gdrc", out, NULL, err);
    cache_set_decode_threads(0);
    return status;
}

static int same_clusters(const gdr_mesh_clusters *a, const gdr_mesh_clusters *b)
{
    return a->cluster_count == b->cluster_count && a->group_count == b->group_count &&
           a->level0_cluster_count == b->level0_cluster_count && a->dag_depth == b->dag_depth &&
           memcmp(a->clusters, b->clusters, sizeof *a->clusters * a->cluster_count) == 0 &&
           memcmp(a->groups, b->groups, sizeof *a->groups * a->group_count) == 0 &&
           a->lod_node_count == b->lod_node_count && a->lod_node_levels == b->lod_node_levels &&
           memcmp(a->lod_nodes, b->lod_nodes, sizeof *a->lod_nodes * a->lod_node_count) == 0;
}

static void test_equal(const gdr_scene *written, const uint8_t *data, size_t size)
{
    gdr_error err = {0};
    gdr_scene *serial = NULL, *parallel = NULL;
    CHECK(read_with(1, data, size, &serial, &err) == GDR_OK);
    CHECK(read_with(4, data, size, &parallel, &err) == GDR_OK);
    uint32_t equal = 0;
    for (uint32_t m = 0; serial && parallel && m < written->mesh_count; m++)
        equal += same_clusters(&serial->meshes[m].clusters, &parallel->meshes[m].clusters) &&
                 same_clusters(&written->meshes[m].clusters, &parallel->meshes[m].clusters);
    printf("%u of %u meshes decode alike on 1 and 4 threads\n", equal, written->mesh_count);
    CHECK(equal == written->mesh_count);
    gdr_scene_destroy(serial);
    gdr_scene_destroy(parallel);
}

/* A copy of the file with the first cluster of each mesh in `meshes` given no vertices (in CLDT), or
 * its first hierarchy node children past the mesh's nodes (in LODH). */
static uint8_t *damaged(const gdr_scene *s, const uint8_t *data, size_t size, const uint32_t *meshes, uint32_t n,
                        const char *section)
{
    uint8_t *copy = malloc(size);
    memcpy(copy, data, size);
    int cldt = strcmp(section, "CLDT") == 0;
    uint64_t start = section_offset(copy, section);
    for (uint32_t k = 0; k < n; k++) {
        uint64_t at = start;
        for (uint32_t m = 0; m < meshes[k]; m++) {
            const gdr_mesh_clusters *c = &s->meshes[m].clusters;
            at += cldt ? (uint64_t)c->cluster_count * CLUSTER_RECORD
                       : 8 + (uint64_t)c->lod_node_count * NODE_RECORD;
        }
        if (cldt) {
            memset(copy + at + 8, 0, 4); /* vertex_count */
        } else {
            uint32_t past = s->meshes[meshes[k]].clusters.lod_node_count + 7;
            memcpy(copy + at + 8 + 24, &past, 4); /* node 0's first child */
        }
    }
    test_cache_fix_checksums(copy, size);
    return copy;
}

static void test_refused(const gdr_scene *s, const uint8_t *data, size_t size, const uint32_t *meshes, uint32_t n,
                         const char *section, const char *expect)
{
    uint8_t *copy = damaged(s, data, size, meshes, n, section);
    gdr_error serial = {0}, parallel = {0};
    gdr_scene *out = NULL;
    CHECK(read_with(1, copy, size, &out, &serial) == GDR_ERROR_PARSE && !out);
    CHECK(read_with(4, copy, size, &out, &parallel) == GDR_ERROR_PARSE && !out);
    printf("serial:   %s\nparallel: %s\n", serial.message, parallel.message);
    CHECK(strcmp(serial.message, parallel.message) == 0);
    CHECK(strstr(parallel.message, expect) != NULL);
    free(copy);
}

int main(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load("unique-field:meshes=5,triangles=8000,seed=11", &load, &scene, &err) == GDR_OK);
    char path[1024];
    snprintf(path, sizeof path, "%s/test_cache_decode.gdrc", GDR_IO_TEST_TMP);
    CHECK(scene && gdr_cache_write(path, scene, NULL, &err) == GDR_OK);
    size_t size = 0;
    uint8_t *data = scene ? read_file(path, &size) : NULL;
    if (data) {
        test_equal(scene, data, size);
        const uint32_t both[] = {1, 3}, last[] = {3};
        test_refused(scene, data, size, both, 2, "CLDT", "'CLDT': mesh 1 cluster 0");
        test_refused(scene, data, size, last, 1, "CLDT", "'CLDT': mesh 3 cluster 0");
        test_refused(scene, data, size, both, 2, "LODH", "'LODH': mesh 1:");
        test_refused(scene, data, size, last, 1, "LODH", "'LODH': mesh 3:");
    }
    free(data);
    remove(path);
    gdr_scene_destroy(scene);
    return test_finish("test_cache_decode");
}
