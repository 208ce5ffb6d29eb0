/* The scene on the GPU (gpu_scene.c): upload, the buffer addresses, the frame slots, the end. */
#ifndef GDR_RENDER_GPU_SCENE_H
#define GDR_RENDER_GPU_SCENE_H

#include "render/renderer_internal.h"

gdr_status gdr_gpu_scene_upload(gdr_renderer *r, const gdr_scene *scene, gdr_error *err);
/* The scene's buffer addresses (GdrGpuScene) for the push constants; after the occlusion history. */
gdr_status gdr_gpu_scene_write_refs(gdr_renderer *r, gdr_error *err);
void gdr_gpu_scene_destroy(gdr_renderer *r);
gdr_status gdr_frame_slots_create(gdr_renderer *r, gdr_error *err);
void gdr_frame_slots_destroy(gdr_renderer *r);

#endif
