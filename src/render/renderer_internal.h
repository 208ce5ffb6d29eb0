/* The renderer's state, shared by the files of src/render. */
#ifndef GDR_RENDERER_INTERNAL_H
#define GDR_RENDERER_INTERNAL_H

#include "gdr/renderer.h"
#include "shaders/shared/gpu_types.h"
#include "vk/vk_buffer.h"
#include "vk/vk_context.h"
#include "vk/vk_image.h"
#include "vk/vk_memory.h"

/* Timestamps written per frame, in order; pass i lasts from timestamp i to i + 1. */
enum gdr_timestamp {
    GDR_TS_BEGIN,
    GDR_TS_AFTER_UPDATE,
    GDR_TS_AFTER_CULL,
    GDR_TS_AFTER_DRAW,
    GDR_TS_END,
    GDR_TS_COUNT
};

/* The geometry pool and the instances on the GPU (seed 000's PrimitiveBuffer and InstanceBuffer). */
typedef struct gdr_gpu_scene {
    gdr_vk_buffer vertices;  /* GdrGpuVertex[], all meshes merged */
    gdr_vk_buffer indices;   /* uint32[], mesh-local indices, all meshes merged */
    gdr_vk_buffer meshes;    /* GdrGpuMesh[] */
    gdr_vk_buffer instances; /* GdrGpuInstance[], persistent; changed through the update ring */
    uint32_t mesh_count;
    uint32_t instance_count;
    GdrGpuMesh *cpu_meshes;        /* host copies, for references and statistics */
    GdrGpuInstance *cpu_instances;
    GdrGpuInstanceUpdate *pending; /* updates not yet sent to the GPU */
    uint32_t pending_count, pending_capacity;
} gdr_gpu_scene;

/* What one frame in flight owns. */
typedef struct gdr_frame_slot {
    VkCommandBuffer cmd;
    VkFence fence;
    bool submitted;
    bool timestamps_written;
    gdr_vk_buffer globals;       /* GdrGpuFrameGlobals, host-written */
    gdr_vk_buffer updates;       /* GdrGpuInstanceUpdate[GDR_INSTANCE_UPDATES_PER_FRAME], host-written ring slot */
    gdr_vk_buffer draws;         /* GdrGpuDrawCommand[instance_count] */
    gdr_vk_buffer draw_stats;    /* GdrGpuDrawStats, device-local */
    gdr_vk_buffer stats_readback;/* GdrGpuDrawStats copied for the CPU */
} gdr_frame_slot;

struct gdr_renderer {
    gdr_vk_context *ctx;
    gdr_vk_allocator allocator;
    gdr_vk_buffer staging;
    uint32_t width, height;
    bool busy_wait;
    gdr_vk_image color, depth;
    gdr_vk_buffer color_readback; /* width * height * 4 bytes */
    bool color_read_back;
    VkPipelineLayout layout;
    VkPipeline cull_pipeline, scatter_pipeline, draw_pipeline;
    VkQueryPool timestamps;
    gdr_gpu_scene scene;
    bool has_scene;
    gdr_frame_slot slots[GDR_FRAMES_IN_FLIGHT];
    uint32_t frame_index;
    int last_slot; /* slot of the last submitted frame, -1 before the first */
};

#define GDR_COLOR_FORMAT VK_FORMAT_R8G8B8A8_UNORM
#define GDR_DEPTH_FORMAT VK_FORMAT_D32_SFLOAT

gdr_status gdr_gpu_scene_upload(gdr_renderer *r, const gdr_scene *scene, gdr_error *err);
void gdr_gpu_scene_destroy(gdr_renderer *r);
gdr_status gdr_frame_slots_create(gdr_renderer *r, gdr_error *err);
void gdr_frame_slots_destroy(gdr_renderer *r);

/* Waits for the slot's previous frame (if any) and gathers its timings into `gpu_ms` (may be NULL). */
gdr_status gdr_frame_slot_wait(gdr_renderer *r, gdr_frame_slot *slot, double gpu_ms[GDR_TS_COUNT - 1], gdr_error *err);
/* Records and submits one frame into `slot`; adds the time spent in vkQueueSubmit2 to *submit_ms. */
gdr_status gdr_frame_record_and_submit(gdr_renderer *r, gdr_frame_slot *slot, const gdr_frame_desc *frame,
                                       bool copy_color, double *submit_ms, gdr_error *err);
double gdr_now_ms(void);

#endif
