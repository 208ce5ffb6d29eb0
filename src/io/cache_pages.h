/* Geometry pages of the scene cache (section 'PAGE', docs/CACHE_FORMAT.md): how a mesh's groups
 * are laid out in pages, one page's encoding and its checked decoding, and the page index. Used by
 * the cache writer, the whole-file reader (cache_sections.c) and the paged reader
 * (paged_cache.c). Not part of the public API. */
#ifndef GDR_IO_CACHE_PAGES_H
#define GDR_IO_CACHE_PAGES_H

#include "gdr/paged_cache.h"
#include "io/cache_internal.h"

#define CACHE_PAGES_VERSION 1u
#define CACHE_PAGES_HEADER 32u       /* the section's own header, before the index */
#define CACHE_PAGE_HEADER 32u        /* each page's header, before its (compressed) body */
#define CACHE_PAGE_CLUSTER_RECORD 56u
#define CACHE_PAGE_GROUP_RECORD 40u
#define CACHE_PAGE_INFO_RECORD 40u
/* The most bytes one page may decode to (records, vertices, triangles): what a reader allocates
 * for a page at most. A writer's page is page_bytes (at most GDR_PAGE_BYTES_MAX) plus one group. */
#define CACHE_PAGE_MAX_RAW (64u << 20)

/* Writes the whole section: header, index, pages (every mesh with a LOD DAG is paged; a mesh
 * without one has no groups and no pages). `page_bytes`: the raw bytes a page is filled to. */
void cache_pages_write(writer *w, const gdr_scene *scene, uint32_t page_bytes);

/* One mesh's part of the section, for a writer that takes a scene mesh by mesh: its entry of the
 * index, whose page offsets count from its own first page until cache_pages_rebase adds where that
 * page lies in the section, and its pages' bytes. The section is the header, every mesh's index
 * entry, then every mesh's pages, in mesh order. */
typedef struct cache_mesh_pages {
    writer index;
    writer pages;
    uint32_t page_count;
    size_t page_table; /* where the index entry's page records start */
} cache_mesh_pages;

/* 0 when out of memory (*out then empty). */
int cache_pages_encode_mesh(const gdr_mesh *mesh, uint32_t page_bytes, cache_mesh_pages *out);
void cache_pages_rebase(cache_mesh_pages *mp, uint64_t base);
void cache_pages_free_mesh(cache_mesh_pages *mp);
/* The section's header: the index that follows it has `index_size` bytes and XXH3 `index_hash`. */
void cache_pages_put_header(writer *w, uint32_t mesh_count, uint32_t page_bytes, uint64_t index_size,
                            uint64_t index_hash);

/* The page index of a section, checked: offsets (made absolute by adding `section_offset`) lie in
 * the section after the index, in order, without overlap; every group sits in exactly one page,
 * which names it; counts agree. `meshes` gets mesh_count entries (freed with
 * cache_pages_free_index). `head` is the section's first CACHE_PAGES_HEADER bytes. */
gdr_status cache_pages_parse_header(const char *name, const uint8_t *head, uint64_t section_size,
                                    uint32_t *mesh_count, uint64_t *index_size, uint64_t *index_hash,
                                    gdr_error *err);
gdr_status cache_pages_parse_index(const char *name, const uint8_t *index, uint64_t index_size,
                                   uint32_t mesh_count, uint64_t section_offset, uint64_t section_size,
                                   gdr_paged_mesh **meshes, gdr_error *err);
void cache_pages_free_index(gdr_paged_mesh *meshes, uint32_t mesh_count);

/* Checks and decodes the stored bytes of page `page` of mesh `mesh` (its checksum included). */
gdr_status cache_page_decode(const char *name, uint32_t mesh, uint32_t page, const gdr_paged_mesh *pm,
                             const uint8_t *bytes, size_t size, gdr_page *out, gdr_error *err);

#endif
