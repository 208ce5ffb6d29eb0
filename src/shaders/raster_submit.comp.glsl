#version 460
// The launches of one raster phase, one thread: from the clusters the cluster cull
// appended since the last phase, the compute rasteriser's VkDispatchIndirectCommand (front of the
// list) and the mesh shaders' VkDrawMeshTasksIndirectCommandEXT (back of the list), one workgroup per
// cluster, and a VkDispatchIndirectCommand per tiny size class over its part of the list, several
// clusters per workgroup (raster_sw.comp's tiny variants). Launches wider than a row use y; the
// shaders skip the tail of the last row. Mesh-shader
// clusters beyond the device's launch limit are dropped and counted as overflow. And the resolve's
// VkDispatchIndirectCommand: the whole screen in the frame's first phase and in a later phase with
// clusters to draw, nothing otherwise (the visibility buffer has not changed since the last resolve).
#include "gpu_shared/glsl_buffers.h"
#include "gpu_shared/visbuffer.h"

layout(local_size_x = 1) in;

// The workgroups of `groups`, in rows of GDR_SW_GROUPS_PER_ROW.
uvec3 sw_dispatch(uint groups)
{
    uint rows = (groups + GDR_SW_GROUPS_PER_ROW - 1u) / GDR_SW_GROUPS_PER_ROW;
    return uvec3(rows > 1u ? GDR_SW_GROUPS_PER_ROW : groups, rows, 1u);
}

void main()
{
    RasterParamsRef params = GDR_FRAME.raster;
    RasterCountersRef counters = RasterCountersRef(params.value.counters);
    uint first = counters.value.sw_dispatched;
    uint count = counters.value.sw_clusters - first;
    counters.value.sw_first = first;
    counters.value.sw_dispatched = counters.value.sw_clusters;
    uvec3 launch = sw_dispatch(count);
    counters.value.dispatch_x = launch.x;
    counters.value.dispatch_y = launch.y;
    counters.value.dispatch_z = launch.z;

    uint tiny_total = 0u;
    for (uint k = 0u; k < GDR_SW_TINY_CLASSES; k++) {
        // Entries asked beyond the part's end went to the front.
        uint tiny_end = min(counters.value.tiny_clusters[k], params.value.tiny_capacity[k]);
        uint tiny_first = counters.value.tiny_dispatched[k];
        uint tiny_count = tiny_end - tiny_first;
        counters.value.tiny_first[k] = tiny_first;
        counters.value.tiny_dispatched[k] = tiny_end;
        uint per_group = GDR_SW_RASTER_WORKGROUP_SIZE / (GDR_SW_TINY_LANES << k);
        launch = sw_dispatch((tiny_count + per_group - 1u) / per_group);
        counters.value.tiny_launch[3u * k] = launch.x;
        counters.value.tiny_launch[3u * k + 1u] = launch.y;
        counters.value.tiny_launch[3u * k + 2u] = launch.z;
        tiny_total += tiny_count;
    }

    uint hw_total = counters.value.hw_clusters;
    uint hw_new = hw_total - counters.value.hw_dispatched;
    uint hw_count = min(hw_new, params.value.hw_launch_limit);
    if (hw_count < hw_new)
        counters.value.overflow += hw_new - hw_count;
    counters.value.hw_first = params.value.capacity - hw_total;
    counters.value.hw_count = hw_count;
    counters.value.hw_dispatched = hw_total;
    uint rows = (hw_count + GDR_MESH_GROUPS_PER_ROW - 1u) / GDR_MESH_GROUPS_PER_ROW;
    counters.value.draw_x = rows > 1u ? GDR_MESH_GROUPS_PER_ROW : hw_count;
    counters.value.draw_y = rows;
    counters.value.draw_z = 1u;

    bool resolve = counters.value.phases == 0u || count > 0u || tiny_total > 0u || hw_count > 0u;
    uvec2 tiles = (uvec2(FrameGlobalsRef(push.globals).value.viewport) + GDR_RESOLVE_TILE - 1u) / GDR_RESOLVE_TILE;
    counters.value.resolve_x = resolve ? tiles.x : 0u;
    counters.value.resolve_y = resolve ? tiles.y : 0u;
    counters.value.resolve_z = resolve ? 1u : 0u;
    counters.value.phases += 1u;
}
