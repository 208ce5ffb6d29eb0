/* The root of each mesh's LOD DAG: how many clusters and triangles it keeps and the DAG's depth, and
 * how many meshes reach a single root cluster.
 * usage: lod_roots FILE (imported without the cache) */
#include <math.h>
#include <stdio.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/scene.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: lod_roots FILE\n");
        return 2;
    }
    gdr_load_options options = {.no_cache = 1, .no_progress = 1};
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    if (gdr_scene_load(argv[1], &options, &scene, &err) != GDR_OK) {
        fprintf(stderr, "lod_roots: %s: %s\n", argv[1], err.message);
        return 1;
    }
    uint32_t single = 0, built = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
        if (!c->group_count)
            continue;
        const gdr_cluster_group *root = &c->groups[c->group_count - 1];
        uint32_t triangles = 0;
        for (uint32_t i = 0; i < root->cluster_count; i++)
            triangles += c->clusters[root->first_cluster + i].triangle_count;
        printf("mesh %u: %u triangles, root %u clusters, %u triangles, depth %u\n", m,
               scene->meshes[m].index_count / 3, root->cluster_count, triangles, c->dag_depth);
        built++;
        single += root->cluster_count == 1;
    }
    printf("meshes with a DAG: %u, single root cluster: %u\n", built, single);
    gdr_scene_destroy(scene);
    return 0;
}
