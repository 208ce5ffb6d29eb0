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
/* The hierarchy's leaves for the record pool: each leaf's first cluster (mesh m's nodes at
 * nodes + first[m]) becomes its group's first record within its page, whose slot holds the page's
 * records in page order. */
void gdr_streaming_leaves_in_pages(gdr_renderer *r, GdrGpuLodNode *nodes, const uint32_t *first);
/* The mesh-local cluster of record `record` of the record pool (its slot's page's), *mesh its mesh;
 * UINT32_MAX where the slot holds no page or the page no such record. */
uint32_t gdr_streaming_record_cluster(const gdr_renderer *r, uint32_t record, uint32_t *mesh);

#endif
