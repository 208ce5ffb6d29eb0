/* What the fuzz targets do with a scene that loaded: what gdr does next, meshlets and the LOD DAG
 * of every mesh, where hostile numbers do their damage. Budgets are small so that every input
 * runs in milliseconds; a build may fail (with a message), never crash or hang. */
#ifndef GDR_FUZZ_GEOMETRY_H
#define GDR_FUZZ_GEOMETRY_H

#include <stdint.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/scene.h"

static const gdr_budget fuzz_budget = {.triangles = 20000, .instances = 4096, .texture_pixels = 1u << 20,
                                       .decoded_bytes = 8u << 20};

static void fuzz_build_geometry(gdr_scene *scene)
{
    gdr_lod_options options = {.thread_count = 1, .no_progress = 1};
    gdr_error err = {0};
    if (gdr_scene_build_lod(scene, &options, NULL, &err) != GDR_OK) {
        if (!err.message[0])
            __builtin_trap(); /* a failure must say why */
        return;
    }
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
        if (scene->meshes[m].index_count && !c->cluster_count)
            __builtin_trap(); /* a mesh with triangles must have clusters */
        for (uint32_t k = 0; k < c->cluster_count; k++)
            if (c->clusters[k].triangle_count == 0 || c->clusters[k].triangle_count > GDR_CLUSTER_MAX_TRIANGLES ||
                c->clusters[k].vertex_count > GDR_CLUSTER_MAX_VERTICES)
                __builtin_trap();
    }
}

#endif
