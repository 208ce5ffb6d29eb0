/* The PVIS section in a build without the culling module (cache_pvs.h; docs/ARCHITECTURE.md,
 * "Optional modules"): nothing here can make, write or read a PVS. The writer leaves the section out
 * (a caller handing it one is refused); the reader skips a file's section, whose checksum the
 * container has checked, as it skips an optional section of a later version, and returns no PVS. */
#include "io/cache_pvs.h"

int cache_pvs_present(const cache_write_input *in) { return in->pvs != NULL; }

gdr_status cache_pvs_check(const cache_write_input *in, const char *path, gdr_error *err)
{
    (void)in;
    return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: precomputed visibility: built without the culling module "
                         "(GDR_EXCLUDE_MODULES)", path);
}

void cache_pvs_write(writer *w, const cache_write_input *in)
{
    (void)in;
    w->failed = 1; /* never reached: cache_pvs_check refuses first */
}

gdr_status cache_pvs_read(const char *name, const reader *r, size_t offset, uint32_t instance_count, gdr_pvs **out,
                          gdr_error *err)
{
    (void)name, (void)r, (void)offset, (void)instance_count, (void)out, (void)err;
    return GDR_OK;
}

void cache_pvs_destroy(gdr_pvs *pvs) { (void)pvs; }
