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

/* What an import found at a path it looked at. */
typedef enum gdr_source_state {
    GDR_SOURCE_READ = 0,   /* a regular file, read: size, time and hash are its own */
    GDR_SOURCE_ABSENT = 1, /* nothing there (size, time and hash 0) */
    GDR_SOURCE_UNREAD = 2, /* something there that was not read (not a regular file, no permission,
                              a link out of the folder): size and time as stat gave them, hash 0 */
} gdr_source_state;

/* A file an import looked for, found or not: its identity is what makes a cache stale (adding,
 * removing or changing any of them rebuilds the cache). */
typedef struct gdr_source_file {
    char *path;        /* absolute (realpath) when it can be resolved, else as opened */
    uint64_t size;     /* bytes */
    int64_t mtime_ns;  /* modification time, nanoseconds since the epoch */
    uint64_t hash;     /* XXH3-64 of the contents */
    gdr_source_state state;
} gdr_source_file;

typedef struct gdr_source_list {
    gdr_source_file *files;
    uint32_t count, capacity;
} gdr_source_list;

GDR_API void gdr_source_list_free(gdr_source_list *list);

/* Precomputed visibility (include/gdr/cull.h): baked offline for a scene's instances (object i =
 * instance i), it is stored in the cache next to the scene, not in gdr_scene (which stays plain
 * arrays with no culling dependency). Write it with gdr_cache_write (options->pvs), get it back with
 * gdr_scene_load (gdr_load_options.pvs). A library without the culling module (gdr/config.h:
 * GDR_HAVE_CULL 0) neither reads nor writes one: a cache's section is skipped and no PVS returned. */
typedef struct gdr_pvs gdr_pvs;

/* --- Options shared by every loader ------------------------------------------------------ */

/* Warnings from importers (a file that loads, but not entirely as written): `message` names the
 * file and the place, e.g. "box.gltf: meshes[0].primitives[1]: mode 1 (lines) skipped". */
typedef void (*gdr_warning_fn)(void *user, const char *message);

/* Limits on what one untrusted scene or cache file may make gdr do (docs/SECURITY.md). Each is
 * checked before the memory it bounds is allocated; a file over one is refused with an error that
 * names the budget and the option that raises it. Zero-initialise: 0 takes the default below. */
typedef struct gdr_budget {
    uint64_t triangles;      /* triangles over all meshes as read (before duplicates are dropped);
                                0: GDR_DEFAULT_MAX_TRIANGLES */
    uint64_t instances;      /* instances the file creates; 0: GDR_DEFAULT_MAX_INSTANCES */
    uint64_t texture_pixels; /* pixels over all decoded images; 0: GDR_DEFAULT_MAX_TEXTURE_PIXELS */
    uint64_t decoded_bytes;  /* bytes made by decoding (base64 data: URIs, EXT_meshopt_compression
                                views, accessors without a bufferView); 0: GDR_DEFAULT_MAX_DECODED_BYTES */
} gdr_budget;

#define GDR_DEFAULT_MAX_TRIANGLES (1ull << 26)      /* 67,108,864 */
#define GDR_DEFAULT_MAX_INSTANCES (1ull << 22)      /* 4,194,304 */
#define GDR_DEFAULT_MAX_TEXTURE_PIXELS (1ull << 27) /* 134,217,728: 512 MiB of RGBA8 */
#define GDR_DEFAULT_MAX_DECODED_BYTES (1ull << 31)  /* 2 GiB */

/* The budget with every 0 replaced by its default. */
GDR_API gdr_budget gdr_budget_resolve(const gdr_budget *budget);

/* What an import said about a file, kept in its cache so that every later run says it again.
 * Zero-initialise; free with gdr_import_report_free. */
typedef struct gdr_import_report {
    char **warnings;         /* the warnings, in order (at most GDR_REPORT_MAX_WARNINGS kept) */
    uint32_t warning_count;  /* entries of warnings[] */
    uint32_t warning_total;  /* warnings given, >= warning_count */
    uint32_t warning_capacity;
    uint32_t file_cameras;   /* camera placements of the file (nodes with a camera), used or not */
    /* Filled by gdr_scene_load for a source file: */
    char *cache_path;        /* the cache read or written (malloc'ed), NULL when none */
    int cache_state;         /* GDR_CACHE_NONE, _READ, _WRITTEN or _NOT_WRITTEN */
} gdr_import_report;

enum { GDR_CACHE_NONE = 0, GDR_CACHE_READ = 1, GDR_CACHE_WRITTEN = 2, GDR_CACHE_NOT_WRITTEN = 3 };

#define GDR_REPORT_MAX_WARNINGS 1024u
#define GDR_REPORT_MAX_WARNING_BYTES 511u /* a stored warning's longest text */

GDR_API void gdr_import_report_free(gdr_import_report *report);

/* The per-user cache folder's size limit when none is given: GDR_CACHE_MAX_MIB from the
 * environment, else this. */
#define GDR_CACHE_DEFAULT_MAX_BYTES (4ull << 30)

/* Options of gdr_scene_load; zero-initialise, every field has a default. */
typedef struct gdr_load_options {
    int no_cache;          /* 1: import the source, never read or write a .gdrc cache */
    const char *cache_dir; /* NULL: the per-user folder ($XDG_CACHE_HOME/gdr, else ~/.cache/gdr,
                              gdr_cache_default_dir), names keyed by the source's absolute path;
                              ".": next to the source (FILE.gdrc); else that folder, keyed alike */
    uint64_t cache_max_bytes; /* a cache folder's size limit: after a write, the least recently used
                              caches gdr wrote there are removed until the folder's caches fit
                              (never the one just written; not for "."); 0: GDR_CACHE_MAX_MIB
                              from the environment, else GDR_CACHE_DEFAULT_MAX_BYTES */
    int no_progress;       /* 1: never draw a progress bar (default: on a terminal only) */
    gdr_warning_fn warning; /* NULL: warnings go to stderr as "gdr: warning: ..." */
    void *warning_user;
    gdr_budget budget;      /* limits for untrusted files; zero: the defaults */
    int allow_outside_files; /* 1: a glTF may name buffers and images outside its own folder
                                (absolute paths, '..', symlinks out); 0: refused */
    int geometry_in_pages;   /* 1: for streaming, a .gdrc with geometry pages is read without the
                                geometry its pages hold (the pages are read by gdr_paged_cache_open); a
                                source file or built-in scene is read so from its paged cache, built
                                first where none is fresh (quantized, with pages: as gdr build --pages;
                                beside the loader's cache for the source, named FILE.pages.gdrc; a
                                built-in scene's in cache_dir or the per-user folder); no_cache refuses
                                a source file */
    char *cache_path;        /* non-NULL, with geometry_in_pages: receives the path of the .gdrc read
                                (cache_path_size bytes at most), to open with gdr_paged_cache_open */
    size_t cache_path_size;
    gdr_pvs **pvs;           /* non-NULL: receives the precomputed visibility of the cache the scene
                                was read from (gdr_pvs_destroy frees it), or NULL when there is none
                                (a built-in scene, an import, a cache without one, a library
                                without the culling module) */
    gdr_source_list *sources; /* non-NULL: receives every file an import read (the source, its
                                buffers and images), for gdr_cache_write; empty when the scene came
                                from a cache or is built in. Free it with gdr_source_list_free */
    gdr_import_report *report; /* non-NULL: receives the import's warnings and camera count (from the
                                cache on a cached run) and where the cache is; the caller frees it
                                with gdr_import_report_free. The warnings are also given to
                                `warning` as they are said, on every run, cached or not */
} gdr_load_options;

/* --- images ------------------------------------------------------------------------------- */

/* Decodes a PNG or JPEG (told by its signature; other formats are refused) into RGBA8, within
 * GDR_DEFAULT_MAX_DECODED_BYTES of decoder memory besides the result. *out_rgba is malloc'ed. */
GDR_API gdr_status gdr_image_decode(const void *data, size_t size, const char *name, uint8_t **out_rgba,
                                    uint32_t *out_width, uint32_t *out_height, gdr_error *err);

/* --- texture compression ------------------------------------------------------------------ */

/* libsquish's colour fits for BC1 and BC3's colour, fastest first (docs/MATERIALS.md has what each
 * costs and gives on real textures); BC4 and BC5 have one encoder. */
#define GDR_TEXTURE_FIT_RANGE 1u
#define GDR_TEXTURE_FIT_CLUSTER 2u
#define GDR_TEXTURE_FIT_ITERATIVE 3u
#define GDR_TEXTURE_FIT_DEFAULT GDR_TEXTURE_FIT_RANGE

/* Options of gdr_scene_compress_textures; zero-initialise, every field has a default. */
typedef struct gdr_texture_compress_options {
    uint32_t fit;          /* a GDR_TEXTURE_FIT_*; 0: GDR_TEXTURE_FIT_DEFAULT */
    uint32_t thread_count; /* encoding threads; 0: one per online processor */
    uint32_t metallic_roughness_format; /* GDR_TEXTURE_BC5_GB (0: the default) or GDR_TEXTURE_BC1 */
} gdr_texture_compress_options;

/* Stores every RGBA8 texture that a material uses in a BC format chosen by its uses (gdr/scene.h,
 * gdr_texture_format): colour (base colour, emissive) BC1, or BC3 where a MASK or BLEND material
 * reads the base colour's alpha and the image has some; a normal map BC5 (x, y; the shaders
 * rebuild z); occlusion alone BC4; metallic-roughness alone BC5_GB; several uses of one image
 * the smallest format holding the channels they read (an occlusion-roughness-metallic image: BC1).
 * Every level of the existing mip chain is encoded. Textures no material uses stay RGBA8.
 * gdr_scene_load does this for every import; procedural scenes are not compressed. */
GDR_API gdr_status gdr_scene_compress_textures(gdr_scene *scene, const gdr_texture_compress_options *options,
                                               gdr_error *err);

/* Decodes level `level` of t into rgba (its w x h RGBA8 texels) as a device samples the texture's
 * format (gdr/scene.h); an RGBA8 texture's level is copied. */
GDR_API gdr_status gdr_texture_decode_level(const gdr_texture *t, uint32_t level, uint8_t *rgba, gdr_error *err);

/* --- processed-scene cache ------------------------------------------------------------------ */

#define GDR_CACHE_FORMAT_VERSION 12u

/* What a cache was built from: the build options (a string that changes whenever the processing
 * would produce different data, e.g. "import=1") and the source files. */
typedef struct gdr_cache_source {
    const char *build_options;
    const gdr_source_list *files; /* NULL or empty for the built-in demo scene */
} gdr_cache_source;

/* What gdr_cache_write stores next to the scene; zero-initialise (or pass NULL): every field has a
 * default. */
typedef struct gdr_cache_write_options {
    gdr_cache_source source; /* build options and source files; empty: none recorded, never stale */
    const gdr_import_report *report; /* the import's warnings and cameras (section 'REPT'); NULL: none */
    const gdr_pvs *pvs;      /* NULL: no precomputed visibility. Otherwise its serialised form in the
                                optional section 'PVIS'; it must have been baked for this scene
                                (gdr_pvs_object_count(pvs) == scene->instance_count), else
                                GDR_ERROR_INVALID_ARGUMENT and nothing is written (a library
                                without the culling module: GDR_ERROR_UNSUPPORTED) */
    uint32_t page_bytes;     /* 0: no geometry pages. Otherwise the optional section 'PAGE' holds every
                                mesh's LOD DAG groups in pages filled to this many raw bytes, in
                                [GDR_PAGE_BYTES_MIN, GDR_PAGE_BYTES_MAX] (gdr/paged_cache.h;
                                GDR_PAGE_BYTES_DEFAULT is the measured choice), read on demand by
                                gdr_paged_cache_open; out of range: GDR_ERROR_INVALID_ARGUMENT.
                                The pages then hold the only copy of the geometry: the sections of the
                                whole geometry ('GEOM', 'VCOL', 'CLGM') are left out, so the file is the
                                pages and what stays resident beside them, and it is read for
                                streaming only (gdr_cache_read_for_streaming; the whole read refuses
                                it by name) */
    int whole_geometry;      /* with page_bytes: also keep the whole geometry beside the pages, so that
                                the file is read whole too (3.4 times larger on the unique field) */
} gdr_cache_write_options;

/* Writes scene to path through a temporary file in the same folder and a rename. options: NULL for
 * the defaults. */
GDR_API gdr_status gdr_cache_write(const char *path, const gdr_scene *scene, const gdr_cache_write_options *options,
                                   gdr_error *err);

/* Writing a scene mesh by mesh (docs/CACHE_FORMAT.md, "Writing mesh by mesh"): the same file as
 * gdr_cache_write with pages, made without holding every mesh at once. `make` builds mesh `index`
 * into a new scene holding that one mesh, ready to be written (clusters, LOD DAG and hierarchy built,
 * vertices on their grid), with `threads` threads of its own at most; it is called from several
 * threads at once, for different meshes, each mesh once. The writer serialises the mesh, hands its
 * section parts to temporary files beside the output, and destroys it: memory holds the meshes in
 * flight and the page index, not the scene. */
typedef gdr_status gdr_cache_mesh_fn(void *user, uint32_t index, uint32_t threads, gdr_scene **out, gdr_error *err);

typedef struct gdr_cache_mesh_source {
    gdr_cache_mesh_fn *make;
    void *user;
    uint32_t thread_count; /* 0: one per processor; meshes built at once: min(thread_count, meshes),
                              each given thread_count / that many threads. The file does not depend on it. */
    int no_progress;       /* 1: never draw a progress bar */
} gdr_cache_mesh_source;

/* Writes the scene whose meshes `meshes` makes, one by one, and whose other parts (materials,
 * textures, instances, cameras; mesh_count) `skeleton` holds (its meshes' arrays are not read), to
 * path, with options->page_bytes set (else GDR_ERROR_INVALID_ARGUMENT). The bytes are those
 * gdr_cache_write writes for the whole scene, whatever the thread count. A failing mesh stops the
 * build: its error, prefixed with "meshes[N]: ", is returned and nothing is written. */
GDR_API gdr_status gdr_cache_write_meshes(const char *path, const gdr_scene *skeleton,
                                          const gdr_cache_mesh_source *meshes, const gdr_cache_write_options *options,
                                          gdr_error *err);

/* What gdr_cache_build_paged takes; zero-initialise, every field has a default. */
typedef struct gdr_paged_build_options {
    uint32_t page_bytes;   /* 0: GDR_PAGE_BYTES_DEFAULT; else in [GDR_PAGE_BYTES_MIN, GDR_PAGE_BYTES_MAX] */
    uint32_t thread_count; /* 0: one per processor (gdr_cache_mesh_source.thread_count) */
    int no_progress;       /* 1: never draw a progress bar */
    int whole_geometry;    /* 1: the whole geometry beside the pages (gdr_cache_write_options) */
} gdr_paged_build_options;

/* Writes the paged cache of a built-in scene (`spec`, as gdr_scene_load takes it) to path: the
 * bytes gdr_cache_write writes (with page_bytes, an empty source list) for the scene gdr_scene_load
 * makes with its vertices on their grids (gdr_scene_quantize_vertices), built mesh by mesh with
 * gdr_cache_write_meshes. The unique field is made one mesh at a time, so that memory follows the
 * meshes in flight; other scenes are made whole first. A file: GDR_ERROR_INVALID_ARGUMENT. */
GDR_API gdr_status gdr_cache_build_paged(const char *spec, const char *path, const gdr_paged_build_options *options,
                                         gdr_error *err);

/* Reads a whole regular file of at most max_size bytes into *out (malloc'ed, one NUL byte after the
 * data, which may hold NUL bytes of its own). A FIFO, device, socket or directory is refused at once
 * ("not a regular file"), never waited on; a larger file is refused before it is read. For the
 * program's small inputs (camera paths, results files). */
GDR_API gdr_status gdr_read_file(const char *path, size_t max_size, char **out, size_t *out_size, gdr_error *err);

/* The cache path of a source in a folder: SOURCE.gdrc next to it when cache_dir is NULL or ".", else
 * in cache_dir, named after the source's file name and a hash of its absolute path. Returns the
 * length written, or 0 when it does not fit. */
GDR_API size_t gdr_cache_path_for(const char *source_path, const char *cache_dir, char *out, size_t out_size);

/* The per-user cache folder: $XDG_CACHE_HOME/gdr when XDG_CACHE_HOME is an absolute path, else
 * $HOME/.cache/gdr. Returns the length written, 0 when there is none (no usable variable) or it does
 * not fit. Nothing is created. */
GDR_API size_t gdr_cache_default_dir(char *out, size_t out_size);

/* One cache file gdr wrote in a cache folder (gdr_cache_list). */
typedef struct gdr_cache_entry {
    const char *path;    /* the cache file */
    const char *source;  /* its source's path as recorded, control characters escaped; "" if unknown */
    uint64_t size;       /* bytes */
    int64_t used_ns;     /* last use (its modification time: a read touches it), ns since the epoch */
} gdr_cache_entry;

typedef void (*gdr_cache_entry_fn)(void *user, const gdr_cache_entry *entry);

/* Every cache gdr wrote in `dir` (NULL: the per-user folder), least recently used first: regular
 * files named NAME-<16 hex digits>.gdrc that start with the cache's magic; nothing else in the
 * folder is looked at further. */
GDR_API gdr_status gdr_cache_list(const char *dir, gdr_cache_entry_fn fn, void *user, gdr_error *err);

/* Removes the caches gdr_cache_list lists (and nothing else); *removed (may be NULL) counts them. */
GDR_API gdr_status gdr_cache_clear(const char *dir, uint32_t *removed, uint64_t *bytes, gdr_error *err);

/* The build options string of this version of the importers. */
GDR_API const char *gdr_cache_build_options(void);

/* --- Loading: the one way from a name to a scene -------------------------------------------- */

/* True when `spec` names a built-in scene ("demo", "lod-field", "occlusion", "unique-field", "rooms", alone or
 * followed by ":options"), which gdr_scene_load builds instead of reading a file. */
GDR_API bool gdr_scene_spec_is_builtin(const char *spec);

/* Loads a scene from a specification, a built-in scene with its level-0 clusters and LOD DAG:
 *     "demo[:instances=N,seed=S,spacing=X]"                 gdr_scene_create_demo
 *     "lod-field[:instances=N,seed=S,triangles=T,spacing=X]" gdr_scene_create_lod_field
 *     "occlusion[:seed=S,hidden=N,visible=N]"               gdr_scene_create_occlusion
 *     "unique-field[:meshes=M,seed=S,triangles=T,spacing=X]" gdr_scene_create_unique_field
 *     "rooms[:rooms=N,seed=S,objects=K]"                    gdr_scene_create_rooms
 * (options in any order, each at most once; values as in the desc, 0 refused), or a file path of
 * a supported format. Source files (.gltf, .glb, .obj) go through the processed-scene cache unless
 * options->no_cache; a .gdrc file is read directly. options: NULL for the defaults. */
GDR_API gdr_status gdr_scene_load(const char *spec, const gdr_load_options *options, gdr_scene **out,
                                  gdr_error *err);

#ifdef __cplusplus
}
#endif
#endif
