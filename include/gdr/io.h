/* gdr io: importers (glTF 2.0, GLB, OBJ) and the processed-scene cache (.gdrc).
 *
 * Every importer treats its input as untrusted: each index, offset, count and length is checked
 * before use, and errors name the file and the place in it, e.g.
 *   "box.gltf: accessors[3].count: exceeds bufferView 2 length".
 * A file that loads but not exactly as written (lines skipped, bad normals regenerated, ...)
 * reports warnings through gdr_import_options.warning (NULL: printed to stderr as
 * "gdr: warning: ..."); the number of warnings is returned in gdr_import_result.
 *
 * The cache format is described in docs/CACHE_FORMAT.md, the importers in docs/IMPORT.md. */
#ifndef GDR_IO_H
#define GDR_IO_H

#include <stddef.h>
#include <stdint.h>

#include "gdr/core.h"
#include "gdr/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* --- source files -------------------------------------------------------------------------- */

/* A file an import read: its identity is what makes a cache stale. */
typedef struct gdr_source_file {
    char *path;        /* absolute (realpath) when it can be resolved, else as opened */
    uint64_t size;     /* bytes */
    int64_t mtime_ns;  /* modification time, nanoseconds since the epoch */
    uint64_t hash;     /* XXH3-64 of the contents */
} gdr_source_file;

typedef struct gdr_source_list {
    gdr_source_file *files;
    uint32_t count, capacity;
} gdr_source_list;

GDR_API void gdr_source_list_free(gdr_source_list *list);

/* --- importers ------------------------------------------------------------------------------ */

/* Zero-initialise; every field has a default. */
typedef struct gdr_import_options {
    gdr_warning_fn warning; /* NULL: "gdr: warning: <message>" on stderr */
    void *warning_user;
    int no_progress;          /* 1: no progress bar (default: shown on a terminal for long work) */
    gdr_source_list *sources; /* optional: receives every file read (the source and its buffers,
                                 images), for the cache's staleness check */
    gdr_budget budget;        /* limits for untrusted files (gdr/scene.h); zero: the defaults */
    int allow_outside_files;  /* 1: external URIs may leave the file's folder (absolute paths, '..',
                                 symlinks pointing out); 0 (default): such a URI is refused */
} gdr_import_options;

typedef struct gdr_import_result {
    uint32_t warning_count;
} gdr_import_result;

/* Imports a .gltf or .glb file (told apart by content: GLB starts with "glTF"). External
 * buffers and images are resolved relative to the file's folder. result may be NULL. */
GDR_API gdr_status gdr_import_gltf(const char *path, const gdr_import_options *options, gdr_scene **out,
                                   gdr_import_result *result, gdr_error *err);

/* Imports glTF JSON or GLB from memory. `name` is used in messages; `base_dir` resolves external
 * URIs (NULL: external URIs are refused, only data: URIs and the GLB chunk are used). */
GDR_API gdr_status gdr_import_gltf_memory(const void *data, size_t size, const char *name, const char *base_dir,
                                          const gdr_import_options *options, gdr_scene **out,
                                          gdr_import_result *result, gdr_error *err);

/* Imports a Wavefront .obj file: v/vt/vn/f, polygons fan-triangulated, negative indices, one mesh
 * per group/object (g, o) and one instance of each with the identity transform. */
GDR_API gdr_status gdr_import_obj(const char *path, const gdr_import_options *options, gdr_scene **out,
                                  gdr_import_result *result, gdr_error *err);
GDR_API gdr_status gdr_import_obj_memory(const void *data, size_t size, const char *name,
                                         const gdr_import_options *options, gdr_scene **out,
                                         gdr_import_result *result, gdr_error *err);

/* Decodes a PNG or JPEG (anything stb_image reads) into RGBA8. *out_rgba is malloc'ed. */
GDR_API gdr_status gdr_image_decode(const void *data, size_t size, const char *name, uint8_t **out_rgba,
                                    uint32_t *out_width, uint32_t *out_height, gdr_error *err);

/* --- processed-scene cache ------------------------------------------------------------------ */

#define GDR_CACHE_FORMAT_VERSION 8u

/* What a cache was built from: the build options (a string that changes whenever the processing
 * would produce different data, e.g. "import=1") and the source files. */
typedef struct gdr_cache_source {
    const char *build_options;
    const gdr_source_list *files; /* NULL or empty for the built-in demo scene */
} gdr_cache_source;

/* Precomputed visibility (include/gdr/cull.h): baked offline for a scene's instances (object i =
 * instance i), it is stored in the cache next to the scene, not in gdr_scene (which stays plain
 * arrays with no culling dependency). Write it with gdr_cache_write (options->pvs), get it back with
 * gdr_cache_read or gdr_scene_load_file (out_pvs). */
typedef struct gdr_pvs gdr_pvs;

/* What gdr_cache_write stores next to the scene; zero-initialise (or pass NULL): every field has a
 * default. */
typedef struct gdr_cache_write_options {
    gdr_cache_source source; /* build options and source files; empty: none recorded, never stale */
    const gdr_pvs *pvs;      /* NULL: no precomputed visibility. Otherwise its serialised form in the
                                optional section 'PVIS'; it must have been baked for this scene
                                (gdr_pvs_object_count(pvs) == scene->instance_count), else
                                GDR_ERROR_INVALID_ARGUMENT and nothing is written */
    uint32_t page_bytes;     /* 0: no geometry pages. Otherwise the optional section 'PAGE' holds every
                                mesh's LOD DAG groups in pages filled to this many raw bytes, in
                                [GDR_PAGE_BYTES_MIN, GDR_PAGE_BYTES_MAX] (gdr/paged_cache.h;
                                GDR_PAGE_BYTES_DEFAULT is the measured choice), read on demand by
                                gdr_paged_cache_open; out of range: GDR_ERROR_INVALID_ARGUMENT */
} gdr_cache_write_options;

/* Writes scene to path through a temporary file in the same folder and a rename. options: NULL for
 * the defaults. */
GDR_API gdr_status gdr_cache_write(const char *path, const gdr_scene *scene, const gdr_cache_write_options *options,
                                   gdr_error *err);

/* Reads a whole regular file of at most max_size bytes into *out (malloc'ed, one NUL byte after the
 * data, which may hold NUL bytes of its own). A FIFO, device, socket or directory is refused at once
 * ("not a regular file"), never waited on; a larger file is refused before it is read. For the
 * program's small inputs (camera paths, results files). */
GDR_API gdr_status gdr_read_file(const char *path, size_t max_size, char **out, size_t *out_size, gdr_error *err);

/* Reads a cache as it stands. Checks magic, version, every size, offset and checksum. When
 * build_options is not NULL, a cache built with different options is refused (stale). The files its
 * source list names are never opened (they are compared only when gdr_scene_load_file reads the
 * cache for its source). On GDR_OK, *out is the scene and, when out_pvs is not
 * NULL, *out_pvs the precomputed visibility (a gdr_pvs the caller destroys with gdr_pvs_destroy),
 * or NULL when the cache holds none. Either way a 'PVIS' section is checked (gdr_pvs_load, and its
 * object count against the scene's instances): a damaged one makes the whole cache refused,
 * naming the section. */
GDR_API gdr_status gdr_cache_read(const char *path, const char *build_options, gdr_scene **out, gdr_pvs **out_pvs,
                                  gdr_error *err);

/* Reads a cache with geometry pages for streaming (gdr_renderer_set_scene_streamed): the header, the
 * table and, each with a positioned read and its checksum checked, every section but the geometry
 * the pages hold too (vertices, indices, vertex colours, cluster vertex lists and triangles, the
 * pages). The scene has every mesh's counts, bounds, cluster and group records and LOD hierarchy,
 * the materials, textures, instances and cameras, and scene->geometry_in_pages set: its meshes hold
 * no vertex or index arrays. Staleness as in gdr_cache_read. A cache without pages is refused
 * (GDR_ERROR_INVALID_ARGUMENT). out_bytes_read (may be NULL): the bytes read from the file. */
GDR_API gdr_status gdr_cache_read_for_streaming(const char *path, const char *build_options, gdr_scene **out,
                                                uint64_t *out_bytes_read, gdr_error *err);

/* Parses a cache from memory without any staleness check (the fuzz target uses this); out_pvs as
 * in gdr_cache_read. */
GDR_API gdr_status gdr_cache_read_memory(const void *data, size_t size, const char *name, gdr_scene **out,
                                         gdr_pvs **out_pvs, gdr_error *err);

/* The cache path used for a source: SOURCE.gdrc next to it, or in cache_dir (named after a hash
 * of the absolute source path) when cache_dir is given. Returns the length written, or 0 when
 * it does not fit. */
GDR_API size_t gdr_cache_path_for(const char *source_path, const char *cache_dir, char *out, size_t out_size);

/* The build options string of this version of the importers. */
GDR_API const char *gdr_cache_build_options(void);

/* Imports any supported source file (.gltf, .glb, .obj by extension) without the cache, and
 * builds every mesh's clusters (gdr_scene_build_clusters, include/gdr/geometry.h). */
GDR_API gdr_status gdr_import_file(const char *path, const gdr_import_options *options, gdr_scene **out,
                                   gdr_import_result *result, gdr_error *err);

/* A source file (.gltf, .glb, .obj) through the cache, or a .gdrc file directly: what
 * gdr_scene_load does for paths. See gdr_load_options in scene.h (NULL: defaults). Every mesh of
 * the scene has its clusters: read from the cache, or built (a cache written from a scene without
 * them). When out_pvs is not NULL, *out_pvs is the precomputed visibility of the cache the scene
 * was read from, a gdr_pvs to destroy with gdr_pvs_destroy, or NULL (an import, or a cache without
 * one). A stale cache is rebuilt from the source without it (the bake is not redone). */
GDR_API gdr_status gdr_scene_load_file(const char *path, const gdr_load_options *options, gdr_scene **out,
                                       gdr_pvs **out_pvs, gdr_error *err);

#ifdef __cplusplus
}
#endif
#endif
