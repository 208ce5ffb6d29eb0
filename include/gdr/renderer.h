/* gdr renderer: a GPU-driven frame on Vulkan, headless.
 *
 * Per frame the CPU records a fixed number of commands whatever the scene: a compute pass culls
 * every instance and appends the visible ones as indirect draw commands, and one
 * vkCmdDrawIndexedIndirectCount draws them (seed 003). */
#ifndef GDR_RENDERER_H
#define GDR_RENDERER_H

#include <stdbool.h>
#include <stdio.h>
#include <stdint.h>

#include "gdr/core.h"
#include "gdr/paged_cache.h"
#include "gdr/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct gdr_renderer gdr_renderer;
typedef struct gdr_pvs gdr_pvs; /* precomputed visibility (gdr/cull.h) */

typedef struct gdr_renderer_desc {
    uint32_t width, height; /* render target size; 0: 1280 x 720 */
    const char *device;     /* NULL: first discrete GPU, else any; "N": index; else a name substring */
    bool validate;          /* Khronos validation layer; messages are counted in the stats */
    bool synchronization_validation; /* also synchronization validation (implies validate) */
    /* Poll frame fences instead of sleeping on them. For benchmarks: a core that sleeps through a
     * long GPU frame wakes up slower, which would make CPU timings depend on the GPU's load. */
    bool busy_wait;
    bool disable_mesh_shaders; /* behave as a device without VK_EXT_mesh_shader (tests the fallback) */
    bool disable_visibility_buffer; /* behave as a device without 64-bit buffer atomics */
    /* behave as a device without BC texture sampling: block-compressed textures are decoded to
     * RGBA8 at upload (tests the fallback; the program sets it from GDR_DISABLE_BC_TEXTURES=1) */
    bool disable_texture_compression_bc;
    /* The GPU-driven pipelines record a frame slot's commands once and submit them again while
     * nothing they depend on changes (pipeline, raster mode, occlusion culling, overdraw view,
     * whether instance updates are pending). true: record every frame (to measure what recording
     * costs). The CPU pipeline always records. */
    bool record_every_frame;
    /* Presenting to a window (gdr/present.h): the instance extensions the window system needs
     * (e.g. from glfwGetRequiredInstanceExtensions; at most 8), and whether the device must be able
     * to present (VK_KHR_swapchain). Without them the renderer is headless. */
    const char *const *instance_extensions;
    uint32_t instance_extension_count;
    bool presentable;
} gdr_renderer_desc;

typedef enum gdr_cull_mode {
    GDR_CULL_DEFAULT = 0, /* on */
    GDR_CULL_ON,
    GDR_CULL_OFF, /* every instance is drawn: the reference image for culling tests */
} gdr_cull_mode;

/* How a frame is culled and submitted. */
typedef enum gdr_pipeline {
    GDR_PIPELINE_DEFAULT = 0, /* mesh where the device has VK_EXT_mesh_shader, else indirect */
    GDR_PIPELINE_MESH,        /* compute instance cull -> task shader meshlet cull -> mesh shader */
    GDR_PIPELINE_INDIRECT,    /* compute instance cull -> one vkCmdDrawIndexedIndirectCount (seed 003) */
    GDR_PIPELINE_CPU,         /* CPU-driven baseline: gdr/cull.h on the CPU, then one vkCmdDrawIndexed
                                 with its own binds per visible instance (seed 003's "before"); a
                                 library without the culling module (GDR_HAVE_CULL 0) refuses it
                                 with GDR_ERROR_UNSUPPORTED */
} gdr_pipeline;

/* What the image shows. */
typedef enum gdr_view {
    GDR_VIEW_MODE_SHADED = 0,
    GDR_VIEW_MODE_MESHLETS,  /* each cluster in a colour from a hash of its index (mesh pipeline) */
    GDR_VIEW_MODE_INSTANCES, /* each instance in a colour of its own */
    GDR_VIEW_MODE_TRIANGLES, /* each triangle in a colour of its own: triangle density (mesh pipeline) */
    GDR_VIEW_MODE_OVERDRAW,  /* fragments per pixel as a heat map normalised by the frame's maximum */
    GDR_VIEW_MODE_LOD,       /* each cluster in the colour of its LOD DAG depth (mesh pipeline) */
} gdr_view;

/* How the mesh pipeline rasterises. The visibility-buffer modes (HYBRID, HW, SW) write
 * one 64-bit (depth, cluster, triangle) value per pixel with atomics, then one full-screen pass
 * shades it; they need 64-bit buffer atomics (shaderBufferInt64Atomics). */
typedef enum gdr_raster {
    GDR_RASTER_DEFAULT = 0, /* HYBRID where the device has 64-bit buffer atomics, else FORWARD */
    GDR_RASTER_HYBRID,      /* clusters whose triangles are smaller than sw_threshold_px on screen go to
                               the compute rasteriser, the rest to the mesh shaders */
    GDR_RASTER_HW,          /* every cluster through the mesh shaders, into the visibility buffer */
    GDR_RASTER_SW,          /* every cluster through the compute rasteriser, except those crossing the
                               near or far plane (which it cannot clip): the mesh shaders take them */
    GDR_RASTER_FORWARD,     /* no visibility buffer: the mesh shaders' fragments are shaded */
} gdr_raster;

/* The hybrid threshold when gdr_frame_desc.sw_threshold_px is 0 (docs/PIPELINE.md says how it was
 * chosen). */
#define GDR_DEFAULT_SW_THRESHOLD_PX 12.0f

typedef struct gdr_frame_desc {
    gdr_camera camera;  /* aspect 0: width / height; zfar 0: infinite reverse-Z projection */
    gdr_cull_mode cull; /* OFF: nothing is culled at any level (instances, clusters, triangles) */
    bool read_back;     /* copy the last frame's image for gdr_renderer_read_color / write_png */
    gdr_pipeline pipeline;
    gdr_view view;
    /* Mesh pipeline, when cull is on: each level can be switched off on its own (DEFAULT: on). */
    gdr_cull_mode meshlet_frustum_cull;
    gdr_cull_mode meshlet_cone_cull;
    gdr_cull_mode triangle_cull; /* back-facing triangles and triangles that cover no sample */
    /* Mesh pipeline: keep the list of clusters the task shaders passed, for
     * gdr_renderer_read_visible_meshlets (tests, tools; costs an append per cluster). */
    bool record_visible_meshlets;
    /* Mesh pipeline: the rasteriser, and for HYBRID the projected triangle size in pixels
     * below which a cluster goes to the compute rasteriser (0: GDR_DEFAULT_SW_THRESHOLD_PX). Other
     * pipelines draw forward; asking them for HYBRID, HW or SW is an error. */
    gdr_raster raster;
    float sw_threshold_px;
    /* Mesh pipeline, meshes with a LOD DAG (gdr/geometry.h "The cut"): the clusters drawn
     * are the cut whose projected error is within lod_error_px pixels (0, the default: full detail,
     * level 0; the gdr program's --lod-error defaults to 1, an image a user sees as the same), or with lod_fixed_depth the discrete cut at DAG depth lod_depth (0: level 0). The
     * indirect and CPU pipelines always draw full detail. */
    float lod_error_px;
    bool lod_fixed_depth;
    uint32_t lod_depth;
    /* With the LOD cut by error: find each instance's clusters by traversing the hierarchy over its
     * DAG (gdr/geometry.h, "LOD hierarchy"), testing nodes by LOD error, frustum and (late phase)
     * occlusion, instead of testing every cluster of the DAG (OFF). DEFAULT: on. The cut is the same. */
    gdr_cull_mode lod_hierarchy;
    /* With the LOD cut by error in the visibility-buffer modes of the mesh pipeline: an instance of a
     * mesh with a DAG whose whole mesh projects within min(lod_error_px, 1) pixels is drawn as one
     * splat, its point level (docs/GEOMETRY.md, "The point level"), instead of its root clusters.
     * DEFAULT: on. */
    gdr_cull_mode point_level;
    /* Two-phase occlusion culling against the depth pyramid (indirect pipeline: instances, mesh
     * pipeline: instances, nodes and clusters; off when cull is off). DEFAULT: on for the indirect
     * pipeline, off for the mesh pipeline, where the H100 measurements found it slower on every
     * scene (docs/OCCLUSION.md). Conservative: the image is the same with it off. The history it
     * keeps between frames is discarded when the pipeline changes and on a camera cut (the caller
     * says so: the frame after a jump, a teleport, a new shot); without history everything goes
     * through the late phase's test. */
    gdr_cull_mode occlusion;
    bool occlusion_camera_cut;
    /* Instance tests of the GPU-driven pipelines and the CPU pipeline (when cull is on), besides the
     * frustum, each instance's screen-size range (gdr_instance) and: the smallest screen size drawn
     * (0: none; culls small detail); a world-space clip plane (a, b, c, d): instances entirely on its
     * negative side (a x + b y + c z + d < 0) are not drawn (all zero: none; it culls whole
     * instances, it does not clip the ones that cross it). */
    float min_screen_size;
    gdr_vec4 clip_plane;
    /* Culling from another point of view ("freeze culling"): when not NULL, instances, LOD nodes
     * and clusters are culled and their LOD chosen for this camera while the image is drawn from
     * `camera`, so what the culling camera keeps can be looked at from outside. Its projection
     * (yfov, aspect, znear, zfar) must equal `camera`'s. Occlusion culling is off in such frames
     * (the depth pyramid is the drawing camera's), and the hybrid rasteriser's per-cluster choice
     * is made for the culling camera. */
    const gdr_camera *cull_camera;
    /* Precomputed visibility (gdr_renderer_set_pvs; docs/CULLING.md): instances that the baked cell
     * holding the culling camera does not list are not drawn, in every pipeline, when cull is on.
     * DEFAULT: on when the renderer holds a PVS; ON without one is an error (GDR_ERROR_UNSUPPORTED
     * in a library without the culling module); OFF: not used. A camera in no baked cell culls
     * nothing by it. */
    gdr_cull_mode pvs;
} gdr_frame_desc;

/* "shaded", "meshlets", "instances", "triangles", "overdraw" or "lod". */
GDR_API const char *gdr_view_name(gdr_view view);

/* "mesh", "indirect" or "cpu". */
GDR_API const char *gdr_pipeline_name(gdr_pipeline pipeline);

/* "default", "hybrid", "hw", "sw" or "forward". */
GDR_API const char *gdr_raster_name(gdr_raster raster);

#define GDR_MAX_PASSES 8
#define GDR_LOD_STATS_DEPTH_COUNT 32 /* = GDR_LOD_STATS_DEPTHS of the shaders */

typedef struct gdr_pass_timing {
    const char *name;
    double gpu_ms; /* mean over the frames */
} gdr_pass_timing;

/* Rasterisation: the path that rasterised (never DEFAULT; FORWARD off the mesh pipeline) and why;
 * the threshold HYBRID used; the last frame's visible clusters and their triangles (before
 * back-face culling) per rasteriser; the GPU time of the cluster cull (the per-cluster tests and
 * binning, with the launches), of the mesh-shader pass, of the compute rasteriser and of the
 * resolve, means over the frames (the four are part of the "draw" passes). */
#define GDR_RASTER_TINY_CLASSES 3 /* = GDR_SW_TINY_CLASSES of the shaders */
typedef struct gdr_raster_stats {
    gdr_raster mode;
    char reason[128];
    float sw_threshold_px;
    uint32_t sw_clusters, hw_clusters;
    uint32_t sw_tiny_clusters; /* of sw_clusters, those drawn several to a workgroup (tiny ones) */
    uint32_t sw_tiny_class_clusters[GDR_RASTER_TINY_CLASSES]; /* those of at most 8, 16, 32 vertices and
                                                                  as many triangles */
    uint64_t sw_triangles, hw_triangles;
    uint32_t overflow; /* clusters lost for want of room in the list (0 below 2^25) or beyond the
                          device's mesh launch limit (0 below 2^22) */
    double cull_ms, hw_ms, sw_ms, resolve_ms;
} gdr_raster_stats;

/* The LOD cut (mesh pipeline), last frame: whether it was applied, the clusters it left out, and
 * the clusters and triangles drawn per DAG depth (the last entry: that depth or deeper; triangles
 * before triangle culling). */
typedef struct gdr_lod_stats_frame {
    bool applied;
    uint32_t meshlets_culled;
    uint32_t depth_count; /* entries used below: deepest depth drawn + 1 */
    uint32_t clusters_per_depth[GDR_LOD_STATS_DEPTH_COUNT];
    uint64_t triangles_per_depth[GDR_LOD_STATS_DEPTH_COUNT];
} gdr_lod_stats_frame;

/* Occlusion culling, last frame, per phase (early: tested against last frame's pyramid, what it
 * hides deferred; late: the deferred ones retested against this frame's pyramid). Clusters: mesh
 * pipeline (nodes: gdr_traversal_stats). Each drawn instance and cluster is drawn in one phase. */
typedef struct gdr_occlusion_stats {
    bool applied;
    uint32_t instances_early_drawn;
    uint32_t instances_early_occluded; /* hidden behind last frame's pyramid: deferred */
    uint32_t instances_late_tested;    /* = the deferred ones */
    uint32_t instances_late_occluded;  /* hidden behind this frame's pyramid: culled */
    uint32_t instances_late_drawn;
    uint32_t meshlets_early_drawn;
    uint32_t meshlets_early_occluded;  /* deferred */
    uint32_t meshlets_late_tested;     /* the deferred ones and the clusters of late instances and nodes */
    uint32_t meshlets_late_occluded;
    uint32_t meshlets_late_drawn;
    uint32_t overflow; /* hidden items that found no room in an occluded list: handled in the early phase */
} gdr_occlusion_stats;

/* The LOD hierarchy traversal (mesh pipeline, LOD cut by error), last frame, both phases: node
 * visits, those whose subtree cannot hold a cluster of the cut, those outside the frustum, those
 * deferred by the early phase (behind last frame's pyramid), those culled behind this frame's
 * pyramid (late phase), the late phase's visits, and visits that did not fit the
 * traversal's queue (their subtrees were not drawn; 0 unless the scene outgrows
 * GDR_TRAVERSE_MAX_VISITS visits per level). */
typedef struct gdr_traversal_stats {
    bool applied;
    uint32_t levels;
    uint32_t nodes_tested;
    uint32_t nodes_lod_culled;
    uint32_t nodes_frustum_culled;
    uint32_t nodes_early_occluded;
    uint32_t nodes_occluded;
    uint32_t late_nodes_tested;
    uint32_t overflow;
} gdr_traversal_stats;

/* Streaming (docs/STREAMING.md): the LOD groups absent from the page table, and the requests the
 * frame's cluster tests made for absent groups its cut needs (one per cluster drawn in such a
 * group's place; the dropped ones did not fit GDR_STREAM_REQUEST_CAPACITY). Mesh pipeline. */
typedef struct gdr_streaming_stats {
    uint64_t absent_groups;
    uint32_t requests;
    uint32_t requests_dropped;
    /* A scene set with gdr_renderer_set_scene_streamed (docs/STREAMING.md); zero otherwise. Counts of
     * the last frame, unless said otherwise. */
    bool enabled;
    uint64_t pool_bytes;          /* the page pool: slot_count slots of slot_bytes */
    uint32_t slot_count, slot_bytes;
    uint64_t resident_bytes;      /* slots holding a page or planned for one */
    uint32_t resident_pages;
    uint32_t groups_used;         /* distinct groups the cut drew (read back a frame or two later) */
    uint32_t distinct_requests;   /* distinct pages asked for */
    uint32_t loads;               /* pages planned for loading */
    uint32_t uploads;             /* pages copied into the pool */
    uint64_t upload_bytes;        /* bytes copied for them (page data and cluster records) */
    uint32_t evictions;
    uint32_t deferred;            /* requests left for later frames (upload budget or no free slot) */
    uint32_t pending;             /* pages being read or waiting for upload room */
    uint32_t frames_since_change; /* frames since a page last arrived or left */
    uint64_t uploads_total, upload_bytes_total, evictions_total; /* since the scene was set */
    uint64_t evicted_in_use;      /* debug counter: evictions of a page the latest cut used; always 0 */
    uint32_t pages_refused;       /* damaged pages so far (their groups stay absent) */
    /* A cut that fits the pool (docs/STREAMING.md): the LOD threshold the last frame drew with
     * (lod_error_px times lod_error_scale, which rises while the cut needs more pages than the pool
     * holds and falls back to 1 when it fits), the pages the latest cut read back needs resident
     * (its pages, those it asked for and their ancestors'; 0 when no cut was read back) against the
     * pool's slots, and the frames since the threshold or the resident set last changed. */
    float lod_error_px;
    float lod_error_scale;
    uint32_t wanted_pages;
    uint32_t settled_frames;
    uint32_t lod_error_changes;   /* times the threshold's factor changed since the scene was set */
    /* The LOD nodes' absent counts, updated from the groups whose residency changed in the frame:
     * those groups, the node updates (each changed group's leaves and their ancestors), and the
     * counts uploaded (words) in how many copies (runs of consecutive nodes). */
    uint32_t node_groups_changed;
    uint32_t node_updates;
    uint32_t node_words_uploaded;
    uint32_t node_copies;
    /* The page loader: pages and bytes it read from the file since the scene was set, the
     * milliseconds some worker was reading or decoding, its throughput (MB/s of file bytes per
     * second of that busy time), and its queue depth now (loads waiting for a worker or being read). */
    uint64_t loader_pages, loader_bytes_read;
    double loader_busy_ms;
    double loader_mb_s;
    uint32_t loader_queue_depth;
    /* The record pool (cluster_record_bytes: room for its page's cluster records beside each pool
     * slot, which follows the pool, not the scene) and what stays on the GPU beside the pool,
     * whatever is resident (docs/STREAMING.md, "What stays resident"): every mesh's LOD hierarchy,
     * the nodes' absent counts, and the page table with the groups' frame stamps and each frame
     * slot's list of groups drawn; and the source triangles of the scene's meshes (level 0 of each,
     * once per mesh). */
    uint64_t cluster_record_bytes, hierarchy_bytes, node_count_bytes, page_table_bytes;
    uint64_t source_triangles;
    /* The set-up's steps, host milliseconds: the open (the paged cache checked against the scene,
     * the residency and its page graph, the tables, the loader, the pool), the scene's upload with
     * the frame slots and the rest of the renderer's scene state, the node counts over every
     * hierarchy, and every mesh's coarsest page read, checked and copied. */
    double setup_open_ms, setup_scene_ms, setup_node_counts_ms, setup_first_pages_ms;
    char refused[GDR_ERROR_MESSAGE_MAX];          /* the last refused page's message (file, mesh, page, why) */
} gdr_streaming_stats;

/* GPU memory: what the renderer holds from the device (whole blocks), and of what it placed in
 * them, the scene's part (geometry, clusters, instances, occluded lists) and the rest (render
 * targets, frame slots, visibility buffer, read-backs). */
typedef struct gdr_memory_stats {
    uint64_t device_bytes;
    uint64_t scene_bytes;
    uint64_t frame_bytes;
    /* The scene's textures, part of scene_bytes: the device memory their images were given, how
     * many the device samples in their block format and how many were decoded to RGBA8 at upload
     * (a device without BC sampling for the format, or disable_texture_compression_bc). */
    uint64_t texture_bytes;
    uint32_t textures_compressed;
    uint32_t textures_decoded;
} gdr_memory_stats;

/* Precomputed visibility, last frame: whether the frame used it (the renderer holds a PVS, the
 * frame did not switch it or culling off), whether the culling camera was in a baked cell (only
 * then does it cull), the instances it removed (valid and in the frustum, not listed by the cell;
 * each culled instance is counted by the first test that culls it: invalid, frustum, PVS, screen
 * size, clip plane), and the CPU time of the cell's lookup and upload (GPU-driven pipelines) or of
 * nothing more than the CPU cull already counts (CPU pipeline: 0), mean per frame. */
typedef struct gdr_pvs_stats {
    bool enabled;
    bool cell_found;
    uint32_t instances_culled;
    uint32_t cells;   /* baked cells of the PVS held */
    double cpu_ms_per_frame;
} gdr_pvs_stats;

typedef struct gdr_frame_stats {
    uint32_t frames;
    uint32_t instances_total;
    uint32_t instances_visible; /* of the last frame */
    /* GPU-driven pipelines, last frame: instances culled by the instance tests, each counted by the
     * first that culled it (invalid, frustum, screen size, clip plane): bounds not finite or without
     * volume (or a mesh without triangles), outside their screen-size range or below the frame's
     * minimum, entirely behind the clip plane. */
    uint32_t instances_invalid;
    uint32_t instances_screen_size_culled;
    uint32_t instances_clip_plane_culled;
    uint32_t instances_points;  /* visible instances drawn as their point level (frame desc point_level) */
    uint64_t triangles;         /* drawn in the last frame */
    uint32_t draws;             /* indirect draw commands executed in the last frame */
    uint32_t draw_calls;        /* draw calls the CPU recorded per frame */
    double cpu_ms_per_frame;    /* recording + submission, mean over the frames */
    double cpu_submit_ms_per_frame; /* the vkQueueSubmit2 part of it */
    double cpu_ms_per_frame_median; /* recording + submission, median over the frames */
    uint32_t frames_recorded;   /* frames whose commands the CPU recorded; the others were submitted
                                   again as recorded (gdr_renderer_desc.record_every_frame) */
    double gpu_ms_per_frame;    /* first to last timestamp, mean over the frames */
    gdr_pass_timing passes[GDR_MAX_PASSES];
    uint32_t pass_count;
    char device[256];
    char driver[528];
    uint32_t validation_messages; /* since the renderer was created */
    gdr_pipeline pipeline;        /* the path that rendered (never DEFAULT) */
    char pipeline_reason[160];    /* why that path: asked for, or the device's capabilities */
    double cpu_cull_ms_per_frame; /* CPU pipeline: the culling part of cpu_ms_per_frame */
    /* Mesh pipeline, last frame. meshlets_total counts the clusters of every instance; the culled
     * counts are of the clusters of instances that passed the instance cull. */
    uint64_t meshlets_total;
    uint32_t meshlets_tested;
    uint32_t meshlets_frustum_culled;
    uint32_t meshlets_cone_culled;
    uint32_t meshlets_visible;            /* drawn */
    uint32_t triangles_backface_culled;   /* by the mesh shader */
    uint32_t triangles_small_culled;      /* covering no sample */
    uint32_t task_workgroups;
    uint32_t task_overflow;               /* task commands lost for want of room: 0 unless a frame phase needs more
                                             than GDR_MAX_TASK_COMMANDS (16 M) */
    uint32_t overdraw_max;                /* overdraw view: the most fragments one pixel received */
    gdr_raster_stats raster;
    gdr_lod_stats_frame lod;
    gdr_occlusion_stats occlusion;
    gdr_traversal_stats traversal;
    gdr_streaming_stats streaming;
    gdr_memory_stats memory;
    gdr_pvs_stats pvs;
} gdr_frame_stats;

GDR_API gdr_status gdr_renderer_create(const gdr_renderer_desc *desc, gdr_renderer **out, gdr_error *err);
GDR_API void gdr_renderer_destroy(gdr_renderer *renderer);

/* Uploads the scene's geometry into the geometry pool and its instances into the instance buffer.
 * The renderer keeps no pointer into `scene`. */
GDR_API gdr_status gdr_renderer_set_scene(gdr_renderer *renderer, const gdr_scene *scene, gdr_error *err);

/* Precomputed visibility for the scene set (docs/CULLING.md, "Precomputed visibility in the
 * frame"): a PVS baked for this scene (gdr_pvs_bake, or read from its cache: gdr_scene_load_file's
 * out_pvs), whose object i is instance i. Frames then cull, by default, the instances that the
 * baked cell holding the culling camera does not list; instances moved with
 * gdr_renderer_update_instance since the scene was set are never culled by it. The renderer keeps
 * the pointer: `pvs` must stay alive until the renderer is destroyed or another call replaces it;
 * NULL removes it. Fails (and keeps the PVS it held) without a scene, or when the PVS's object
 * count is not the scene's instance count. A library without the culling module (gdr/config.h:
 * GDR_HAVE_CULL 0) can make no PVS and holds none: NULL succeeds, anything else fails with
 * GDR_ERROR_UNSUPPORTED. */
GDR_API gdr_status gdr_renderer_set_pvs(gdr_renderer *renderer, const gdr_pvs *pvs, gdr_error *err);

/* Streaming (docs/STREAMING.md): the clusters' vertices and triangles live in a page pool of fixed
 * size instead of being uploaded whole; the pages of a paged cache of the same scene are read by a
 * loader thread as the frames' cuts ask for them and copied into the pool within a per-frame upload
 * budget; where a group is absent the cut draws the resident group above it (never a hole, never a
 * crack). Frames must use the mesh pipeline and a LOD cut by error (lod_error_px > 0). */
typedef struct gdr_streaming_desc {
    gdr_paged_cache *cache;         /* the scene's cache (written with gdr_cache_write_options.page_bytes),
                                       opened by the caller with gdr_paged_cache_open; it stays the
                                       caller's, open until the renderer is destroyed (a loader thread
                                       reads its pages) */
    uint64_t geometry_budget_bytes; /* the page pool; 0: a quarter of the device-local heap; at most 4 GiB */
    uint64_t upload_budget_bytes;   /* copied into the pool per frame at most (at least one page); 0: 16 MiB */
    bool wait_for_loads;            /* each frame waits for the pages it planned (deterministic: tests) */
    bool fixed_lod_error;           /* true: the LOD threshold never rises to fit the pool (a pool smaller
                                       than a view's cut then evicts and reloads pages frame after frame) */
} gdr_streaming_desc;

#define GDR_GEOMETRY_BUDGET_MAX (4ull << 30)
#define GDR_UPLOAD_BUDGET_DEFAULT (16ull << 20)

/* gdr_renderer_set_scene with streaming: only the scene's cluster records, LOD hierarchy and page
 * table are uploaded; geometry arrives page by page. `scene` must be the one the cache
 * desc->cache was written from (checked: meshes, groups and clusters per page) and must stay
 * alive, unchanged, until the renderer is destroyed (the renderer reads its LOD hierarchy). */
GDR_API gdr_status gdr_renderer_set_scene_streamed(gdr_renderer *renderer, const gdr_scene *scene,
                                                   const gdr_streaming_desc *desc, gdr_error *err);

/* Streaming: which groups of mesh `mesh` the last frame could draw (group_resident[g], one byte per
 * group of the mesh's clusters.groups). */
GDR_API gdr_status gdr_renderer_read_residency(gdr_renderer *renderer, uint32_t mesh, uint8_t *group_resident,
                                               gdr_error *err);

/* Changes an instance's transform and colour; sent to the GPU through the instance ring with the
 * next frame (at most GDR_INSTANCE_UPDATES_PER_FRAME records per frame; more wait for later frames). */
GDR_API gdr_status gdr_renderer_update_instance(gdr_renderer *renderer, uint32_t index, const gdr_mat4 *transform,
                                                const gdr_vec4 *color, gdr_error *err);

/* Renders `frames` frames of the same view (at least 1) and fills `stats` (may be NULL). */
GDR_API gdr_status gdr_renderer_render(gdr_renderer *renderer, const gdr_frame_desc *frame, uint32_t frames,
                                       gdr_frame_stats *stats, gdr_error *err);

/* The last frame's image as tightly packed RGBA8 rows, top row first (width * height * 4 bytes);
 * needs a frame rendered with read_back. */
GDR_API gdr_status gdr_renderer_read_color(gdr_renderer *renderer, uint8_t *rgba, gdr_error *err);

/* What the device can do: whether the mesh pipeline is available, and if not, why (may be NULL). */
GDR_API bool gdr_renderer_has_mesh_pipeline(const gdr_renderer *renderer, const char **why_not);

/* Indices of the instances found visible in the last frame (by the GPU, or by the CPU on the CPU
 * pipeline), in draw order. */
GDR_API gdr_status gdr_renderer_read_visible(gdr_renderer *renderer, uint32_t *indices, uint32_t capacity,
                                             uint32_t *count, gdr_error *err);

/* A cluster drawn in the last frame: instance index and the cluster's index within its mesh's
 * clusters (gdr_mesh.clusters.clusters). */
typedef struct gdr_visible_meshlet {
    uint32_t instance;
    uint32_t meshlet;
} gdr_visible_meshlet;

/* The clusters the last frame drew, in no particular order; needs a mesh-pipeline frame rendered
 * with record_visible_meshlets. */
GDR_API gdr_status gdr_renderer_read_visible_meshlets(gdr_renderer *renderer, gdr_visible_meshlet *meshlets,
                                                      uint32_t capacity, uint32_t *count, gdr_error *err);

/* A group the last frame found absent where its cut needs it (docs/STREAMING.md): a cluster was
 * drawn in its place while the group's projected error, `priority` (pixels), is above the
 * threshold. One per such cluster and instance: the same group may come several times. */
typedef struct gdr_group_request {
    uint32_t mesh, group; /* group: index in the mesh's clusters.groups */
    float priority;
    uint32_t instance;
} gdr_group_request;

/* The last frame's requests, in no particular order; needs a mesh-pipeline frame. *dropped: the
 * requests that did not fit the frame's list (4096, GDR_STREAM_REQUEST_CAPACITY of the shaders). */
GDR_API gdr_status gdr_renderer_read_group_requests(gdr_renderer *renderer, gdr_group_request *requests,
                                                    uint32_t capacity, uint32_t *count, uint32_t *dropped,
                                                    gdr_error *err);

GDR_API void gdr_renderer_size(const gdr_renderer *renderer, uint32_t *width, uint32_t *height);

/* Writes, as Markdown, the passes of the frame of every configuration (pipeline, raster, occlusion
 * culling, overdraw view): per pass the resources it reads and writes and the barrier derived
 * before it. docs/PIPELINE.md holds this output (`gdr info --passes`). Needs no device. */
GDR_API void gdr_describe_frame_passes(FILE *out);

/* Writes RGBA8 pixels as a PNG through a temporary file and a rename: never a half-written file. */
GDR_API gdr_status gdr_write_png(const char *path, const uint8_t *rgba, uint32_t width, uint32_t height,
                                 gdr_error *err);

#ifdef __cplusplus
}
#endif
#endif
