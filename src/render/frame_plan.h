/* The frame as data. A frame of a given configuration (pipeline, raster, occlusion, view, instance
 * updates) is a list of passes, built once (frame_passes.c) and kept with the frame's recorded
 * commands. Each pass names the resources it reads and writes and how; from the list alone come
 * the barriers before each pass (gdr_frame_plan_derive), the timestamp queries and the timing
 * sections of the statistics, and the description of the frame in docs/PIPELINE.md
 * (gdr_describe_frame_passes). Adding a pass is adding a template and its recording function. */
#ifndef GDR_RENDER_FRAME_PLAN_H
#define GDR_RENDER_FRAME_PLAN_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "gdr/renderer.h"
#include "gpu_shared/gpu_config.h"
#include "vk/vk_image.h"

/* Two-phase occlusion culling's phases; the culling shaders' specialisation constant PHASE. */
typedef enum gdr_occlusion_phase {
    GDR_PHASE_ONLY = 0, /* no occlusion culling: one phase */
    GDR_PHASE_EARLY,    /* what was visible last frame, against last frame's pyramid */
    GDR_PHASE_LATE,     /* the rest, against the pyramid of what the early phase drew */
} gdr_occlusion_phase;

/* What the passes of a frame share. Buffers are synchronised with one global memory barrier per
 * pass, images also get their layout transitions. */
typedef enum gdr_frame_resource {
    GDR_RES_INSTANCES,        /* GdrGpuInstance[] (the update ring writes it) */
    GDR_RES_OCCLUDED,         /* the occluded lists: what the early phase defers to the late one */
    GDR_RES_DRAW_STATS,       /* the frame's counters and indirect launches (GdrGpuDrawStats) */
    GDR_RES_DRAWS,            /* indirect draw commands */
    GDR_RES_TASKS,            /* task commands */
    GDR_RES_TRAVERSAL,        /* the LOD hierarchy traversal's node visits */
    GDR_RES_VISIBLE_MESHLETS, /* the record of drawn clusters (tests, tools) */
    GDR_RES_OVERDRAW,         /* fragments per pixel (overdraw view) */
    GDR_RES_RASTER_COUNTERS,  /* GdrGpuRasterCounters with the rasterisers' launches */
    GDR_RES_RASTER_CLUSTERS,  /* the visible-cluster list */
    GDR_RES_VISBUFFER,        /* the 64-bit visibility buffer */
    GDR_RES_READBACK,         /* host-visible copies of the counters */
    GDR_RES_COLOR,            /* image: the colour target */
    GDR_RES_DEPTH,            /* image: the depth target */
    GDR_RES_HZB,              /* image: the depth pyramid (always GENERAL; its build orders its levels) */
    GDR_RES_COUNT
} gdr_frame_resource;

#define GDR_RES_FIRST_IMAGE GDR_RES_COLOR

/* The timing sections of the statistics (gdr_frame_stats.passes), in order. */
typedef enum gdr_frame_section {
    GDR_SECTION_INSTANCE_UPDATE,
    GDR_SECTION_CULL,
    GDR_SECTION_DRAW,
    GDR_SECTION_PYRAMID,
    GDR_SECTION_LATE_CULL,
    GDR_SECTION_LATE_DRAW,
    GDR_SECTION_READBACK,
    GDR_SECTION_COUNT,
    GDR_SECTION_NONE = GDR_SECTION_COUNT /* not timed (the frame's first and last synchronisation) */
} gdr_frame_section;

/* The visibility buffer's timings within the draw sections (raster_cull_ms .. raster_resolve_ms). */
typedef enum gdr_raster_timer {
    GDR_RASTER_TIMER_NONE,
    GDR_RASTER_TIMER_CULL,
    GDR_RASTER_TIMER_HW,
    GDR_RASTER_TIMER_SW,
    GDR_RASTER_TIMER_RESOLVE,
    GDR_RASTER_TIMER_COUNT
} gdr_raster_timer;

/* When a template's use applies. */
#define GDR_USE_ALWAYS 0u
#define GDR_USE_OVERDRAW_VIEW 1u  /* only in frames of the overdraw view */
#define GDR_USE_VISBUFFER 2u      /* only in visibility-buffer frames */
#define GDR_USE_CLEARS 4u         /* an image the pass writes whole (clears, or the resolve) in the
                                     frame's first raster phase (old contents discarded) and keeps in
                                     the late phase */
#define GDR_USE_TRAVERSAL 16u     /* only in frames that traverse the LOD hierarchy */

typedef struct gdr_resource_use {
    gdr_frame_resource resource;
    VkPipelineStageFlags2 stages;
    VkAccessFlags2 access;  /* 0 with an image: only its layout matters (the frame's end) */
    VkImageLayout layout;   /* images */
    bool discard;           /* images: the pass writes every texel, old contents are not kept */
    uint32_t flags;         /* GDR_USE_* */
} gdr_resource_use;

typedef struct gdr_frame_config {
    gdr_pipeline pipeline;  /* MESH, INDIRECT or CPU */
    bool visbuffer;         /* mesh pipeline: a visibility-buffer raster mode (HYBRID, HW, SW) */
    bool occlusion;         /* two phases against the depth pyramid */
    bool overdraw;          /* the overdraw view */
    bool updates;           /* instance updates in the ring: the scatter pass runs */
    uint32_t traversal_levels; /* mesh pipeline: levels of the LOD hierarchy traversal (0: none) */
} gdr_frame_config;

struct gdr_renderer;
struct gdr_frame_slot;
struct gdr_frame_pass;
typedef void (*gdr_pass_record_fn)(struct gdr_renderer *r, struct gdr_frame_slot *slot,
                                   const struct gdr_frame_pass *pass, VkCommandBuffer cmd);

#define GDR_PASS_MAX_USES 10
#define GDR_FRAME_MAX_PASSES (48 + 2 * GDR_LOD_TREE_LEVELS)
#define GDR_FRAME_MAX_TIMESTAMPS (GDR_FRAME_MAX_PASSES + 1)

/* A pass as written in the table. */
typedef struct gdr_pass_template {
    const char *name;
    gdr_pass_record_fn record; /* NULL: synchronisation only */
    gdr_raster_timer timer;
    const char *what;          /* one line for the frame's description */
    gdr_resource_use uses[GDR_PASS_MAX_USES];
} gdr_pass_template;

typedef struct gdr_image_transition {
    gdr_frame_resource resource;
    VkImageLayout from, to;
    gdr_vk_scope src, dst;
} gdr_image_transition;

/* What must happen before a pass: one pipeline barrier. */
typedef struct gdr_frame_barrier {
    gdr_vk_scope src, dst; /* the global memory barrier; empty: none */
    uint32_t image_count;
    gdr_image_transition images[3];
} gdr_frame_barrier;

/* A pass of a built frame. */
typedef struct gdr_frame_pass {
    const gdr_pass_template *template_;
    gdr_occlusion_phase phase;
    uint32_t step;                 /* a repeated pass's step (the traversal's level) */
    gdr_frame_section section;
    uint32_t use_count;
    gdr_resource_use uses[GDR_PASS_MAX_USES];
    /* Derived from the list: */
    gdr_frame_barrier barrier;
    bool begins_everything_before; /* the barrier is the frame's first: everything before it */
    int timestamp;                 /* the timestamp written before the pass, or -1 */
} gdr_frame_pass;

typedef struct gdr_frame_plan {
    gdr_frame_config config;
    uint32_t pass_count;
    gdr_frame_pass passes[GDR_FRAME_MAX_PASSES];
    gdr_frame_barrier end_barrier;  /* after the last pass: layouts and host reads for the CPU */
    uint32_t timestamp_count;       /* the last one follows the end barrier */
    /* Interval i (timestamp i to i + 1) belongs to: */
    gdr_frame_section interval_section[GDR_FRAME_MAX_TIMESTAMPS];
    gdr_raster_timer interval_timer[GDR_FRAME_MAX_TIMESTAMPS];
} gdr_frame_plan;

/* Builds the frame of `config` (frame_passes.c). */
void gdr_frame_plan_build(const gdr_frame_config *config, gdr_frame_plan *plan);
/* Appends a pass from its template (the uses that apply to the configuration and phase). */
void gdr_frame_plan_add(gdr_frame_plan *plan, const gdr_pass_template *pass, gdr_occlusion_phase phase,
                        gdr_frame_section section);
/* The same for step `step` of a repeated pass. */
void gdr_frame_plan_add_step(gdr_frame_plan *plan, const gdr_pass_template *pass, gdr_occlusion_phase phase,
                             uint32_t step, gdr_frame_section section);
/* Derives barriers and timestamps: what gdr_frame_plan_build ends with. */
void gdr_frame_plan_derive(gdr_frame_plan *plan);

/* The frame's start: every use by an earlier frame (whatever its configuration) or by the colour
 * read-back happens before the frame's first pass. The frame's end: `final_uses` of the images'
 * layouts and the host's reads. */
extern const gdr_pass_template gdr_frame_end_template;

const char *gdr_frame_section_name(gdr_frame_section section);
const char *gdr_frame_resource_name(gdr_frame_resource resource);
/* Writes the plan as Markdown (docs/PIPELINE.md). */
void gdr_frame_plan_describe(const gdr_frame_plan *plan, FILE *out);

#endif
