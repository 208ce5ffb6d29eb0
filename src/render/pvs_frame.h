/* Precomputed visibility in the frame (pvs_frame.c; cull_absent.c in a build without the culling
 * module): the moved-instance bits for a scene being set, the frame's decision and the cell's bits in
 * the slot's buffer (before its globals are written), an instance that moved, and the end. */
#ifndef GDR_RENDER_PVS_FRAME_H
#define GDR_RENDER_PVS_FRAME_H

#include "render/renderer_internal.h"

gdr_status gdr_render_pvs_scene(gdr_renderer *r, gdr_error *err);
/* Whether a frame culls by the PVS: one is held and neither culling nor the PVS is switched off. */
bool gdr_render_pvs_wanted(const gdr_renderer *r, const gdr_frame_desc *frame);
void gdr_render_pvs_begin_frame(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_desc *frame,
                                gdr_pipeline pipeline);
void gdr_render_pvs_moved(gdr_renderer *r, uint32_t instance);
bool gdr_render_pvs_is_moved(const gdr_renderer *r, uint32_t instance);
void gdr_render_pvs_destroy(gdr_renderer *r);
/* The baked cells of the PVS held (0: none). */
uint32_t gdr_render_pvs_cells(const gdr_renderer *r);

#endif
