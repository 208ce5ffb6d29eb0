#include "stats_output.h"

#include <string.h>

#include <cjson/cJSON.h>

/* "on", "off" (held, switched off) or "none" (the scene's cache holds no precomputed visibility). */
static const char *pvs_state(const gdr_pvs_stats *pvs)
{
    return pvs->enabled ? "on" : pvs->cells > 0 ? "off" : "none";
}

static void stats_print_pvs(FILE *out, const gdr_pvs_stats *pvs)
{
    if (!pvs->enabled) {
        fprintf(out, "pvs                 %s\n", pvs_state(pvs));
        return;
    }
    if (pvs->cell_found)
        fprintf(out, "pvs                 on: camera in a baked cell (of %u), %u instances culled (in the frustum, "
                "not listed by the cell); lookup %.4f ms/frame\n", pvs->cells, pvs->instances_culled, pvs->cpu_ms_per_frame);
    else
        fprintf(out, "pvs                 on: camera in none of the %u baked cells, nothing culled by it\n", pvs->cells);
}

/* The scene, the device, the target and the instances' culling. */
static void print_scene_lines(FILE *out, const stats_context *context, const gdr_frame_stats *s)
{
    fprintf(out, "scene               %s\n", context->scene);
    fprintf(out, "device              %s (%s)\n", s->device, s->driver);
    fprintf(out, "resolution          %ux%u, %u frame(s), culling %s\n", context->width, context->height, s->frames,
            context->cull);
    fprintf(out, "pipeline            %s (%s)\n", gdr_pipeline_name(s->pipeline), s->pipeline_reason);
    if (context->view && strcmp(context->view, "shaded") != 0)
        fprintf(out, "view                %s\n", context->view);
    fprintf(out, "instances_total     %u\n", s->instances_total);
    fprintf(out, "instances_visible   %u\n", s->instances_visible);
    if (s->instances_invalid || s->instances_screen_size_culled || s->instances_clip_plane_culled)
        fprintf(out, "instances_culled    %u invalid or empty bounds, %u by screen size, %u behind the clip plane\n",
                s->instances_invalid, s->instances_screen_size_culled, s->instances_clip_plane_culled);
    if (s->instances_points)
        fprintf(out, "instances_points    %u (drawn as their point level)\n", s->instances_points);
    stats_print_pvs(out, &s->pvs);
    fprintf(out, "triangles           %llu\n", (unsigned long long)s->triangles);
}

/* The rasteriser's choice and, where compute rasterises, its split of the clusters. */
static void print_raster_lines(FILE *out, const gdr_frame_stats *s)
{
    fprintf(out, "raster              %s (%s)\n", gdr_raster_name(s->raster.mode), s->raster.reason);
    if (s->raster.mode == GDR_RASTER_FORWARD)
        return;
    const uint32_t *tiny = s->raster.sw_tiny_class_clusters;
    fprintf(out, "raster_clusters     compute %u (%u tiny: %u/%u/%u of 8/16/32; %llu triangles), "
                 "mesh shaders %u (%llu triangles)", s->raster.sw_clusters, s->raster.sw_tiny_clusters, tiny[0],
            tiny[1], tiny[2], (unsigned long long)s->raster.sw_triangles, s->raster.hw_clusters,
            (unsigned long long)s->raster.hw_triangles);
    if (s->raster.mode == GDR_RASTER_HYBRID)
        fprintf(out, "; threshold %g px", (double)s->raster.sw_threshold_px);
    fprintf(out, s->raster.overflow ? "; %u lost to overflow\n" : "\n", s->raster.overflow);
    fprintf(out, "raster_gpu_ms       cluster cull %.4f, mesh shaders %.4f, compute %.4f, resolve %.4f "
                 "(part of draw)\n", s->raster.cull_ms, s->raster.hw_ms, s->raster.sw_ms, s->raster.resolve_ms);
}

/* The LOD hierarchy's traversal and the cut's clusters by DAG depth. */
static void print_lod_lines(FILE *out, const gdr_frame_stats *s)
{
    if (s->traversal.applied)
        fprintf(out, "lod_hierarchy       %u levels; nodes %u tested (%u late), %u LOD-culled, %u outside the frustum, "
                     "%u deferred, %u occluded%s\n", s->traversal.levels, s->traversal.nodes_tested,
                s->traversal.late_nodes_tested, s->traversal.nodes_lod_culled, s->traversal.nodes_frustum_culled,
                s->traversal.nodes_early_occluded, s->traversal.nodes_occluded,
                s->traversal.overflow ? "; VISITS LOST TO OVERFLOW" : "");
    if (s->traversal.overflow)
        fprintf(out, "traversal_overflow  %u node visits did not fit (their clusters were not drawn)\n",
                s->traversal.overflow);
    if (!s->lod.applied)
        return;
    fprintf(out, "meshlets_lod_culled %u (not in the LOD cut)\n", s->lod.meshlets_culled);
    fprintf(out, "lod_depths          clusters/triangles drawn per DAG depth:");
    for (uint32_t d = 0; d < s->lod.depth_count; d++)
        fprintf(out, " %u:%u/%llu", d, s->lod.clusters_per_depth[d], (unsigned long long)s->lod.triangles_per_depth[d]);
    fputc('\n', out);
}

/* What the pipeline drew: the mesh pipeline's clusters, rasteriser and LOD, or the draws of the
 * others. */
static void print_pipeline_lines(FILE *out, const gdr_frame_stats *s)
{
    if (s->pipeline == GDR_PIPELINE_CPU) {
        fprintf(out, "draws               %u (in %u draw calls recorded by the CPU)\n", s->draws, s->draw_calls);
        fprintf(out, "cpu_cull_ms_per_frame %.4f\n", s->cpu_cull_ms_per_frame);
        return;
    }
    if (s->pipeline != GDR_PIPELINE_MESH) {
        fprintf(out, "draws               %u (in %u indirect draw call)\n", s->draws, s->draw_calls);
        return;
    }
    fprintf(out, "meshlets_total      %llu\n", (unsigned long long)s->meshlets_total);
    fprintf(out, "meshlets_tested     %u (of visible instances)\n", s->meshlets_tested);
    fprintf(out, "meshlets_frustum_culled %u\n", s->meshlets_frustum_culled);
    fprintf(out, "meshlets_cone_culled %u\n", s->meshlets_cone_culled);
    fprintf(out, "meshlets_visible    %u\n", s->meshlets_visible);
    fprintf(out, "triangles_culled    %u back-facing, %u covering no sample\n", s->triangles_backface_culled,
            s->triangles_small_culled);
    fprintf(out, "task_workgroups     %u (in 1 indirect mesh-tasks launch; %u lost to overflow)\n", s->task_workgroups,
            s->task_overflow);
    print_raster_lines(out, s);
    print_lod_lines(out, s);
}

/* The two occlusion phases. */
static void print_occlusion_lines(FILE *out, const gdr_frame_stats *s)
{
    if (!s->occlusion.applied)
        return;
    fprintf(out, "occlusion early     instances %u drawn, %u deferred (behind last frame's pyramid); clusters %u drawn, "
            "%u deferred; %u overflow\n", s->occlusion.instances_early_drawn, s->occlusion.instances_early_occluded,
            s->occlusion.meshlets_early_drawn, s->occlusion.meshlets_early_occluded, s->occlusion.overflow);
    fprintf(out, "occlusion late      instances %u tested, %u occluded, %u drawn; clusters %u tested, %u occluded, "
            "%u drawn\n", s->occlusion.instances_late_tested, s->occlusion.instances_late_occluded,
            s->occlusion.instances_late_drawn, s->occlusion.meshlets_late_tested, s->occlusion.meshlets_late_occluded,
            s->occlusion.meshlets_late_drawn);
}

/* Time a frame (CPU, GPU, per pass) and memory. */
static void print_cost_lines(FILE *out, const gdr_frame_stats *s)
{
    fprintf(out, "cpu_ms_per_frame    %.4f (of which vkQueueSubmit2 %.4f; commands recorded in %u of the frames, "
            "the others submitted again)\n", s->cpu_ms_per_frame, s->cpu_submit_ms_per_frame, s->frames_recorded);
    fprintf(out, "gpu_ms_per_frame    %.4f\n", s->gpu_ms_per_frame);
    for (uint32_t p = 0; p < s->pass_count; p++)
        fprintf(out, "  gpu_ms.%-16s %.4f\n", s->passes[p].name, s->passes[p].gpu_ms);
    fprintf(out, "gpu_memory_bytes    %llu (scene %llu, frame %llu)\n", (unsigned long long)s->memory.device_bytes,
            (unsigned long long)s->memory.scene_bytes, (unsigned long long)s->memory.frame_bytes);
    fprintf(out, "gpu_texture_bytes   %llu (%u textures sampled compressed, %u decoded to RGBA8)\n",
            (unsigned long long)s->memory.texture_bytes, s->memory.textures_compressed, s->memory.textures_decoded);
}

void stats_print(FILE *out, const stats_context *context, const gdr_frame_stats *s)
{
    print_scene_lines(out, context, s);
    print_pipeline_lines(out, s);
    print_occlusion_lines(out, s);
    print_cost_lines(out, s);
    stats_print_streaming(out, &s->streaming);
    fprintf(out, "validation_messages %u\n", s->validation_messages);
}

void stats_add_meshlet_json(cJSON *object, const gdr_frame_stats *s)
{
    cJSON_AddNumberToObject(object, "meshlets_total", (double)s->meshlets_total);
    cJSON_AddNumberToObject(object, "meshlets_tested", s->meshlets_tested);
    cJSON_AddNumberToObject(object, "meshlets_frustum_culled", s->meshlets_frustum_culled);
    cJSON_AddNumberToObject(object, "meshlets_cone_culled", s->meshlets_cone_culled);
    cJSON_AddNumberToObject(object, "meshlets_visible", s->meshlets_visible);
    cJSON_AddNumberToObject(object, "triangles_backface_culled", s->triangles_backface_culled);
    cJSON_AddNumberToObject(object, "triangles_small_culled", s->triangles_small_culled);
    cJSON_AddBoolToObject(object, "lod_applied", s->lod.applied);
    cJSON_AddNumberToObject(object, "meshlets_lod_culled", s->lod.meshlets_culled);
    cJSON *clusters = cJSON_AddArrayToObject(object, "lod_clusters_per_depth");
    cJSON *triangles = cJSON_AddArrayToObject(object, "lod_triangles_per_depth");
    for (uint32_t d = 0; clusters && triangles && d < s->lod.depth_count; d++) {
        cJSON_AddItemToArray(clusters, cJSON_CreateNumber(s->lod.clusters_per_depth[d]));
        cJSON_AddItemToArray(triangles, cJSON_CreateNumber((double)s->lod.triangles_per_depth[d]));
    }
    cJSON_AddStringToObject(object, "raster", gdr_raster_name(s->raster.mode));
    cJSON_AddStringToObject(object, "raster_reason", s->raster.reason);
    if (s->raster.mode != GDR_RASTER_FORWARD) {
        cJSON_AddNumberToObject(object, "sw_threshold_px", s->raster.sw_threshold_px);
        cJSON_AddNumberToObject(object, "raster_sw_clusters", s->raster.sw_clusters);
        cJSON_AddNumberToObject(object, "raster_sw_tiny_clusters", s->raster.sw_tiny_clusters);
        cJSON *tiny = cJSON_AddArrayToObject(object, "raster_sw_tiny_class_clusters");
        for (uint32_t k = 0; tiny && k < GDR_RASTER_TINY_CLASSES; k++)
            cJSON_AddItemToArray(tiny, cJSON_CreateNumber(s->raster.sw_tiny_class_clusters[k]));
        cJSON_AddNumberToObject(object, "raster_hw_clusters", s->raster.hw_clusters);
        cJSON_AddNumberToObject(object, "raster_sw_triangles", (double)s->raster.sw_triangles);
        cJSON_AddNumberToObject(object, "raster_hw_triangles", (double)s->raster.hw_triangles);
        cJSON_AddNumberToObject(object, "raster_overflow", s->raster.overflow);
        cJSON_AddNumberToObject(object, "raster_cull_ms", s->raster.cull_ms);
        cJSON_AddNumberToObject(object, "raster_hw_ms", s->raster.hw_ms);
        cJSON_AddNumberToObject(object, "raster_sw_ms", s->raster.sw_ms);
        cJSON_AddNumberToObject(object, "raster_resolve_ms", s->raster.resolve_ms);
    }
}

void stats_add_occlusion_json(cJSON *object, const gdr_frame_stats *s)
{
    cJSON_AddBoolToObject(object, "occlusion_applied", s->occlusion.applied);
    if (!s->occlusion.applied)
        return;
    cJSON_AddNumberToObject(object, "instances_early_drawn", s->occlusion.instances_early_drawn);
    cJSON_AddNumberToObject(object, "instances_early_occluded", s->occlusion.instances_early_occluded);
    cJSON_AddNumberToObject(object, "instances_late_tested", s->occlusion.instances_late_tested);
    cJSON_AddNumberToObject(object, "instances_late_occluded", s->occlusion.instances_late_occluded);
    cJSON_AddNumberToObject(object, "instances_late_drawn", s->occlusion.instances_late_drawn);
    cJSON_AddNumberToObject(object, "meshlets_early_drawn", s->occlusion.meshlets_early_drawn);
    cJSON_AddNumberToObject(object, "meshlets_early_occluded", s->occlusion.meshlets_early_occluded);
    cJSON_AddNumberToObject(object, "occluded_overflow", s->occlusion.overflow);
    cJSON_AddNumberToObject(object, "meshlets_late_tested", s->occlusion.meshlets_late_tested);
    cJSON_AddNumberToObject(object, "meshlets_late_occluded", s->occlusion.meshlets_late_occluded);
    cJSON_AddNumberToObject(object, "meshlets_late_drawn", s->occlusion.meshlets_late_drawn);
}

void stats_add_traversal_json(cJSON *object, const gdr_frame_stats *s)
{
    cJSON_AddBoolToObject(object, "lod_hierarchy_applied", s->traversal.applied);
    if (!s->traversal.applied)
        return;
    cJSON_AddNumberToObject(object, "lod_hierarchy_levels", s->traversal.levels);
    cJSON_AddNumberToObject(object, "nodes_tested", s->traversal.nodes_tested);
    cJSON_AddNumberToObject(object, "nodes_lod_culled", s->traversal.nodes_lod_culled);
    cJSON_AddNumberToObject(object, "nodes_frustum_culled", s->traversal.nodes_frustum_culled);
    cJSON_AddNumberToObject(object, "nodes_early_occluded", s->traversal.nodes_early_occluded);
    cJSON_AddNumberToObject(object, "nodes_occluded", s->traversal.nodes_occluded);
    cJSON_AddNumberToObject(object, "late_nodes_tested", s->traversal.late_nodes_tested);
    cJSON_AddNumberToObject(object, "traversal_overflow", s->traversal.overflow);
}

void stats_print_streaming(FILE *out, const gdr_streaming_stats *st)
{
    if (!st->enabled)
        return;
    fprintf(out, "streaming pool      %llu bytes: %u slots of %u, %u pages resident (%llu bytes), %llu groups absent\n",
            (unsigned long long)st->pool_bytes, st->slot_count, st->slot_bytes, st->resident_pages,
            (unsigned long long)st->resident_bytes, (unsigned long long)st->absent_groups);
    fprintf(out, "streaming frame     %u requests (%u distinct pages), %u loads, %u uploads (%llu bytes), %u evictions, "
            "%u deferred, %u pending; %u frames since a change\n", st->requests, st->distinct_requests, st->loads,
            st->uploads, (unsigned long long)st->upload_bytes, st->evictions, st->deferred, st->pending,
            st->frames_since_change);
    fprintf(out, "streaming cut       threshold %g px (x %g to fit the pool, %u changes), %u pages wanted of %u slots, "
            "settled %u frames\n", (double)st->lod_error_px, (double)st->lod_error_scale, st->lod_error_changes,
            st->wanted_pages, st->slot_count, st->settled_frames);
    fprintf(out, "streaming loader    %llu pages, %llu bytes read in %.1f ms busy: %.1f MB/s; %u in its queue\n",
            (unsigned long long)st->loader_pages, (unsigned long long)st->loader_bytes_read, st->loader_busy_ms,
            st->loader_mb_s, st->loader_queue_depth);
    /* The cluster records live in the record pool, a slot's room beside each pool slot: they follow
     * the pool, not the scene. */
    uint64_t tables = st->hierarchy_bytes + st->node_count_bytes + st->page_table_bytes;
    double per_triangle = st->source_triangles ? 1.0 / (double)st->source_triangles : 0.0;
    fprintf(out, "streaming resident  %llu bytes beside the pool, %.3f per source triangle: hierarchy %.3f, node "
            "counts %.4f, page table %.4f; the pool's cluster records %llu bytes\n", (unsigned long long)tables,
            (double)tables * per_triangle, (double)st->hierarchy_bytes * per_triangle,
            (double)st->node_count_bytes * per_triangle, (double)st->page_table_bytes * per_triangle,
            (unsigned long long)st->cluster_record_bytes);
    fprintf(out, "streaming set-up    open %.1f ms, scene %.1f ms, node counts %.1f ms, first pages %.1f ms\n",
            st->setup_open_ms, st->setup_scene_ms, st->setup_node_counts_ms, st->setup_first_pages_ms);
    fprintf(out, "streaming totals    %llu uploads (%llu bytes), %llu evictions, %u pages refused%s%s\n",
            (unsigned long long)st->uploads_total, (unsigned long long)st->upload_bytes_total,
            (unsigned long long)st->evictions_total, st->pages_refused, st->pages_refused ? ": " : "",
            st->pages_refused ? st->refused : "");
}

static void add_streaming_json(cJSON *object, const gdr_streaming_stats *st)
{
    cJSON *o = st->enabled ? cJSON_AddObjectToObject(object, "streaming") : NULL;
    if (!o)
        return;
    const struct { const char *name; double value; } fields[] = {
        {"pool_bytes", (double)st->pool_bytes}, {"slot_count", st->slot_count}, {"slot_bytes", st->slot_bytes},
        {"resident_pages", st->resident_pages}, {"resident_bytes", (double)st->resident_bytes},
        {"absent_groups", (double)st->absent_groups}, {"requests", st->requests},
        {"distinct_requests", st->distinct_requests}, {"loads", st->loads}, {"uploads", st->uploads},
        {"upload_bytes", (double)st->upload_bytes}, {"evictions", st->evictions}, {"deferred", st->deferred},
        {"pending", st->pending}, {"frames_since_change", st->frames_since_change},
        {"uploads_total", (double)st->uploads_total}, {"upload_bytes_total", (double)st->upload_bytes_total},
        {"evictions_total", (double)st->evictions_total}, {"evicted_in_use", (double)st->evicted_in_use},
        {"pages_refused", st->pages_refused}, {"lod_error_px", st->lod_error_px},
        {"lod_error_scale", st->lod_error_scale}, {"lod_error_changes", st->lod_error_changes},
        {"wanted_pages", st->wanted_pages}, {"settled_frames", st->settled_frames},
        {"node_groups_changed", st->node_groups_changed}, {"node_updates", st->node_updates},
        {"node_words_uploaded", st->node_words_uploaded}, {"node_copies", st->node_copies},
        {"loader_pages", (double)st->loader_pages}, {"loader_bytes_read", (double)st->loader_bytes_read},
        {"loader_busy_ms", st->loader_busy_ms}, {"loader_mb_s", st->loader_mb_s},
        {"loader_queue_depth", st->loader_queue_depth},
        {"cluster_record_bytes", (double)st->cluster_record_bytes}, {"hierarchy_bytes", (double)st->hierarchy_bytes},
        {"node_count_bytes", (double)st->node_count_bytes}, {"page_table_bytes", (double)st->page_table_bytes},
        {"source_triangles", (double)st->source_triangles}, {"setup_open_ms", st->setup_open_ms},
        {"setup_scene_ms", st->setup_scene_ms}, {"setup_node_counts_ms", st->setup_node_counts_ms},
        {"setup_first_pages_ms", st->setup_first_pages_ms}};
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++)
        cJSON_AddNumberToObject(o, fields[i].name, fields[i].value);
}

void stats_add_memory_json(cJSON *object, const gdr_frame_stats *s)
{
    add_streaming_json(object, &s->streaming);
    cJSON_AddNumberToObject(object, "gpu_memory_bytes", (double)s->memory.device_bytes);
    cJSON_AddNumberToObject(object, "gpu_memory_scene_bytes", (double)s->memory.scene_bytes);
    cJSON_AddNumberToObject(object, "gpu_memory_frame_bytes", (double)s->memory.frame_bytes);
    cJSON_AddNumberToObject(object, "gpu_texture_bytes", (double)s->memory.texture_bytes);
    cJSON_AddNumberToObject(object, "textures_compressed", s->memory.textures_compressed);
    cJSON_AddNumberToObject(object, "textures_decoded", s->memory.textures_decoded);
}

stats_path_frame stats_path_row(const gdr_frame_stats *s)
{
    const gdr_streaming_stats *st = &s->streaming;
    stats_path_frame row = {s->gpu_ms_per_frame, s->cpu_ms_per_frame, 0.0, s->triangles, st->lod_error_px,
                            st->wanted_pages, st->resident_pages, st->uploads, st->evictions, st->requests,
                            .pass_count = s->pass_count};
    memcpy(row.passes, s->passes, sizeof row.passes);
    return row;
}

static void add_path_json(cJSON *root, const stats_context *context)
{
    cJSON *rows = context->path_count ? cJSON_AddArrayToObject(root, "path") : NULL;
    for (uint32_t i = 0; rows && i < context->path_count; i++) {
        const stats_path_frame *f = &context->path[i];
        cJSON *row = cJSON_CreateObject();
        if (!row || !cJSON_AddItemToArray(rows, row))
            break;
        cJSON_AddNumberToObject(row, "frame", i);
        cJSON_AddNumberToObject(row, "gpu_ms", f->gpu_ms);
        cJSON_AddNumberToObject(row, "cpu_ms", f->cpu_ms);
        cJSON_AddNumberToObject(row, "wall_ms", f->wall_ms);
        cJSON_AddNumberToObject(row, "triangles", (double)f->triangles);
        cJSON_AddNumberToObject(row, "lod_error_px", f->lod_error_px);
        cJSON_AddNumberToObject(row, "wanted_pages", f->wanted_pages);
        cJSON_AddNumberToObject(row, "resident_pages", f->resident_pages);
        cJSON_AddNumberToObject(row, "uploads", f->uploads);
        cJSON_AddNumberToObject(row, "evictions", f->evictions);
        cJSON_AddNumberToObject(row, "requests", f->requests);
        cJSON *passes = cJSON_AddObjectToObject(row, "gpu_ms_passes");
        for (uint32_t p = 0; passes && p < f->pass_count; p++)
            cJSON_AddNumberToObject(passes, f->passes[p].name, f->passes[p].gpu_ms);
    }
}

char *stats_to_json(const stats_context *context, const gdr_frame_stats *s)
{
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return NULL;
    cJSON_AddStringToObject(root, "scene", context->scene);
    cJSON_AddStringToObject(root, "device", s->device);
    cJSON_AddStringToObject(root, "driver", s->driver);
    cJSON_AddNumberToObject(root, "width", context->width);
    cJSON_AddNumberToObject(root, "height", context->height);
    cJSON_AddNumberToObject(root, "frames", s->frames);
    cJSON_AddStringToObject(root, "cull", context->cull);
    cJSON_AddStringToObject(root, "pipeline", gdr_pipeline_name(s->pipeline));
    cJSON_AddStringToObject(root, "pipeline_reason", s->pipeline_reason);
    cJSON_AddStringToObject(root, "view", context->view ? context->view : "shaded");
    cJSON_AddNumberToObject(root, "instances_total", s->instances_total);
    cJSON_AddNumberToObject(root, "instances_visible", s->instances_visible);
    cJSON_AddNumberToObject(root, "instances_invalid", s->instances_invalid);
    cJSON_AddNumberToObject(root, "instances_screen_size_culled", s->instances_screen_size_culled);
    cJSON_AddNumberToObject(root, "instances_clip_plane_culled", s->instances_clip_plane_culled);
    cJSON_AddNumberToObject(root, "instances_points", s->instances_points);
    cJSON_AddStringToObject(root, "pvs", pvs_state(&s->pvs));
    cJSON_AddBoolToObject(root, "pvs_cell_found", s->pvs.cell_found);
    cJSON_AddNumberToObject(root, "pvs_cells", s->pvs.cells);
    cJSON_AddNumberToObject(root, "instances_pvs_culled", s->pvs.instances_culled);
    cJSON_AddNumberToObject(root, "pvs_cpu_ms_per_frame", s->pvs.cpu_ms_per_frame);
    cJSON_AddNumberToObject(root, "triangles", (double)s->triangles);
    cJSON_AddNumberToObject(root, "draws", s->draws);
    cJSON_AddNumberToObject(root, "draw_calls", s->draw_calls);
    if (s->pipeline == GDR_PIPELINE_MESH) {
        stats_add_meshlet_json(root, s);
        cJSON_AddNumberToObject(root, "task_workgroups", s->task_workgroups);
        cJSON_AddNumberToObject(root, "task_overflow", s->task_overflow);
    }
    if (s->pipeline == GDR_PIPELINE_CPU)
        cJSON_AddNumberToObject(root, "cpu_cull_ms_per_frame", s->cpu_cull_ms_per_frame);
    stats_add_occlusion_json(root, s);
    stats_add_traversal_json(root, s);
    cJSON_AddNumberToObject(root, "cpu_ms_per_frame", s->cpu_ms_per_frame);
    cJSON_AddNumberToObject(root, "cpu_submit_ms_per_frame", s->cpu_submit_ms_per_frame);
    cJSON_AddNumberToObject(root, "frames_recorded", s->frames_recorded);
    cJSON_AddNumberToObject(root, "cpu_ms_per_frame_median", s->cpu_ms_per_frame_median);
    cJSON_AddNumberToObject(root, "gpu_ms_per_frame", s->gpu_ms_per_frame);
    cJSON *passes = cJSON_AddObjectToObject(root, "gpu_ms");
    for (uint32_t p = 0; passes && p < s->pass_count; p++)
        cJSON_AddNumberToObject(passes, s->passes[p].name, s->passes[p].gpu_ms);
    stats_add_memory_json(root, s);
    cJSON_AddNumberToObject(root, "validation_messages", s->validation_messages);
    add_path_json(root, context);
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    return text;
}
