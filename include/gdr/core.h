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

/* --- status codes (one list, so tests can match them) --- */
typedef enum gdr_status {
    GDR_OK = 0,
    GDR_ERROR_INVALID_ARGUMENT, /* a caller-supplied value is out of range */
    GDR_ERROR_IO,               /* a file could not be read or written */
    GDR_ERROR_PARSE,            /* input data is malformed */
    GDR_ERROR_OUT_OF_MEMORY,    /* host or device allocation failed */
    GDR_ERROR_UNSUPPORTED,      /* the device or input needs something gdr does not have */
    GDR_ERROR_VULKAN,           /* a Vulkan call failed */
    GDR_ERROR_CAPACITY,         /* a fixed-size list would overflow */
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
