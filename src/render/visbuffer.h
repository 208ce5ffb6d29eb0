/* The visibility buffer and the hybrid rasteriser of the mesh pipeline (issue 8, docs/PIPELINE.md).
 *
 * Per frame, in the visibility-buffer modes:
 *  1. fills: the counters and the visibility buffer to zero (gdr_visbuffer_begin_frame);
 *  2. the cluster cull (clustercull.comp), launched indirectly over the instance cull's task
 *     commands: the per-cluster tests of the task shader (shared/cluster_cull.h), then each visible
 *     cluster binned (shared/raster_bin.h) and appended to the frame's visible-cluster list, the
 *     compute rasteriser's at the front and the mesh shaders' at the back;
 *  3. raster_submit.comp writes both launches: the compute rasteriser's VkDispatchIndirectCommand
 *     and the mesh shaders' VkDrawMeshTasksIndirectCommandEXT;
 *  4. the mesh-shader pass without a task shader (meshlet_list.mesh), one workgroup per cluster at
 *     the back of the list; its fragments write (depth, id) with a 64-bit atomicMax
 *     (meshlet_visbuffer.frag), no attachments;
 *  5. raster_sw.comp, one workgroup per cluster at the front, writes the same atomics;
 *  6. the resolve (visbuffer_resolve.comp) shades every pixel and writes its colour and depth into
 *     a buffer, copied into the colour and depth images.
 * Steps 2 to 6 are gdr_visbuffer_record_raster; the CPU records the same commands whatever the scene.
 *
 * The list holds every cluster of every instance's DAG (at most GDR_RASTER_MAX_CLUSTERS entries),
 * so it cannot overflow below that size; beyond it, clusters that do not fit are dropped and counted
 * (GdrGpuRasterCounters.overflow, gdr_frame_stats.raster_overflow). */
#ifndef GDR_VISBUFFER_H
#define GDR_VISBUFFER_H

#include "gdr/renderer.h"
#include "shaders/shared/gpu_types.h"
#include "vk/vk_buffer.h"

struct gdr_frame_slot;

enum gdr_visbuffer_timestamp {
    GDR_VISBUFFER_TS_BEGIN,     /* before the cluster cull */
    GDR_VISBUFFER_TS_AFTER_CULL,
    GDR_VISBUFFER_TS_AFTER_HW,
    GDR_VISBUFFER_TS_AFTER_SW,
    GDR_VISBUFFER_TS_AFTER_RESOLVE,
    GDR_VISBUFFER_TS_COUNT
};

typedef struct gdr_visbuffer {
    bool supported;              /* mesh shaders and 64-bit buffer atomics */
    char missing[160];           /* why not, when not */
    gdr_vk_buffer pixels;        /* uint64 per pixel */
    gdr_vk_buffer resolved;      /* the resolve's output: RGBA8 per pixel, then float depth per pixel */
    gdr_vk_buffer clusters;      /* GdrGpuRasterCluster[capacity], made with the scene */
    gdr_vk_buffer counters;      /* GdrGpuRasterCounters */
    gdr_vk_buffer params[GDR_FRAMES_IN_FLIGHT];            /* GdrGpuRasterParams, host-written */
    gdr_vk_buffer counters_readback[GDR_FRAMES_IN_FLIGHT]; /* the counters of the slot's last frame */
    uint32_t capacity;
    uint32_t mode;               /* GDR_GPU_RASTER_* of the frames of the current render call */
    char reason[128];            /* why that mode */
    VkPipeline cull_pipelines[3]; /* cluster cull per occlusion phase: none, early, late */
    VkPipeline hw_pipeline;       /* mesh shaders (no task shader) into the visibility buffer */
    VkPipeline sw_pipeline, submit_pipeline;
    VkPipeline resolve_pipelines[2]; /* shading; depth only (occlusion culling's early phase) */
    VkQueryPool timestamps;      /* GDR_VISBUFFER_TS_COUNT per raster phase, two phases per frame slot */
    uint32_t slot_mode[GDR_FRAMES_IN_FLIGHT]; /* GDR_GPU_RASTER_* of the slot's last frame */
    uint32_t slot_phases[GDR_FRAMES_IN_FLIGHT]; /* raster phases timed in it, yet to be read */
    double pass_ms[GDR_VISBUFFER_TS_COUNT - 1]; /* cull, hw, sw, resolve, summed over the timed frames
                                                    of one render call */
    uint32_t timed_frames;
} gdr_visbuffer;

/* Creates the visibility buffer and the pipelines where the device can (else records why). */
gdr_status gdr_visbuffer_create(gdr_renderer *r, bool disabled, gdr_error *err);
/* Sizes the visible-cluster list from the uploaded scene. */
gdr_status gdr_visbuffer_set_scene(gdr_renderer *r, gdr_error *err);
void gdr_visbuffer_destroy(gdr_renderer *r);

/* The GDR_GPU_RASTER_* mode a frame asks for on `pipeline`, with the reason; fails for a
 * visibility-buffer mode the device or the pipeline cannot do. */
gdr_status gdr_visbuffer_resolve_mode(const gdr_renderer *r, const gdr_frame_desc *frame, gdr_pipeline pipeline,
                                      uint32_t *mode, char *reason, size_t reason_size, gdr_error *err);
/* Public name of a GDR_GPU_RASTER_* mode. */
gdr_raster gdr_visbuffer_public_mode(uint32_t mode);
/* The threshold a frame uses: its own, or the default. */
float gdr_visbuffer_threshold(const gdr_frame_desc *frame);

/* Start of a gdr_renderer_render call: timings restart. */
void gdr_visbuffer_begin_render(gdr_renderer *r);
/* Adds the timings of the slot's last frame (summed over its raster phases), if it was timed and
 * has finished (its fence was waited for before this is called); a no-op once collected. */
void gdr_visbuffer_collect_timings(gdr_renderer *r, uint32_t slot_index);
/* Writes the slot's parameters for a frame in `mode`. The slot's previous frame must have finished
 * and its timings been collected (gdr_frame_slot_wait does both). */
void gdr_visbuffer_begin_frame(gdr_renderer *r, uint32_t slot_index, const gdr_frame_desc *frame, uint32_t mode);
/* Records the frame's fills (before the barrier that follows the frame's other fills: transfer
 * writes -> task, mesh, fragment and compute shaders). */
void gdr_visbuffer_record_fills(gdr_renderer *r, uint32_t slot_index, VkCommandBuffer cmd);
/* Steps 2 to 6 above for one raster phase (0: the only one, 1: occlusion culling's early phase,
 * 2: its late phase, which adds to what the early one wrote), after the instance cull's barrier
 * (which must make its writes visible to compute shaders and indirect reads); `launch`: the offset
 * of the phase's cluster-cull launch (a VkDispatchIndirectCommand) in the slot's draw stats.
 * Leaves the depth image in DEPTH_ATTACHMENT_OPTIMAL with the depth of everything rasterised so far
 * (for the depth pyramid) and, except in the early phase (depth only: the late phase shades
 * everything), the colour image shaded in COLOR_ATTACHMENT_OPTIMAL; their writes and the overdraw
 * counts visible to fragment and compute shaders. */
void gdr_visbuffer_record_raster(gdr_renderer *r, struct gdr_frame_slot *slot, VkCommandBuffer cmd, int phase,
                                 VkDeviceSize launch);
/* Copies the counters for the CPU (after a barrier making task and compute writes visible to copies). */
void gdr_visbuffer_record_readback(gdr_renderer *r, uint32_t slot_index, VkCommandBuffer cmd);
/* Fills the raster fields of `stats` from the last frame (slot `slot_index`), once every slot has
 * finished; the timings are means over the frames of the render call. */
void gdr_visbuffer_stats(gdr_renderer *r, uint32_t slot_index, gdr_frame_stats *stats);

/* Tests and tools: one pixel of the last frame's visibility buffer, decoded. */
typedef struct gdr_visbuffer_pixel {
    float depth;       /* 0: empty */
    uint32_t instance; /* UINT32_MAX when empty */
    uint32_t meshlet;  /* global cluster index */
    uint32_t triangle;
} gdr_visbuffer_pixel;

/* Reads back the visibility buffer of the last frame (width * height pixels, rows top first). */
gdr_status gdr_visbuffer_read_pixels(gdr_renderer *r, gdr_visbuffer_pixel *pixels, gdr_error *err);
/* Reads back the depth image of the last frame (width * height floats). */
gdr_status gdr_visbuffer_read_depth(gdr_renderer *r, float *depth, gdr_error *err);
/* Reads back the overdraw view's counts of the last frame (width * height). */
gdr_status gdr_visbuffer_read_overdraw(gdr_renderer *r, uint32_t *counts, gdr_error *err);

#endif
