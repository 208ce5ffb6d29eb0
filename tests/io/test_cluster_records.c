/* The cluster records (GdrGpuMeshlet) filled in parallel chunks (src/render/cluster_records.c, the
 * renderer's set-up) are byte for byte the records built one by one in order: on the meshes of a
 * small `unique-field` with a mesh without clusters between them (first records shared), with the
 * offsets of a whole upload and of a streamed one (0), for chunks of one cluster, of a few (ranges
 * that span meshes), of about a mesh and of more than the whole, with and without a thread pool.
 * The hierarchy nodes' records (GdrGpuLodNode) filled a mesh a task on four threads are byte for
 * byte those filled in order on one, each beginning with its gdr_lod_node's bytes. */
#include <stdlib.h>
#include <string.h>

#include "gdr/io.h"
#include "gpu_shared/raster_bin.h"
#include "render/cluster_records.h"
#include "test_util.h"

#define MESHES 4 /* three of the scene's, an empty one second */

/* The records one by one, in mesh order: what the renderer built before the chunks. */
static void fill_serial(GdrGpuMeshlet *out, const gdr_cluster_record_layout *l)
{
    for (uint32_t m = 0; m < l->mesh_count; m++)
        for (uint32_t i = 0; i < l->clusters[m]->cluster_count; i++) {
            out[l->first[m] + i] = gdr_cluster_record(l->clusters[m], i, l->vertex_base[m], l->byte_base[m]);
            out[l->first[m] + i].cluster_id = l->first[m] + i;
        }
}

static int check_layout(const gdr_cluster_record_layout *l, uint32_t total, gdr_thread_pool *pool)
{
    size_t bytes = sizeof(GdrGpuMeshlet) * total;
    GdrGpuMeshlet *want = calloc(total, sizeof *want), *got = calloc(total, sizeof *got);
    CHECK(want && got);
    fill_serial(want, l);
    const uint32_t chunks[] = {1, 7, 333, 5000, total + 100};
    int differ = 0;
    for (size_t k = 0; k < sizeof chunks / sizeof *chunks; k++) {
        for (int with_pool = 0; with_pool < 2; with_pool++) {
            memset(got, 0, bytes); /* as the renderer allocates them; a record left unwritten differs */
            gdr_cluster_records_fill(got, l, chunks[k], with_pool ? pool : NULL);
            if (memcmp(got, want, bytes) != 0) {
                uint32_t first_bad = 0;
                while (memcmp(&got[first_bad], &want[first_bad], sizeof *got) == 0)
                    first_bad++;
                fprintf(stderr, "chunk %u, %s: record %u of %u differs\n", chunks[k], with_pool ? "pool" : "serial",
                        first_bad, total);
                differ++;
            }
        }
    }
    free(want);
    free(got);
    return differ;
}

static void check_nodes(const gdr_mesh_clusters *const *clusters, uint32_t mesh_count, gdr_thread_pool *pool)
{
    uint32_t first[MESHES], total = 0;
    for (uint32_t m = 0; m < mesh_count; m++) {
        first[m] = total;
        total += clusters[m]->lod_node_count;
    }
    GdrGpuLodNode *serial = calloc(total, sizeof *serial), *parallel = calloc(total, sizeof *parallel);
    CHECK(serial && parallel && total > 0);
    if (!serial || !parallel)
        return;
    gdr_lod_node_records_fill(serial, clusters, first, mesh_count, NULL);
    gdr_lod_node_records_fill(parallel, clusters, first, mesh_count, pool);
    uint32_t differ = 0, copied = 0;
    for (uint32_t m = 0; m < mesh_count; m++)
        for (uint32_t n = 0; n < clusters[m]->lod_node_count; n++) {
            differ += memcmp(&serial[first[m] + n], &parallel[first[m] + n], sizeof *serial) != 0;
            copied += memcmp(&parallel[first[m] + n], &clusters[m]->lod_nodes[n], sizeof(gdr_lod_node)) == 0;
        }
    printf("%u hierarchy nodes: %u differ between one thread and four, %u begin with their node\n", total, differ,
           copied);
    CHECK(differ == 0 && copied == total);
    free(serial);
    free(parallel);
}

/* The tiny raster classes of a streamed scene come from its clusters' size classes (its records are
 * in the pages): every cluster size has the tiny class of its size class's upper bound. */
static void check_size_classes(void)
{
    uint32_t wrong = 0;
    for (uint32_t v = 1; v <= GDR_CLUSTER_MAX_VERTICES; v++)
        for (uint32_t t = 1; t <= GDR_CLUSTER_MAX_TRIANGLES; t++) {
            uint32_t b = gdr_cluster_size_class(v, t), size = v > t ? v : t;
            wrong += gdr_raster_tiny_class(v, t) != gdr_raster_tiny_class(1u << b, 1u << b);
            wrong += size > (1u << b) || (b > 0 && size <= (1u << (b - 1)));
        }
    printf("size classes: %u of %u cluster sizes in the wrong class\n", wrong,
           GDR_CLUSTER_MAX_VERTICES * GDR_CLUSTER_MAX_TRIANGLES);
    CHECK(wrong == 0);
}

int main(void)
{
    check_size_classes();
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load("unique-field:meshes=3,triangles=20000,seed=7", &load, &scene, &err) == GDR_OK);
    CHECK(scene->mesh_count == 3);
    gdr_mesh_clusters empty = {0};
    const gdr_mesh_clusters *clusters[MESHES] = {&scene->meshes[0].clusters, &empty, &scene->meshes[1].clusters,
                                                 &scene->meshes[2].clusters};
    uint32_t first[MESHES], vertex_base[MESHES], byte_base[MESHES], zeros[MESHES] = {0};
    uint32_t total = 0, vertices = 0, bytes = 0;
    for (uint32_t m = 0; m < MESHES; m++) {
        first[m] = total;
        vertex_base[m] = vertices;
        byte_base[m] = bytes;
        total += clusters[m]->cluster_count;
        vertices += clusters[m]->vertex_count;
        bytes += clusters[m]->triangle_byte_count;
    }
    CHECK(total > 3 * 333 && clusters[0]->cluster_count > 7);
    gdr_thread_pool *pool = NULL;
    CHECK(gdr_thread_pool_create(4, &pool, &err) == GDR_OK);
    gdr_cluster_record_layout whole = {clusters, first, vertex_base, byte_base, MESHES};
    gdr_cluster_record_layout streamed = {clusters, first, zeros, zeros, MESHES};
    int differ = check_layout(&whole, total, pool) + check_layout(&streamed, total, pool);
    printf("%u clusters in %u meshes: %d fills of 20 differ from the serial records\n", total, MESHES, differ);
    CHECK(differ == 0);
    check_nodes(clusters, MESHES, pool);
    gdr_thread_pool_destroy(pool);
    gdr_scene_destroy(scene);
    return test_finish("test_cluster_records");
}
