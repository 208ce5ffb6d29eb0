/* Helpers shared by the importers and the cache (not part of the public API). */
#ifndef GDR_IO_INTERNAL_H
#define GDR_IO_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include "core/progress.h"
#include "geometry/vertex_weld.h"
#include "gdr/io.h"
#include "io/loaders.h"

/* Largest file an importer reads whole (bytes). */
#define GDR_IO_MAX_FILE_SIZE (4ull << 30)
/* The whole-file reader's limit in force: GDR_IO_MAX_FILE_SIZE; tests lower it to reach the limit
 * (and what the cache writer does past it) with small files. */
extern uint64_t gdr_io_max_file_size;
/* Largest element count of an accessor that no buffer data backs (it would be all zeros). */
#define GDR_IO_MAX_UNBACKED_ELEMENTS (1u << 24)

/* Largest magnitude of a vertex coordinate an importer accepts (gdr/scene.h). */
#define GDR_IO_MAX_COORDINATE GDR_MAX_COORDINATE
/* A vertex used by more triangles than this is split into copies (gdr_io_split_shared_vertices).
 * The geometry builder's weld of equal vertices joins no more than this many uses, so that it
 * never joins those copies again. */
#define GDR_IO_MAX_VERTEX_VALENCE GDR_WELD_MAX_VERTEX_USES

/* Opens a file for reading without blocking on a FIFO or a device: refuses anything that is not a
 * regular file ("not a regular file") before reading a byte. *out_fd is the descriptor (blocking
 * again), or -1 on failure. */
gdr_status gdr_io_open_regular(const char *path, int *out_fd, gdr_error *err);

/* Exactly `size` bytes at `offset` of fd into dst (pread, again after EINTR and short reads).
 * Returns the bytes read: `size`, or fewer when the file ends or a read fails (errno set then,
 * 0 when it ended). */
size_t gdr_io_pread_exact(int fd, void *dst, size_t size, uint64_t offset);

/* Reads a whole file into a malloc'ed buffer (one extra NUL byte after the data). When sources
 * is not NULL, the file's identity is appended to it. */
gdr_status gdr_io_read_file(const char *path, uint8_t **out_data, size_t *out_size, gdr_source_list *sources,
                            gdr_error *err);

/* Appends a file identity to a list (path copied). */
gdr_status gdr_io_source_add(gdr_source_list *list, const char *path, uint64_t size, int64_t mtime_ns,
                             uint64_t hash, gdr_error *err);

/* Appends a path an import looked for but did not read (made absolute): GDR_SOURCE_ABSENT when
 * nothing is there, else GDR_SOURCE_UNREAD with what stat says. list may be NULL. */
gdr_status gdr_io_source_add_looked_for(gdr_source_list *list, const char *path, gdr_error *err);

/* path made absolute: realpath when it exists, else its folder's realpath and its last part, else
 * joined to the working directory. */
void gdr_io_absolute_path(const char *path, char *out, size_t out_size);

/* Copies `length` bytes of untrusted text into out (NUL-terminated, cut to fit) with every byte that
 * a terminal could take for a command escaped as \xNN: control characters (C0, DEL, C1) and bytes
 * that are not valid UTF-8. Returns the length written. */
size_t gdr_io_escape_text(const char *text, size_t length, char *out, size_t out_size);

/* size and modification time of a file; returns 0 on success. */
int gdr_io_stat(const char *path, uint64_t *size, int64_t *mtime_ns);

uint64_t gdr_io_hash(const void *data, size_t size);

/* What one import has used of its budget (gdr_budget). */
typedef enum gdr_io_budget_kind {
    GDR_BUDGET_TRIANGLES, GDR_BUDGET_INSTANCES, GDR_BUDGET_TEXTURE_PIXELS, GDR_BUDGET_DECODED_BYTES,
    GDR_BUDGET_KIND_COUNT
} gdr_io_budget_kind;

typedef struct gdr_io_budget {
    uint64_t limit[GDR_BUDGET_KIND_COUNT];
    uint64_t used[GDR_BUDGET_KIND_COUNT];
} gdr_io_budget;

void gdr_io_budget_init(gdr_io_budget *b, const gdr_budget *limits);
/* Takes `amount` of a budget, before allocating for it; over the limit, an error naming the file,
 * the place, the budget and how to raise it (GDR_ERROR_BUDGET). */
gdr_status gdr_io_budget_take(gdr_io_budget *b, gdr_io_budget_kind kind, uint64_t amount, const char *name,
                              const char *place, gdr_error *err);
/* Gives back `amount` taken before for memory that has been freed since (an image's decoding). */
void gdr_io_budget_give(gdr_io_budget *b, gdr_io_budget_kind kind, uint64_t amount);

/* mesh_clean.c: positions all finite and within GDR_IO_MAX_COORDINATE, else an error naming the
 * file (`name`), the place and the vertex. */
gdr_status gdr_io_check_positions(const gdr_vec3 *positions, uint32_t count, const char *name, const char *place,
                                  gdr_error *err);
/* Removes, in place and in order, triangles with two corners at one position or zero area
 * (*degenerate) and triangles that repeat an earlier one, corners in the same rotation order, by
 * position (*duplicate); *index_count shrinks. Linear. Returns GDR_ERROR_OUT_OF_MEMORY or GDR_OK. */
gdr_status gdr_io_drop_bad_triangles(const gdr_vec3 *positions, uint32_t vertex_count, uint32_t *indices,
                                     uint32_t *index_count, uint32_t *degenerate, uint32_t *duplicate);
/* Gives every block of GDR_IO_MAX_VERTEX_VALENCE uses of a vertex (in index order) beyond the first
 * its own copy (same position, normal, uv): the arrays (malloc'ed; normals and uvs may be NULL) grow,
 * *added copies. Returns GDR_ERROR_OUT_OF_MEMORY or GDR_OK. */
gdr_status gdr_io_split_shared_vertices(gdr_vec3 **positions, gdr_vec3 **normals, gdr_vec2 **uvs, gdr_vec4 **colors,
                                        uint32_t *vertex_count, uint32_t *indices, uint32_t index_count,
                                        uint32_t *added);

/* The same two steps for every mesh of a scene that has triangles but no clusters (a cache read
 * without them): what gdr_scene_build_clusters then gets is clean. */
gdr_status gdr_io_clean_unclustered_meshes(gdr_scene *scene, const char *name, gdr_error *err);

/* Images: PNG and JPEG only (what glTF allows), told apart by their signature (image.c). */
typedef enum gdr_io_image_format { GDR_IO_IMAGE_PNG = 1, GDR_IO_IMAGE_JPEG = 2 } gdr_io_image_format;

typedef struct gdr_io_image_info {
    gdr_io_image_format format;
    uint32_t width, height;
    /* What the decoder may allocate besides the RGBA8 result (rows, a progressive JPEG's
     * coefficients); decoding is refused when it would need more. */
    uint64_t work_bytes;
} gdr_io_image_info;

/* An image's format, size and decoding memory from its headers, without decoding it: anything
 * but a PNG or JPEG signature is refused, naming the format where it is a known one, and so is a
 * side above GDR_IO_IMAGE_MAX_SIDE. `name` starts every message. */
#define GDR_IO_IMAGE_MAX_SIDE 16384u
gdr_status gdr_io_image_probe(const void *data, size_t size, const char *name, gdr_io_image_info *info,
                              gdr_error *err);
/* Decodes what gdr_io_image_probe described into *out_rgba (malloc'ed, width x height x 4),
 * within info->work_bytes of working memory. */
gdr_status gdr_io_image_decode(const void *data, size_t size, const char *name, const gdr_io_image_info *info,
                               uint8_t **out_rgba, gdr_error *err);

/* gdr_cache_read for the cache of `source` (NULL: a cache read on its own): the cache must
 * record that file as the first of its sources, with the same size and contents (its folder may
 * have moved: the other sources are then looked for under the new folder), else it is stale.
 * out_report (may be NULL): the import's report the cache keeps (section 'REPT'). */
gdr_status gdr_io_cache_read_for(const char *path, const char *source, const char *build_options, gdr_scene **out,
                                 gdr_pvs **out_pvs, gdr_import_report *out_report, gdr_error *err);

/* gdr_cache_read_for_streaming for the cache of `source` (NULL: a cache read on its own; stale as
 * gdr_io_cache_read_for says), also returning the import's report the cache keeps (may be NULL). */
gdr_status gdr_io_cache_read_for_streaming(const char *path, const char *source, const char *build_options,
                                           gdr_scene **out, gdr_pvs **out_pvs, gdr_import_report *out_report,
                                           uint64_t *out_bytes_read, gdr_error *err);

/* The source a cache file records first (the file it was built from), control characters escaped;
 * reads only the header, the table and section 'SRCE', each checksum checked. */
gdr_status gdr_io_cache_recorded_source(const char *path, char *out, size_t out_size, gdr_error *err);

/* cache_dir.c: a cache folder gdr keeps (the per-user one, or --cache-dir). */
/* Creates it (mode 0700, its parent too when missing) and checks it is a folder of this user that
 * no one else may write to; else an error naming it (a cache there could be planted by others). */
gdr_status gdr_io_cache_dir_prepare(const char *dir, gdr_error *err);
/* Marks a cache as used now (its modification time), for least-recently-used eviction. */
void gdr_io_cache_touch(const char *path);
/* Removes the least recently used caches gdr wrote in dir (gdr_cache_list's) until those left
 * hold at most max_bytes; never `keep`. Returns how many were removed. */
uint32_t gdr_io_cache_evict(const char *dir, uint64_t max_bytes, const char *keep);
/* The size limit: max_bytes, else GDR_CACHE_MAX_MIB from the environment, else the default. */
uint64_t gdr_io_cache_limit(uint64_t max_bytes);

/* Warning sink of one import. */
typedef struct gdr_io_warnings {
    gdr_warning_fn fn;
    void *user;
    uint32_t count;
} gdr_io_warnings;

void gdr_io_warn(gdr_io_warnings *w, const char *format, ...) __attribute__((format(printf, 2, 3)));

/* Decodes standard base64 (with or without padding); returns the decoded length, or SIZE_MAX
 * on a character outside the alphabet. out must hold gdr_base64_decoded_max(length) bytes. */
size_t gdr_base64_decode(uint8_t *out, const char *in, size_t length);
static inline size_t gdr_base64_decoded_max(size_t length) { return length / 4 * 3 + 3; }

/* Dirname of path (including the trailing '/'), or "" when it has none. */
void gdr_io_dirname(const char *path, char *out, size_t out_size);
/* True when path ends with ext (case-insensitive, ext includes the dot). */
int gdr_io_has_extension(const char *path, const char *ext);

#endif
