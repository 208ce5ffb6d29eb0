/* The recording functions of the frame's passes (frame_record.c; the visibility buffer's are in
 * visbuffer.h), the viewport and the state every pass expects bound. */
#ifndef GDR_RENDER_FRAME_RECORD_H
#define GDR_RENDER_FRAME_RECORD_H

#include "render/renderer_internal.h"

void gdr_pass_record_instance_scatter(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                      VkCommandBuffer cmd);
void gdr_pass_record_clear(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass, VkCommandBuffer cmd);
void gdr_pass_record_instance_cull(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                   VkCommandBuffer cmd);
void gdr_pass_record_draw_indexed(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                  VkCommandBuffer cmd);
void gdr_pass_record_lod_traverse(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                  VkCommandBuffer cmd);
void gdr_pass_record_task_submit(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                 VkCommandBuffer cmd);
void gdr_pass_record_meshlets(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass, VkCommandBuffer cmd);
void gdr_pass_record_pyramid(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass, VkCommandBuffer cmd);
void gdr_pass_record_overdraw_max(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                  VkCommandBuffer cmd);
void gdr_pass_record_overdraw_paint(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass,
                                    VkCommandBuffer cmd);
void gdr_pass_record_cpu_draws(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass, VkCommandBuffer cmd);
void gdr_pass_record_readback(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_pass *pass, VkCommandBuffer cmd);
/* The frame's viewport and scissor: the Vulkan Y flip (seed 000) for the scene, none for
 * full-screen passes. */
void gdr_frame_set_viewport(gdr_renderer *r, VkCommandBuffer cmd, bool flip_y);
/* What every frame pipeline expects bound: the push constants and the depth pyramid (set 0). */
void gdr_frame_bind_state(gdr_renderer *r, gdr_frame_slot *slot, VkCommandBuffer cmd);

#endif
