/* The residency tables the traversal and the cluster tests read (shared/residency.h): a word per
 * group of every mesh (the page table: GDR_GPU_PAGE_ABSENT, or resident) and a count per LOD node
 * of the clusters below whose refined group is absent, and the stamps of the groups a streaming
 * frame drew. A scene uploaded whole starts with every group resident (gdr_renderer_debug_set_
 * residency marks groups absent, to check the traversal's cut over resident groups against the
 * CPU's); a streamed scene's tables come from its residency (streaming.c). */
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"
#include "render/page_table.h"

gdr_status gdr_page_table_create(gdr_renderer *r, const gdr_mesh_clusters *const *clusters, uint32_t mesh_count,
                                 gdr_error *err)
{
    gdr_gpu_scene *g = &r->scene;
    uint64_t groups = 0, nodes = 0;
    for (uint32_t m = 0; m < mesh_count; m++) {
        g->cpu_meshes[m].page_table_offset = (uint32_t)groups;
        groups += clusters[m]->group_count;
        nodes += clusters[m]->lod_node_count;
    }
    if (groups > UINT32_MAX / 2)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "scene: %llu LOD groups exceed the page table's 32-bit offsets",
                             (unsigned long long)groups);
    g->group_total = (uint32_t)groups;
    g->node_total = (uint32_t)nodes;
    g->absent_groups = 0;
    const VkBufferUsageFlags usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT; /* TRANSFER_SRC: read back */
    size_t words = (size_t)(groups > nodes ? groups : nodes);
    uint32_t *zeros = calloc(words ? words : 1, sizeof *zeros); /* 0: resident; 0 absent below */
    if (!zeros)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene upload: out of memory for the page table");
    gdr_status status = gdr_vk_buffer_create(&r->allocator, sizeof *zeros * (groups ? groups : 1), usage,
                                             GDR_VK_BUFFER_DEVICE, &g->page_table, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, sizeof *zeros * (nodes ? nodes : 1), usage, GDR_VK_BUFFER_DEVICE,
                                      &g->node_absent_refined, err);
    if (status == GDR_OK) /* 0: no streaming frame drew the group yet */
        status = gdr_vk_buffer_create(&r->allocator, sizeof *zeros * (groups ? groups : 1), usage, GDR_VK_BUFFER_DEVICE,
                                      &g->group_stamps, err);
    if (status == GDR_OK && groups)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->group_stamps, 0, zeros, sizeof *zeros * groups, err);
    if (status == GDR_OK && groups)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->page_table, 0, zeros, sizeof *zeros * groups, err);
    if (status == GDR_OK && nodes)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->node_absent_refined, 0, zeros, sizeof *zeros * nodes,
                                      err);
    free(zeros);
    return status;
}

void gdr_page_table_destroy(gdr_renderer *r)
{
    gdr_vk_buffer_destroy(r->ctx, &r->scene.page_table);
    gdr_vk_buffer_destroy(r->ctx, &r->scene.node_absent_refined);
    gdr_vk_buffer_destroy(r->ctx, &r->scene.group_stamps);
    free(r->scene.cpu_mesh_absent);
    r->scene.cpu_mesh_absent = NULL;
}

/* Counts the scene's absent groups from each mesh's count (cpu_mesh_absent, made on first use). */
gdr_status gdr_page_table_set_absent(gdr_renderer *r, uint32_t mesh, uint32_t absent, gdr_error *err)
{
    gdr_gpu_scene *g = &r->scene;
    if (!g->cpu_mesh_absent) {
        g->cpu_mesh_absent = calloc(g->mesh_count ? g->mesh_count : 1, sizeof *g->cpu_mesh_absent);
        if (!g->cpu_mesh_absent)
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "residency: out of memory");
    }
    g->absent_groups -= g->cpu_mesh_absent[mesh];
    g->cpu_mesh_absent[mesh] = absent;
    g->absent_groups += absent;
    return GDR_OK;
}

gdr_status gdr_renderer_debug_set_residency(gdr_renderer *r, uint32_t mesh, const uint8_t *group_resident,
                                            const uint32_t *node_absent_refined, gdr_error *err)
{
    gdr_gpu_scene *g = &r->scene;
    if (mesh >= g->mesh_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "residency: mesh %u of %u", mesh, g->mesh_count);
    if (g->streamed)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "residency: the scene streams; its residency decides");
    const GdrGpuMesh *m = &g->cpu_meshes[mesh];
    uint32_t next = mesh + 1 < g->mesh_count ? g->cpu_meshes[mesh + 1].page_table_offset : g->group_total;
    uint32_t groups = next - m->page_table_offset, absent = 0;
    uint32_t *words = malloc(sizeof *words * (groups ? groups : 1));
    if (!words)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "residency: out of memory");
    for (uint32_t i = 0; i < groups; i++) {
        words[i] = group_resident[i] ? 0u : GDR_GPU_PAGE_ABSENT;
        absent += group_resident[i] == 0;
    }
    /* The frames in flight read the tables: let them finish first. */
    gdr_status status = GDR_OK;
    if (vkDeviceWaitIdle(r->ctx->device) != VK_SUCCESS)
        status = gdr_error_set(err, GDR_ERROR_VULKAN, "residency: vkDeviceWaitIdle failed");
    if (status == GDR_OK && groups)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->page_table, sizeof *words * m->page_table_offset,
                                      words, sizeof *words * groups, err);
    if (status == GDR_OK && m->lod_node_count)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->node_absent_refined,
                                      sizeof *words * m->lod_node_offset, node_absent_refined,
                                      sizeof *words * m->lod_node_count, err);
    free(words);
    return status == GDR_OK ? gdr_page_table_set_absent(r, mesh, absent, err) : status;
}

gdr_status gdr_renderer_read_group_requests(gdr_renderer *r, gdr_group_request *requests, uint32_t capacity,
                                            uint32_t *count, uint32_t *dropped, gdr_error *err)
{
    *count = *dropped = 0;
    if (r->last_slot < 0 || r->slots[r->last_slot].pipeline != GDR_PIPELINE_MESH)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "read_group_requests: the last frame was not a "
                             "mesh-pipeline frame of a scene");
    const gdr_frame_slot *slot = &r->slots[r->last_slot];
    GdrGpuDrawStats gpu;
    memcpy(&gpu, slot->stats_readback.mapped, sizeof gpu);
    uint32_t n = gpu.stream_requests < GDR_STREAM_REQUEST_CAPACITY ? gpu.stream_requests : GDR_STREAM_REQUEST_CAPACITY;
    if (n > capacity)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "read_group_requests: %u requests, room for %u", n, capacity);
    *dropped = gpu.stream_requests - n;
    *count = n;
    for (uint32_t i = 0; i < n; i++) {
        GdrGpuStreamRequest q;
        memcpy(&q, (const uint8_t *)slot->stream_requests.mapped + sizeof q * i, sizeof q);
        requests[i] = (gdr_group_request){q.mesh, q.group, q.priority, q.instance};
    }
    return GDR_OK;
}

gdr_status gdr_renderer_read_residency(gdr_renderer *r, uint32_t mesh, uint8_t *group_resident, gdr_error *err)
{
    gdr_gpu_scene *g = &r->scene;
    if (!r->has_scene || mesh >= g->mesh_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "read_residency: mesh %u of %u", mesh, g->mesh_count);
    uint32_t next = mesh + 1 < g->mesh_count ? g->cpu_meshes[mesh + 1].page_table_offset : g->group_total;
    uint32_t groups = next - g->cpu_meshes[mesh].page_table_offset;
    if (groups == 0)
        return GDR_OK;
    gdr_vk_buffer readback = {0};
    gdr_status status = gdr_vk_buffer_read_back(&r->allocator, g->page_table.buffer,
                                                sizeof(uint32_t) * g->cpu_meshes[mesh].page_table_offset,
                                                sizeof(uint32_t) * groups, &readback, err);
    for (uint32_t i = 0; status == GDR_OK && i < groups; i++) {
        uint32_t word;
        memcpy(&word, (const uint8_t *)readback.mapped + sizeof word * i, sizeof word);
        group_resident[i] = word != GDR_GPU_PAGE_ABSENT;
    }
    gdr_vk_buffer_destroy(r->ctx, &readback);
    return status;
}

gdr_status gdr_renderer_debug_read_node_counts(gdr_renderer *r, uint32_t mesh, uint32_t *counts, gdr_error *err)
{
    gdr_gpu_scene *g = &r->scene;
    if (!r->has_scene || mesh >= g->mesh_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "read_node_counts: mesh %u of %u", mesh, g->mesh_count);
    const GdrGpuMesh *m = &g->cpu_meshes[mesh];
    if (m->lod_node_count == 0)
        return GDR_OK;
    if (vkDeviceWaitIdle(r->ctx->device) != VK_SUCCESS)
        return gdr_error_set(err, GDR_ERROR_VULKAN, "read_node_counts: vkDeviceWaitIdle failed");
    gdr_vk_buffer readback = {0};
    gdr_status status = gdr_vk_buffer_read_back(&r->allocator, g->node_absent_refined.buffer,
                                                sizeof *counts * m->lod_node_offset,
                                                sizeof *counts * m->lod_node_count, &readback, err);
    if (status == GDR_OK)
        memcpy(counts, readback.mapped, sizeof *counts * m->lod_node_count);
    gdr_vk_buffer_destroy(r->ctx, &readback);
    return status;
}
