/* The renderer's state, shared by the files of src/render. */
#ifndef GDR_RENDERER_INTERNAL_H
#define GDR_RENDERER_INTERNAL_H

#include "gdr/renderer.h"
#include "gdr/thread_pool.h"
#include "render/frame_plan.h"
#include "render/renderer_debug.h"
#include "render/materials.h"
#include "render/occlusion.h"
#include "render/pipelines.h"
#include "gpu_shared/gpu_types.h"
#include "vk/vk_buffer.h"
#include "vk/vk_context.h"
#include "vk/vk_image.h"
#include "vk/vk_memory.h"
#include "render/visbuffer.h"
#include "stream/lod_budget.h"

/* GPU timings summed over the frames of one gdr_renderer_render call. */
typedef struct gdr_frame_timings {
    double section_ms[GDR_SECTION_COUNT];
    double raster_ms[GDR_RASTER_TIMER_COUNT];
    uint32_t frames;        /* frames timed */
    uint32_t raster_frames; /* of those, frames with visibility-buffer passes */
} gdr_frame_timings;

/* The CPU-driven baseline (seed 003's "before"): the gdr/cull.h library culls on the CPU, then
 * one vkCmdDrawIndexed with its own binds per visible instance. */
typedef struct gdr_cpu_path {
    struct gdr_cull_mesh_bounds *mesh_bounds; /* per mesh, from gdr_cpu_path_create */
    uint32_t mesh_count;
    struct gdr_cull_scene *cull_scene;        /* built when the pipeline is first used */
    uint32_t *visible_bits;   /* gdr_cull_word_count(instances) words */
    uint32_t *visible;        /* indices of the visible instances of the last culled frame */
    uint32_t visible_count;
    uint64_t triangles;
    uint32_t pvs_culled;      /* the last frame's instances culled by the precomputed visibility */
    bool pvs_cell_found;      /* the last frame's camera was in a baked cell */
    double cull_ms;           /* summed over the frames of one gdr_renderer_render */
} gdr_cpu_path;

/* Precomputed visibility (pvs_frame.c): the caller's PVS, the renderer's lookups in it, and the
 * instances moved since the scene was set, which it never culls. */
typedef struct gdr_render_pvs {
    const struct gdr_pvs *pvs;       /* NULL: none */
    struct gdr_pvs_cache *cache;     /* lookups for the GPU-driven frames and the CPU pipeline's cull */
    uint32_t *moved;                 /* gdr_cull_word_count(instances) words: bit i, instance i moved */
    uint32_t words;
    uint64_t moved_version;          /* bumped when a bit of `moved` is set */
    uint64_t version;                /* bumped when the PVS is replaced */
    double cpu_ms;                   /* lookups and uploads, summed over the frames of one render call */
} gdr_render_pvs;

/* The geometry pool and the instances on the GPU (seed 000's PrimitiveBuffer and InstanceBuffer). */
typedef struct gdr_gpu_scene {
    gdr_vk_buffer vertices;  /* GdrGpuVertex[], all meshes merged */
    gdr_vk_buffer indices;   /* uint32[], mesh-local indices, all meshes merged */
    gdr_vk_buffer meshes;    /* GdrGpuMesh[] */
    gdr_vk_buffer instances; /* GdrGpuInstance[], persistent; changed through the update ring */
    gdr_vk_buffer meshlets;          /* GdrGpuMeshlet[], all meshes' clusters */
    gdr_vk_buffer meshlet_vertices;  /* uint32[]: global vertex index per cluster-local vertex */
    gdr_vk_buffer meshlet_triangles; /* uint32[] holding 3 bytes per cluster triangle */
    gdr_vk_buffer traversal;         /* GdrGpuNodeVisit[2 * traversal_capacity]: the traversal's levels */
    gdr_vk_buffer lod_nodes;         /* GdrGpuLodNode[]: every mesh's LOD hierarchy, as gdr_lod_node */
    gdr_vk_buffer page_table;        /* uint32 per group of every mesh (shared/residency.h, page_table.c) */
    gdr_vk_buffer node_absent_refined; /* uint32 per LOD node: clusters below whose refined group is absent */
    gdr_vk_buffer group_stamps;      /* uint32 per group of every mesh: the last streaming frame that drew it */
    gdr_vk_buffer refs;              /* GdrGpuScene: the addresses above, for the push constants */
    uint32_t group_total, node_total; /* LOD groups and nodes of every mesh */
    uint64_t absent_groups;          /* groups whose page-table word is GDR_GPU_PAGE_ABSENT */
    uint32_t *cpu_mesh_absent;       /* absent groups per mesh (NULL until a group was marked) */
    bool streamed;                   /* geometry in the streaming page pool (streaming.c), not uploaded whole */
    uint32_t mesh_count;
    uint32_t instance_count;
    uint32_t meshlet_count;
    uint32_t task_capacity;        /* task commands of one phase: the task buffer holds two phases */
    uint32_t traversal_capacity;   /* node visits of one traversal level */
    uint32_t traversal_levels;     /* levels of the deepest mesh hierarchy */
    uint64_t instance_meshlet_count; /* level-0 clusters summed over the instances (meshlets_total) */
    uint64_t instance_lod_cluster_count; /* every DAG cluster summed over the instances */
    uint64_t instance_tiny_cluster_count[GDR_SW_TINY_CLASSES]; /* of those, the tiny ones per size class */
    uint64_t bytes;                /* device memory of the buffers above and the occlusion history */
    GdrGpuMesh *cpu_meshes;        /* host copies, for references and statistics */
    GdrGpuMeshlet *cpu_meshlets;
    GdrGpuInstance *cpu_instances;
    GdrGpuInstanceUpdate *pending; /* updates not yet sent to the GPU */
    uint32_t pending_count, pending_capacity;
} gdr_gpu_scene;

/* What one frame in flight owns. A GPU-driven slot keeps the plan its command buffer was recorded
 * from and submits it again while the next frame's configuration is the same: everything else a
 * frame changes (camera, options read by the shaders, instance updates) lives in buffers the CPU
 * rewrites before each submit. */
typedef struct gdr_frame_slot {
    VkCommandBuffer cmd;
    VkCommandBuffer readback_cmd; /* copies the colour image for the CPU; recorded once, submitted after
                                     `cmd` in frames that read the image back */
    gdr_frame_plan plan;         /* the passes of the frame last recorded into `cmd` */
    bool recorded;               /* `cmd` holds `plan` and may be submitted again */
    bool resubmitted;            /* the last frame submitted `cmd` again without recording */
    VkFence fence;
    bool submitted;
    bool timed;                  /* the submitted frame wrote its timestamps: read them after the fence */
    gdr_vk_buffer globals;       /* GdrGpuFrameGlobals, host-written */
    gdr_vk_buffer frame_buffers; /* GdrGpuFrameBuffers, host-written */
    gdr_vk_buffer updates;       /* GdrGpuInstanceUpdate[GDR_INSTANCE_UPDATES_PER_FRAME], host-written ring slot */
    gdr_vk_buffer draws;         /* GdrGpuDrawCommand[2 * instance_count]: early (or only) phase, late phase */
    gdr_vk_buffer draw_stats;    /* GdrGpuDrawStats, device-local */
    gdr_vk_buffer stats_readback;/* GdrGpuDrawStats copied for the CPU */
    gdr_vk_buffer tasks;         /* GdrGpuTaskCommand[2 * task_capacity]: early (or only) phase, late phase */
    gdr_vk_buffer stream_requests; /* GdrGpuStreamRequest[GDR_STREAM_REQUEST_CAPACITY], host-read */
    gdr_vk_buffer used_groups;   /* uint32 per group of every mesh (streaming: the groups the cut drew), host-read */
    /* Streaming: the pages, records and page-table words this frame copies into place, in a command
     * buffer submitted before `cmd`. */
    VkCommandBuffer stream_cmd;
    gdr_vk_buffer stream_staging;
    bool stream_copies;          /* stream_cmd holds this frame's copies */
    bool stream_results;         /* the slot's last frame streamed: its lists are to be read */
    uint32_t stream_frame;       /* the number stamped on the groups the frame drew (0: no list) */
    float stream_lod_scale;      /* the factor on the LOD threshold the frame drew with */
    gdr_pipeline pipeline;       /* of the frame last recorded into this slot */
    bool lod_applied;            /* that frame selected a LOD cut (GDR_FRAME_LOD) */
    bool occlusion_applied;      /* that frame culled in two phases against the depth pyramid */
    /* CPU pipeline: what the CPU decided for the frame last recorded into this slot. */
    uint32_t cpu_visible_count;
    uint64_t cpu_triangles;
    uint32_t cpu_pvs_culled;
    /* Precomputed visibility: the cell's bits of the slot's frame (host-written, read by the
     * instance cull under GDR_FRAME_PVS), what they were made from (to skip an unchanged copy), and
     * what the frame used. */
    gdr_vk_buffer pvs_visible;
    const uint32_t *pvs_source;
    uint64_t pvs_source_decompressions, pvs_source_moved, pvs_source_version;
    bool pvs_enabled, pvs_cell_found;
} gdr_frame_slot;

/* The renderer's side of streaming (streaming.c, docs/STREAMING.md): the page pool, the residency
 * deciding what it holds, the loader thread, and the pages read but not yet copied. */
typedef struct gdr_streaming {
    bool enabled;
    bool wait_for_loads;
    gdr_thread_pool *set_up_pool; /* from the open to the first pages' arrival (NULL: one thread) */
    bool meshes_changed;    /* a page 0 set its mesh's root shortcut: the meshes are uploaded again */
    uint32_t records_per_slot; /* the most clusters a page holds: a slot's room in the record pool */
    const gdr_scene *scene;             /* the caller's: clusters and LOD hierarchies */
    struct gdr_paged_cache *cache;
    struct gdr_residency *residency;
    struct gdr_page_loader *loader;
    gdr_vk_buffer pool;                 /* slot_count x slot_bytes: vertices, vertex list, triangles per page */
    uint32_t slot_count, slot_bytes;
    uint64_t upload_budget;
    uint64_t staging_bytes;             /* each frame slot's staging buffer */
    uint32_t *slot_page;                /* per pool slot: the global page the GPU may read there, or UINT32_MAX */
    uint32_t *page_base;                /* per mesh + 1: its first global page */
    uint8_t *mesh_dirty;                /* meshes whose absent groups change this frame ... */
    uint32_t *dirty_list, dirty_count;  /* ... listed */
    VkBufferCopy *copies;               /* scratch: a frame's copy regions (groups + slots + nodes) */
    uint32_t *words;                    /* scratch: a frame's page-table words (3 x groups) */
    struct gdr_node_counts *node_counts; /* the LOD nodes' absent counts, updated per changed group */
    struct gdr_node_run *node_runs;     /* scratch: a frame's runs of changed counts */
    struct gdr_page_result *pending;    /* read and checked, waiting for upload room, in load order */
    uint32_t pending_count, pending_capacity;
    struct gdr_stream_request *requests; /* scratch: GDR_STREAM_REQUEST_CAPACITY */
    struct gdr_stream_load *loads;      /* scratch: slot_count */
    uint32_t frame;                     /* streaming frames begun */
    gdr_lod_budget lod_budget;          /* the factor on the LOD threshold that fits the cut to the pool */
    bool fixed_lod_error;               /* the factor stays 1 */
    uint32_t unsettled_frame;           /* the last frame whose factor or resident set changed */
    gdr_streaming_stats stats;          /* the last frame's, and the totals */
} gdr_streaming;

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
    VkPipeline pipelines[GDR_PIPE_COUNT]; /* the registry's (pipelines.h); NULL where the device cannot */
    gdr_occlusion occlusion;
    gdr_materials materials;      /* the material buffer and the bindless textures (set GDR_TEXTURE_SET) */
    gdr_vk_buffer overdraw;       /* uint32 per pixel, then the maximum (overdraw view) */
    gdr_vk_buffer visible_meshlets; /* uint32 pairs, one per cluster of every instance; made on first use */
    gdr_visbuffer vis;            /* the visibility buffer and the hybrid rasteriser */
    gdr_cpu_path cpu;
    gdr_render_pvs pvs;
    VkQueryPool timestamps;       /* GDR_FRAME_MAX_TIMESTAMPS per frame slot */
    gdr_frame_timings timings;
    gdr_gpu_scene scene;
    gdr_streaming stream;
    bool has_scene;
    gdr_frame_slot slots[GDR_FRAMES_IN_FLIGHT];
    uint32_t frame_index;
    bool record_every_frame;      /* gdr_renderer_desc.record_every_frame: never resubmit */
    gdr_renderer_debug debug;     /* tests' knobs (render/renderer_debug.h) */
    int last_slot; /* slot of the last submitted frame, -1 before the first */
};

#define GDR_COLOR_FORMAT VK_FORMAT_R8G8B8A8_UNORM
#define GDR_DEPTH_FORMAT VK_FORMAT_D32_SFLOAT

#define GDR_CLEAR_COLOR {{GDR_BACKGROUND_R, GDR_BACKGROUND_G, GDR_BACKGROUND_B, 1.0f}} /* the background */

/* Milliseconds on a monotonic clock (renderer.c). */
double gdr_now_ms(void);

#endif
