/* Helpers shared by the importers and the cache (not part of the public API). */
#ifndef GDR_IO_INTERNAL_H
#define GDR_IO_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include "core/progress.h"
#include "gdr/io.h"

/* Largest file an importer reads whole (bytes). */
#define GDR_IO_MAX_FILE_SIZE (4ull << 30)
/* Largest element count of an accessor that no buffer data backs (it would be all zeros). */
#define GDR_IO_MAX_UNBACKED_ELEMENTS (1u << 24)

/* Reads a whole file into a malloc'ed buffer (one extra NUL byte after the data). When sources
 * is not NULL, the file's identity is appended to it. */
gdr_status gdr_io_read_file(const char *path, uint8_t **out_data, size_t *out_size, gdr_source_list *sources,
                            gdr_error *err);

/* Appends a file identity to a list (path copied). */
gdr_status gdr_io_source_add(gdr_source_list *list, const char *path, uint64_t size, int64_t mtime_ns,
                             uint64_t hash, gdr_error *err);

/* size and modification time of a file; returns 0 on success. */
int gdr_io_stat(const char *path, uint64_t *size, int64_t *mtime_ns);

uint64_t gdr_io_hash(const void *data, size_t size);

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
