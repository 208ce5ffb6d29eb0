/* The statistics of a gdr_renderer_render call, from the last frame's counters, the timings of
 * every frame and the renderer's memory. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/renderer_internal.h"
#include "render/frame_stats.h"
#include "render/pvs_frame.h"

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static void fill_occlusion(const GdrGpuDrawStats *gpu, bool applied, gdr_occlusion_stats *o)
{
    *o = (gdr_occlusion_stats){
        .applied = applied,
        .instances_early_drawn = gpu->instances_early_drawn,
        .instances_early_occluded = gpu->instances_early_occluded,
        .instances_late_tested = gpu->instances_late_tested,
        .instances_late_occluded = gpu->instances_late_occluded,
        .instances_late_drawn = gpu->instances_late_drawn,
        .meshlets_early_drawn = gpu->meshlets_early_drawn,
        .meshlets_early_occluded = gpu->meshlets_early_occluded,
        .meshlets_late_tested = gpu->meshlets_late_tested,
        .meshlets_late_occluded = gpu->meshlets_late_occluded,
        .meshlets_late_drawn = gpu->meshlets_late_drawn,
        .overflow = gpu->occluded_overflow,
    };
}

/* What the GPU-driven pipelines counted. */
static void fill_gpu_driven(const gdr_frame_slot *slot, const GdrGpuDrawStats *gpu, gdr_frame_stats *stats)
{
    bool occlusion = slot->occlusion_applied;
    stats->instances_visible = gpu->draw_count + (occlusion ? gpu->instances_late_drawn : 0);
    stats->instances_invalid = gpu->instances_invalid;
    stats->instances_screen_size_culled = gpu->instances_screen_size_culled;
    stats->instances_clip_plane_culled = gpu->instances_clip_plane_culled;
    stats->instances_points = gpu->instances_points;
    stats->draws = slot->pipeline == GDR_PIPELINE_MESH
                       ? gpu->task_groups_x * gpu->task_groups_y + gpu->late_task_groups_x * gpu->late_task_groups_y
                       : gpu->draw_count + gpu->late_draw_count;
    stats->draw_calls = occlusion ? 2 : 1;
    fill_occlusion(gpu, occlusion, &stats->occlusion);
    stats->triangles = ((uint64_t)gpu->triangles_high << 32) | gpu->triangles_low;
    stats->triangles += stats->raster.sw_triangles; /* the mesh shaders count only their own */
}

static void fill_traversal(const gdr_frame_slot *slot, const GdrGpuDrawStats *gpu, gdr_traversal_stats *t)
{
    *t = (gdr_traversal_stats){
        .applied = slot->plan.config.traversal_levels > 0,
        .levels = slot->plan.config.traversal_levels,
        .nodes_tested = gpu->nodes_tested,
        .nodes_lod_culled = gpu->nodes_lod_culled,
        .nodes_frustum_culled = gpu->nodes_frustum_culled,
        .nodes_early_occluded = gpu->nodes_early_occluded,
        .nodes_occluded = gpu->nodes_occluded,
        .late_nodes_tested = gpu->late_nodes_tested,
        .overflow = gpu->traversal_overflow,
    };
}

/* The mesh pipeline's clusters and LOD cut. */
static void fill_mesh(const gdr_renderer *r, const gdr_frame_slot *slot, const GdrGpuDrawStats *gpu,
                      gdr_frame_stats *stats)
{
    stats->meshlets_total = r->scene.instance_meshlet_count;
    stats->meshlets_tested = gpu->meshlets_tested;
    stats->meshlets_frustum_culled = gpu->meshlets_frustum_culled;
    stats->meshlets_cone_culled = gpu->meshlets_cone_culled;
    stats->meshlets_visible = gpu->meshlets_visible;
    stats->triangles_backface_culled = gpu->triangles_backface_culled;
    stats->triangles_small_culled = gpu->triangles_small_culled;
    stats->task_workgroups = gpu->task_count + gpu->late_task_count;
    stats->task_overflow = gpu->task_overflow;
    fill_traversal(slot, gpu, &stats->traversal);
    uint32_t kept = gpu->stream_requests < GDR_STREAM_REQUEST_CAPACITY ? gpu->stream_requests : GDR_STREAM_REQUEST_CAPACITY;
    stats->streaming = r->stream.stats;
    stats->streaming.absent_groups = r->scene.absent_groups;
    stats->streaming.requests = kept;
    stats->streaming.requests_dropped = gpu->stream_requests - kept;
    stats->lod.applied = slot->lod_applied;
    stats->lod.meshlets_culled = gpu->meshlets_lod_culled;
    for (uint32_t d = 0; d < GDR_LOD_STATS_DEPTH_COUNT; d++) {
        stats->lod.clusters_per_depth[d] = gpu->lod_clusters[d];
        stats->lod.triangles_per_depth[d] = gpu->lod_triangles[d];
        if (gpu->lod_clusters[d] > 0)
            stats->lod.depth_count = d + 1;
    }
}

static void fill_timings(const gdr_renderer *r, double *frame_cpu_ms, uint32_t frames, double submit_ms,
                         uint32_t recorded, gdr_frame_stats *stats)
{
    double cpu_ms = 0.0;
    for (uint32_t f = 0; f < frames; f++)
        cpu_ms += frame_cpu_ms[f];
    qsort(frame_cpu_ms, frames, sizeof *frame_cpu_ms, compare_double);
    stats->cpu_ms_per_frame_median = frames % 2 ? frame_cpu_ms[frames / 2]
                                                : 0.5 * (frame_cpu_ms[frames / 2 - 1] + frame_cpu_ms[frames / 2]);
    stats->cpu_ms_per_frame = cpu_ms / frames;
    stats->cpu_submit_ms_per_frame = submit_ms / frames;
    stats->frames_recorded = recorded;
    stats->pass_count = GDR_SECTION_COUNT;
    for (uint32_t p = 0; p < GDR_SECTION_COUNT; p++) {
        stats->passes[p].name = gdr_frame_section_name((gdr_frame_section)p);
        stats->passes[p].gpu_ms = r->timings.frames ? r->timings.section_ms[p] / r->timings.frames : 0.0;
        stats->gpu_ms_per_frame += stats->passes[p].gpu_ms;
    }
}

static void fill_memory(const gdr_renderer *r, gdr_memory_stats *memory)
{
    uint64_t used = 0;
    for (uint32_t b = 0; b < r->allocator.block_count; b++)
        used += r->allocator.blocks[b].used;
    memory->device_bytes = r->allocator.bytes_allocated;
    memory->scene_bytes = r->scene.bytes;
    memory->texture_bytes = r->materials.texture_bytes;
    memory->textures_compressed = r->materials.textures_compressed;
    memory->textures_decoded = r->materials.textures_decoded;
    memory->frame_bytes = used > r->scene.bytes ? used - r->scene.bytes : 0;
}

void gdr_frame_stats_fill(gdr_renderer *r, gdr_pipeline pipeline, const char *reason, double *frame_cpu_ms,
                          uint32_t frames, double submit_ms, uint32_t recorded, gdr_frame_stats *stats)
{
    memset(stats, 0, sizeof *stats);
    const gdr_frame_slot *last_slot = &r->slots[r->last_slot];
    GdrGpuDrawStats gpu;
    memcpy(&gpu, last_slot->stats_readback.mapped, sizeof gpu);
    stats->frames = frames;
    stats->instances_total = r->scene.instance_count;
    stats->pipeline = pipeline;
    snprintf(stats->pipeline_reason, sizeof stats->pipeline_reason, "%s", reason);
    gdr_visbuffer_stats(r, (uint32_t)r->last_slot, stats);
    snprintf(stats->raster.reason, sizeof stats->raster.reason, "%s", r->vis.reason);
    if (pipeline == GDR_PIPELINE_CPU) {
        stats->instances_visible = last_slot->cpu_visible_count;
        stats->draws = last_slot->cpu_visible_count;
        stats->draw_calls = last_slot->cpu_visible_count;
        stats->triangles = last_slot->cpu_triangles;
        stats->cpu_cull_ms_per_frame = r->cpu.cull_ms / frames;
    } else {
        fill_gpu_driven(last_slot, &gpu, stats);
    }
    if (pipeline == GDR_PIPELINE_MESH)
        fill_mesh(r, last_slot, &gpu, stats);
    stats->pvs = (gdr_pvs_stats){
        .enabled = last_slot->pvs_enabled, .cell_found = last_slot->pvs_cell_found,
        .instances_culled = pipeline == GDR_PIPELINE_CPU ? last_slot->cpu_pvs_culled : gpu.instances_pvs_culled,
        .cells = gdr_render_pvs_cells(r), .cpu_ms_per_frame = r->pvs.cpu_ms / frames};
    fill_timings(r, frame_cpu_ms, frames, submit_ms, recorded, stats);
    fill_memory(r, &stats->memory);
    snprintf(stats->device, sizeof stats->device, "%s", r->ctx->properties.deviceName);
    snprintf(stats->driver, sizeof stats->driver, "%s", r->ctx->driver_info);
    stats->validation_messages = r->ctx->validation_messages;
}
