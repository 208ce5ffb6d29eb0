#include "core/output_file.h"

gdr_status gdr_write_file_atomic(const char *path, const void *data, size_t size, gdr_error *err)
{
    gdr_output_file out;
    gdr_status status = gdr_output_open(path, &out, err);
    if (status != GDR_OK)
        return status;
    bool ok = fwrite(data, 1, size, out.file) == size;
    return gdr_output_close(&out, ok, path, err);
}
