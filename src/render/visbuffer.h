/* The visibility buffer and the hybrid rasteriser of the mesh pipeline (docs/PIPELINE.md).
 *
 * Per raster phase, in the visibility-buffer modes (passes of frame_passes.c, recorded here):
 *  1. cluster_cull (clustercull.comp), launched indirectly over the instance cull's task commands:
 *     the per-cluster tests (shared/cluster_cull.h), then each visible cluster binned
 *     (shared/raster_bin.h) and appended to the frame's visible-cluster list, the compute
 *     rasteriser's at the front (its tiny clusters to the parts of their size classes after the
 *     list's `capacity` entries) and the mesh shaders' at the back;
 *  2. raster_submit (raster_submit.comp) writes the launches: the compute rasteriser's
 *     VkDispatchIndirectCommands (front, each tiny class) and the mesh shaders'
 *     VkDrawMeshTasksIndirectCommandEXT;
 *  3. raster_hw: the mesh-shader pass without a task shader (meshlet_list.mesh), one workgroup per
 *     cluster at the back of the list; its fragments write (depth, id) with a 64-bit atomicMax
 *     (meshlet_visbuffer.frag), no attachments;
 *  4. raster_sw (raster_sw.comp), the same atomics: its tiny variants over the tiny classes' parts of
 *     the list, several clusters per workgroup, then one workgroup per cluster at the front;
 *  5. resolve (visbuffer_resolve.comp) shades every pixel into the colour image (a storage image);
 *     the depth stays in the visibility buffer, from which the depth pyramid is built.
 * The frame's clear pass zeroes the counters and the visibility buffer.
 *
 * The list holds every cluster of every instance's DAG (at most GDR_RASTER_MAX_CLUSTERS entries),
 * so it cannot overflow below that size; beyond it, clusters that do not fit are dropped and counted
 * (GdrGpuRasterCounters.overflow, gdr_frame_stats.raster_overflow). */
#ifndef GDR_VISBUFFER_H
#define GDR_VISBUFFER_H

#include "gdr/renderer.h"
#include "gpu_shared/gpu_types.h"
#include "vk/vk_buffer.h"

struct gdr_frame_slot;

typedef struct gdr_visbuffer {
    bool supported;              /* mesh shaders and 64-bit buffer atomics */
    char missing[160];           /* why not, when not */
    gdr_vk_buffer pixels;        /* uint64 per pixel */
    gdr_vk_buffer clusters;      /* GdrGpuRasterCluster[slots], made with the scene */
    gdr_vk_buffer counters;      /* GdrGpuRasterCounters */
    gdr_vk_buffer params[GDR_FRAMES_IN_FLIGHT];            /* GdrGpuRasterParams, host-written */
    gdr_vk_buffer counters_readback[GDR_FRAMES_IN_FLIGHT]; /* the counters of the slot's last frame */
    uint32_t capacity;           /* the front and back of the list */
    uint32_t tiny_capacity[GDR_SW_TINY_CLASSES]; /* each tiny class's part after them (0: none) */
    uint32_t tiny_base[GDR_SW_TINY_CLASSES];     /* the first slot of each */
    uint32_t slots;              /* capacity and the tiny parts */
    uint32_t mode;               /* GDR_GPU_RASTER_* of the frames of the current render call */
    char reason[128];            /* why that mode */
    uint32_t slot_mode[GDR_FRAMES_IN_FLIGHT]; /* GDR_GPU_RASTER_* of the slot's last frame */
} gdr_visbuffer;

/* Creates the visibility buffer where the device can (else records why); its pipelines are the
 * registry's (pipelines.h). */
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

/* Writes the slot's parameters for a frame in `mode`. The slot's previous frame must have finished
 * (gdr_frame_slot_wait). */
void gdr_visbuffer_begin_frame(gdr_renderer *r, uint32_t slot_index, const gdr_frame_desc *frame, uint32_t mode);
/* The recording functions of the passes above. */
struct gdr_frame_pass;
void gdr_visbuffer_record_cluster_cull(gdr_renderer *r, struct gdr_frame_slot *slot, const struct gdr_frame_pass *pass,
                                       VkCommandBuffer cmd);
void gdr_visbuffer_record_raster_submit(gdr_renderer *r, struct gdr_frame_slot *slot,
                                        const struct gdr_frame_pass *pass, VkCommandBuffer cmd);
void gdr_visbuffer_record_raster_hw(gdr_renderer *r, struct gdr_frame_slot *slot, const struct gdr_frame_pass *pass,
                                    VkCommandBuffer cmd);
void gdr_visbuffer_record_raster_sw(gdr_renderer *r, struct gdr_frame_slot *slot, const struct gdr_frame_pass *pass,
                                    VkCommandBuffer cmd);
void gdr_visbuffer_record_resolve(gdr_renderer *r, struct gdr_frame_slot *slot, const struct gdr_frame_pass *pass,
                                  VkCommandBuffer cmd);
/* Fills the raster fields of `stats` from the last frame (slot `slot_index`), once every slot has
 * finished; the timings are means over the frames of the render call. */
void gdr_visbuffer_stats(gdr_renderer *r, uint32_t slot_index, gdr_frame_stats *stats);

/* Tests and tools: one pixel of the last frame's visibility buffer, decoded. */
typedef struct gdr_visbuffer_pixel {
    float depth;       /* 0: empty */
    uint32_t instance; /* UINT32_MAX when empty */
    uint32_t meshlet;  /* global cluster index; UINT32_MAX for a point level's splat */
    uint32_t triangle; /* GDR_VISBUFFER_POINT_TRIANGLE for a point level's splat */
} gdr_visbuffer_pixel;

/* Reads back the visibility buffer of the last frame (width * height pixels, rows top first). */
gdr_status gdr_visbuffer_read_pixels(gdr_renderer *r, gdr_visbuffer_pixel *pixels, gdr_error *err);
/* Reads back the depth image of the last frame (width * height floats). */
gdr_status gdr_visbuffer_read_depth(gdr_renderer *r, float *depth, gdr_error *err);
/* Reads back the overdraw view's counts of the last frame (width * height). */
gdr_status gdr_visbuffer_read_overdraw(gdr_renderer *r, uint32_t *counts, gdr_error *err);

#endif
