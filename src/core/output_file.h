/* Output files (images, statistics, caches): how a path given for writing is treated.
 *  - a symbolic link is followed: the file it points to is what gets written (a dangling link is
 *    refused);
 *  - an existing regular file, or a new one, is replaced atomically: written to a temporary file
 *    in the same folder, flushed, then renamed over it, so a crash, a full disk or an error never
 *    leaves a half-written file;
 *  - the process's own descriptors (/dev/stdout, /dev/stderr, /dev/fd/N, /proc/self/fd/N, or a link
 *    to one) are written through the descriptor, after what stdio has buffered for it, whatever it
 *    is (a terminal, a pipe, a file the shell redirected);
 *  - an existing device, FIFO or socket (/dev/null, a pipe) is written directly, never replaced; a
 *    FIFO without a reader is refused at once instead of waiting for one;
 *  - a directory is refused. */
#ifndef GDR_CORE_OUTPUT_FILE_H
#define GDR_CORE_OUTPUT_FILE_H

#include <stdio.h>

#include "gdr/core.h"

typedef struct gdr_output_file {
    FILE *file;
    char *target;    /* the path written in the end (links resolved) */
    char *temporary; /* NULL when writing directly */
} gdr_output_file;

gdr_status gdr_output_open(const char *path, gdr_output_file *out, gdr_error *err);
/* Finishes the write: with `ok`, flushes and (atomic writes) renames into place; without it (or on
 * a failure) removes the temporary file. Frees what gdr_output_open allocated. */
gdr_status gdr_output_close(gdr_output_file *out, bool ok, const char *path, gdr_error *err);

#endif
