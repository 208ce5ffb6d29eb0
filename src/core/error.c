#include "gdr/core.h"

#include <stdio.h>

const char *gdr_status_name(gdr_status status)
{
    switch (status) {
    case GDR_OK: return "GDR_OK";
    case GDR_ERROR_INVALID_ARGUMENT: return "GDR_ERROR_INVALID_ARGUMENT";
    case GDR_ERROR_IO: return "GDR_ERROR_IO";
    case GDR_ERROR_PARSE: return "GDR_ERROR_PARSE";
    case GDR_ERROR_OUT_OF_MEMORY: return "GDR_ERROR_OUT_OF_MEMORY";
    case GDR_ERROR_UNSUPPORTED: return "GDR_ERROR_UNSUPPORTED";
    case GDR_ERROR_VULKAN: return "GDR_ERROR_VULKAN";
    case GDR_ERROR_CAPACITY: return "GDR_ERROR_CAPACITY";
    case GDR_ERROR_BUDGET: return "GDR_ERROR_BUDGET";
    case GDR_ERROR_OUTSIDE_FOLDER: return "GDR_ERROR_OUTSIDE_FOLDER";
    case GDR_ERROR_NOT_A_FILE: return "GDR_ERROR_NOT_A_FILE";
    case GDR_ERROR_STALE: return "GDR_ERROR_STALE";
    case GDR_ERROR_CORRUPT: return "GDR_ERROR_CORRUPT";
    }
    return "GDR_ERROR_UNKNOWN";
}

gdr_status gdr_error_set(gdr_error *err, gdr_status status, const char *format, ...)
{
    if (err) {
        va_list args;
        va_start(args, format);
        err->status = status;
        vsnprintf(err->message, sizeof err->message, format, args);
        va_end(args);
    }
    return status;
}

const char *gdr_version(void)
{
    return GDR_VERSION_STRING;
}
