#version 460
// The cluster cull of the visibility-buffer modes: one workgroup per GDR_CLUSTER_CULL_TASKS task
// commands (each up to GDR_TASK_WORKGROUP_SIZE clusters of one visible instance),
// GDR_CLUSTER_CULL_LANES invocations per command stepping through its clusters, launched indirectly
// (tasksubmit.comp). The tests are the task shader's
// (shared/cluster_cull.h); each visible cluster is then binned and appended to the frame's
// visible-cluster list (shared/raster_bin.h): small triangles to the compute rasteriser, the rest to
// the mesh shaders, which raster_submit.comp launches without a task shader. A compute pass instead
// of a task shader because a task workgroup is expensive to launch even when it emits nothing, and
// in these modes most clusters leave for the compute rasteriser.
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "gpu_shared/glsl_buffers.h"
#include "math/cull_math.h"
#include "gpu_shared/lod_math.h"
#include "gpu_shared/occlusion_test.h"
#include "gpu_shared/meshlet_payload.h"
#include "gpu_shared/cluster_cull.h"
#include "gpu_shared/raster_bin.h"

layout(local_size_x = GDR_CLUSTER_CULL_LANES * GDR_CLUSTER_CULL_TASKS) in;
// Occlusion culling phase: GDR_PHASE_NONE, _EARLY or _LATE.
layout(constant_id = 0) const uint PHASE = GDR_PHASE_NONE;

shared uint largest_task; // clusters in the workgroup's largest task command
// Early phase: per task command, its clusters behind last frame's pyramid; after the deferral,
// only those of commands that found no room in the late region (drawn now instead).
shared uint deferred[GDR_CLUSTER_CULL_TASKS];
shared bool deferral_failed;

// Early phase: one retest command per task command with hidden clusters; where the late region is
// full, those clusters are drawn now.
void defer_hidden_clusters(GdrGpuFrameGlobals g, uint task_index, uint task_slot, uint lane)
{
    barrier();
    if (lane == 0u && deferred[task_slot] != 0u) {
        GdrGpuTaskCommand task = gdr_task_region(g, GDR_PHASE_EARLY).items[task_index];
        if (gdr_defer_clusters(g, task, deferred[task_slot]))
            deferred[task_slot] = 0u;
        else
            deferral_failed = true;
    }
    barrier();
    if (!deferral_failed)
        return;
    GdrGpuTaskCommand task = gdr_task_region(g, GDR_PHASE_EARLY).items[min(task_index, g.task_capacity - 1u)];
    for (uint first = 0u; first < largest_task; first += GDR_CLUSTER_CULL_LANES) {
        uint cluster = first + lane;
        bool draw = cluster < 32u && (deferred[task_slot] & (1u << cluster)) != 0u;
        gdr_raster_append(g, draw, task.instance, task.meshlet_first + cluster);
    }
}

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * GDR_TASK_GROUPS_PER_ROW;
    uint task_slot = gl_LocalInvocationIndex / GDR_CLUSTER_CULL_LANES;
    uint task_index = group * GDR_CLUSTER_CULL_TASKS + task_slot;
    uint lane = gl_LocalInvocationIndex % GDR_CLUSTER_CULL_LANES;
    if (gl_LocalInvocationIndex == 0u) {
        largest_task = 0u;
        deferral_failed = false;
    }
    if (lane == 0u)
        deferred[task_slot] = 0u;
    barrier();
    if (lane == 0u)
        atomicMax(largest_task, gdr_cluster_task_size(g, PHASE, task_index));
    barrier();
    // Steps of GDR_CLUSTER_CULL_LANES clusters, as many as the largest command needs (uniform).
    for (uint first = 0u; first < largest_task; first += GDR_CLUSTER_CULL_LANES) {
        GdrClusterResult cluster = gdr_cluster_test(g, PHASE, task_index, first + lane);
        gdr_raster_append(g, cluster.visible, cluster.instance, cluster.meshlet);
        gdr_cluster_count(g, PHASE, cluster);
        if (PHASE == GDR_PHASE_EARLY && cluster.occluded)
            atomicOr(deferred[task_slot], 1u << (first + lane));
    }
    if (PHASE == GDR_PHASE_EARLY)
        defer_hidden_clusters(g, task_index, task_slot, lane);
}
