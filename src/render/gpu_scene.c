/* The GPU scene: one geometry pool (merged vertex and index buffers, seed 003 plan A) and the
 * persistent instance buffer, with per-frame resources sized from the scene so they cannot overflow. */
#include <stdlib.h>
#include <string.h>

#include "render/renderer_internal.h"

static GdrGpuInstance gpu_instance_from(const gdr_scene *scene, const gdr_instance *instance)
{
    GdrGpuInstance g = {.model = instance->transform, .color = instance->color, .mesh = instance->mesh};
    if (instance->material != GDR_NO_INDEX) {
        gdr_vec4 base = scene->materials[instance->material].base_color;
        g.color = (gdr_vec4){g.color.x * base.x, g.color.y * base.y, g.color.z * base.z, g.color.w * base.w};
    }
    return g;
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

    GdrGpuVertex *vertices = malloc(sizeof *vertices * (vertex_total ? vertex_total : 1));
    uint32_t *indices = malloc(sizeof *indices * (index_total ? index_total : 1));
    g->cpu_meshes = calloc(scene->mesh_count ? scene->mesh_count : 1, sizeof *g->cpu_meshes);
    g->cpu_instances = calloc(scene->instance_count ? scene->instance_count : 1, sizeof *g->cpu_instances);
    if (!vertices || !indices || !g->cpu_meshes || !g->cpu_instances) {
        free(vertices);
        free(indices);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene upload: out of memory");
    }
    uint32_t vertex_cursor = 0, index_cursor = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh *mesh = &scene->meshes[m];
        g->cpu_meshes[m] = (GdrGpuMesh){vertex_cursor, index_cursor, mesh->index_count, 0, mesh->bounds};
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

    const VkBufferUsageFlags dst = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    gdr_status status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuVertex) * vertex_total,
                                             dst | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                             GDR_VK_BUFFER_DEVICE, &g->vertices, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(uint32_t) * index_total,
                                      dst | VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                      GDR_VK_BUFFER_DEVICE, &g->indices, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuMesh) * g->mesh_count,
                                      dst | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_DEVICE, &g->meshes, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuInstance) * g->instance_count,
                                      dst | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_DEVICE, &g->instances, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->vertices, 0, vertices, sizeof(GdrGpuVertex) * vertex_total, err);
    if (status == GDR_OK)
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

void gdr_gpu_scene_destroy(gdr_renderer *r)
{
    gdr_gpu_scene *g = &r->scene;
    gdr_vk_buffer_destroy(r->ctx, &g->vertices);
    gdr_vk_buffer_destroy(r->ctx, &g->indices);
    gdr_vk_buffer_destroy(r->ctx, &g->meshes);
    gdr_vk_buffer_destroy(r->ctx, &g->instances);
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
        VkFenceCreateInfo fence = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        GDR_VK_TRY(err, vkCreateFence(r->ctx->device, &fence, NULL, &slot->fence));
        gdr_status status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuFrameGlobals),
                                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_UPLOAD,
                                                 &slot->globals, err);
        if (status == GDR_OK)
            status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuInstanceUpdate) * GDR_INSTANCE_UPDATES_PER_FRAME,
                                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GDR_VK_BUFFER_UPLOAD, &slot->updates, err);
        if (status == GDR_OK) /* one command per instance at most: the list cannot overflow */
            status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuDrawCommand) * (instances ? instances : 1),
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
        gdr_vk_buffer_destroy(r->ctx, &slot->globals);
        gdr_vk_buffer_destroy(r->ctx, &slot->updates);
        gdr_vk_buffer_destroy(r->ctx, &slot->draws);
        gdr_vk_buffer_destroy(r->ctx, &slot->draw_stats);
        gdr_vk_buffer_destroy(r->ctx, &slot->stats_readback);
        memset(slot, 0, sizeof *slot);
    }
}
