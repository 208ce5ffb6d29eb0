#version 460
// The compute rasteriser's "submit" pass (issue 8): one thread turns the number of clusters the
// task shaders binned to it since the last launch into the VkDispatchIndirectCommand that launches
// one workgroup each. Launches wider than GDR_SW_GROUPS_PER_ROW use rows (y); the rasteriser skips
// the tail of the last row.
#include "shared/glsl_buffers.h"
#include "shared/visbuffer.h"

layout(local_size_x = 1) in;

void main()
{
    RasterCountersRef counters = RasterCountersRef(RasterParamsRef(push.raster).value.counters);
    // The clusters appended since the last dispatch of the frame (one per raster phase).
    uint first = counters.value.sw_dispatched;
    uint count = counters.value.sw_clusters - first;
    counters.value.sw_first = first;
    counters.value.sw_dispatched = counters.value.sw_clusters;
    uint rows = (count + GDR_SW_GROUPS_PER_ROW - 1u) / GDR_SW_GROUPS_PER_ROW;
    counters.value.dispatch_x = rows > 1u ? GDR_SW_GROUPS_PER_ROW : count;
    counters.value.dispatch_y = rows;
    counters.value.dispatch_z = 1u;
}
