/* One frame (frame.c): waiting for a slot, recording and submitting, the push constants, the
 * camera's matrices. */
#ifndef GDR_RENDER_FRAME_H
#define GDR_RENDER_FRAME_H

#include "render/renderer_internal.h"

/* Waits for the slot's previous frame (if any) and adds its GPU timings to r->timings. */
gdr_status gdr_frame_slot_wait(gdr_renderer *r, gdr_frame_slot *slot, gdr_error *err);
/* Records the commands that copy the colour image (left COLOR_ATTACHMENT_OPTIMAL by every frame)
 * into color_readback for the host. */
gdr_status gdr_frame_record_color_readback(gdr_renderer *r, VkCommandBuffer cmd, gdr_error *err);
/* Records (or reuses) and submits one frame into `slot`; adds the time spent in vkQueueSubmit2 to
 * *submit_ms. */
gdr_status gdr_frame_record_and_submit(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_desc *frame,
                                       gdr_pipeline pipeline, bool copy_color, double *submit_ms, gdr_error *err);
/* The push constants of the slot's frames. */
GdrGpuPushConstants gdr_frame_push_constants(const gdr_renderer *r, const gdr_frame_slot *slot);
/* The camera's projection and view for a frame (shared by the GPU globals and the CPU cull). */
void gdr_frame_matrices(const gdr_renderer *r, const gdr_camera *camera, gdr_mat4 *projection, gdr_mat4 *view);

#endif
