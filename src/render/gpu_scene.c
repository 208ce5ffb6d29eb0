/* The GPU scene: one geometry pool (merged vertex and index buffers, seed 003 plan A) and the
 * persistent instance buffer, with per-frame resources sized from the scene so they cannot overflow. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h" /* gdr_lod_enclosing_sphere */
#include "gpu_shared/point_level.h"
#include "gpu_shared/raster_bin.h"
#include "render/renderer_internal.h"
#include "render/cluster_records.h"
#include "render/frame.h"
#include "render/gpu_scene.h"
#include "render/page_table.h"
#include "render/root_shortcut.h"
#include "render/streaming.h"

static GdrGpuInstance gpu_instance_from(const gdr_scene *scene, const gdr_instance *instance)
{
    /* The material's factors and textures are applied by the shaders (shared/material.h); instances
     * without one take the default material the material buffer appends after the scene's. */
    bool has_material = instance->material < scene->material_count;
    return (GdrGpuInstance){.model = instance->transform, .color = instance->color, .mesh = instance->mesh,
                            .material = has_material ? instance->material : scene->material_count,
                            .min_screen_size = instance->min_screen_size,
                            .max_screen_size = instance->max_screen_size};
}

/* The clusters of every mesh: the scene's own, or built here for meshes that have none (a scene
 * assembled through the API). built[m] holds what was built and is freed by the caller. */
/* Every mesh's clusters, which the scene must bring: uploading never builds geometry (that is the
 * geometry module's, run by gdr_scene_load or the caller). A mesh with triangles and no clusters is
 * refused. */
static gdr_status gather_clusters(const gdr_scene *scene, const gdr_mesh_clusters **clusters, gdr_error *err)
{
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh *mesh = &scene->meshes[m];
        if (mesh->clusters.cluster_count == 0 && mesh->index_count > 0)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "scene upload: mesh %u '%s' has no clusters: build "
                                 "them first (gdr_scene_build_clusters or gdr_scene_build_lod, gdr/geometry.h; "
                                 "gdr_scene_load does)", m, mesh->name);
        clusters[m] = &mesh->clusters;
    }
    return GDR_OK;
}

/* The clusters of each mesh per tiny size class (raster_bin.h), GDR_SW_TINY_CLASSES + 1 counts per
 * mesh, the last the clusters of no class: the tiny classes' counts size their parts of the
 * visible-cluster list. From the records, or (meshlets NULL: streamed, the records are in the pages)
 * from the clusters, or where the scene was read for streaming without them, from the meshes' size
 * classes, whose bounds are powers of two as the tiny classes' are. */
_Static_assert((GDR_SW_TINY_LANES & (GDR_SW_TINY_LANES - 1)) == 0, "tiny classes bounded by powers of two");
static uint32_t *count_tiny_clusters(uint32_t mesh_count, const GdrGpuMesh *meshes, const GdrGpuMeshlet *meshlets,
                                     const gdr_mesh_clusters *const *clusters)
{
    const uint32_t stride = GDR_SW_TINY_CLASSES + 1;
    uint32_t *tiny = calloc((size_t)(mesh_count ? mesh_count : 1) * stride, sizeof *tiny);
    for (uint32_t m = 0; m < mesh_count && tiny && !meshlets; m++) {
        const gdr_mesh_clusters *c = clusters[m];
        for (uint32_t i = 0; c->clusters && i < c->cluster_count; i++) /* a scene loaded whole, streamed */
            tiny[m * stride + gdr_raster_tiny_class(c->clusters[i].vertex_count, c->clusters[i].triangle_count)]++;
        for (uint32_t b = 0; !c->clusters && b < GDR_CLUSTER_SIZE_CLASSES; b++) /* (2^(b-1), 2^b]: one class */
            tiny[m * stride + gdr_raster_tiny_class(1u << b, 1u << b)] += c->size_classes[b];
    }
    for (uint32_t m = 0; m < mesh_count && tiny && meshlets; m++)
        for (uint32_t i = 0; i < meshes[m].lod_cluster_count; i++) {
            const GdrGpuMeshlet *k = &meshlets[meshes[m].meshlet_offset + i];
            tiny[m * stride + gdr_raster_tiny_class(k->vertex_count, k->triangle_count)]++;
        }
    return tiny;
}

#define RECORD_CHUNK 16384u /* clusters a task: 2 MiB of records */

/* The records of every cluster (cluster_records.c): mesh m's from the sum of the clusters, vertex
 * references and triangle bytes before it (those offsets 0 when streamed: the pages set them). */
static gdr_status fill_records(uint32_t mesh_count, const gdr_mesh_clusters *const *clusters, bool streamed,
                               GdrGpuMeshlet *out, gdr_thread_pool *pool, gdr_error *err)
{
    size_t n = mesh_count ? mesh_count : 1;
    uint32_t *first = malloc(3 * sizeof *first * n);
    if (!first)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene upload: out of memory");
    uint32_t *vertex_base = first + n, *byte_base = first + 2 * n;
    uint32_t records = 0, vertices = 0, bytes = 0;
    for (uint32_t m = 0; m < mesh_count; m++) {
        first[m] = records;
        vertex_base[m] = streamed ? 0 : vertices;
        byte_base[m] = streamed ? 0 : bytes;
        records += clusters[m]->cluster_count;
        vertices += clusters[m]->vertex_count;
        bytes += clusters[m]->triangle_byte_count;
    }
    gdr_cluster_record_layout layout = {clusters, first, vertex_base, byte_base, mesh_count};
    gdr_cluster_records_fill(out, &layout, RECORD_CHUNK, pool);
    free(first);
    return GDR_OK;
}

/* The set-up's threads, one per processor, where the scene has enough clusters to gain from them;
 * NULL (the work done on this thread, the same bytes) otherwise or without threads. */
static gdr_thread_pool *setup_pool(const gdr_mesh_clusters *const *clusters, uint32_t mesh_count)
{
    uint64_t records = 0;
    for (uint32_t m = 0; m < mesh_count; m++)
        records += clusters[m]->cluster_count;
    return gdr_thread_pool_create_if(records >= 2 * RECORD_CHUNK);
}

/* Each mesh's cluster fields, offsets and root shortcut; whole (not streamed): its vertex references
 * and triangle bytes packed into words at the pool's offsets. */
static void pack_meshes(gdr_gpu_scene *g, uint32_t mesh_count, const gdr_mesh_clusters *const *clusters,
                        uint32_t *vertex_refs, uint32_t *words)
{
    uint32_t meshlet_cursor = 0, vertex_cursor = 0, byte_cursor = 0;
    for (uint32_t m = 0; m < mesh_count; m++) {
        const gdr_mesh_clusters *c = clusters[m];
        GdrGpuMesh *mesh = &g->cpu_meshes[m];
        mesh->meshlet_offset = meshlet_cursor;
        mesh->meshlet_count = c->level0_cluster_count;
        mesh->task_count = (c->level0_cluster_count + GDR_TASK_WORKGROUP_SIZE - 1) / GDR_TASK_WORKGROUP_SIZE;
        mesh->lod_cluster_count = c->cluster_count;
        mesh->lod_task_count = (c->cluster_count + GDR_TASK_WORKGROUP_SIZE - 1) / GDR_TASK_WORKGROUP_SIZE;
        if (c->group_count > 0 && !g->streamed) /* streamed: when its page 0 arrives (streaming.c) */
            gdr_root_shortcut_set(c, gdr_cluster_refined_of_clusters, c, mesh);
        meshlet_cursor += c->cluster_count;
        if (g->streamed)
            continue;
        for (uint32_t v = 0; v < c->vertex_count; v++)
            vertex_refs[vertex_cursor + v] = mesh->vertex_offset + c->vertices[v];
        for (uint32_t b = 0; b < c->triangle_byte_count; b++) {
            uint32_t at = byte_cursor + b;
            words[at / 4] |= (uint32_t)c->triangles[b] << (8 * (at % 4));
        }
        vertex_cursor += c->vertex_count;
        byte_cursor += c->triangle_byte_count;
    }
}

/* The clusters every instance brings (level 0, the whole DAG, the tiny classes), for statistics and
 * the task capacity. */
static gdr_status count_instance_clusters(gdr_gpu_scene *g, const gdr_scene *scene, const GdrGpuMeshlet *meshlets,
                                          const gdr_mesh_clusters *const *clusters, gdr_error *err)
{
    uint64_t instance_meshlets = 0, instance_lod_clusters = 0, instance_tiny[GDR_SW_TINY_CLASSES] = {0};
    uint32_t *tiny = count_tiny_clusters(scene->mesh_count, g->cpu_meshes, meshlets, clusters);
    if (!tiny)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene upload: out of memory");
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        instance_meshlets += g->cpu_meshes[scene->instances[i].mesh].meshlet_count;
        instance_lod_clusters += g->cpu_meshes[scene->instances[i].mesh].lod_cluster_count;
        for (uint32_t k = 0; k < GDR_SW_TINY_CLASSES; k++)
            instance_tiny[k] += tiny[scene->instances[i].mesh * (GDR_SW_TINY_CLASSES + 1) + k];
    }
    free(tiny);
    g->instance_meshlet_count = instance_meshlets;
    g->instance_lod_cluster_count = instance_lod_clusters;
    memcpy(g->instance_tiny_cluster_count, instance_tiny, sizeof instance_tiny);
    return GDR_OK;
}

/* Tests (renderer_debug.h): every record of a streamed scene one that would be drawn wherever it is
 * read, until its page arrives. */
static gdr_status upload_poison_records(gdr_renderer *r, uint64_t count, gdr_error *err)
{
    GdrGpuMeshlet *poison = malloc(sizeof *poison * (count ? count : 1));
    if (!poison)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene upload: out of memory");
    for (uint64_t i = 0; i < count; i++)
        poison[i] = (GdrGpuMeshlet){.sphere = {0.0f, 0.0f, 0.0f, 1.0e30f}, .cone_cutoff = 1.0f,
                                    .group = GDR_GPU_NO_GROUP, .refined_group = GDR_GPU_NO_GROUP, .refined_depth = -1,
                                    .group_sphere = {0.0f, 0.0f, 0.0f, 1.0f}, .refined_sphere = {0.0f, 0.0f, 0.0f, 1.0f},
                                    .group_error = INFINITY, .refined_error = 0.0f};
    gdr_status status = gdr_vk_buffer_upload(r->ctx, &r->staging, &r->scene.meshlets, 0, poison,
                                             sizeof *poison * count, err);
    free(poison);
    return status;
}

/* The cluster pool: GdrGpuMeshlet[] with pool-global offsets, global vertex indices, and the
 * triangle bytes packed into words. Fills the meshes' meshlet fields and the task capacity. */
static gdr_status upload_clusters(gdr_renderer *r, const gdr_scene *scene, const gdr_mesh_clusters *const *clusters,
                                  gdr_thread_pool *pool, gdr_error *err)
{
    gdr_gpu_scene *g = &r->scene;
    uint64_t meshlet_total = 0, vertex_total = 0, byte_total = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        meshlet_total += clusters[m]->cluster_count;
        vertex_total += clusters[m]->vertex_count;
        byte_total += clusters[m]->triangle_byte_count;
    }
    /* Streamed: the clusters' vertex lists and triangles arrive with their pages (streaming.c), which
     * set the records' offsets into the pool's slots; until then no record is drawn (its group is
     * absent). The whole scene's vertex lists and triangles are never in one buffer then: only the
     * records count against the 32-bit offsets. */
    if (g->streamed)
        vertex_total = byte_total = 0;
    if (meshlet_total > UINT32_MAX / 2 || vertex_total > UINT32_MAX / 2 || byte_total > UINT32_MAX / 2)
        return gdr_error_set(err, GDR_ERROR_CAPACITY,
                             "scene: %llu clusters, %llu vertex references, %llu triangle bytes: past the cluster "
                             "pool's 32-bit offsets",
                             (unsigned long long)meshlet_total, (unsigned long long)vertex_total,
                             (unsigned long long)byte_total);
    uint64_t word_total = (byte_total + 3) / 4;
    /* The records' buffer: every cluster's, or streamed, the record pool: each pool slot's room for
     * its page's records. */
    uint64_t record_slots = g->streamed ? (uint64_t)r->stream.slot_count * r->stream.records_per_slot : meshlet_total;
    /* Streamed: no record is uploaded here; a page's arrival writes its clusters' (streaming.c), and
     * the records of absent groups are never read (GDR_FRAME_PAGED_RECORDS). */
    GdrGpuMeshlet *meshlets = g->streamed ? NULL : calloc(meshlet_total ? meshlet_total : 1, sizeof *meshlets);
    uint32_t *vertex_refs = malloc(sizeof(uint32_t) * (vertex_total ? vertex_total : 1));
    uint32_t *words = calloc(word_total ? word_total : 1, sizeof(uint32_t));
    gdr_status status = GDR_OK;
    if ((!meshlets && !g->streamed) || !vertex_refs || !words)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene upload: out of memory");
    if (status == GDR_OK && !g->streamed)
        status = fill_records(scene->mesh_count, clusters, g->streamed, meshlets, pool, err);
    if (status == GDR_OK)
        pack_meshes(g, scene->mesh_count, clusters, vertex_refs, words);
    if (status == GDR_OK)
        status = count_instance_clusters(g, scene, meshlets, clusters, err);
    g->meshlet_count = (uint32_t)meshlet_total;
    const VkBufferUsageFlags usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuMeshlet) * (record_slots ? record_slots : 1), usage,
                                      GDR_VK_BUFFER_DEVICE, &g->meshlets, err);
    if (status == GDR_OK && !g->streamed)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(uint32_t) * (vertex_total ? vertex_total : 1), usage,
                                      GDR_VK_BUFFER_DEVICE, &g->meshlet_vertices, err);
    if (status == GDR_OK && !g->streamed)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(uint32_t) * (word_total ? word_total : 1), usage,
                                      GDR_VK_BUFFER_DEVICE, &g->meshlet_triangles, err);
    if (status == GDR_OK && !g->streamed)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->meshlets, 0, meshlets, sizeof(GdrGpuMeshlet) * meshlet_total, err);
    if (status == GDR_OK && g->streamed && r->debug.poison_absent_records)
        status = upload_poison_records(r, record_slots, err);
    if (status == GDR_OK && !g->streamed)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->meshlet_vertices, 0, vertex_refs,
                                      sizeof(uint32_t) * vertex_total, err);
    if (status == GDR_OK && !g->streamed)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->meshlet_triangles, 0, words, sizeof(uint32_t) * word_total, err);
    if (status == GDR_OK) {
        g->cpu_meshlets = meshlets; /* kept for references and statistics */
        meshlets = NULL;
    }
    free(meshlets);
    free(vertex_refs);
    free(words);
    return status;
}

/* Task commands one instance of mesh `c` can need in a phase: all its clusters (flat), or one run
 * per hierarchy leaf the traversal reaches. */
static uint64_t tasks_per_instance(const gdr_mesh_clusters *c, const GdrGpuMesh *mesh)
{
    uint64_t leaves = 0;
    for (uint32_t n = 0; n < c->lod_node_count; n++)
        if (c->lod_nodes[n].flags & GDR_GPU_LOD_NODE_LEAF)
            leaves += (c->lod_nodes[n].count + GDR_TASK_WORKGROUP_SIZE - 1) / GDR_TASK_WORKGROUP_SIZE;
    return leaves > mesh->lod_task_count ? leaves : mesh->lod_task_count; /* >= task_count, the root's */
}

/* The task list and the traversal's levels: what every instance could need, up to the limits of
 * gpu_config.h (a frame that needs more counts what it drops); render/renderer_debug.h overrides them for tests. */
static void size_queues(gdr_renderer *r, const gdr_scene *scene, const gdr_mesh_clusters *const *clusters)
{
    gdr_gpu_scene *g = &r->scene;
    uint64_t *per_mesh = calloc(scene->mesh_count ? scene->mesh_count : 1, sizeof *per_mesh);
    uint64_t tasks = 0, visits = 0;
    for (uint32_t m = 0; per_mesh && m < scene->mesh_count; m++)
        per_mesh[m] = tasks_per_instance(clusters[m], &g->cpu_meshes[m]);
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        uint32_t m = scene->instances[i].mesh;
        tasks += per_mesh ? per_mesh[m] : GDR_MAX_TASK_COMMANDS;
        visits += g->cpu_meshes[m].lod_node_count;
    }
    free(per_mesh);
    g->task_capacity = (uint32_t)(tasks < GDR_MAX_TASK_COMMANDS ? tasks : GDR_MAX_TASK_COMMANDS);
    g->traversal_capacity = (uint32_t)(visits < GDR_TRAVERSE_MAX_VISITS ? visits : GDR_TRAVERSE_MAX_VISITS);
    if (r->debug.task_capacity)
        g->task_capacity = r->debug.task_capacity;
    if (r->debug.traversal_capacity)
        g->traversal_capacity = r->debug.traversal_capacity;
    g->task_capacity = g->task_capacity ? g->task_capacity : 1;
    g->traversal_capacity = g->traversal_capacity ? g->traversal_capacity : 1;
}

/* The LOD hierarchy pool: every mesh's nodes (gdr_lod_node_records_fill, mesh-local indices), one after another.
 * Fills the meshes' lod_node fields. */
static gdr_status upload_lod_nodes(gdr_renderer *r, const gdr_scene *scene, const gdr_mesh_clusters *const *clusters,
                                   gdr_thread_pool *pool, gdr_error *err)
{
    gdr_gpu_scene *g = &r->scene;
    uint64_t total = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++)
        total += clusters[m]->lod_node_count;
    if (total > UINT32_MAX / 2)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "scene: %llu LOD hierarchy nodes exceed 32-bit offsets",
                             (unsigned long long)total);
    GdrGpuLodNode *nodes = malloc(sizeof *nodes * (total ? total : 1));
    if (!nodes)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene upload: out of memory for %llu LOD nodes",
                             (unsigned long long)total);
    uint32_t *first = malloc(sizeof *first * (scene->mesh_count ? scene->mesh_count : 1));
    if (!first) {
        free(nodes);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene upload: out of memory for %llu LOD nodes",
                             (unsigned long long)total);
    }
    uint32_t cursor = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh_clusters *c = clusters[m];
        first[m] = cursor;
        g->cpu_meshes[m].lod_node_offset = cursor;
        g->cpu_meshes[m].lod_node_count = c->lod_node_count;
        g->cpu_meshes[m].lod_node_levels = c->lod_node_levels;
        /* As drawcull.comp decides: a streamed scene traverses every mesh (GDR_FRAME_PAGED_RECORDS). */
        bool traversed = g->cpu_meshes[m].lod_task_count > GDR_TRAVERSE_MIN_TASKS || g->streamed;
        if (traversed && c->lod_node_levels > g->traversal_levels)
            g->traversal_levels = c->lod_node_levels;
        cursor += c->lod_node_count;
    }
    gdr_lod_node_records_fill(nodes, clusters, first, scene->mesh_count, pool);
    if (g->streamed)
        gdr_streaming_leaves_in_pages(r, nodes, first);
    free(first);
    /* TRANSFER_SRC: tests read the pool back. */
    const VkBufferUsageFlags usage =
        VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    gdr_status status = gdr_vk_buffer_create(&r->allocator, sizeof *nodes * (total ? total : 1), usage,
                                             GDR_VK_BUFFER_DEVICE, &g->lod_nodes, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->lod_nodes, 0, nodes, sizeof *nodes * total, err);
    free(nodes);
    return status;
}

/* The surface area of a mesh's triangles (mesh units squared). */
static float surface_area(const gdr_mesh *mesh)
{
    double area = 0.0;
    for (uint32_t t = 0; t + 2 < mesh->index_count; t += 3) {
        gdr_vec3 a = mesh->positions[mesh->indices[t]], b = mesh->positions[mesh->indices[t + 1]];
        gdr_vec3 c = mesh->positions[mesh->indices[t + 2]];
        gdr_vec3 u = {b.x - a.x, b.y - a.y, b.z - a.z}, v = {c.x - a.x, c.y - a.y, c.z - a.z};
        double x = (double)u.y * v.z - (double)u.z * v.y, y = (double)u.z * v.x - (double)u.x * v.z;
        double z = (double)u.x * v.y - (double)u.y * v.x;
        area += 0.5 * sqrt(x * x + y * y + z * z);
    }
    return (float)area;
}

/* The point level of a mesh with a LOD DAG whose triangles are at hand (shared/point_level.h); a
 * streamed mesh, whose triangles stay in the file, has none. */
static void set_point_level(const gdr_mesh *mesh, bool streamed, GdrGpuMesh *out)
{
    if (streamed || mesh->clusters.group_count == 0 || !(mesh->bounds.w > 0.0f))
        return;
    out->point_error = mesh->bounds.w;
    out->point_radius = gdr_point_radius(surface_area(mesh), mesh->bounds.w);
}

/* Every mesh's vertices and indices into the pool's arrays, the meshes' offsets and the instances
 * into the host copies. */
static void merge_geometry(gdr_renderer *r, const gdr_scene *scene, GdrGpuVertex *vertices, uint32_t *indices)
{
    gdr_gpu_scene *g = &r->scene;
    uint32_t vertex_cursor = 0, index_cursor = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh *mesh = &scene->meshes[m];
        g->cpu_meshes[m] = (GdrGpuMesh){.vertex_offset = vertex_cursor, .first_index = index_cursor,
                                        .index_count = mesh->index_count, .bounds = mesh->bounds};
        set_point_level(mesh, g->streamed, &g->cpu_meshes[m]);
        if (g->streamed) /* no vertex pipeline: the vertices come with the pages */
            continue;
        for (uint32_t v = 0; v < mesh->vertex_count; v++)
            vertices[vertex_cursor + v] = (GdrGpuVertex){mesh->positions[v], mesh->normals[v], mesh->uvs[v]};
        memcpy(indices + index_cursor, mesh->indices, sizeof(uint32_t) * mesh->index_count);
        vertex_cursor += mesh->vertex_count;
        index_cursor += mesh->index_count;
    }
    for (uint32_t i = 0; i < scene->instance_count; i++)
        g->cpu_instances[i] = gpu_instance_from(scene, &scene->instances[i]);
    g->mesh_count = scene->mesh_count;
    g->instance_count = scene->instance_count;
}

gdr_status gdr_gpu_scene_upload(gdr_renderer *r, const gdr_scene *scene, gdr_error *err)
{
    gdr_gpu_scene *g = &r->scene;
    uint64_t vertex_total = 0, index_total = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        vertex_total += scene->meshes[m].vertex_count;
        index_total += scene->meshes[m].index_count;
    }
    if (vertex_total > INT32_MAX || index_total > UINT32_MAX)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "scene: %llu vertices / %llu indices exceed the geometry pool's "
                             "32-bit offsets", (unsigned long long)vertex_total, (unsigned long long)index_total);

    if (g->streamed)
        vertex_total = index_total = 0;
    GdrGpuVertex *vertices = malloc(sizeof *vertices * (vertex_total ? vertex_total : 1));
    uint32_t *indices = malloc(sizeof *indices * (index_total ? index_total : 1));
    g->cpu_meshes = calloc(scene->mesh_count ? scene->mesh_count : 1, sizeof *g->cpu_meshes);
    g->cpu_instances = calloc(scene->instance_count ? scene->instance_count : 1, sizeof *g->cpu_instances);
    if (!vertices || !indices || !g->cpu_meshes || !g->cpu_instances) {
        free(vertices);
        free(indices);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene upload: out of memory");
    }
    merge_geometry(r, scene, vertices, indices);

    const VkBufferUsageFlags dst = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    gdr_status status = GDR_OK;
    if (!g->streamed)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuVertex) * vertex_total,
                                      dst | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                      GDR_VK_BUFFER_DEVICE, &g->vertices, err);
    if (status == GDR_OK && !g->streamed)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(uint32_t) * index_total,
                                      dst | VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                      GDR_VK_BUFFER_DEVICE, &g->indices, err);
    /* The cluster pool first: it fills the meshes' cluster fields. */
    const gdr_mesh_clusters **clusters = calloc(scene->mesh_count ? scene->mesh_count : 1, sizeof *clusters);
    if (status == GDR_OK && !clusters)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene upload: out of memory");
    if (status == GDR_OK)
        status = gather_clusters(scene, clusters, err);
    gdr_thread_pool *pool = status == GDR_OK ? setup_pool(clusters, scene->mesh_count) : NULL;
    if (status == GDR_OK)
        status = upload_clusters(r, scene, clusters, pool, err);
    if (status == GDR_OK)
        status = upload_lod_nodes(r, scene, clusters, pool, err);
    gdr_thread_pool_destroy(pool);
    if (status == GDR_OK)
        status = gdr_page_table_create(r, clusters, scene->mesh_count, err);
    if (status == GDR_OK)
        size_queues(r, scene, clusters);
    if (status == GDR_OK) /* the traversal's visits: even levels, then odd levels */
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuNodeVisit) * 2 * (VkDeviceSize)g->traversal_capacity,
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_DEVICE, &g->traversal, err);
    free(clusters);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuMesh) * g->mesh_count,
                                      dst | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_DEVICE, &g->meshes, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuInstance) * g->instance_count,
                                      dst | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_DEVICE, &g->instances, err);
    if (status == GDR_OK && !g->streamed)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->vertices, 0, vertices, sizeof(GdrGpuVertex) * vertex_total, err);
    if (status == GDR_OK && !g->streamed)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->indices, 0, indices, sizeof(uint32_t) * index_total, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->meshes, 0, g->cpu_meshes, sizeof(GdrGpuMesh) * g->mesh_count, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->instances, 0, g->cpu_instances,
                                      sizeof(GdrGpuInstance) * g->instance_count, err);
    free(vertices);
    free(indices);
    return status;
}

gdr_status gdr_gpu_scene_write_refs(gdr_renderer *r, gdr_error *err)
{
    gdr_gpu_scene *g = &r->scene;
    /* Streamed: a page's vertices, vertex list and triangles lie in its pool slot, addressed from the
     * pool's start by all three references (streaming.c). */
    VkDeviceAddress pool = r->stream.pool.address;
    GdrGpuScene refs = {.instances = g->instances.address, .meshes = g->meshes.address,
                        .vertices = g->streamed ? pool : g->vertices.address, .meshlets = g->meshlets.address,
                        .meshlet_vertices = g->streamed ? pool : g->meshlet_vertices.address,
                        .meshlet_triangles = g->streamed ? pool : g->meshlet_triangles.address,
                        .group_stamps = g->group_stamps.address,
                        .lod_nodes = g->lod_nodes.address, .page_table = g->page_table.address,
                        .node_absent_refined = g->node_absent_refined.address,
                        .materials = r->materials.buffer.address,
                        .vertex_colors = r->materials.vertex_colors.address,
                        .mesh_color_offsets = r->materials.mesh_color_offsets.address};
    gdr_status status = gdr_vk_buffer_create(&r->allocator, sizeof refs,
                                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                             GDR_VK_BUFFER_DEVICE, &g->refs, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->refs, 0, &refs, sizeof refs, err);
    const gdr_vk_buffer *buffers[] = {&g->vertices, &g->indices, &g->meshes, &g->instances, &g->meshlets,
                                      &g->meshlet_vertices, &g->meshlet_triangles, &g->refs, &g->page_table,
                                      &g->node_absent_refined, &g->group_stamps, &r->stream.pool,
                                      &r->occlusion.occluded_instances, &r->occlusion.occluded_nodes,
                                      &r->occlusion.retest_masks};
    g->bytes = r->materials.bytes;
    for (size_t i = 0; i < sizeof buffers / sizeof buffers[0]; i++)
        g->bytes += buffers[i]->size;
    return status;
}

void gdr_gpu_scene_destroy(gdr_renderer *r)
{
    gdr_gpu_scene *g = &r->scene;
    gdr_vk_buffer_destroy(r->ctx, &g->vertices);
    gdr_vk_buffer_destroy(r->ctx, &g->indices);
    gdr_vk_buffer_destroy(r->ctx, &g->meshes);
    gdr_vk_buffer_destroy(r->ctx, &g->instances);
    gdr_vk_buffer_destroy(r->ctx, &g->meshlets);
    gdr_vk_buffer_destroy(r->ctx, &g->meshlet_vertices);
    gdr_vk_buffer_destroy(r->ctx, &g->meshlet_triangles);
    gdr_vk_buffer_destroy(r->ctx, &g->lod_nodes);
    gdr_vk_buffer_destroy(r->ctx, &g->traversal);
    gdr_vk_buffer_destroy(r->ctx, &g->refs);
    gdr_page_table_destroy(r);
    free(g->cpu_meshlets);
    free(g->cpu_meshes);
    free(g->cpu_instances);
    free(g->pending);
    memset(g, 0, sizeof *g);
}

gdr_status gdr_frame_slots_create(gdr_renderer *r, gdr_error *err)
{
    uint32_t instances = r->scene.instance_count;
    for (uint32_t i = 0; i < GDR_FRAMES_IN_FLIGHT; i++) {
        gdr_frame_slot *slot = &r->slots[i];
        VkCommandBufferAllocateInfo alloc = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                             .commandPool = r->ctx->command_pool,
                                             .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, .commandBufferCount = 1};
        GDR_VK_TRY(err, vkAllocateCommandBuffers(r->ctx->device, &alloc, &slot->cmd));
        GDR_VK_TRY(err, vkAllocateCommandBuffers(r->ctx->device, &alloc, &slot->readback_cmd));
        gdr_status recorded = gdr_frame_record_color_readback(r, slot->readback_cmd, err);
        if (recorded != GDR_OK)
            return recorded;
        VkFenceCreateInfo fence = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        GDR_VK_TRY(err, vkCreateFence(r->ctx->device, &fence, NULL, &slot->fence));
        gdr_status status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuFrameGlobals),
                                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_UPLOAD,
                                                 &slot->globals, err);
        if (status == GDR_OK)
            status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuFrameBuffers), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                          GDR_VK_BUFFER_UPLOAD, &slot->frame_buffers, err);
        if (status == GDR_OK)
            status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuInstanceUpdate) * GDR_INSTANCE_UPDATES_PER_FRAME,
                                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_UPLOAD, &slot->updates, err);
        if (status == GDR_OK) /* one command per instance at most: the list cannot overflow */
            status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuDrawCommand) * 2 * (instances ? instances : 1),
                                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                                              VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                          GDR_VK_BUFFER_DEVICE, &slot->draws, err);
        if (status == GDR_OK)
            status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuDrawStats),
                                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                                              VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                          GDR_VK_BUFFER_DEVICE, &slot->draw_stats, err);
        if (status == GDR_OK)
            status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuDrawStats), VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                          GDR_VK_BUFFER_READBACK, &slot->stats_readback, err);
        if (status == GDR_OK)
            status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuStreamRequest) * GDR_STREAM_REQUEST_CAPACITY,
                                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_READBACK,
                                          &slot->stream_requests, err);
        if (status == GDR_OK) /* a bit per instance */
            status = gdr_vk_buffer_create(&r->allocator, sizeof(uint32_t) * (instances / 32 + 1),
                                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_UPLOAD, &slot->pvs_visible,
                                          err);
        if (status == GDR_OK) /* each group once at most: cannot overflow */
            status = gdr_vk_buffer_create(&r->allocator, sizeof(uint32_t) * (r->scene.group_total ? r->scene.group_total : 1),
                                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_READBACK,
                                          &slot->used_groups, err);
        if (status == GDR_OK && r->stream.enabled)
            status = gdr_streaming_slot_create(r, slot, err);
        if (status == GDR_OK) /* every task workgroup of every instance at most: cannot overflow */
            status = gdr_vk_buffer_create(&r->allocator,
                                          sizeof(GdrGpuTaskCommand) * 2 * (r->scene.task_capacity ? r->scene.task_capacity : 1),
                                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                          GDR_VK_BUFFER_DEVICE, &slot->tasks, err);
        if (status != GDR_OK)
            return status;
    }
    return GDR_OK;
}

void gdr_frame_slots_destroy(gdr_renderer *r)
{
    for (uint32_t i = 0; i < GDR_FRAMES_IN_FLIGHT; i++) {
        gdr_frame_slot *slot = &r->slots[i];
        if (slot->fence)
            vkDestroyFence(r->ctx->device, slot->fence, NULL);
        if (slot->cmd)
            vkFreeCommandBuffers(r->ctx->device, r->ctx->command_pool, 1, &slot->cmd);
        if (slot->readback_cmd)
            vkFreeCommandBuffers(r->ctx->device, r->ctx->command_pool, 1, &slot->readback_cmd);
        gdr_vk_buffer_destroy(r->ctx, &slot->globals);
        gdr_vk_buffer_destroy(r->ctx, &slot->frame_buffers);
        gdr_vk_buffer_destroy(r->ctx, &slot->updates);
        gdr_vk_buffer_destroy(r->ctx, &slot->draws);
        gdr_vk_buffer_destroy(r->ctx, &slot->draw_stats);
        gdr_vk_buffer_destroy(r->ctx, &slot->stats_readback);
        gdr_vk_buffer_destroy(r->ctx, &slot->tasks);
        gdr_vk_buffer_destroy(r->ctx, &slot->stream_requests);
        gdr_vk_buffer_destroy(r->ctx, &slot->used_groups);
        gdr_vk_buffer_destroy(r->ctx, &slot->pvs_visible);
        gdr_vk_buffer_destroy(r->ctx, &slot->stream_staging);
        if (slot->stream_cmd)
            vkFreeCommandBuffers(r->ctx->device, r->ctx->command_pool, 1, &slot->stream_cmd);
        memset(slot, 0, sizeof *slot);
    }
}
