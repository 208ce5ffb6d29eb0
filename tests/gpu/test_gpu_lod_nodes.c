/* The LOD hierarchy on the GPU: after gdr_renderer_set_scene the node pool (read back from the
 * device; lavapipe in CI) holds every mesh's gdr_lod_node array byte for byte with a culling sphere
 * per node that holds what is below it, and each mesh's
 * GdrGpuMesh (as uploaded) names its range and level count. Validation on: no message. */
#include <string.h>

#include "gdr/io.h"
#include "gpu_test_util.h"
#include "render/renderer_internal.h"

static const void *read_back(gdr_renderer *r, VkBuffer buffer, VkDeviceSize size, gdr_vk_buffer *copy)
{
    gdr_error err = {0};
    if (gdr_vk_buffer_read_back(&r->allocator, buffer, 0, size, copy, &err) != GDR_OK) {
        fprintf(stderr, "read back: %s\n", err.message);
        return NULL;
    }
    return copy->mapped;
}

static bool sphere_inside(gdr_vec4 inner, gdr_vec4 outer)
{
    gdr_vec3 d = {inner.x - outer.x, inner.y - outer.y, inner.z - outer.z};
    return gdr_vec3_length(d) + inner.w <= outer.w * (1.0f + 1e-5f) + 1e-6f;
}

/* Each node's gdr_lod_node bytes as they are; its culling sphere holds its clusters' (leaf) or its
 * children's culling spheres (inner node). */
static bool same_nodes(const GdrGpuLodNode *gpu, const gdr_mesh_clusters *c)
{
    for (uint32_t n = 0; n < c->lod_node_count; n++) {
        const gdr_lod_node *node = &c->lod_nodes[n];
        if (memcmp(&gpu[n], node, sizeof *node) != 0)
            return false;
        for (uint32_t i = 0; i < node->count; i++) {
            bool leaf = node->flags & GDR_LOD_NODE_LEAF;
            gdr_vec4 child = leaf ? c->clusters[node->first + i].sphere : gpu[node->first + i].bounds;
            if (!sphere_inside(child, gpu[n].bounds)) {
                fprintf(stderr, "node %u child %u (%s) outside: %g %g %g %g in %g %g %g %g\n", n, i, leaf ? "cluster" : "node",
                        child.x, child.y, child.z, child.w, gpu[n].bounds.x, gpu[n].bounds.y, gpu[n].bounds.z, gpu[n].bounds.w);
                return false;
            }
        }
    }
    return true;
}

static void check_scene(const char *spec)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    CHECK(gdr_scene_load(spec, &(gdr_load_options){.no_progress = 1}, &scene, &err) == GDR_OK);
    gdr_renderer *r = scene ? gpu_test_renderer(64, 64, scene) : NULL;
    CHECK(r != NULL);
    if (!r) {
        gdr_scene_destroy(scene);
        return;
    }
    uint64_t total = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++)
        total += scene->meshes[m].clusters.lod_node_count;
    gdr_vk_buffer nodes_copy = {0};
    const GdrGpuLodNode *nodes = read_back(r, r->scene.lod_nodes.buffer, sizeof *nodes * total, &nodes_copy);
    const GdrGpuMesh *meshes = r->scene.cpu_meshes; /* what was uploaded as GdrGpuMesh[] */
    CHECK(nodes != NULL);
    uint32_t bad = 0;
    for (uint32_t m = 0; nodes && m < scene->mesh_count; m++) {
        const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
        const GdrGpuMesh *g = &meshes[m];
        bad += g->lod_node_count != c->lod_node_count || g->lod_node_levels != c->lod_node_levels ||
               (c->cluster_count > 0) != (g->lod_node_count > 0) ||
               (uint64_t)g->lod_node_offset + g->lod_node_count > total ||
               !same_nodes(nodes + g->lod_node_offset, c);
    }
    CHECK(bad == 0);
    CHECK(r->scene.lod_nodes.address != 0);
    printf("%s: %u meshes, %llu LOD nodes on the GPU, %u differ\n", spec, scene->mesh_count,
           (unsigned long long)total, bad);
    gdr_vk_buffer_destroy(r->ctx, &nodes_copy);
    CHECK(r->ctx->validation_messages == 0);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(scene);
}

int main(void)
{
    check_scene("demo:instances=50");
    check_scene("lod-field:instances=4,triangles=4000");
    return test_finish("test_gpu_lod_nodes");
}
