/* The cache's precomputed visibility (section PVIS, docs/CACHE_FORMAT.md): everything io asks of the
 * culling module. cache_pvs.c does it with gdr/cull.h; in a build without the culling module
 * (docs/ARCHITECTURE.md, "Optional modules") cache_pvs_absent.c stands in: the section is never
 * written and, when a file holds one, skipped like an optional section this build does not know. */
#ifndef GDR_IO_CACHE_PVS_H
#define GDR_IO_CACHE_PVS_H

#include "io/cache_internal.h"

/* The section's description (gdr_cache_sections): whether it is written for this input, what the
 * input must satisfy, its bytes. */
int cache_pvs_present(const cache_write_input *in);
gdr_status cache_pvs_check(const cache_write_input *in, const char *path, gdr_error *err);
void cache_pvs_write(writer *w, const cache_write_input *in);

/* The section's bytes `r`, at `offset` in the file `name`, for a scene of instance_count instances:
 * checked whole whether or not the caller wants the PVS; *out (when out is not NULL) receives it. */
gdr_status cache_pvs_read(const char *name, const reader *r, size_t offset, uint32_t instance_count, gdr_pvs **out,
                          gdr_error *err);

/* Frees a PVS the reader returned (NULL: nothing). */
void cache_pvs_destroy(gdr_pvs *pvs);

#endif
