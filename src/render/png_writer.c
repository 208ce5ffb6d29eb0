/* PNG output through stb_image_write, written to a temporary file and renamed into place. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <stb/stb_image_write.h>

#include "gdr/renderer.h"

gdr_status gdr_write_png(const char *path, const uint8_t *rgba, uint32_t width, uint32_t height, gdr_error *err)
{
    if (width == 0 || height == 0 || width > 65535 || height > 65535)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: image size %ux%u is not writable", path, width, height);
    size_t length = strlen(path);
    char *temporary = malloc(length + 32);
    if (!temporary)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    snprintf(temporary, length + 32, "%s.tmp.%ld", path, (long)getpid());
    if (!stbi_write_png(temporary, (int)width, (int)height, 4, rgba, (int)width * 4)) {
        int saved = errno;
        remove(temporary);
        free(temporary);
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot write the PNG (%s)", path,
                             saved ? strerror(saved) : "encoder failed");
    }
    if (rename(temporary, path) != 0) {
        int saved = errno;
        remove(temporary);
        free(temporary);
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot rename the finished PNG into place (%s)", path,
                             strerror(saved));
    }
    free(temporary);
    return GDR_OK;
}
