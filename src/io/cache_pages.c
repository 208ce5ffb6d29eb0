/* Geometry pages of the scene cache: a mesh's LOD DAG groups laid out coarsest first in pages of
 * whole groups; each page its groups' clusters (bounds and cones as records), their vertices
 * (meshoptimizer's vertex codec) and triangles (its index codec), then zstd over the three where
 * that pays; the page index with every group's header. Layout: docs/CACHE_FORMAT.md, 'PAGE'. */
#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>
#include <zstd.h>

#include "geometry/vertex_quantize.h"
#include "io/cache_pages.h"
#include "io/io_internal.h"

#define PAGE_MAGIC 0x47504447u /* "GDPG" */
_Static_assert(sizeof(gdr_page_vertex) == sizeof(gdr_vertex_bytes) &&
                   offsetof(gdr_page_vertex, normal) == offsetof(gdr_vertex_bytes, normal) &&
                   offsetof(gdr_page_vertex, uv) == offsetof(gdr_vertex_bytes, uv),
               "a decoded page vertex is compared and decoded as gdr_vertex_bytes");
#define PAGE_FLAG_ZSTD 1u
#define PAGE_FLAG_QUANTIZED 2u /* the vertices as integers on the grid the body gives (gdr_quantized_vertex) */
#define PAGE_GRID_BLOCK 32u    /* that grid: i32 position exponent, f32 x3 origin, i32 uv exponent, f32 x2 origin, u32 0 */
/* zstd level of the page bodies: 3 measured as good as 9 here on these bodies (docs/CACHE_FORMAT.md). */
#define PAGE_ZSTD_LEVEL 3
/* zstd is kept only when it saves at least this share of the body (else decoding it costs for nothing). */
#define PAGE_ZSTD_MIN_SAVING 0.03

/* --- layout: groups coarsest first, packed into pages of whole groups --------------------------- */

typedef struct group_key {
    uint32_t group, depth;
    int root;
} group_key;

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static int compare_group_keys(const void *a, const void *b)
{
    const group_key *x = a, *y = b;
    if (x->root != y->root)
        return x->root ? -1 : 1;
    if (x->depth != y->depth)
        return x->depth > y->depth ? -1 : 1;
    return x->group < y->group ? -1 : x->group > y->group;
}

/* Whether cluster c's vertex list is its triangles' corners in order of first use (every builder
 * makes it so; a page stores only the triangles and rebuilds the list from them). */
static int vertices_in_first_use_order(const gdr_mesh_clusters *mc, const gdr_cluster *c)
{
    uint32_t seen = 0;
    for (uint32_t i = 0; i < 3 * c->triangle_count; i++) {
        uint32_t local = mc->triangles[c->triangle_offset + i];
        if (local > seen)
            return 0;
        seen += local == seen;
    }
    return seen == c->vertex_count;
}

/* True when the mesh's groups cover its clusters exactly (every DAG does) and every cluster's vertex
 * list can be rebuilt from its triangles: it can be paged. */
static int mesh_pageable(const gdr_mesh_clusters *mc)
{
    if (mc->group_count == 0)
        return 0;
    uint64_t covered = 0;
    for (uint32_t g = 0; g < mc->group_count; g++) {
        const gdr_cluster_group *gr = &mc->groups[g];
        if ((uint64_t)gr->first_cluster + gr->cluster_count > mc->cluster_count)
            return 0;
        for (uint32_t c = gr->first_cluster; c < gr->first_cluster + gr->cluster_count; c++)
            if (mc->clusters[c].group != g || !vertices_in_first_use_order(mc, &mc->clusters[c]))
                return 0;
        covered += gr->cluster_count;
    }
    return covered == mc->cluster_count;
}

static uint64_t group_raw_bytes(const gdr_mesh_clusters *mc, uint32_t g)
{
    uint64_t bytes = 0;
    const gdr_cluster_group *gr = &mc->groups[g];
    for (uint32_t c = gr->first_cluster; c < gr->first_cluster + gr->cluster_count; c++)
        bytes += CACHE_PAGE_CLUSTER_RECORD + (uint64_t)mc->clusters[c].vertex_count * sizeof(gdr_page_vertex) +
                 (uint64_t)mc->clusters[c].triangle_count * 3;
    return bytes;
}

/* One encoded page and what the index says of it. */
typedef struct encoded_page {
    uint8_t *bytes;
    uint32_t size, first, group_count, cluster_count, vertex_count, triangle_count;
    uint64_t checksum;
} encoded_page;

typedef struct mesh_pages {
    uint32_t *order; /* group indices in page order */
    encoded_page *pages;
    uint32_t page_count;
} mesh_pages;

/* --- encoding one page ---------------------------------------------------------------------------- */

typedef struct page_source {
    const gdr_mesh *mesh;
    const uint32_t *groups;
    uint32_t group_count;
    uint32_t *remap; /* mesh vertex -> page vertex, UINT32_MAX between pages (mesh vertex_count entries) */
} page_source;

static void put_cluster_record(writer *w, const gdr_cluster *c)
{
    put_u32(w, c->refined_group);
    put_u32(w, c->vertex_count);
    put_u32(w, c->triangle_count);
    put_f32s(w, &c->sphere.x, 4);
    put_f32s(w, &c->cone_apex.x, 3);
    put_f32s(w, &c->cone_axis.x, 3);
    put_f32s(w, &c->cone_cutoff, 1);
}

/* The page's clusters' records, its vertices (each mesh vertex once, in order of first use by the
 * triangles) and its triangles as indices of those, unencoded; counts into *e (vertex_count: the
 * clusters' vertices, as decoded), the page's own vertex count into *unique. 0 when out of memory. */
static int gather_page(const page_source *src, writer *records, gdr_page_vertex **vertices, uint32_t **indices,
                       encoded_page *e, uint32_t *unique)
{
    const gdr_mesh_clusters *mc = &src->mesh->clusters;
    uint64_t vc = 0, tc = 0;
    for (uint32_t k = 0; k < src->group_count; k++) {
        const gdr_cluster_group *gr = &mc->groups[src->groups[k]];
        for (uint32_t c = gr->first_cluster; c < gr->first_cluster + gr->cluster_count; c++)
            vc += mc->clusters[c].vertex_count, tc += mc->clusters[c].triangle_count, e->cluster_count++;
    }
    *vertices = malloc(sizeof **vertices * (vc ? vc : 1));
    *indices = malloc(sizeof **indices * (tc ? 3 * tc : 1));
    uint32_t *mesh_vertex = malloc(sizeof *mesh_vertex * (vc ? vc : 1));
    int ok = *vertices && *indices && mesh_vertex;
    uint32_t u = 0, t = 0;
    for (uint32_t k = 0; ok && k < src->group_count; k++) {
        const gdr_cluster_group *gr = &mc->groups[src->groups[k]];
        for (uint32_t ci = gr->first_cluster; ok && ci < gr->first_cluster + gr->cluster_count; ci++) {
            const gdr_cluster *c = &mc->clusters[ci];
            put_cluster_record(records, c);
            for (uint32_t i = 0; ok && i < c->triangle_count * 3; i++) {
                uint32_t mv = mc->vertices[c->vertex_offset + mc->triangles[c->triangle_offset + i]];
                if (src->remap[mv] == UINT32_MAX) {
                    src->remap[mv] = u;
                    mesh_vertex[u] = mv;
                    (*vertices)[u++] = (gdr_page_vertex){src->mesh->positions[mv], src->mesh->normals[mv],
                                                         src->mesh->uvs[mv]};
                }
                (*indices)[t++] = src->remap[mv];
            }
        }
    }
    for (uint32_t i = 0; mesh_vertex && i < u; i++)
        src->remap[mesh_vertex[i]] = UINT32_MAX;
    free(mesh_vertex);
    e->vertex_count = (uint32_t)vc;
    e->triangle_count = t / 3;
    *unique = u;
    return ok && !records->failed;
}

/* The page's vertices as integers on the mesh's grid, or NULL when the mesh is not quantized or a
 * vertex does not encode exactly (then the page keeps floats). */
static gdr_quantized_vertex *quantize_page(const gdr_mesh *mesh, const gdr_page_vertex *vertices, uint32_t count)
{
    if (!mesh->quantization.enabled)
        return NULL;
    gdr_quantized_vertex *q = malloc(sizeof *q * (count ? count : 1));
    for (uint32_t v = 0; q && v < count; v++)
        if (!gdr_vertex_encode(&mesh->quantization, vertices[v].position, vertices[v].normal, vertices[v].uv, &q[v])) {
            free(q);
            return NULL;
        }
    return q;
}

static void put_grid(writer *w, const gdr_vertex_quantization *q)
{
    put_u32(w, (uint32_t)q->position_exponent);
    put_f32s(w, &q->position_origin.x, 3);
    put_u32(w, (uint32_t)q->uv_exponent);
    put_f32s(w, &q->uv_origin.x, 2);
    put_u32(w, 0);
}

/* Encodes `count` vertices of `vertex_size` bytes and `index_count` indices onto the end of `body`;
 * their sizes in vs, is. */
static int put_streams(writer *body, const void *vertices, size_t vertex_size, uint32_t count, const uint32_t *indices,
                       size_t index_count, size_t *vs, size_t *is)
{
    size_t vbound = meshopt_encodeVertexBufferBound(count, vertex_size);
    size_t ibound = meshopt_encodeIndexBufferBound(index_count, count);
    uint8_t *vbuf = malloc(vbound), *ibuf = malloc(ibound);
    *vs = vbuf ? meshopt_encodeVertexBuffer(vbuf, vbound, vertices, count, vertex_size) : 0;
    *is = ibuf ? meshopt_encodeIndexBuffer(ibuf, ibound, indices, index_count) : 0;
    put(body, vbuf, *vs);
    put(body, ibuf, *is);
    free(vbuf);
    free(ibuf);
    return *vs > 0 && *is > 0 && !body->failed;
}

/* Header + body (records, the grid where quantized, vertex stream, index stream), zstd over the body
 * where it pays. */
static int encode_page(const page_source *src, encoded_page *e)
{
    writer body = {0};
    gdr_page_vertex *vertices = NULL;
    uint32_t *indices = NULL;
    size_t vs = 0, is = 0;
    uint32_t unique = 0, quantized_flag = 0;
    int ok = gather_page(src, &body, &vertices, &indices, e, &unique);
    gdr_quantized_vertex *quantized = ok ? quantize_page(src->mesh, vertices, unique) : NULL;
    if (quantized) {
        quantized_flag = PAGE_FLAG_QUANTIZED;
        put_grid(&body, &src->mesh->quantization);
        ok = put_streams(&body, quantized, sizeof *quantized, unique, indices, 3 * (size_t)e->triangle_count, &vs, &is);
    } else if (ok) {
        ok = put_streams(&body, vertices, sizeof *vertices, unique, indices, 3 * (size_t)e->triangle_count, &vs, &is);
    }
    free(quantized);
    free(vertices);
    free(indices);
    size_t zbound = ZSTD_compressBound(body.size);
    uint8_t *stored = ok ? malloc(CACHE_PAGE_HEADER + (zbound > body.size ? zbound : body.size)) : NULL;
    if (!stored) {
        free(body.data);
        return 0;
    }
    size_t z = ZSTD_compress(stored + CACHE_PAGE_HEADER, zbound, body.data, body.size, PAGE_ZSTD_LEVEL);
    uint32_t flags = 0, body_stored = (uint32_t)body.size;
    if (!ZSTD_isError(z) && (double)z <= (1.0 - PAGE_ZSTD_MIN_SAVING) * (double)body.size)
        flags = PAGE_FLAG_ZSTD, body_stored = (uint32_t)z;
    else
        memcpy(stored + CACHE_PAGE_HEADER, body.data, body.size);
    flags |= quantized_flag;
    uint32_t header[8] = {PAGE_MAGIC, flags, (uint32_t)body.size, e->cluster_count, unique, e->triangle_count,
                          (uint32_t)vs, (uint32_t)is};
    memcpy(stored, header, sizeof header);
    free(body.data);
    e->bytes = stored;
    e->size = CACHE_PAGE_HEADER + body_stored;
    e->checksum = gdr_io_hash(stored, e->size);
    return 1;
}

/* --- a mesh's pages ----------------------------------------------------------------------------- */

static void free_mesh_pages(mesh_pages *mp)
{
    for (uint32_t p = 0; p < mp->page_count; p++)
        free(mp->pages[p].bytes);
    free(mp->pages);
    free(mp->order);
    *mp = (mesh_pages){0};
}

/* Orders the groups (root first, then by depth, coarsest first) and cuts the order into pages of
 * whole groups holding at least page_bytes raw bytes each (the last one less). A mesh with a page
 * the reader would refuse (over CACHE_PAGE_MAX_RAW: a single huge group) is left without pages. */
static int build_mesh_pages(const gdr_mesh *mesh, uint32_t page_bytes, mesh_pages *mp)
{
    const gdr_mesh_clusters *mc = &mesh->clusters;
    *mp = (mesh_pages){0};
    if (!mesh_pageable(mc))
        return 1;
    group_key *keys = malloc(sizeof *keys * mc->group_count);
    mp->order = malloc(sizeof *mp->order * mc->group_count);
    mp->pages = malloc(sizeof *mp->pages * mc->group_count);
    uint32_t *remap = malloc(sizeof *remap * (mesh->vertex_count ? mesh->vertex_count : 1));
    if (!keys || !mp->order || !mp->pages || !remap) {
        free(keys);
        free(remap);
        free_mesh_pages(mp);
        return 0;
    }
    memset(remap, 0xff, sizeof *remap * mesh->vertex_count);
    for (uint32_t g = 0; g < mc->group_count; g++)
        keys[g] = (group_key){g, mc->groups[g].depth, isinf(mc->groups[g].error)};
    qsort(keys, mc->group_count, sizeof *keys, compare_group_keys);
    for (uint32_t g = 0; g < mc->group_count; g++)
        mp->order[g] = keys[g].group;
    free(keys);
    for (uint32_t first = 0; first < mc->group_count;) {
        uint32_t end = first;
        uint64_t raw = 0;
        for (; end < mc->group_count && raw < page_bytes; end++)
            raw += group_raw_bytes(mc, mp->order[end]);
        if (raw > CACHE_PAGE_MAX_RAW) { /* a group the reader would refuse: the mesh is not paged */
            free(remap);
            free_mesh_pages(mp);
            return 1;
        }
        encoded_page *e = &mp->pages[mp->page_count];
        *e = (encoded_page){.first = first, .group_count = end - first};
        page_source src = {mesh, mp->order + first, end - first, remap};
        if (!encode_page(&src, e)) {
            free(remap);
            free_mesh_pages(mp);
            return 0;
        }
        mp->page_count++;
        first = end;
    }
    free(remap);
    return 1;
}

/* --- the section -------------------------------------------------------------------------------- */

/* The DAG's edges of a mesh: for each group, the groups holding clusters made from it, sorted,
 * without repeats (first[g] .. first[g + 1] in *edges). */
static int mesh_parents(const gdr_mesh_clusters *mc, uint32_t **first_out, uint32_t **edges_out, uint32_t *count)
{
    uint64_t *pairs = malloc(sizeof *pairs * (mc->cluster_count ? mc->cluster_count : 1));
    uint32_t *first = calloc((size_t)mc->group_count + 1, sizeof *first);
    uint32_t *edges = malloc(sizeof *edges * (mc->cluster_count ? mc->cluster_count : 1));
    if (!pairs || !first || !edges) {
        free(pairs), free(first), free(edges);
        return 0;
    }
    uint32_t n = 0;
    for (uint32_t c = 0; c < mc->cluster_count; c++)
        if (mc->clusters[c].refined_group < mc->group_count)
            pairs[n++] = (uint64_t)mc->clusters[c].refined_group << 32 | mc->clusters[c].group;
    qsort(pairs, n, sizeof *pairs, compare_u64);
    uint32_t unique = 0;
    for (uint32_t i = 0; i < n; i++)
        if (i == 0 || pairs[i] != pairs[i - 1]) {
            edges[unique++] = (uint32_t)pairs[i];
            first[(pairs[i] >> 32) + 1]++;
        }
    for (uint32_t g = 0; g < mc->group_count; g++)
        first[g + 1] += first[g];
    free(pairs);
    *first_out = first, *edges_out = edges, *count = unique;
    return 1;
}

static void put_mesh_groups(writer *w, const gdr_mesh_clusters *mc, const mesh_pages *mp, const uint32_t *first)
{
    uint32_t *page_of = calloc(mc->group_count, sizeof *page_of);
    if (!page_of) {
        w->failed = 1;
        return;
    }
    for (uint32_t p = 0; p < mp->page_count; p++)
        for (uint32_t k = 0; k < mp->pages[p].group_count; k++)
            page_of[mp->order[mp->pages[p].first + k]] = p;
    for (uint32_t g = 0; g < mc->group_count; g++) {
        const gdr_cluster_group *gr = &mc->groups[g];
        put_f32s(w, &gr->sphere.x, 4);
        put_f32s(w, &gr->error, 1);
        put_u32(w, gr->depth);
        put_u32(w, gr->cluster_count);
        put_u32(w, page_of[g]);
        put_u32(w, first[g]);
        put_u32(w, first[g + 1] - first[g]);
    }
    free(page_of);
}

/* A mesh's entry of the index; its pages' offsets counted from `page_offset` on. */
static void put_mesh_index(writer *w, const gdr_mesh *mesh, const mesh_pages *mp, uint64_t page_offset)
{
    const gdr_mesh_clusters *mc = &mesh->clusters;
    uint32_t *first = NULL, *edges = NULL, edge_count = 0;
    if (mp->page_count && !mesh_parents(mc, &first, &edges, &edge_count)) {
        w->failed = 1;
        return;
    }
    uint32_t groups = mp->page_count ? mc->group_count : 0;
    put_u32(w, groups);
    put_u32(w, mp->page_count);
    put_u32(w, mesh->index_count / 3);
    put_u32(w, edge_count);
    if (groups)
        put_mesh_groups(w, mc, mp, first);
    put(w, mp->order, sizeof *mp->order * groups);
    put(w, edges, sizeof *edges * edge_count);
    free(first), free(edges);
    for (uint32_t p = 0; p < mp->page_count; p++) {
        const encoded_page *e = &mp->pages[p];
        put_u64(w, page_offset);
        put_u32(w, e->size);
        put_u32(w, e->first);
        put_u32(w, e->group_count);
        put_u32(w, e->cluster_count);
        put_u32(w, e->vertex_count);
        put_u32(w, e->triangle_count);
        put_u64(w, e->checksum);
        page_offset += e->size;
    }
}

int cache_pages_encode_mesh(const gdr_mesh *mesh, uint32_t page_bytes, cache_mesh_pages *out)
{
    *out = (cache_mesh_pages){0};
    mesh_pages mp;
    if (!build_mesh_pages(mesh, page_bytes, &mp))
        return 0;
    put_mesh_index(&out->index, mesh, &mp, 0);
    out->page_count = mp.page_count;
    out->page_table = out->index.size - (size_t)mp.page_count * CACHE_PAGE_INFO_RECORD;
    for (uint32_t p = 0; p < mp.page_count; p++)
        put(&out->pages, mp.pages[p].bytes, mp.pages[p].size);
    free_mesh_pages(&mp);
    if (out->index.failed || out->pages.failed) {
        cache_pages_free_mesh(out);
        return 0;
    }
    return 1;
}

void cache_pages_rebase(cache_mesh_pages *mp, uint64_t base)
{
    for (uint32_t p = 0; p < mp->page_count; p++) {
        uint8_t *at = mp->index.data + mp->page_table + (size_t)p * CACHE_PAGE_INFO_RECORD;
        uint64_t offset;
        memcpy(&offset, at, 8);
        offset += base;
        memcpy(at, &offset, 8);
    }
}

void cache_pages_free_mesh(cache_mesh_pages *mp)
{
    free(mp->index.data);
    free(mp->pages.data);
    *mp = (cache_mesh_pages){0};
}

void cache_pages_put_header(writer *w, uint32_t mesh_count, uint32_t page_bytes, uint64_t index_size,
                            uint64_t index_hash)
{
    put_u32(w, CACHE_PAGES_VERSION);
    put_u32(w, mesh_count);
    put_u32(w, page_bytes);
    put_u32(w, 0);
    put_u64(w, index_size);
    put_u64(w, index_hash);
}

void cache_pages_write(writer *w, const gdr_scene *scene, uint32_t page_bytes)
{
    cache_mesh_pages *mp = calloc(scene->mesh_count ? scene->mesh_count : 1, sizeof *mp);
    int ok = mp != NULL;
    for (uint32_t m = 0; ok && m < scene->mesh_count; m++)
        ok = cache_pages_encode_mesh(&scene->meshes[m], page_bytes, &mp[m]);
    /* The index's size does not depend on the offsets in it: the pages start right after it. */
    writer index = {0};
    uint64_t page_offset = CACHE_PAGES_HEADER;
    for (uint32_t m = 0; ok && m < scene->mesh_count; m++)
        page_offset += mp[m].index.size;
    for (uint32_t m = 0; ok && m < scene->mesh_count; m++) {
        cache_pages_rebase(&mp[m], page_offset);
        page_offset += mp[m].pages.size;
        put(&index, mp[m].index.data, mp[m].index.size);
    }
    if (!ok || index.failed) {
        w->failed = 1;
    } else {
        cache_pages_put_header(w, scene->mesh_count, page_bytes, index.size, gdr_io_hash(index.data, index.size));
        put(w, index.data, index.size);
        for (uint32_t m = 0; m < scene->mesh_count; m++)
            put(w, mp[m].pages.data, mp[m].pages.size);
    }
    free(index.data);
    for (uint32_t m = 0; mp && m < scene->mesh_count; m++)
        cache_pages_free_mesh(&mp[m]);
    free(mp);
}

/* --- reading: the index ------------------------------------------------------------------------- */

#define PAGE_ERR(...) gdr_error_set(err, GDR_ERROR_PARSE, __VA_ARGS__)

gdr_status cache_pages_parse_header(const char *name, const uint8_t *head, uint64_t section_size,
                                    uint32_t *mesh_count, uint64_t *index_size, uint64_t *index_hash,
                                    gdr_error *err)
{
    if (section_size < CACHE_PAGES_HEADER)
        return PAGE_ERR("%s: section 'PAGE': %llu bytes, shorter than its header", name,
                        (unsigned long long)section_size);
    reader r = {head, CACHE_PAGES_HEADER, 0, 0};
    uint32_t version = get_u32(&r);
    *mesh_count = get_u32(&r);
    uint32_t page_bytes = get_u32(&r), reserved = get_u32(&r);
    *index_size = get_u64(&r);
    *index_hash = get_u64(&r);
    if (version != CACHE_PAGES_VERSION)
        return PAGE_ERR("%s: section 'PAGE': version %u, this build reads %u", name, version, CACHE_PAGES_VERSION);
    if (reserved != 0 || page_bytes < GDR_PAGE_BYTES_MIN || page_bytes > GDR_PAGE_BYTES_MAX)
        return PAGE_ERR("%s: section 'PAGE': page size %u (reserved %u) is not valid", name, page_bytes, reserved);
    if (*index_size > section_size - CACHE_PAGES_HEADER)
        return PAGE_ERR("%s: section 'PAGE': index of %llu bytes does not fit its %llu bytes", name,
                        (unsigned long long)*index_size, (unsigned long long)section_size);
    return GDR_OK;
}

void cache_pages_free_index(gdr_paged_mesh *meshes, uint32_t mesh_count)
{
    for (uint32_t m = 0; meshes && m < mesh_count; m++) {
        free(meshes[m].groups);
        free(meshes[m].page_groups);
        free(meshes[m].parents);
        free(meshes[m].pages);
    }
    free(meshes);
}

static gdr_status read_groups(const char *name, reader *r, uint32_t m, gdr_paged_mesh *pm, gdr_error *err)
{
    for (uint32_t g = 0; g < pm->group_count; g++) {
        gdr_page_group *gr = &pm->groups[g];
        get_f32s(r, &gr->sphere.x, 4);
        get_f32s(r, &gr->error, 1);
        gr->depth = get_u32(r);
        gr->cluster_count = get_u32(r);
        gr->page = get_u32(r);
        gr->parent_first = get_u32(r);
        gr->parent_count = get_u32(r);
        if (!isfinite(gr->sphere.x) || !isfinite(gr->sphere.y) || !isfinite(gr->sphere.z) || !(gr->sphere.w >= 0.0f) ||
            !isfinite(gr->sphere.w) || isnan(gr->error) || gr->cluster_count == 0 || gr->page >= pm->page_count ||
            gr->parent_first > pm->parent_count || gr->parent_count > pm->parent_count - gr->parent_first)
            return PAGE_ERR("%s: section 'PAGE': mesh %u group %u: bad header (sphere, error, %u clusters, page %u, "
                            "parents %u+%u)", name, m, g, gr->cluster_count, gr->page, gr->parent_first,
                            gr->parent_count);
    }
    return GDR_OK;
}

/* The page order is a permutation of the groups, the first group the root (infinite error), the
 * groups' parent lists do not overlap, and every edge goes to a deeper group (so the DAG has no
 * cycle). */
static gdr_status check_order_and_edges(const char *name, uint32_t m, const gdr_paged_mesh *pm, gdr_error *err)
{
    uint8_t *seen = calloc(pm->group_count, 1);
    if (!seen)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: mesh %u: %u groups", name, m, pm->group_count);
    gdr_status status = GDR_OK;
    for (uint32_t k = 0; k < pm->group_count && status == GDR_OK; k++) {
        uint32_t g = pm->page_groups[k];
        if (g >= pm->group_count || seen[g])
            status = PAGE_ERR("%s: section 'PAGE': mesh %u: page order entry %u (group %u) is out of range or "
                              "repeated", name, m, k, g);
        else
            seen[g] = 1;
    }
    free(seen);
    if (status == GDR_OK && !isinf(pm->groups[pm->page_groups[0]].error))
        status = PAGE_ERR("%s: section 'PAGE': mesh %u: page 0 does not start with the root group", name, m);
    /* Each edge belongs to one group: lists that overlap would make readers that gather them per
     * page (the residency's page graph) write more than the mesh's edges. */
    uint64_t listed = 0;
    for (uint32_t g = 0; g < pm->group_count; g++)
        listed += pm->groups[g].parent_count;
    if (status == GDR_OK && listed > pm->parent_count)
        status = PAGE_ERR("%s: section 'PAGE': mesh %u: its groups list %llu parent edges, the index holds %u "
                          "(lists overlap)", name, m, (unsigned long long)listed, pm->parent_count);
    for (uint32_t g = 0; g < pm->group_count && status == GDR_OK; g++)
        for (uint32_t e = pm->groups[g].parent_first; e < pm->groups[g].parent_first + pm->groups[g].parent_count; e++)
            if (pm->parents[e] >= pm->group_count || pm->groups[pm->parents[e]].depth <= pm->groups[g].depth)
                return PAGE_ERR("%s: section 'PAGE': mesh %u group %u: parent %u is not a deeper group", name, m, g,
                                pm->parents[e]);
    return status;
}

/* Pages lie one after another from `*cursor` (section-relative), cover the page order in runs,
 * and hold what their groups say. Offsets become absolute. */
static gdr_status read_pages(const char *name, reader *r, uint32_t m, gdr_paged_mesh *pm, uint64_t section_offset,
                             uint64_t section_size, uint64_t *cursor, gdr_error *err)
{
    uint32_t next_first = 0;
    for (uint32_t p = 0; p < pm->page_count; p++) {
        gdr_page_info *pi = &pm->pages[p];
        pi->offset = get_u64(r);
        pi->stored_size = get_u32(r);
        pi->first = get_u32(r);
        pi->group_count = get_u32(r);
        pi->cluster_count = get_u32(r);
        pi->vertex_count = get_u32(r);
        pi->triangle_count = get_u32(r);
        pi->checksum = get_u64(r);
        uint64_t clusters = 0;
        int groups_ok = pi->first == next_first && pi->group_count >= 1 &&
                        pi->group_count <= pm->group_count - pi->first;
        for (uint32_t k = 0; groups_ok && k < pi->group_count; k++) {
            const gdr_page_group *gr = &pm->groups[pm->page_groups[pi->first + k]];
            groups_ok = gr->page == p;
            clusters += gr->cluster_count;
        }
        if (r->failed || pi->offset != *cursor || pi->stored_size < CACHE_PAGE_HEADER ||
            pi->stored_size > section_size - *cursor || !groups_ok || clusters != pi->cluster_count ||
            pi->vertex_count < clusters || pi->vertex_count > clusters * GDR_CLUSTER_MAX_VERTICES ||
            pi->triangle_count < clusters || pi->triangle_count > clusters * GDR_CLUSTER_MAX_TRIANGLES ||
            clusters * CACHE_PAGE_CLUSTER_RECORD + (uint64_t)pi->vertex_count * sizeof(gdr_page_vertex) +
                    (uint64_t)pi->triangle_count * 3 > CACHE_PAGE_MAX_RAW)
            return PAGE_ERR("%s: section 'PAGE': mesh %u page %u: bad entry (offset %llu, %u bytes, groups %u+%u, "
                            "%u clusters, %u vertices, %u triangles)", name, m, p, (unsigned long long)pi->offset,
                            pi->stored_size, pi->first, pi->group_count, pi->cluster_count, pi->vertex_count,
                            pi->triangle_count);
        *cursor += pi->stored_size;
        next_first += pi->group_count;
        pi->offset += section_offset;
    }
    if (next_first != pm->group_count)
        return PAGE_ERR("%s: section 'PAGE': mesh %u: pages hold %u of its %u groups", name, m, next_first,
                        pm->group_count);
    return GDR_OK;
}

static gdr_status read_mesh_index(const char *name, reader *r, uint32_t m, gdr_paged_mesh *pm, uint64_t section_offset,
                                  uint64_t section_size, uint64_t *cursor, gdr_error *err)
{
    pm->group_count = get_u32(r);
    pm->page_count = get_u32(r);
    pm->source_triangles = get_u32(r);
    pm->parent_count = get_u32(r);
    uint64_t need = (uint64_t)pm->group_count * (CACHE_PAGE_GROUP_RECORD + 4) + (uint64_t)pm->parent_count * 4 +
                    (uint64_t)pm->page_count * CACHE_PAGE_INFO_RECORD;
    if (r->failed || need > r->size - r->at || (pm->group_count == 0) != (pm->page_count == 0) ||
        pm->page_count > pm->group_count)
        return PAGE_ERR("%s: section 'PAGE': mesh %u: %u groups, %u pages, %u edges do not fit the index", name, m,
                        pm->group_count, pm->page_count, pm->parent_count);
    if (pm->group_count == 0)
        return GDR_OK;
    pm->groups = malloc(sizeof *pm->groups * pm->group_count);
    pm->page_groups = malloc(sizeof *pm->page_groups * pm->group_count);
    pm->parents = malloc(sizeof *pm->parents * (pm->parent_count ? pm->parent_count : 1));
    pm->pages = malloc(sizeof *pm->pages * pm->page_count);
    if (!pm->groups || !pm->page_groups || !pm->parents || !pm->pages)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: mesh %u: page index of %u groups", name, m,
                             pm->group_count);
    gdr_status status = read_groups(name, r, m, pm, err);
    if (status != GDR_OK)
        return status;
    for (uint32_t k = 0; k < pm->group_count; k++)
        pm->page_groups[k] = get_u32(r);
    for (uint32_t e = 0; e < pm->parent_count; e++)
        pm->parents[e] = get_u32(r);
    if ((status = check_order_and_edges(name, m, pm, err)) != GDR_OK)
        return status;
    return read_pages(name, r, m, pm, section_offset, section_size, cursor, err);
}

gdr_status cache_pages_parse_index(const char *name, const uint8_t *index, uint64_t index_size,
                                   uint32_t mesh_count, uint64_t section_offset, uint64_t section_size,
                                   gdr_paged_mesh **meshes, gdr_error *err)
{
    *meshes = NULL;
    if ((uint64_t)mesh_count * 16 > index_size)
        return PAGE_ERR("%s: section 'PAGE': %u meshes do not fit an index of %llu bytes", name, mesh_count,
                        (unsigned long long)index_size);
    gdr_paged_mesh *pm = calloc(mesh_count ? mesh_count : 1, sizeof *pm);
    if (!pm)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: page index of %u meshes", name, mesh_count);
    reader r = {index, (size_t)index_size, 0, 0};
    uint64_t cursor = CACHE_PAGES_HEADER + index_size;
    gdr_status status = GDR_OK;
    for (uint32_t m = 0; m < mesh_count && status == GDR_OK; m++)
        status = read_mesh_index(name, &r, m, &pm[m], section_offset, section_size, &cursor, err);
    if (status == GDR_OK && (r.at != r.size || cursor != section_size))
        status = PAGE_ERR("%s: section 'PAGE': %zu index bytes and %llu page bytes left over", name, r.size - r.at,
                          (unsigned long long)(section_size - cursor));
    if (status != GDR_OK) {
        cache_pages_free_index(pm, mesh_count);
        return status;
    }
    *meshes = pm;
    return GDR_OK;
}

/* --- reading: one page ---------------------------------------------------------------------------- */

/* One zstd decompression context per thread, made on its first compressed page and freed when the
 * thread ends: setting one up for every page cost a few percent of decoding. NULL when none can be
 * had (then each page makes its own, as ZSTD_decompress does). */
static pthread_key_t dctx_key;
static pthread_once_t dctx_once = PTHREAD_ONCE_INIT;
static int dctx_key_made;

static void free_dctx(void *dctx) { ZSTD_freeDCtx(dctx); }

static void make_dctx_key(void) { dctx_key_made = pthread_key_create(&dctx_key, free_dctx) == 0; }

static ZSTD_DCtx *thread_dctx(void)
{
    if (pthread_once(&dctx_once, make_dctx_key) != 0 || !dctx_key_made)
        return NULL;
    ZSTD_DCtx *dctx = pthread_getspecific(dctx_key);
    if (!dctx && (dctx = ZSTD_createDCtx()) != NULL && pthread_setspecific(dctx_key, dctx) != 0) {
        ZSTD_freeDCtx(dctx);
        dctx = NULL;
    }
    return dctx;
}

/* The body as stored (raw or zstd) into exactly body_size bytes; *owned when it had to be inflated. */
static gdr_status page_body(const char *where, const uint8_t *stored, size_t stored_size, uint32_t flags,
                            uint32_t body_size, const uint8_t **body, uint8_t **owned, gdr_error *err)
{
    *owned = NULL;
    if (!(flags & PAGE_FLAG_ZSTD)) {
        if (stored_size != body_size)
            return PAGE_ERR("%s: body of %zu bytes, the header says %u", where, stored_size, body_size);
        *body = stored;
        return GDR_OK;
    }
    unsigned long long content = ZSTD_getFrameContentSize(stored, stored_size);
    if (content != body_size)
        return PAGE_ERR("%s: compressed body holds %llu bytes, the header says %u", where, content, body_size);
    *owned = malloc(body_size ? body_size : 1);
    if (!*owned)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: %u bytes", where, body_size);
    ZSTD_DCtx *dctx = thread_dctx();
    size_t n = dctx ? ZSTD_decompressDCtx(dctx, *owned, body_size, stored, stored_size)
                    : ZSTD_decompress(*owned, body_size, stored, stored_size);
    if (ZSTD_isError(n) || n != body_size) {
        free(*owned);
        *owned = NULL;
        return PAGE_ERR("%s: compressed body does not decompress (%s)", where,
                        ZSTD_isError(n) ? ZSTD_getErrorName(n) : "short");
    }
    *body = *owned;
    return GDR_OK;
}

static int finite_floats(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* The cluster records, each given its group from the page's groups in order. */
static gdr_status decode_clusters(const char *where, reader *r, const gdr_paged_mesh *pm, const gdr_page_info *pi,
                                  gdr_page *out, gdr_error *err)
{
    uint32_t k = 0, left = pm->groups[pm->page_groups[pi->first]].cluster_count, v = 0, t = 0;
    for (uint32_t c = 0; c < pi->cluster_count; c++) {
        while (left == 0)
            left = pm->groups[pm->page_groups[pi->first + ++k]].cluster_count;
        left--;
        gdr_page_cluster *pc = &out->clusters[c];
        pc->group = pm->page_groups[pi->first + k];
        pc->refined_group = get_u32(r);
        pc->vertex_count = get_u32(r);
        pc->triangle_count = get_u32(r);
        get_f32s(r, &pc->sphere.x, 4);
        get_f32s(r, &pc->cone_apex.x, 3);
        get_f32s(r, &pc->cone_axis.x, 3);
        get_f32s(r, &pc->cone_cutoff, 1);
        if ((pc->refined_group != GDR_NO_INDEX && pc->refined_group >= pm->group_count) || pc->vertex_count == 0 ||
            pc->vertex_count > GDR_CLUSTER_MAX_VERTICES || pc->triangle_count == 0 ||
            pc->triangle_count > GDR_CLUSTER_MAX_TRIANGLES || !finite_floats(&pc->sphere.x, 4) ||
            !(pc->sphere.w >= 0.0f) || !finite_floats(&pc->cone_apex.x, 3) || !finite_floats(&pc->cone_axis.x, 3) ||
            !isfinite(pc->cone_cutoff) || pc->vertex_count > pi->vertex_count - v ||
            pc->triangle_count > pi->triangle_count - t)
            return PAGE_ERR("%s: cluster %u: bad record (refined group %u, %u vertices, %u triangles)", where, c,
                            pc->refined_group, pc->vertex_count, pc->triangle_count);
        pc->vertex_offset = v;
        pc->triangle_offset = out->triangle_byte_count;
        out->triangle_byte_count += (pc->triangle_count * 3 + 3) & ~3u;
        v += pc->vertex_count;
        t += pc->triangle_count;
    }
    if (v != pi->vertex_count || t != pi->triangle_count)
        return PAGE_ERR("%s: clusters hold %u vertices and %u triangles, the page %u and %u", where, v, t,
                        pi->vertex_count, pi->triangle_count);
    return GDR_OK;
}

/* Where each page vertex stands in the cluster being expanded: cluster[u] == c + 1 once cluster c
 * used it, local[u] its index in that cluster's vertex list. Two arrays, not one record: whether a
 * corner is new then depends only on earlier stores of a constant, not on the list's length, so
 * the corners do not wait on each other through memory. */
typedef struct vertex_marks {
    uint32_t *cluster, *local;
} vertex_marks;

/* yes ? a : b for yes 0 or 1, as arithmetic: compilers turn a ?: on an unpredictable condition
 * (which corner of a triangle is lowest, whether a vertex is new) into a branch that mispredicts. */
static inline uint32_t select_u32(uint32_t yes, uint32_t a, uint32_t b)
{
    uint32_t mask = 0u - yes;
    return (a & mask) | (b & ~mask);
}

static inline uint64_t select_u64(uint32_t yes, uint64_t a, uint64_t b)
{
    uint64_t mask = 0u - (uint64_t)yes;
    return (a & mask) | (b & ~mask);
}

/* Each triangle's page vertex indices put into its canonical rotation in place, whatever rotation
 * the index codec chose (keys: each page vertex's gdr_vertex_bytes_key). Returns the first triangle
 * with a corner beyond the page's vertices (it and those after it are left alone), else the count.
 * A pass of its own: no triangle waits on another. */
static uint32_t rotate_triangles(uint32_t *corners, uint32_t triangle_count, const gdr_page_vertex *unique,
                                 const uint64_t *keys, uint32_t unique_count)
{
    for (uint32_t t = 0; t < triangle_count; t++, corners += 3) {
        uint32_t a = corners[0], b = corners[1], c = corners[2];
        if (a >= unique_count || b >= unique_count || c >= unique_count)
            return t;
        uint64_t ka = keys[a], kb = keys[b], kc = keys[c];
        uint32_t second, third; /* whether the canonical rotation starts at corner b, at corner c */
        if (ka != kb && kb != kc && ka != kc) {
            /* Distinct keys decide alone. */
            second = kb < ka;
            third = kc < select_u64(second, kb, ka);
        } else {
            const gdr_vertex_bytes *v[3] = {(const gdr_vertex_bytes *)&unique[a], (const gdr_vertex_bytes *)&unique[b],
                                            (const gdr_vertex_bytes *)&unique[c]};
            uint32_t first = gdr_triangle_first_corner_keyed(v, (uint64_t[3]){ka, kb, kc});
            second = first == 1, third = first == 2;
        }
        corners[0] = select_u32(third, c, select_u32(second, b, a));
        corners[1] = select_u32(third, a, select_u32(second, c, b));
        corners[2] = select_u32(third, b, select_u32(second, a, c));
    }
    return triangle_count;
}

/* One cluster's vertex list and local triangles from its triangles' page vertex indices: each
 * triangle in its canonical rotation, local indices in order of first use (how the writer's clusters
 * list their vertices). Without a branch on whether a corner is new (a coin toss the predictor
 * loses): every corner's page vertex is written to the next free slot of the list, and only a new
 * one moves the list on. `corners` is rotated in place. */
static gdr_status expand_cluster(const char *where, uint32_t c, uint32_t *corners, const gdr_page_vertex *unique,
                                 const uint64_t *keys, uint32_t unique_count, const vertex_marks *mark, gdr_page *out,
                                 gdr_error *err)
{
    const gdr_page_cluster *pc = &out->clusters[c];
    uint32_t valid = rotate_triangles(corners, pc->triangle_count, unique, keys, unique_count);
    /* A triangle adds at most 3 vertices, and the list is checked against the cluster's count (at
     * most GDR_CLUSTER_MAX_VERTICES) after each. */
    uint32_t list[GDR_CLUSTER_MAX_VERTICES + 3];
    uint8_t *triangles = out->triangles + pc->triangle_offset;
    /* The arrays in locals: a byte store may alias any pointer held in memory. */
    uint32_t *marked = mark->cluster, *local_of = mark->local, seen = 0, stamp = c + 1;
    for (uint32_t t = 0; t < valid; t++) {
        for (uint32_t k = 0; k < 3; k++) {
            uint32_t u = corners[3 * t + k];
            uint32_t fresh = marked[u] != stamp, local = select_u32(fresh, seen, local_of[u]);
            list[seen] = u;
            marked[u] = stamp;
            local_of[u] = local;
            triangles[3 * t + k] = (uint8_t)local;
            seen += fresh;
        }
        if (seen > pc->vertex_count)
            return PAGE_ERR("%s: cluster %u: its triangles use more than its %u vertices", where, c, pc->vertex_count);
    }
    if (valid < pc->triangle_count)
        return PAGE_ERR("%s: cluster %u triangle %u: a vertex beyond the page's %u", where, c, valid, unique_count);
    if (seen != pc->vertex_count)
        return PAGE_ERR("%s: cluster %u: its triangles use %u of its %u vertices", where, c, seen, pc->vertex_count);
    gdr_page_vertex *vertices = out->vertices + pc->vertex_offset;
    for (uint32_t i = 0; i < seen; i++)
        vertices[i] = unique[list[i]];
    return GDR_OK;
}

/* The clusters' vertices and triangles from the page's vertices and triangles (`indices`, used up). */
static gdr_status expand_clusters(const char *where, uint32_t *indices, const gdr_page_vertex *unique,
                                  uint32_t unique_count, gdr_page *out, gdr_error *err)
{
    out->triangles = calloc(out->triangle_byte_count ? out->triangle_byte_count : 1, 1);
    vertex_marks mark = {calloc(unique_count, sizeof *mark.cluster), calloc(unique_count, sizeof *mark.local)};
    uint64_t *keys = malloc(sizeof *keys * unique_count);
    gdr_status status = GDR_OK;
    if (!out->triangles || !mark.cluster || !mark.local || !keys)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: %u triangle bytes", where, out->triangle_byte_count);
    for (uint32_t u = 0; status == GDR_OK && u < unique_count; u++)
        keys[u] = gdr_vertex_bytes_key((const gdr_vertex_bytes *)&unique[u]);
    for (uint32_t c = 0; c < out->cluster_count && status == GDR_OK; c++) {
        status = expand_cluster(where, c, indices, unique, keys, unique_count, &mark, out, err);
        indices += 3 * out->clusters[c].triangle_count;
    }
    free(mark.cluster);
    free(mark.local);
    free(keys);
    return status;
}

/* The grid of a quantized page's vertices, checked as the cache's MESH record is. */
static gdr_status get_grid(const char *where, reader *r, gdr_vertex_quantization *q, gdr_error *err)
{
    *q = (gdr_vertex_quantization){.enabled = 1};
    q->position_exponent = (int32_t)get_u32(r);
    get_f32s(r, &q->position_origin.x, 3);
    q->uv_exponent = (int32_t)get_u32(r);
    get_f32s(r, &q->uv_origin.x, 2);
    uint32_t reserved = get_u32(r);
    if (r->failed || reserved != 0 || q->position_exponent < -126 || q->position_exponent > 100 ||
        q->uv_exponent < -126 || q->uv_exponent > 100 || !finite_floats(&q->position_origin.x, 3) ||
        !finite_floats(&q->uv_origin.x, 2))
        return PAGE_ERR("%s: the vertex grid is malformed", where);
    return GDR_OK;
}

/* A quantized vertex stream into floats. */
static int decode_quantized(gdr_page_vertex *vertices, uint32_t unique, const uint8_t *vstream, uint32_t vs,
                            const gdr_vertex_quantization *grid)
{
    gdr_quantized_vertex *q = malloc(sizeof *q * unique);
    int ok = q && meshopt_decodeVertexBuffer(q, unique, sizeof *q, vstream, vs) == 0;
    if (ok)
        gdr_vertex_decode_many(grid, q, unique, (gdr_vertex_bytes *)vertices);
    free(q);
    return ok;
}

/* Whether none of n floats is an infinity or a NaN (exponent bits not all ones), on their bits:
 * integer work without a branch per float. */
static int finite_float_bits(const float *v, size_t n)
{
    uint32_t bad = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t bits;
        memcpy(&bits, &v[i], sizeof bits);
        bad |= (~bits & 0x7f800000u) == 0;
    }
    return !bad;
}

/* The vertex stream holds the page's `unique` vertices (floats, or integers on `grid` when it is not
 * NULL), the index stream its triangles over them. */
static gdr_status decode_streams(const char *where, reader *r, uint32_t unique, uint32_t vs, uint32_t is,
                                 const gdr_vertex_quantization *grid, const gdr_page_info *pi, gdr_page *out,
                                 gdr_error *err)
{
    const uint8_t *vstream = take(r, vs), *istream = take(r, is);
    gdr_page_vertex *vertices = malloc(sizeof *vertices * unique);
    out->vertices = malloc(sizeof *out->vertices * pi->vertex_count);
    uint32_t *indices = malloc(sizeof *indices * 3 * (size_t)pi->triangle_count);
    gdr_status status = GDR_OK;
    if (!vertices || !out->vertices || !indices)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: %u vertices", where, pi->vertex_count);
    else if (!vstream || !istream || r->at != r->size)
        status = PAGE_ERR("%s: streams of %u and %u bytes do not fill the body", where, vs, is);
    else if (grid ? !decode_quantized(vertices, unique, vstream, vs, grid)
                  : meshopt_decodeVertexBuffer(vertices, unique, sizeof *vertices, vstream, vs) != 0)
        status = PAGE_ERR("%s: vertex stream does not decode", where);
    else if (meshopt_decodeIndexBuffer(indices, 3 * (size_t)pi->triangle_count, 4, istream, is) != 0)
        status = PAGE_ERR("%s: index stream does not decode", where);
    else if (!(grid && gdr_vertex_grid_finite(grid)) &&
             !finite_float_bits(&vertices[0].position.x, (size_t)unique * 8))
        status = PAGE_ERR("%s: a vertex is not finite", where);
    out->vertex_count = pi->vertex_count;
    if (status == GDR_OK)
        status = expand_clusters(where, indices, vertices, unique, out, err);
    free(vertices);
    free(indices);
    return status;
}

gdr_status cache_page_decode(const char *name, uint32_t mesh, uint32_t page, const gdr_paged_mesh *pm,
                             const uint8_t *bytes, size_t size, gdr_page *out, gdr_error *err)
{
    *out = (gdr_page){.mesh = mesh, .page = page};
    char where[320];
    snprintf(where, sizeof where, "%s: mesh %u page %u", name, mesh, page);
    const gdr_page_info *pi = &pm->pages[page];
    uint64_t hash = gdr_io_hash(bytes, size);
    if (size != pi->stored_size || hash != pi->checksum)
        return gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: checksum mismatch (%zu bytes read at offset %llu): the page "
                             "is damaged", where, size, (unsigned long long)pi->offset);
    uint32_t h[8];
    memcpy(h, bytes, sizeof h);
    /* h[4]: the page's own vertices, each shared by the clusters that use it (at most theirs in all). */
    int quantized = (h[1] & PAGE_FLAG_QUANTIZED) != 0;
    size_t vertex_size = quantized ? sizeof(gdr_quantized_vertex) : sizeof(gdr_page_vertex);
    size_t vbound = meshopt_encodeVertexBufferBound(h[4], vertex_size);
    size_t ibound = meshopt_encodeIndexBufferBound(3 * (size_t)pi->triangle_count, h[4]);
    if (h[0] != PAGE_MAGIC || h[1] > (PAGE_FLAG_ZSTD | PAGE_FLAG_QUANTIZED) || h[3] != pi->cluster_count ||
        h[4] == 0 || h[4] > pi->vertex_count || h[5] != pi->triangle_count || h[6] > vbound || h[7] > ibound ||
        (uint64_t)h[2] != (uint64_t)pi->cluster_count * CACHE_PAGE_CLUSTER_RECORD + (quantized ? PAGE_GRID_BLOCK : 0) +
                              h[6] + h[7])
        return PAGE_ERR("%s: bad page header", where);
    const uint8_t *body = NULL;
    uint8_t *owned = NULL;
    gdr_status status = page_body(where, bytes + CACHE_PAGE_HEADER, size - CACHE_PAGE_HEADER, h[1], h[2], &body,
                                  &owned, err);
    if (status != GDR_OK)
        return status;
    reader r = {body, h[2], 0, 0};
    out->clusters = malloc(sizeof *out->clusters * pi->cluster_count);
    out->cluster_count = pi->cluster_count;
    if (!out->clusters)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: %u clusters", where, pi->cluster_count);
    if (status == GDR_OK)
        status = decode_clusters(where, &r, pm, pi, out, err);
    gdr_vertex_quantization grid;
    if (status == GDR_OK && quantized)
        status = get_grid(where, &r, &grid, err);
    if (status == GDR_OK)
        status = decode_streams(where, &r, h[4], h[6], h[7], quantized ? &grid : NULL, pi, out, err);
    free(owned);
    if (status != GDR_OK)
        gdr_page_free(out);
    return status;
}

void gdr_page_free(gdr_page *page)
{
    if (!page)
        return;
    free(page->clusters);
    free(page->vertices);
    free(page->triangles);
    *page = (gdr_page){0};
}
