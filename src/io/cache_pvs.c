/* The PVIS section over the culling module's serialised PVS (gdr/cull.h; cache_pvs.h). */
#include "gdr/cull.h"
#include "io/cache_pvs.h"

int cache_pvs_present(const cache_write_input *in) { return in->pvs != NULL; }

gdr_status cache_pvs_check(const cache_write_input *in, const char *path, gdr_error *err)
{
    if (gdr_pvs_object_count(in->pvs) == in->scene->instance_count)
        return GDR_OK;
    return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                         "%s: the precomputed visibility was baked for %u objects, the scene has %u instances", path,
                         gdr_pvs_object_count(in->pvs), in->scene->instance_count);
}

void cache_pvs_write(writer *w, const cache_write_input *in)
{
    size_t size = gdr_pvs_serialized_size(in->pvs);
    uint8_t *blob = put_space(w, size);
    if (blob && gdr_pvs_serialize(in->pvs, blob, size, NULL) != GDR_OK)
        w->failed = 1;
}

/* gdr_pvs_load checks all of the blob, baked for this scene's instances. */
gdr_status cache_pvs_read(const char *name, const reader *r, size_t offset, uint32_t instance_count, gdr_pvs **out,
                          gdr_error *err)
{
    gdr_pvs *pvs = NULL;
    gdr_error pvs_err = {0};
    gdr_status status = gdr_pvs_load(r->data, r->size, &pvs, &pvs_err);
    if (status != GDR_OK)
        return gdr_error_set(err, status, "%s: section 'PVIS' (%zu bytes at offset %zu): %s", name, r->size, offset,
                             pvs_err.message);
    if (gdr_pvs_object_count(pvs) != instance_count) {
        status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'PVIS': baked for %u objects, the scene has %u "
                               "instances", name, gdr_pvs_object_count(pvs), instance_count);
        gdr_pvs_destroy(pvs);
        return status;
    }
    if (out)
        *out = pvs;
    else
        gdr_pvs_destroy(pvs);
    return GDR_OK;
}

void cache_pvs_destroy(gdr_pvs *pvs) { gdr_pvs_destroy(pvs); }
