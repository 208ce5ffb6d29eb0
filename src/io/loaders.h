/* The loaders behind gdr_scene_load (gdr/io.h), for the library, its tests and benchmarks: the
 * importers of each format, the cache's readers and the path loader. Applications call
 * gdr_scene_load. */
#ifndef GDR_IO_LOADERS_H
#define GDR_IO_LOADERS_H

#include <limits.h>
#include <stddef.h>
#include <stdint.h>

#include "gdr/io.h"
#include "gdr/procedural.h"

/* --- importers ------------------------------------------------------------------------------ */

/* Zero-initialise; every field has a default. */
typedef struct gdr_import_options {
    gdr_warning_fn warning; /* NULL: "gdr: warning: <message>" on stderr */
    void *warning_user;
    int no_progress;          /* 1: no progress bar (default: shown on a terminal for long work) */
    gdr_source_list *sources; /* optional: receives every file read (the source and its buffers,
                                 images) and every path looked at where none could be read, for the
                                 cache's staleness check */
    gdr_budget budget;        /* limits for untrusted files (gdr/scene.h); zero: the defaults */
    int allow_outside_files;  /* 1: external URIs may leave the file's folder (absolute paths, '..',
                                 symlinks pointing out); 0 (default): such a URI is refused */
} gdr_import_options;

typedef struct gdr_import_result {
    uint32_t warning_count;
    uint32_t file_cameras; /* camera placements in the file (nodes with a camera), used or not */
} gdr_import_result;

/* Imports a .gltf or .glb file (told apart by content: GLB starts with "glTF"). External
 * buffers and images are resolved relative to the file's folder. result may be NULL. */
gdr_status gdr_import_gltf(const char *path, const gdr_import_options *options, gdr_scene **out,
                                   gdr_import_result *result, gdr_error *err);

/* Imports glTF JSON or GLB from memory. `name` is used in messages; `base_dir` resolves external
 * URIs (NULL: external URIs are refused, only data: URIs and the GLB chunk are used). */
gdr_status gdr_import_gltf_memory(const void *data, size_t size, const char *name, const char *base_dir,
                                          const gdr_import_options *options, gdr_scene **out,
                                          gdr_import_result *result, gdr_error *err);

/* Imports a Wavefront .obj file: v/vt/vn/f, polygons fan-triangulated, negative indices, one mesh
 * per group/object (g, o) and one instance of each with the identity transform. */
gdr_status gdr_import_obj(const char *path, const gdr_import_options *options, gdr_scene **out,
                                  gdr_import_result *result, gdr_error *err);
gdr_status gdr_import_obj_memory(const void *data, size_t size, const char *name,
                                         const gdr_import_options *options, gdr_scene **out,
                                         gdr_import_result *result, gdr_error *err);

/* Reads a cache as it stands. Checks magic, version, every size, offset and checksum. When
 * build_options is not NULL, a cache built with different options is refused (stale). The files its
 * source list names are never opened (they are compared only when gdr_scene_load_file reads the
 * cache for its source). On GDR_OK, *out is the scene and, when out_pvs is not
 * NULL, *out_pvs the precomputed visibility (a gdr_pvs the caller destroys with gdr_pvs_destroy),
 * or NULL when the cache holds none. Either way a 'PVIS' section is checked (gdr_pvs_load, and its
 * object count against the scene's instances): a damaged one makes the whole cache refused,
 * naming the section. */
gdr_status gdr_cache_read(const char *path, const char *build_options, gdr_scene **out, gdr_pvs **out_pvs,
                                  gdr_error *err);

/* Reads a cache with geometry pages for streaming (gdr_renderer_set_scene_streamed): the header, the
 * table and, each with a positioned read and its checksum checked, every section but the geometry
 * the pages hold too (vertices, indices, vertex colours, cluster vertex lists and triangles, the
 * pages). The scene has every mesh's counts, bounds, cluster and group records and LOD hierarchy,
 * the materials, textures, instances and cameras, and scene->geometry_in_pages set: its meshes hold
 * no vertex or index arrays. Staleness as in gdr_cache_read. A cache without pages is refused
 * (GDR_ERROR_INVALID_ARGUMENT). out_pvs as in gdr_cache_read (the 'PVIS' section is read too).
 * out_bytes_read (may be NULL): the bytes read from the file. */
gdr_status gdr_cache_read_for_streaming(const char *path, const char *build_options, gdr_scene **out,
                                        gdr_pvs **out_pvs, uint64_t *out_bytes_read, gdr_error *err);

/* Streaming from a source file or a built-in scene (load_paged.c): the scene read for streaming from
 * its paged cache, built (quantized, with pages) where no fresh one is found. `candidates` are the
 * loader's cache files for the source, in order (a built-in scene: NULL, the candidate is made
 * from options->cache_dir or the per-user cache folder); the paged cache sits beside each, named
 * FILE.pages.gdrc. Its path goes to options->cache_path; the import's warnings, said when it is
 * built, are kept in it and said again when it is read (into `report`, which may be NULL). */
gdr_status gdr_io_load_paged(const char *spec, const gdr_load_options *options, char (*candidates)[PATH_MAX], int count,
                             gdr_scene **out, gdr_pvs **out_pvs, gdr_import_report *report, gdr_error *err);

/* Whether `spec` names the built-in unique-field scene (*is_unique), its options then parsed into *d
 * (a bad option: GDR_ERROR_INVALID_ARGUMENT, as gdr_scene_load says it). */
gdr_status gdr_io_unique_field_spec(const char *spec, gdr_unique_field_desc *d, bool *is_unique, gdr_error *err);

/* A scene's paged cache made mesh by mesh (paged_build.c): the unique field one mesh at a time,
 * any other scene made or imported whole first (as gdr_scene_load would: clusters and LOD DAG),
 * then each mesh taken out of it, moved onto its grid, written and freed. */
typedef struct gdr_io_paged_source {
    gdr_scene *skeleton;          /* every part but the meshes' geometry (or, whole, the scene itself) */
    gdr_unique_field_desc unique; /* with `generated` */
    int generated;                /* 1: the unique field, each mesh made when it is written */
} gdr_io_paged_source;

/* Makes the source: a built-in scene (`builtin`), or an imported file whose files are listed in
 * *sources and whose warnings go to *report. */
gdr_status gdr_io_paged_source_open(const char *spec, const gdr_load_options *o, bool builtin,
                                    gdr_io_paged_source *src, gdr_source_list *sources, gdr_import_report *report,
                                    gdr_error *err);
/* Writes it to path with gdr_cache_write_meshes (`write` with page_bytes set); once only: a scene
 * made whole gives its meshes away while it is written. threads 0: one per processor. */
gdr_status gdr_io_paged_source_write(gdr_io_paged_source *src, const char *path, const gdr_cache_write_options *write,
                                     uint32_t threads, int no_progress, gdr_error *err);
void gdr_io_paged_source_close(gdr_io_paged_source *src);

/* Parses a cache from memory without any staleness check (the fuzz target uses this); out_pvs as
 * in gdr_cache_read. */
gdr_status gdr_cache_read_memory(const void *data, size_t size, const char *name, gdr_scene **out,
                                         gdr_pvs **out_pvs, gdr_error *err);

/* Imports any supported source file (.gltf, .glb, .obj by extension) without the cache, builds
 * every mesh's clusters (gdr_scene_build_clusters, include/gdr/geometry.h) and compresses its
 * textures (gdr_scene_compress_textures). */
gdr_status gdr_import_file(const char *path, const gdr_import_options *options, gdr_scene **out,
                                   gdr_import_result *result, gdr_error *err);

/* A source file (.gltf, .glb, .obj) through the cache, or a .gdrc file directly: what
 * gdr_scene_load does for paths. See gdr_load_options in gdr/io.h (NULL: defaults). Every mesh of
 * the scene has its clusters: read from the cache, or built (a cache written from a scene without
 * them). When out_pvs is not NULL, *out_pvs is the precomputed visibility of the cache the scene
 * was read from, a gdr_pvs to destroy with gdr_pvs_destroy, or NULL (an import, or a cache without
 * one). A stale cache is rebuilt from the source without it (the bake is not redone). */
gdr_status gdr_scene_load_file(const char *path, const gdr_load_options *options, gdr_scene **out,
                                       gdr_pvs **out_pvs, gdr_error *err);

#endif
