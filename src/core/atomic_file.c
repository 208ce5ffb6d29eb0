#include "gdr/core.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

gdr_status gdr_write_file_atomic(const char *path, const void *data, size_t size, gdr_error *err)
{
    size_t length = strlen(path);
    char *temporary = malloc(length + 32);
    if (!temporary)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    snprintf(temporary, length + 32, "%s.tmp.%ld", path, (long)getpid());
    FILE *file = fopen(temporary, "wb");
    bool ok = file && fwrite(data, 1, size, file) == size;
    int saved = errno;
    if (file && fclose(file) != 0 && ok) {
        ok = false;
        saved = errno;
    }
    if (ok && rename(temporary, path) != 0) {
        ok = false;
        saved = errno;
    }
    if (!ok)
        remove(temporary);
    free(temporary);
    if (!ok)
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot write (%s)", path, strerror(saved));
    return GDR_OK;
}
