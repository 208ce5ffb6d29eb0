/* Geometry streaming, the GPU side (streaming.c): the pool, residency and loader for a scene about
 * to be uploaded (before gdr_gpu_scene_upload, which then leaves the geometry out), the frame slots'
 * parts, the work before each frame (read-backs into the residency, loads, evictions, copies
 * recorded into slot->stream_cmd), statistics, and the end. */
#ifndef GDR_RENDER_STREAMING_H
#define GDR_RENDER_STREAMING_H

#include "render/renderer_internal.h"

gdr_status gdr_streaming_open(gdr_renderer *r, const gdr_scene *scene, const gdr_streaming_desc *desc, gdr_error *err);
gdr_status gdr_streaming_start(gdr_renderer *r, gdr_error *err);
gdr_status gdr_streaming_slot_create(gdr_renderer *r, gdr_frame_slot *slot, gdr_error *err);
gdr_status gdr_streaming_begin_frame(gdr_renderer *r, gdr_frame_slot *slot, gdr_error *err);
void gdr_streaming_destroy(gdr_renderer *r);

#endif
