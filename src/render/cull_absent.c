/* The renderer built without the culling module (GDR_EXCLUDE_MODULES=cull; docs/ARCHITECTURE.md,
 * "Optional modules"): the functions that cpu_driven.c and pvs_frame.c define over gdr/cull.h, doing
 * without it. The renderer holds no precomputed visibility and has no CPU pipeline: check_frame
 * (renderer.c) refuses a frame that asks for either before anything here would be reached, and
 * gdr_renderer_set_pvs accepts only NULL (nothing to hold), since nothing in this build can make a
 * gdr_pvs. */
#include "render/renderer_internal.h"
#include "render/cpu_driven.h"
#include "render/pvs_frame.h"

#define WITHOUT_CULL "built without the culling module (GDR_EXCLUDE_MODULES)"

gdr_status gdr_renderer_set_pvs(gdr_renderer *r, const gdr_pvs *pvs, gdr_error *err)
{
    if (!r->has_scene)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "set_pvs: no scene (call gdr_renderer_set_scene first)");
    if (pvs)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "set_pvs: precomputed visibility: " WITHOUT_CULL);
    return GDR_OK;
}

gdr_status gdr_render_pvs_scene(gdr_renderer *r, gdr_error *err)
{
    (void)r, (void)err;
    return GDR_OK;
}

bool gdr_render_pvs_wanted(const gdr_renderer *r, const gdr_frame_desc *frame)
{
    (void)r, (void)frame;
    return false;
}

void gdr_render_pvs_begin_frame(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_desc *frame,
                                gdr_pipeline pipeline)
{
    (void)r, (void)frame, (void)pipeline;
    slot->pvs_enabled = false;
    slot->pvs_cell_found = false;
}

void gdr_render_pvs_moved(gdr_renderer *r, uint32_t instance) { (void)r, (void)instance; }

bool gdr_render_pvs_is_moved(const gdr_renderer *r, uint32_t instance)
{
    (void)r, (void)instance;
    return false;
}

void gdr_render_pvs_destroy(gdr_renderer *r) { (void)r; }

uint32_t gdr_render_pvs_cells(const gdr_renderer *r)
{
    (void)r;
    return 0;
}

gdr_status gdr_cpu_path_create(gdr_renderer *r, const gdr_scene *scene, gdr_error *err)
{
    (void)r, (void)scene, (void)err;
    return GDR_OK;
}

void gdr_cpu_path_destroy(gdr_renderer *r) { (void)r; }

gdr_status gdr_cpu_path_update_instance(gdr_renderer *r, uint32_t index, gdr_error *err)
{
    (void)r, (void)index, (void)err;
    return GDR_OK;
}

gdr_status gdr_cpu_path_cull(gdr_renderer *r, const gdr_frame_desc *frame, gdr_error *err)
{
    (void)r, (void)frame;
    return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "render: pipeline cpu: " WITHOUT_CULL);
}

void gdr_cpu_path_record_draws(gdr_renderer *r, VkCommandBuffer cmd, const GdrGpuPushConstants *push)
{
    (void)r, (void)cmd, (void)push; /* no CPU pipeline: never recorded */
}
