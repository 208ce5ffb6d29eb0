/* The CPU-driven pipeline (cpu_driven.c; cull_absent.c in a build without the culling module). */
#ifndef GDR_RENDER_CPU_DRIVEN_H
#define GDR_RENDER_CPU_DRIVEN_H

#include "render/renderer_internal.h"

gdr_status gdr_cpu_path_create(gdr_renderer *r, const gdr_scene *scene, gdr_error *err);
void gdr_cpu_path_destroy(gdr_renderer *r);
/* Instance `index` has moved: refresh its culling bounds. */
gdr_status gdr_cpu_path_update_instance(gdr_renderer *r, uint32_t index, gdr_error *err);
/* Culls on the CPU for this frame's camera (before recording). */
gdr_status gdr_cpu_path_cull(gdr_renderer *r, const gdr_frame_desc *frame, gdr_error *err);
/* One bind + draw sequence per visible instance, inside the render pass. */
void gdr_cpu_path_record_draws(gdr_renderer *r, VkCommandBuffer cmd, const GdrGpuPushConstants *push);

#endif
