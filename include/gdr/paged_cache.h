/* gdr paged cache: a scene cache's geometry in pages, read on demand (docs/CACHE_FORMAT.md,
 * section 'PAGE'; docs/STREAMING.md).
 *
 * A cache written with gdr_cache_write_options.page_bytes holds, next to the rest of the scene (and
 * the whole geometry only with whole_geometry), every mesh's LOD DAG groups in pages: a page holds
 * whole groups (coarsest first, so a mesh's page 0 holds its root group), compressed
 * (meshoptimizer's vertex and index codecs, then zstd where it pays) and checksummed on its own.
 * gdr_paged_cache_open reads only the file's header, section table, instances and the page index
 * (group headers and where every page lies); pages are read one at a time with positioned reads
 * (pread), each checked before it is decoded. The file is untrusted: every count, offset and index
 * is checked, and a damaged page is refused with an error naming the file, the mesh and the page,
 * while the other pages stay readable. */
#ifndef GDR_PAGED_CACHE_H
#define GDR_PAGED_CACHE_H

#include <stdint.h>

#include "gdr/core.h"
#include "gdr/math.h"
#include "gdr/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The default page size: the raw (decoded) bytes a page is filled to before the next group starts
 * a new one; chosen by measurement (docs/CACHE_FORMAT.md, "Page size"). */
#define GDR_PAGE_BYTES_DEFAULT (128u << 10)
#define GDR_PAGE_BYTES_MIN (4u << 10)
#define GDR_PAGE_BYTES_MAX (16u << 20)

/* A group's header, resident from the open on: what the traversal and the page table need. */
typedef struct gdr_page_group {
    gdr_vec4 sphere;        /* mesh space */
    float error;            /* mesh space; INFINITY for the root group */
    uint32_t depth;         /* DAG depth */
    uint32_t cluster_count; /* clusters in the group */
    uint32_t page;          /* the page holding it */
    uint32_t parent_first;  /* the groups made from it (holding clusters whose refined group it is): */
    uint32_t parent_count;  /* gdr_paged_mesh.parents[parent_first .. + parent_count), each deeper */
} gdr_page_group;

/* Where one page lies and what it holds. */
typedef struct gdr_page_info {
    uint64_t offset;        /* from the start of the file */
    uint32_t stored_size;   /* bytes in the file */
    uint32_t first;         /* its groups: gdr_paged_mesh.page_groups[first .. first + group_count) */
    uint32_t group_count;
    uint32_t cluster_count;
    uint32_t vertex_count;  /* decoded vertices (each cluster's own, shared ones repeated) */
    uint32_t triangle_count;
    uint64_t checksum;      /* XXH3-64 of the stored bytes */
} gdr_page_info;

typedef struct gdr_paged_mesh {
    uint32_t group_count, page_count;
    uint32_t source_triangles;   /* triangles of the mesh's level 0 (the DAG's input) */
    gdr_page_group *groups;      /* group_count */
    uint32_t *page_groups;       /* group indices in page order (pages hold consecutive runs) */
    uint32_t *parents;           /* parent_count: the DAG's edges, child to parent groups */
    uint32_t parent_count;
    gdr_page_info *pages;        /* page_count; page 0 holds the root group: always resident */
} gdr_paged_mesh;

/* One decoded cluster of a page. */
typedef struct gdr_page_cluster {
    uint32_t group;           /* mesh-local group it is part of */
    uint32_t refined_group;   /* mesh-local group it was made from, GDR_NO_INDEX for level 0 */
    uint32_t vertex_offset;   /* first vertex in gdr_page.vertices */
    uint32_t vertex_count;    /* 1 .. GDR_CLUSTER_MAX_VERTICES */
    uint32_t triangle_offset; /* first byte in gdr_page.triangles, a multiple of 4 */
    uint32_t triangle_count;  /* 1 .. GDR_CLUSTER_MAX_TRIANGLES */
    gdr_vec4 sphere;
    gdr_vec3 cone_apex, cone_axis;
    float cone_cutoff;
} gdr_page_cluster;

/* One vertex as the GPU reads it (GdrGpuVertex). */
typedef struct gdr_page_vertex {
    gdr_vec3 position, normal;
    gdr_vec2 uv;
} gdr_page_vertex;

/* A decoded page: its groups' clusters in page order, each with its own vertices and its local
 * triangles (3 bytes each, below the cluster's vertex_count; zero bytes up to a multiple of 4). */
typedef struct gdr_page {
    uint32_t mesh, page;
    gdr_page_cluster *clusters;
    uint32_t cluster_count;
    gdr_page_vertex *vertices;
    uint32_t vertex_count;
    uint8_t *triangles;
    uint32_t triangle_byte_count;
} gdr_page;

typedef struct gdr_paged_cache gdr_paged_cache;

/* Opens `path`: checks the container (magic, version, header, table, file size) and reads,
 * checking each section's checksum, the instances and the page index. Nothing else is read.
 * A cache without pages is refused ("has no geometry pages; write it with page_bytes"). */
GDR_API gdr_status gdr_paged_cache_open(const char *path, gdr_paged_cache **out, gdr_error *err);
GDR_API void gdr_paged_cache_close(gdr_paged_cache *cache);

/* The path it was opened with, for messages. */
GDR_API const char *gdr_paged_cache_path(const gdr_paged_cache *cache);
GDR_API uint32_t gdr_paged_cache_mesh_count(const gdr_paged_cache *cache);
GDR_API const gdr_paged_mesh *gdr_paged_cache_mesh(const gdr_paged_cache *cache, uint32_t mesh);
GDR_API const gdr_instance *gdr_paged_cache_instances(const gdr_paged_cache *cache, uint32_t *count);
/* Bytes read from the file so far (header, table, sections, pages): what the open cost. */
GDR_API uint64_t gdr_paged_cache_bytes_read(const gdr_paged_cache *cache);
/* The page bytes the file holds (the 'PAGE' section), for bytes per source triangle. */
GDR_API uint64_t gdr_paged_cache_page_bytes(const gdr_paged_cache *cache);
/* 1 when the pages hold the only copy of the geometry (the file has no whole geometry beside them:
 * gdr_cache_write_options.whole_geometry was 0), so that the file is read for streaming only. */
GDR_API int gdr_paged_cache_pages_only(const gdr_paged_cache *cache);

/* Reads page `page` of mesh `mesh` with one positioned read, checks its checksum and every count,
 * offset and index in it, and decodes it into *out (freed with gdr_page_free). Safe to call from
 * several threads at once. A damaged page: GDR_ERROR_PARSE, "FILE: mesh M page P: ...". */
GDR_API gdr_status gdr_paged_cache_read_page(gdr_paged_cache *cache, uint32_t mesh, uint32_t page, gdr_page *out,
                                             gdr_error *err);
GDR_API void gdr_page_free(gdr_page *page);
/* Checks that the cache's pages describe `scene` (read from the same file with
 * gdr_cache_read_for_streaming): the same mesh count, each mesh's LOD groups, and each page's
 * clusters as the sum of its groups'. What streaming (gdr_renderer_set_scene_streamed) checks before
 * sizing anything from the pages; `path` names the file in the error (GDR_ERROR_INVALID_ARGUMENT). */
GDR_API gdr_status gdr_paged_cache_check_scene(const gdr_paged_cache *cache, const gdr_scene *scene, const char *path,
                                               gdr_error *err);

#ifdef __cplusplus
}
#endif
#endif
