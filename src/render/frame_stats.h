/* The statistics of a render call (frame_stats.c). */
#ifndef GDR_RENDER_FRAME_STATS_H
#define GDR_RENDER_FRAME_STATS_H

#include "render/renderer_internal.h"

/* The statistics of a render call (frame_stats.c) after its last frame has finished; sorts
 * frame_cpu_ms. */
void gdr_frame_stats_fill(gdr_renderer *r, gdr_pipeline pipeline, const char *reason, double *frame_cpu_ms,
                          uint32_t frames, double submit_ms, uint32_t recorded, gdr_frame_stats *stats);

#endif
