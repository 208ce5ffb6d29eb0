/* gdr core: status codes, error reports, export macro.
 *
 * Every function that can fail returns a gdr_status and, when given a gdr_error, fills it
 * with a message that names the file and the place in it. */
#ifndef GDR_CORE_H
#define GDR_CORE_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gdr/config.h"

#ifdef __cplusplus
extern "C" {
#endif

#define GDR_API __attribute__((visibility("default")))

/* --- status codes (one list, so callers and tests can act on them) ---
 *
 * Each code says what a caller can do about the failure; the message says where (the file and
 * the place in it) and why. The `gdr` program exits with 2 for a value given on its command line
 * that was refused (GDR_ERROR_INVALID_ARGUMENT from a built-in scene's options, a --device, a
 * target size) and with 1 for every other failure, whatever its code. New codes are added at the
 * end, so a code's number never changes. */
typedef enum gdr_status {
    GDR_OK = 0,
    /* A caller-supplied value is out of range (a desc field, a built-in scene's option, a mesh
     * handed to the API). Fix the value. Exit status 2 where the value came from the command
     * line, 1 otherwise. */
    GDR_ERROR_INVALID_ARGUMENT,
    /* A file could not be opened, read or written (the system's reason follows). Exit status 1. */
    GDR_ERROR_IO,
    /* Input data is malformed: it breaks its format's rules (a glTF index out of range, an OBJ
     * number that is not one, a cache section that contradicts itself). Fix or re-export the
     * file. Exit status 1. */
    GDR_ERROR_PARSE,
    /* Host or device memory ran out. Exit status 1. */
    GDR_ERROR_OUT_OF_MEMORY,
    /* Well-formed input, or a request, that needs something gdr or the device does not have (a
     * required glTF extension, an image format glTF does not allow, a cache of another format
     * version, the mesh pipeline on a device without mesh shaders). Exit status 1. */
    GDR_ERROR_UNSUPPORTED,
    /* A Vulkan call failed (the VkResult is named). Exit status 1. */
    GDR_ERROR_VULKAN,
    /* A fixed limit of gdr's would be exceeded (a list's 32-bit offsets, the renderer's texture
     * slots, a cache's largest texture): no option raises it. Exit status 1. */
    GDR_ERROR_CAPACITY,
    /* A file needs more than a budget allows (triangles, instances, texture pixels or decoded
     * bytes: gdr_budget). The message names the budget; raise it with `--budget KEY=N` (the
     * program) or gdr_budget (the library). Exit status 1. */
    GDR_ERROR_BUDGET,
    /* A file a scene refers to (a glTF buffer's or image's URI) lies outside the scene's folder
     * (an absolute path, '..', a symbolic link leading out) and was not read. Allow it with
     * `--allow-outside-files` (allow_outside_files in the options). Exit status 1. */
    GDR_ERROR_OUTSIDE_FOLDER,
    /* A path names a directory, FIFO, socket or device where gdr reads a whole file, or a
     * directory where it writes one. Give a regular file. Exit status 1. */
    GDR_ERROR_NOT_A_FILE,
    /* A .gdrc cache that is intact but no longer matches what it was built from: its source
     * files changed or are gone, or it was built with other options. gdr_scene_load rebuilds
     * it without a word; rebuild it with `gdr build`. Exit status 1. */
    GDR_ERROR_STALE,
    /* A file's bytes fail its own integrity checks: a checksum mismatch, a file shorter or
     * longer than its header says, a reserved byte that is not zero (a .gdrc cache, its pages).
     * Damaged in storage or transfer: read it again or rebuild it. Exit status 1. */
    GDR_ERROR_CORRUPT,
} gdr_status;

/* Marks "none" in every index field (a mesh's material, a cluster's group, ...). */
#define GDR_NO_INDEX UINT32_MAX

#define GDR_ERROR_MESSAGE_MAX 512

typedef struct gdr_error {
    gdr_status status;
    char message[GDR_ERROR_MESSAGE_MAX];
} gdr_error;

/* Name of a status code, e.g. "GDR_ERROR_PARSE". */
GDR_API const char *gdr_status_name(gdr_status status);

/* Records status and a printf-style message in err (which may be NULL); returns status. */
GDR_API gdr_status gdr_error_set(gdr_error *err, gdr_status status, const char *format, ...)
    __attribute__((format(printf, 3, 4)));

/* Writes a whole file through a temporary file in the same folder and a rename, so a crash or a
 * full disk never leaves a half-written file at `path`. A symbolic link is followed (its target
 * is replaced; a dangling link is refused); /dev/stdout and the like go through the process's own
 * descriptor; an existing device, FIFO or socket (a pipe) is written directly and never replaced, a FIFO without a reader refused at once; a
 * directory is refused. */
GDR_API gdr_status gdr_write_file_atomic(const char *path, const void *data, size_t size, gdr_error *err);

/* Version string of the library, e.g. "0.1.0". */
GDR_API const char *gdr_version(void);

#ifdef __cplusplus
}
#endif
#endif
