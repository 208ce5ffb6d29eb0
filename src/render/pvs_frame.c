/* Precomputed visibility in the frame (seed 002): the caller's PVS, the cell holding the culling
 * camera looked up once per frame, and its bitset, with the instances moved since the scene was set
 * added, copied into the frame slot's buffer, which the GPU instance cull reads (drawcull.comp). The
 * CPU pipeline hands the same lookup to gdr/cull.h (cpu_driven.c). A frame whose camera is in no
 * baked cell culls nothing by it. */
#include <stdlib.h>
#include <string.h>

#include "gdr/cull.h"
#include "render/renderer_internal.h"
#include "render/pvs_frame.h"

gdr_status gdr_render_pvs_scene(gdr_renderer *r, gdr_error *err)
{
    uint32_t words = gdr_cull_word_count(r->scene.instance_count);
    r->pvs.moved = calloc(words ? words : 1, sizeof(uint32_t));
    if (!r->pvs.moved)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "precomputed visibility: out of memory for %u instances",
                             r->scene.instance_count);
    r->pvs.words = words;
    return GDR_OK;
}

gdr_status gdr_renderer_set_pvs(gdr_renderer *r, const gdr_pvs *pvs, gdr_error *err)
{
    if (!r->has_scene)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "set_pvs: no scene (call gdr_renderer_set_scene first)");
    if (pvs && gdr_pvs_object_count(pvs) != r->scene.instance_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "set_pvs: the precomputed visibility was baked for %u objects, the scene has %u instances",
                             gdr_pvs_object_count(pvs), r->scene.instance_count);
    gdr_pvs_cache *cache = NULL;
    if (pvs) {
        gdr_status status = gdr_pvs_cache_create(pvs, &cache, err);
        if (status != GDR_OK)
            return status;
    }
    gdr_pvs_cache_destroy(r->pvs.cache);
    r->pvs.cache = cache;
    r->pvs.pvs = pvs;
    r->pvs.version++;
    return GDR_OK;
}

bool gdr_render_pvs_wanted(const gdr_renderer *r, const gdr_frame_desc *frame)
{
    return r->pvs.pvs && frame->cull != GDR_CULL_OFF && frame->pvs != GDR_CULL_OFF;
}

/* Whether the slot's buffer already holds these bits: the same place in the lookup's chunk with no
 * decompression since (so the same cell), the same moved instances and the same PVS. */
static bool slot_holds(const gdr_renderer *r, const gdr_frame_slot *slot, const uint32_t *bits)
{
    return slot->pvs_source == bits &&
           slot->pvs_source_decompressions == gdr_pvs_cache_decompressions(r->pvs.cache) &&
           slot->pvs_source_moved == r->pvs.moved_version && slot->pvs_source_version == r->pvs.version;
}

void gdr_render_pvs_begin_frame(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_desc *frame,
                                gdr_pipeline pipeline)
{
    slot->pvs_enabled = gdr_render_pvs_wanted(r, frame);
    slot->pvs_cell_found = false;
    if (!slot->pvs_enabled || pipeline == GDR_PIPELINE_CPU) /* the CPU cull looks up for itself */
        return;
    double start = gdr_now_ms();
    const gdr_camera *camera = frame->cull_camera ? frame->cull_camera : &frame->camera;
    const uint32_t *bits = gdr_pvs_lookup(r->pvs.cache, camera->position);
    slot->pvs_cell_found = bits != NULL;
    if (bits && !slot_holds(r, slot, bits)) {
        uint32_t *out = slot->pvs_visible.mapped;
        for (uint32_t w = 0; w < r->pvs.words; w++)
            out[w] = bits[w] | r->pvs.moved[w];
        slot->pvs_source = bits;
        slot->pvs_source_decompressions = gdr_pvs_cache_decompressions(r->pvs.cache);
        slot->pvs_source_moved = r->pvs.moved_version;
        slot->pvs_source_version = r->pvs.version;
    }
    r->pvs.cpu_ms += gdr_now_ms() - start;
}

void gdr_render_pvs_moved(gdr_renderer *r, uint32_t instance)
{
    uint32_t bit = 1u << (instance % 32);
    if (r->pvs.moved[instance / 32] & bit)
        return;
    r->pvs.moved[instance / 32] |= bit;
    r->pvs.moved_version++;
}

bool gdr_render_pvs_is_moved(const gdr_renderer *r, uint32_t instance)
{
    return r->pvs.moved && (r->pvs.moved[instance / 32] >> (instance % 32) & 1u);
}

uint32_t gdr_render_pvs_cells(const gdr_renderer *r) { return r->pvs.pvs ? gdr_pvs_cell_count(r->pvs.pvs) : 0; }

void gdr_render_pvs_destroy(gdr_renderer *r)
{
    gdr_pvs_cache_destroy(r->pvs.cache);
    free(r->pvs.moved);
    memset(&r->pvs, 0, sizeof r->pvs);
}
