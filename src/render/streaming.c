/* Streaming in the renderer (docs/STREAMING.md): the clusters' vertices and triangles live in a
 * page pool of fixed size; the residency (stream/residency.c) decides which pages it holds, the
 * loader thread (stream/page_loader.c) reads and checks them, and each frame copies what arrived
 * into the pool within its upload budget, before the frame's own commands.
 *
 * Each pool slot holds one page: its vertices (GdrGpuVertex), then its cluster vertex list (one
 * word per vertex: the vertex's index in the pool), then its triangle bytes. The scene's vertex,
 * vertex-list and triangle references all point at the pool's start, so a slot's data is addressed
 * by offsets within it, and the shaders read streamed clusters as they read uploaded ones. The
 * cluster records (GdrGpuMeshlet) live in the record pool: records_per_slot of them beside each slot.
 * A page's arrival writes its clusters' records there (from the page's own records, with offsets into
 * the slot) and marks its groups resident in the page table, each word its slot; an eviction marks
 * them absent. The traversal finds a leaf's records at its group's slot (GDR_FRAME_PAGED_RECORDS)
 * and never reads a record no resident page wrote. */
#include <stdlib.h>
#include <string.h>

#include "gdr/paged_cache.h"
#include "geometry/lod_cut.h"
#include "render/renderer_internal.h"
#include "render/node_counts.h"
#include "stream/page_loader.h"
#include "stream/residency.h"
#include "render/cluster_records.h"
#include "render/page_table.h"
#include "render/root_shortcut.h"
#include "render/streaming.h"

/* What one frame copies: regions into the pool, the records and the node counts, words to fill in the
 * page table, all staged in the slot's staging buffer. */
typedef struct stream_copies {
    VkBufferCopy *pool, *records, *nodes;
    uint32_t pool_count, record_count, node_count;
    uint32_t *absent_words, absent_count;       /* page-table words of evicted groups */
    uint32_t *resident_words, *resident_slots;  /* page-table words of arrived groups, and their slots */
    uint32_t resident_count;
    uint64_t staged;                            /* bytes of the staging buffer used */
} stream_copies;

static const gdr_paged_mesh *paged_mesh(const gdr_streaming *s, uint32_t mesh)
{
    return gdr_paged_cache_mesh(s->cache, mesh);
}

/* The mesh of global page `page`. */
static uint32_t page_mesh(const gdr_streaming *s, uint32_t mesh_count, uint32_t page)
{
    uint32_t lo = 0, hi = mesh_count;
    while (hi - lo > 1) {
        uint32_t mid = (lo + hi) / 2;
        if (s->page_base[mid] <= page)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* The mesh whose page-table words hold word `word`. */
static uint32_t word_mesh(const gdr_gpu_scene *g, uint32_t word)
{
    uint32_t lo = 0, hi = g->mesh_count;
    while (hi - lo > 1) {
        uint32_t mid = (lo + hi) / 2;
        if (g->cpu_meshes[mid].page_table_offset <= word)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* The default budget: a quarter of the largest device-local heap, at most GDR_GEOMETRY_BUDGET_MAX. */
static uint64_t default_budget(const gdr_renderer *r)
{
    VkPhysicalDeviceMemoryProperties memory;
    vkGetPhysicalDeviceMemoryProperties(r->ctx->physical_device, &memory);
    uint64_t largest = 0;
    for (uint32_t i = 0; i < memory.memoryHeapCount; i++)
        if ((memory.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) && memory.memoryHeaps[i].size > largest)
            largest = memory.memoryHeaps[i].size;
    uint64_t budget = largest / 4;
    return budget < GDR_GEOMETRY_BUDGET_MAX ? budget : GDR_GEOMETRY_BUDGET_MAX;
}

static gdr_status alloc_tables(gdr_streaming *s, const gdr_scene *scene, gdr_error *err)
{
    uint32_t meshes = scene->mesh_count;
    s->page_base = malloc(sizeof *s->page_base * ((size_t)meshes + 1));
    s->mesh_dirty = calloc(meshes ? meshes : 1, 1);
    s->dirty_list = malloc(sizeof *s->dirty_list * (meshes ? meshes : 1));
    if (!s->page_base || !s->mesh_dirty || !s->dirty_list)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "streaming: out of memory");
    uint32_t pages = 0;
    s->records_per_slot = 1;
    for (uint32_t m = 0; m < meshes; m++) {
        const gdr_paged_mesh *pm = paged_mesh(s, m);
        s->page_base[m] = pages;
        pages += pm->page_count;
        for (uint32_t p = 0; p < pm->page_count; p++)
            s->records_per_slot = pm->pages[p].cluster_count > s->records_per_slot ? pm->pages[p].cluster_count
                                                                                  : s->records_per_slot;
    }
    s->page_base[meshes] = pages;
    s->slot_page = malloc(sizeof *s->slot_page * (s->slot_count ? s->slot_count : 1));
    s->requests = malloc(sizeof *s->requests * GDR_STREAM_REQUEST_CAPACITY);
    s->loads = malloc(sizeof *s->loads * (s->slot_count ? s->slot_count : 1));
    uint64_t groups = 0, nodes = 0;
    for (uint32_t m = 0; m < meshes; m++) {
        groups += scene->meshes[m].clusters.group_count;
        nodes += scene->meshes[m].clusters.lod_node_count;
    }
    /* Copies: a page's data per slot, its records per group, a run of node counts per node at most. */
    s->copies = malloc(sizeof *s->copies * (groups + s->slot_count + nodes + 1));
    s->words = malloc(sizeof *s->words * (3 * groups + 1));
    if (!s->slot_page || !s->requests || !s->loads || !s->copies || !s->words)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "streaming: out of memory for %u slots", s->slot_count);
    for (uint32_t i = 0; i < s->slot_count; i++)
        s->slot_page[i] = UINT32_MAX;
    return GDR_OK;
}

/* Each slot's staging: the upload budget plus one page with its cluster records (a frame copies at
 * least one page), plus every node count of the scene (the meshes whose residency changed). */
static uint64_t staging_bytes(const gdr_streaming *s, const gdr_scene *scene)
{
    uint64_t largest_records = 0, nodes = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_paged_mesh *pm = paged_mesh(s, m);
        for (uint32_t p = 0; p < pm->page_count; p++) {
            uint64_t bytes = (uint64_t)pm->pages[p].cluster_count * sizeof(GdrGpuMeshlet);
            largest_records = bytes > largest_records ? bytes : largest_records;
        }
        nodes += scene->meshes[m].clusters.lod_node_count;
    }
    return s->upload_budget + s->slot_bytes + largest_records + 4 * nodes;
}

/* The staging of every frame in flight must fit the device: each one buffer of at most
 * maxBufferSize, all of them in the largest host-visible heap. Checked before anything is created,
 * so that an upload budget the device cannot hold is refused with its numbers rather than by a
 * failed vkCreateBuffer (or an allocation the driver cannot back). */
static gdr_status check_staging_fits(const gdr_renderer *r, uint64_t bytes, gdr_error *err)
{
    VkPhysicalDeviceMaintenance4Properties limits = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_PROPERTIES};
    VkPhysicalDeviceProperties2 properties = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &limits};
    vkGetPhysicalDeviceProperties2(r->ctx->physical_device, &properties);
    VkPhysicalDeviceMemoryProperties memory;
    vkGetPhysicalDeviceMemoryProperties(r->ctx->physical_device, &memory);
    uint64_t host_heap = 0;
    for (uint32_t t = 0; t < memory.memoryTypeCount; t++) {
        VkMemoryPropertyFlags wanted = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        uint64_t size = memory.memoryHeaps[memory.memoryTypes[t].heapIndex].size;
        if ((memory.memoryTypes[t].propertyFlags & wanted) == wanted && size > host_heap)
            host_heap = size;
    }
    uint64_t total = bytes * GDR_FRAMES_IN_FLIGHT, largest = limits.maxBufferSize;
    if (bytes > largest || total > host_heap)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "streaming: an upload budget of %llu MiB needs %u staging buffers "
                             "of %llu MiB (one per frame in flight); this device allows buffers of at most %llu MiB "
                             "and has %llu MiB of host-visible memory: give a smaller upload budget "
                             "(gdr render --upload-budget MIB)", (unsigned long long)(r->stream.upload_budget >> 20),
                             GDR_FRAMES_IN_FLIGHT, (unsigned long long)((bytes + (1u << 20) - 1) >> 20),
                             (unsigned long long)(largest >> 20), (unsigned long long)(host_heap >> 20));
    return GDR_OK;
}

/* Threads for the set-up's work a mesh at a time (the residency's page graph, the node counts), one
 * per processor, where several meshes hold enough nodes to gain from them (a billion-triangle field
 * of 1,000 meshes: 270 ms of node counts on one thread); NULL otherwise (the same results on this
 * thread). */
static gdr_thread_pool *set_up_pool(const gdr_scene *scene)
{
    uint64_t nodes = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++)
        nodes += scene->meshes[m].clusters.lod_node_count;
    return gdr_thread_pool_create_if(scene->mesh_count > 1 && nodes >= 65536);
}

gdr_status gdr_streaming_open(gdr_renderer *r, const gdr_scene *scene, const gdr_streaming_desc *desc, gdr_error *err)
{
    gdr_streaming *s = &r->stream;
    if (!desc || !desc->cache)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "streaming: no paged cache");
    if (desc->geometry_budget_bytes > GDR_GEOMETRY_BUDGET_MAX)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "streaming: a geometry budget of %llu MiB is over the "
                             "%llu MiB the pool's 32-bit offsets reach",
                             (unsigned long long)(desc->geometry_budget_bytes >> 20),
                             (unsigned long long)(GDR_GEOMETRY_BUDGET_MAX >> 20));
    s->enabled = true;
    s->scene = scene;
    s->wait_for_loads = desc->wait_for_loads;
    s->fixed_lod_error = desc->fixed_lod_error;
    gdr_lod_budget_init(&s->lod_budget);
    s->upload_budget = desc->upload_budget_bytes ? desc->upload_budget_bytes : GDR_UPLOAD_BUDGET_DEFAULT;
    s->cache = desc->cache;
    gdr_status status = gdr_paged_cache_check_scene(s->cache, scene, gdr_paged_cache_path(s->cache), err);
    gdr_residency_desc res = {.cache = s->cache,
                              .budget_bytes = desc->geometry_budget_bytes ? desc->geometry_budget_bytes
                                                                          : default_budget(r),
                              .upload_budget_bytes = s->upload_budget};
    s->set_up_pool = set_up_pool(scene);
    res.pool = s->set_up_pool;
    if (status == GDR_OK)
        status = gdr_residency_create(&res, &s->residency, err);
    if (status == GDR_OK) {
        s->slot_count = gdr_residency_slot_count(s->residency);
        s->slot_bytes = gdr_residency_slot_bytes(s->residency);
        status = alloc_tables(s, scene, err);
    }
    if (status == GDR_OK) {
        s->staging_bytes = staging_bytes(s, scene);
        status = check_staging_fits(r, s->staging_bytes, err);
    }
    if (status == GDR_OK)
        status = gdr_page_loader_create(s->cache, 0, &s->loader, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, (VkDeviceSize)s->slot_count * s->slot_bytes,
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                      GDR_VK_BUFFER_DEVICE, &s->pool, err);
    if (status != GDR_OK) /* a cache that failed to open or to match has no pages to size anything by */
        return status;
    s->stats.enabled = true;
    s->stats.slot_count = s->slot_count;
    s->stats.slot_bytes = s->slot_bytes;
    s->stats.pool_bytes = (uint64_t)s->slot_count * s->slot_bytes;
    r->scene.streamed = true;
    return status;
}

gdr_status gdr_streaming_slot_create(gdr_renderer *r, gdr_frame_slot *slot, gdr_error *err)
{
    VkCommandBufferAllocateInfo alloc = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                         .commandPool = r->ctx->command_pool,
                                         .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, .commandBufferCount = 1};
    GDR_VK_TRY(err, vkAllocateCommandBuffers(r->ctx->device, &alloc, &slot->stream_cmd));
    return gdr_vk_buffer_create(&r->allocator, r->stream.staging_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                GDR_VK_BUFFER_UPLOAD, &slot->stream_staging, err);
}

void gdr_streaming_destroy(gdr_renderer *r)
{
    gdr_streaming *s = &r->stream;
    gdr_page_loader_destroy(s->loader);
    for (uint32_t i = 0; i < s->pending_count; i++)
        gdr_page_free(&s->pending[i].page);
    gdr_residency_destroy(s->residency); /* the paged cache stays open: it is the caller's */
    if (r->ctx)
        gdr_vk_buffer_destroy(r->ctx, &s->pool);
    gdr_node_counts_destroy(s->node_counts);
    gdr_thread_pool_destroy(s->set_up_pool);
    free(s->pending), free(s->slot_page), free(s->page_base), free(s->mesh_dirty), free(s->node_runs);
    free(s->requests), free(s->loads), free(s->dirty_list), free(s->copies), free(s->words);
    memset(s, 0, sizeof *s);
}

/* --- one page into its slot ------------------------------------------------------------------- */

static void mark_dirty(gdr_streaming *s, uint32_t mesh)
{
    if (!s->mesh_dirty[mesh])
        s->dirty_list[s->dirty_count++] = mesh;
    s->mesh_dirty[mesh] = 1;
}

/* A group's page-table word changes: its node counts follow (node_counts.h). */
static void set_group(gdr_streaming *s, uint32_t mesh, uint32_t group, bool resident)
{
    uint32_t touched = gdr_node_counts_set(s->node_counts, mesh, group, resident);
    s->stats.node_groups_changed++;
    s->stats.node_updates += touched;
}

static void *stage(gdr_frame_slot *slot, stream_copies *c, uint64_t bytes)
{
    void *at = (uint8_t *)slot->stream_staging.mapped + c->staged;
    c->staged += bytes;
    return at;
}

/* A group's clusters in a page (`count` of them at pc) against its refinements in a scene read for
 * streaming: the same refined groups in the same order of first use, as many clusters of each. */
static bool refinements_match(const gdr_mesh_clusters *c, uint32_t group, const gdr_page_cluster *pc, uint32_t count)
{
    uint32_t first = gdr_lod_first_refinement(c, group), end = first, seen[GDR_CLUSTER_MAX_TRIANGLES], n = 0;
    while (end < c->refinement_count && c->refinements[end].group == group)
        end++;
    for (uint32_t i = 0; i < count; i++) {
        uint32_t r = pc[i].refined_group, k = 0;
        if (r == GDR_NO_INDEX)
            continue;
        while (k < n && c->refinements[first + k].refined_group != r)
            k++;
        if (k == n) { /* first use: the next refinement's */
            if (first + n >= end || c->refinements[first + n].refined_group != r || n == GDR_CLUSTER_MAX_TRIANGLES)
                return false;
            seen[n++] = 0;
        }
        seen[k]++;
    }
    for (uint32_t k = 0; k < n; k++)
        if (seen[k] != c->refinements[first + k].cluster_count)
            return false;
    return first + n == end;
}

/* The decoded page against what the scene says its groups hold (cluster by cluster where the scene
 * has its clusters, else each group's refinements) and the slot's size. NULL when it matches, else
 * what differs. */
static const char *page_mismatch(const gdr_streaming *s, const gdr_page *page)
{
    const gdr_paged_mesh *pm = paged_mesh(s, page->mesh);
    const gdr_page_info *info = &pm->pages[page->page];
    const gdr_mesh_clusters *c = &s->scene->meshes[page->mesh].clusters;
    if ((uint64_t)page->vertex_count * (sizeof(GdrGpuVertex) + 4) + page->triangle_byte_count > s->slot_bytes)
        return "larger than a pool slot";
    if (page->cluster_count != info->cluster_count)
        return "cluster count differs from its index";
    uint32_t j = 0;
    for (uint32_t k = info->first; k < info->first + info->group_count; k++) {
        const gdr_cluster_group *group = &c->groups[pm->page_groups[k]];
        if (!c->clusters) {
            for (uint32_t i = 0; i < group->cluster_count; i++)
                if (page->clusters[j + i].group != pm->page_groups[k])
                    return "clusters differ from the scene's";
            if (!refinements_match(c, pm->page_groups[k], &page->clusters[j], group->cluster_count))
                return "its clusters' refined groups differ from the scene's";
            j += group->cluster_count;
            continue;
        }
        for (uint32_t i = group->first_cluster; i < group->first_cluster + group->cluster_count; i++, j++) {
            const gdr_page_cluster *pc = &page->clusters[j];
            if (pc->group != pm->page_groups[k] || pc->vertex_count != c->clusters[i].vertex_count ||
                pc->triangle_count != c->clusters[i].triangle_count)
                return "clusters differ from the scene's";
        }
    }
    return NULL;
}

/* Page 0 of a mesh (its root group and the coarsest groups) against mesh-local cluster indices: the
 * refined groups root_shortcut.h walks, known for the clusters of the page's groups. */
typedef struct page_refined {
    const gdr_mesh_clusters *clusters;
    const gdr_paged_mesh *mesh;
    const gdr_page *page;
} page_refined;

static uint32_t refined_in_page(const void *user, uint32_t cluster, bool *known)
{
    const page_refined *p = user;
    const gdr_page_info *info = &p->mesh->pages[p->page->page];
    uint32_t j = 0;
    for (uint32_t k = info->first; k < info->first + info->group_count; k++) {
        const gdr_cluster_group *g = &p->clusters->groups[p->mesh->page_groups[k]];
        if (cluster >= g->first_cluster && cluster - g->first_cluster < g->cluster_count) {
            *known = true;
            return p->page->clusters[j + cluster - g->first_cluster].refined_group;
        }
        j += g->cluster_count;
    }
    *known = false;
    return GDR_NO_INDEX;
}

/* Bytes a page's copy stages: its data and its clusters' records. */
static uint64_t page_upload_bytes(const gdr_page *page)
{
    return (uint64_t)page->vertex_count * (sizeof(GdrGpuVertex) + 4) + page->triangle_byte_count +
           (uint64_t)page->cluster_count * sizeof(GdrGpuMeshlet);
}

/* A page's cluster as the GPU reads it: its record with offsets into the slot's vertex list (in
 * words) and triangle bytes, and its groups' LOD data from the scene's groups. */
static GdrGpuMeshlet page_record(const gdr_mesh_clusters *c, const gdr_page_cluster *pc, uint32_t list_base,
                                 uint32_t triangle_base)
{
    gdr_cluster k = {.vertex_offset = pc->vertex_offset, .triangle_offset = pc->triangle_offset,
                     .vertex_count = pc->vertex_count, .triangle_count = pc->triangle_count, .sphere = pc->sphere,
                     .cone_apex = pc->cone_apex, .cone_axis = pc->cone_axis, .cone_cutoff = pc->cone_cutoff,
                     .group = pc->group, .refined_group = pc->refined_group};
    return gdr_cluster_record_of(c, &k, list_base, triangle_base);
}

/* Stages page `page` for pool slot `pool_slot`: its data, its clusters' records with offsets into the
 * slot, and its groups' page-table words. */
static void stage_page(gdr_renderer *r, gdr_frame_slot *slot, stream_copies *c, const gdr_page *page,
                       uint32_t pool_slot)
{
    gdr_streaming *s = &r->stream;
    gdr_gpu_scene *g = &r->scene;
    uint64_t base = (uint64_t)pool_slot * s->slot_bytes;
    uint32_t nv = page->vertex_count;
    uint64_t data_bytes = (uint64_t)nv * (sizeof(GdrGpuVertex) + 4) + page->triangle_byte_count;
    uint64_t at = c->staged;
    uint8_t *data = stage(slot, c, data_bytes);
    for (uint32_t v = 0; v < nv; v++) {
        const gdr_page_vertex *pv = &page->vertices[v];
        GdrGpuVertex gv = {pv->position, pv->normal, pv->uv};
        memcpy(data + sizeof gv * v, &gv, sizeof gv);
        uint32_t index = (uint32_t)(base / sizeof(GdrGpuVertex)) + v; /* slots are 256-byte aligned */
        memcpy(data + sizeof gv * nv + 4 * v, &index, 4);
    }
    memcpy(data + (sizeof(GdrGpuVertex) + 4) * nv, page->triangles, page->triangle_byte_count);
    c->pool[c->pool_count++] = (VkBufferCopy){at, base, data_bytes};

    const gdr_paged_mesh *pm = paged_mesh(s, page->mesh);
    const gdr_page_info *info = &pm->pages[page->page];
    const gdr_mesh_clusters *mc = &s->scene->meshes[page->mesh].clusters;
    uint32_t list_base = (uint32_t)((base + sizeof(GdrGpuVertex) * nv) / 4), triangle_base = (uint32_t)(base + 36ull * nv);
    /* The page's records, in page order, into the slot's place in the record pool. */
    uint64_t bytes = sizeof(GdrGpuMeshlet) * (uint64_t)page->cluster_count, from = c->staged;
    GdrGpuMeshlet *records = stage(slot, c, bytes);
    uint32_t j = 0;
    for (uint32_t k = info->first; k < info->first + info->group_count; k++) {
        uint32_t group = pm->page_groups[k];
        const gdr_cluster_group *gr = &mc->groups[group];
        uint32_t cluster_id = g->cpu_meshes[page->mesh].meshlet_offset + gr->first_cluster;
        for (uint32_t i = 0; i < gr->cluster_count; i++, j++) {
            records[j] = page_record(mc, &page->clusters[j], list_base, triangle_base);
            records[j].cluster_id = cluster_id + i;
        }
        c->resident_words[c->resident_count] = g->cpu_meshes[page->mesh].page_table_offset + group;
        c->resident_slots[c->resident_count++] = pool_slot;
        set_group(s, page->mesh, group, true);
    }
    c->records[c->record_count++] =
        (VkBufferCopy){from, sizeof(GdrGpuMeshlet) * (uint64_t)pool_slot * s->records_per_slot, bytes};
    s->slot_page[pool_slot] = s->page_base[page->mesh] + page->page;
    mark_dirty(s, page->mesh);
    if (page->page == 0 && mc->group_count > 0) { /* the root's records arrive: its shortcut and chain */
        page_refined p = {mc, pm, page};
        GdrGpuMesh *mesh = &g->cpu_meshes[page->mesh];
        gdr_root_shortcut_set(mc, refined_in_page, &p, mesh);
        /* The root group leads page 0: its records lead the slot's (pinned: the slot stays). No root
         * chain: its clusters' records do not lie one before the other in the pool. */
        mesh->root_first = pool_slot * s->records_per_slot;
        mesh->root_chain = 0;
        s->meshes_changed = true;
    }
}

void gdr_streaming_leaves_in_pages(gdr_renderer *r, GdrGpuLodNode *nodes, const uint32_t *first)
{
    const gdr_streaming *s = &r->stream;
    for (uint32_t m = 0; m < s->scene->mesh_count; m++) {
        const gdr_mesh_clusters *c = &s->scene->meshes[m].clusters;
        const gdr_paged_mesh *pm = paged_mesh(s, m);
        uint32_t *at = c->group_count ? malloc(sizeof *at * c->group_count) : NULL;
        for (uint32_t p = 0; at && p < pm->page_count; p++) {
            uint32_t offset = 0;
            for (uint32_t k = pm->pages[p].first; k < pm->pages[p].first + pm->pages[p].group_count; k++) {
                at[pm->page_groups[k]] = offset;
                offset += c->groups[pm->page_groups[k]].cluster_count;
            }
        }
        for (uint32_t n = 0; at && n < c->lod_node_count; n++) {
            GdrGpuLodNode *node = &nodes[first[m] + n];
            if ((node->flags & GDR_GPU_LOD_NODE_LEAF) && node->group < c->group_count)
                node->first = at[node->group];
        }
        free(at);
    }
}

uint32_t gdr_streaming_record_cluster(const gdr_renderer *r, uint32_t record, uint32_t *mesh)
{
    const gdr_streaming *s = &r->stream;
    uint32_t slot = record / s->records_per_slot, j = record % s->records_per_slot;
    uint32_t page = slot < s->slot_count ? s->slot_page[slot] : UINT32_MAX;
    if (page == UINT32_MAX)
        return UINT32_MAX;
    uint32_t m = page_mesh(s, r->scene.mesh_count, page);
    const gdr_paged_mesh *pm = paged_mesh(s, m);
    const gdr_page_info *info = &pm->pages[page - s->page_base[m]];
    const gdr_mesh_clusters *c = &s->scene->meshes[m].clusters;
    *mesh = m;
    for (uint32_t k = info->first; k < info->first + info->group_count; k++) {
        const gdr_cluster_group *g = &c->groups[pm->page_groups[k]];
        if (j < g->cluster_count)
            return g->first_cluster + j;
        j -= g->cluster_count;
    }
    return UINT32_MAX;
}

/* --- the frame's work ------------------------------------------------------------------------- */

/* The slot's previous frame, read back: the groups its cut drew (their pages' last use) and the
 * groups it asked for. Returns the requests' count. */
static uint32_t read_slot_results(gdr_renderer *r, gdr_frame_slot *slot)
{
    gdr_streaming *s = &r->stream;
    gdr_gpu_scene *g = &r->scene;
    if (!slot->recorded && !slot->resubmitted && slot->stream_frame == 0 && s->frame == 0)
        return 0;
    GdrGpuDrawStats gpu;
    memcpy(&gpu, slot->stats_readback.mapped, sizeof gpu);
    uint32_t used = slot->stream_frame ? gpu.groups_used : 0;
    used = used < g->group_total ? used : g->group_total;
    const uint32_t *words = slot->used_groups.mapped;
    for (uint32_t i = 0; i < used; i++) {
        uint32_t m = word_mesh(g, words[i]);
        uint32_t group = words[i] - g->cpu_meshes[m].page_table_offset;
        if (group < paged_mesh(s, m)->group_count)
            gdr_residency_mark_used(s->residency, slot->stream_frame, m, paged_mesh(s, m)->groups[group].page);
    }
    s->stats.groups_used = used;
    uint32_t n = gpu.stream_requests < GDR_STREAM_REQUEST_CAPACITY ? gpu.stream_requests : GDR_STREAM_REQUEST_CAPACITY;
    const GdrGpuStreamRequest *q = slot->stream_requests.mapped;
    for (uint32_t i = 0; i < n; i++)
        s->requests[i] = (gdr_stream_request){q[i].mesh, q[i].group, q[i].priority};
    return n;
}

/* Pages whose slot the residency took back (evicted, or removed with a damaged page): their groups
 * become absent. Walks the pool, not the scene. */
static void find_evictions(gdr_renderer *r, stream_copies *c)
{
    gdr_streaming *s = &r->stream;
    for (uint32_t slot = 0; slot < s->slot_count; slot++) {
        uint32_t page = s->slot_page[slot];
        if (page == UINT32_MAX)
            continue;
        uint32_t m = page_mesh(s, r->scene.mesh_count, page), local = page - s->page_base[m];
        if (gdr_residency_page_slot(s->residency, m, local) == slot)
            continue;
        const gdr_paged_mesh *pm = paged_mesh(s, m);
        const gdr_page_info *info = &pm->pages[local];
        for (uint32_t k = info->first; k < info->first + info->group_count; k++) {
            c->absent_words[c->absent_count++] = r->scene.cpu_meshes[m].page_table_offset + pm->page_groups[k];
            set_group(s, m, pm->page_groups[k], false);
        }
        s->slot_page[slot] = UINT32_MAX;
        mark_dirty(s, m);
    }
}

static gdr_status keep_pending(gdr_streaming *s, const gdr_page_result *result, gdr_error *err)
{
    if (s->pending_count == s->pending_capacity) {
        uint32_t capacity = s->pending_capacity ? 2 * s->pending_capacity : 64;
        gdr_page_result *grown = realloc(s->pending, sizeof *grown * capacity);
        if (!grown)
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "streaming: out of memory for loaded pages");
        s->pending = grown;
        s->pending_capacity = capacity;
    }
    s->pending[s->pending_count++] = *result;
    return GDR_OK;
}

/* What the loader finished, into the pending list; damaged pages are refused here (their groups
 * stay absent, and the pages depending on them are taken back). */
static gdr_status collect_loads(gdr_streaming *s, gdr_error *err)
{
    gdr_page_result result;
    while (gdr_page_loader_collect(s->loader, s->wait_for_loads, &result, 1) == 1) {
        const char *why = result.status == GDR_OK ? page_mismatch(s, &result.page) : NULL;
        if (result.status == GDR_OK && !why) {
            gdr_status status = keep_pending(s, &result, err);
            if (status != GDR_OK) {
                gdr_page_free(&result.page);
                return status;
            }
            continue;
        }
        if (why)
            snprintf(s->stats.refused, sizeof s->stats.refused, "%s: mesh %u page %u: %s",
                     gdr_paged_cache_path(s->cache), result.load.mesh, result.load.page, why);
        else
            snprintf(s->stats.refused, sizeof s->stats.refused, "%s", result.error.message);
        s->stats.pages_refused++;
        gdr_residency_failed(s->residency, result.load.mesh, result.load.page);
        gdr_page_free(&result.page);
    }
    return GDR_OK;
}

/* Pending pages into their slots while the upload budget lasts (at least one a frame); pages the
 * residency no longer plans (taken back meanwhile) are dropped. */
static void upload_pending(gdr_renderer *r, gdr_frame_slot *slot, stream_copies *c)
{
    gdr_streaming *s = &r->stream;
    uint32_t done = 0;
    uint64_t bytes = 0;
    for (; done < s->pending_count; done++) {
        gdr_page *page = &s->pending[done].page;
        uint32_t pool_slot = gdr_residency_planned_slot(s->residency, page->mesh, page->page);
        if (pool_slot == UINT32_MAX) {
            gdr_page_free(page);
            continue;
        }
        uint64_t need = page_upload_bytes(page);
        if (s->stats.uploads > 0 && bytes + need > s->upload_budget)
            break;
        stage_page(r, slot, c, page, pool_slot);
        gdr_residency_loaded(s->residency, page->mesh, page->page);
        bytes += need;
        s->stats.uploads++;
        gdr_page_free(page);
    }
    memmove(s->pending, s->pending + done, sizeof *s->pending * (s->pending_count - done));
    s->pending_count -= done;
    s->stats.upload_bytes = bytes;
}

/* The node counts that changed (node_counts.h), a copy per run of consecutive nodes, and the absent
 * groups of every mesh whose residency changed. */
static gdr_status stage_node_counts(gdr_renderer *r, gdr_frame_slot *slot, stream_copies *c, gdr_error *err)
{
    gdr_streaming *s = &r->stream;
    gdr_status status = GDR_OK;
    for (uint32_t i = 0; i < s->dirty_count && status == GDR_OK; i++) {
        uint32_t m = s->dirty_list[i];
        s->mesh_dirty[m] = 0;
        status = gdr_page_table_set_absent(r, m, gdr_node_counts_absent_groups(s->node_counts, m), err);
    }
    s->dirty_count = 0;
    uint32_t words = 0, runs = gdr_node_counts_take_changes(s->node_counts, s->node_runs, &words);
    const uint32_t *counts = gdr_node_counts_words(s->node_counts);
    for (uint32_t i = 0; i < runs; i++) {
        uint64_t bytes = 4ull * s->node_runs[i].count, from = c->staged;
        memcpy(stage(slot, c, bytes), counts + s->node_runs[i].first, bytes);
        c->nodes[c->node_count++] = (VkBufferCopy){from, 4ull * s->node_runs[i].first, bytes};
    }
    s->stats.node_words_uploaded = words;
    s->stats.node_copies = runs;
    return status;
}

/* The frame's copies into stream_cmd: the evicted groups' words first, then (after a barrier, since
 * an evicted page may come back in the same frame) the pages, records, node counts and the arrived
 * groups' words; all after every earlier command's reads and before every later command. */
static gdr_status record_copies(gdr_renderer *r, gdr_frame_slot *slot, const stream_copies *c, gdr_error *err)
{
    gdr_gpu_scene *g = &r->scene;
    VkCommandBuffer cmd = slot->stream_cmd;
    GDR_VK_TRY(err, vkResetCommandBuffer(cmd, 0));
    VkCommandBufferBeginInfo begin = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                      .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
    GDR_VK_TRY(err, vkBeginCommandBuffer(cmd, &begin));
    const gdr_vk_scope transfer = {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
    gdr_vk_memory_barrier(cmd, (gdr_vk_scope){VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                              VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT}, transfer);
    for (uint32_t i = 0; i < c->absent_count; i++)
        vkCmdFillBuffer(cmd, g->page_table.buffer, 4ull * c->absent_words[i], 4, GDR_GPU_PAGE_ABSENT);
    if (c->absent_count)
        gdr_vk_memory_barrier(cmd, transfer, transfer);
    VkBuffer staging = slot->stream_staging.buffer;
    if (c->pool_count)
        vkCmdCopyBuffer(cmd, staging, r->stream.pool.buffer, c->pool_count, c->pool);
    if (c->record_count)
        vkCmdCopyBuffer(cmd, staging, g->meshlets.buffer, c->record_count, c->records);
    if (c->node_count)
        vkCmdCopyBuffer(cmd, staging, g->node_absent_refined.buffer, c->node_count, c->nodes);
    for (uint32_t i = 0; i < c->resident_count; i++)
        vkCmdFillBuffer(cmd, g->page_table.buffer, 4ull * c->resident_words[i], 4, c->resident_slots[i]);
    gdr_vk_memory_barrier(cmd, transfer, (gdr_vk_scope){VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                                        VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT});
    GDR_VK_TRY(err, vkEndCommandBuffer(cmd));
    return GDR_OK;
}

static stream_copies frame_copies(gdr_renderer *r)
{
    gdr_streaming *s = &r->stream;
    uint32_t groups = r->scene.group_total;
    return (stream_copies){.pool = s->copies, .records = s->copies + s->slot_count,
                           .nodes = s->copies + s->slot_count + groups, .absent_words = s->words,
                           .resident_words = s->words + groups, .resident_slots = s->words + 2 * (size_t)groups};
}

/* The slot's read-back cut against the pool (stream/lod_budget.h): the factor on the LOD threshold
 * that this frame draws with. Returns the requests still wanted: none when the read-back frame drew
 * with a lower threshold than this frame will (its requests were for detail no longer asked for). */
static uint32_t fit_cut_to_pool(gdr_renderer *r, gdr_frame_slot *slot, uint32_t request_count)
{
    gdr_streaming *s = &r->stream;
    bool known = slot->stream_results && slot->stream_frame != 0;
    gdr_lod_budget_observation o = {.scale = slot->stream_lod_scale, .known = known,
                                    .all_resident = r->scene.absent_groups == 0, .requests = request_count,
                                    .capacity = s->slot_count,
                                    .pinned = gdr_residency_get_stats(s->residency).pinned_pages};
    if (known)
        o.wanted = gdr_residency_count_wanted(s->residency, slot->stream_frame, s->requests, request_count);
    s->stats.wanted_pages = o.wanted;
    if (!s->fixed_lod_error && gdr_lod_budget_update(&s->lod_budget, &o))
        s->unsettled_frame = s->frame;
    bool coarser_now = known && o.scale < s->lod_budget.scale;
    slot->stream_lod_scale = s->lod_budget.scale;
    s->stats.lod_error_scale = s->lod_budget.scale;
    s->stats.lod_error_changes = s->lod_budget.changes;
    return coarser_now ? 0 : request_count;
}

/* The residency's figures into the statistics. */
static void update_stats(gdr_streaming *s)
{
    gdr_residency_stats rs = gdr_residency_get_stats(s->residency);
    s->stats.resident_bytes = rs.resident_bytes;
    s->stats.resident_pages = rs.resident_pages;
    s->stats.distinct_requests = rs.requests;
    s->stats.loads = rs.loads;
    s->stats.evictions = rs.evictions;
    s->stats.deferred = rs.deferred;
    s->stats.frames_since_change = rs.frames_since_change;
    s->stats.evicted_in_use = rs.evicted_in_use;
    s->stats.pending = s->pending_count + gdr_page_loader_pending(s->loader);
    s->stats.uploads_total += s->stats.uploads;
    s->stats.upload_bytes_total += s->stats.upload_bytes;
    s->stats.evictions_total += rs.evictions;
    gdr_page_loader_stats ls = gdr_page_loader_get_stats(s->loader);
    s->stats.loader_pages = ls.pages_read;
    s->stats.loader_bytes_read = ls.bytes_read;
    s->stats.loader_busy_ms = 1e3 * ls.busy_s;
    s->stats.loader_mb_s = ls.busy_s > 0.0 ? 1e-6 * (double)ls.bytes_read / ls.busy_s : 0.0;
    s->stats.loader_queue_depth = ls.queued + ls.reading;
}

gdr_status gdr_streaming_begin_frame(gdr_renderer *r, gdr_frame_slot *slot, gdr_error *err)
{
    gdr_streaming *s = &r->stream;
    slot->stream_copies = false;
    if (!s->enabled)
        return GDR_OK;
    uint32_t frame = ++s->frame;
    s->stats.uploads = 0;
    s->stats.upload_bytes = 0;
    s->stats.node_groups_changed = s->stats.node_updates = 0;
    uint32_t request_count = slot->stream_results ? read_slot_results(r, slot) : 0;
    request_count = fit_cut_to_pool(r, slot, request_count);
    uint32_t load_count = 0;
    gdr_residency_plan(s->residency, frame, s->requests, request_count, s->loads, s->slot_count, &load_count);
    gdr_status status = gdr_page_loader_submit(s->loader, s->loads, load_count, err);
    if (status == GDR_OK)
        status = collect_loads(s, err);
    stream_copies c = frame_copies(r);
    if (status == GDR_OK) {
        find_evictions(r, &c);
        upload_pending(r, slot, &c);
        status = stage_node_counts(r, slot, &c, err);
    }
    if (status == GDR_OK && (c.absent_count || c.pool_count || c.node_count)) {
        status = record_copies(r, slot, &c, err);
        slot->stream_copies = status == GDR_OK;
    }
    /* The group-use list only where something can be evicted for a request: some group absent. */
    slot->stream_frame = r->scene.absent_groups > 0 ? frame : 0;
    slot->stream_results = true;
    update_stats(s);
    if (s->stats.uploads || s->stats.evictions)
        s->unsettled_frame = frame;
    s->stats.settled_frames = frame - s->unsettled_frame;
    return status;
}

/* The node counts over the scene's hierarchies, every group absent (as the page table starts). */
static gdr_status create_node_counts(gdr_renderer *r, gdr_error *err)
{
    gdr_streaming *s = &r->stream;
    gdr_gpu_scene *g = &r->scene;
    uint32_t meshes = s->scene->mesh_count;
    const gdr_mesh_clusters **clusters = malloc(sizeof *clusters * (meshes ? meshes : 1));
    uint32_t *offsets = malloc(sizeof *offsets * (meshes ? meshes : 1));
    gdr_status status = GDR_OK;
    if (!clusters || !offsets)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "streaming: out of memory for the node counts");
    for (uint32_t m = 0; status == GDR_OK && m < meshes; m++) {
        clusters[m] = &s->scene->meshes[m].clusters;
        offsets[m] = g->cpu_meshes[m].lod_node_offset;
    }
    if (status == GDR_OK)
        status = gdr_node_counts_create_on(clusters, offsets, meshes, s->set_up_pool, &s->node_counts, err);
    uint32_t nodes = status == GDR_OK ? gdr_node_counts_node_total(s->node_counts) : 0;
    if (status == GDR_OK && !(s->node_runs = malloc(sizeof *s->node_runs * (nodes ? nodes : 1))))
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "streaming: out of memory for the node counts");
    free(clusters);
    free(offsets);
    return status;
}

/* The GPU memory that stays resident beside the pool, and the scene's source triangles. */
static void count_resident_tables(gdr_renderer *r)
{
    gdr_streaming *s = &r->stream;
    const gdr_gpu_scene *g = &r->scene;
    s->stats.cluster_record_bytes = sizeof(GdrGpuMeshlet) * (uint64_t)s->slot_count * s->records_per_slot;
    s->stats.hierarchy_bytes = sizeof(GdrGpuLodNode) * (uint64_t)g->node_total;
    s->stats.node_count_bytes = 4ull * g->node_total;
    s->stats.page_table_bytes = 4ull * g->group_total * (2 + GDR_FRAMES_IN_FLIGHT); /* words, stamps, lists */
    s->stats.source_triangles = 0;
    for (uint32_t m = 0; m < g->mesh_count; m++)
        s->stats.source_triangles += paged_mesh(s, m)->source_triangles;
}

/* Before the first frame: every group absent, then every mesh's coarsest page (pinned) read, checked
 * and copied, waiting for them: the first frame draws every mesh at its coarsest at least. */
gdr_status gdr_streaming_start(gdr_renderer *r, gdr_error *err)
{
    gdr_streaming *s = &r->stream;
    gdr_gpu_scene *g = &r->scene;
    uint32_t *absent = malloc(sizeof *absent * (g->group_total ? g->group_total : 1));
    if (!absent)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "streaming: out of memory");
    for (uint32_t i = 0; i < g->group_total; i++)
        absent[i] = GDR_GPU_PAGE_ABSENT;
    gdr_status status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->page_table, 0, absent,
                                             sizeof *absent * g->group_total, err);
    free(absent);
    double start = gdr_now_ms();
    if (status == GDR_OK)
        status = create_node_counts(r, err);
    s->stats.setup_node_counts_ms = gdr_now_ms() - start;
    start = gdr_now_ms();
    gdr_thread_pool_destroy(s->set_up_pool); /* the set-up's last work a mesh at a time */
    s->set_up_pool = NULL;
    count_resident_tables(r);
    bool wait = s->wait_for_loads;
    s->wait_for_loads = true;
    gdr_frame_slot *slot = &r->slots[0];
    if (status == GDR_OK) {
        for (uint32_t m = 0; m < g->mesh_count; m++)
            mark_dirty(s, m);
        status = gdr_streaming_begin_frame(r, slot, err);
    }
    /* The pinned pages come without the upload budget: copy until none is left. */
    while (status == GDR_OK && slot->stream_copies) {
        VkCommandBufferSubmitInfo info = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO,
                                          .commandBuffer = slot->stream_cmd};
        VkSubmitInfo2 submit = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2, .commandBufferInfoCount = 1,
                                .pCommandBufferInfos = &info};
        if (vkQueueSubmit2(r->ctx->queue, 1, &submit, VK_NULL_HANDLE) != VK_SUCCESS ||
            vkQueueWaitIdle(r->ctx->queue) != VK_SUCCESS)
            return gdr_error_set(err, GDR_ERROR_VULKAN, "streaming: the first pages' upload failed");
        slot->stream_copies = false;
        if (s->pending_count == 0)
            break;
        slot->stream_results = false; /* no frame ran: nothing to read back */
        status = gdr_streaming_begin_frame(r, slot, err);
    }
    slot->stream_results = false;
    s->wait_for_loads = wait;
    /* The meshes' root shortcuts came with their pages 0. */
    if (status == GDR_OK && s->meshes_changed)
        status = gdr_vk_buffer_upload(r->ctx, &r->staging, &g->meshes, 0, g->cpu_meshes,
                                      sizeof(GdrGpuMesh) * g->mesh_count, err);
    s->meshes_changed = false;
    s->stats.setup_first_pages_ms = gdr_now_ms() - start;
    for (uint32_t m = 0; status == GDR_OK && m < g->mesh_count; m++)
        if (gdr_residency_page_slot(s->residency, m, 0) == UINT32_MAX && paged_mesh(s, m)->page_count)
            status = gdr_error_set(err, GDR_ERROR_PARSE, "streaming: mesh %u's coarsest page could not be read: %s", m,
                                   s->stats.refused);
    return status;
}
