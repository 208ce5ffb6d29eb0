#version 460
// Meshlet culling for the forward mesh pipeline (seeds 000/001/004): one task workgroup per task
// command (up to GDR_TASK_WORKGROUP_SIZE clusters of one visible instance), one thread per cluster
// running the tests of shared/cluster_cull.h. Survivors are compacted into the payload with subgroup
// ballots; one mesh workgroup each. (The visibility-buffer modes run the same tests in
// clustercull.comp instead.)
#extension GL_EXT_mesh_shader : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "gpu_shared/glsl_buffers.h"
#include "math/cull_math.h"
#include "gpu_shared/lod_math.h"
#include "gpu_shared/occlusion_test.h"
#include "gpu_shared/meshlet_payload.h"
#include "gpu_shared/cluster_cull.h"

layout(local_size_x = GDR_TASK_WORKGROUP_SIZE) in;
// Occlusion culling phase: GDR_PHASE_NONE, _EARLY or _LATE.
layout(constant_id = 0) const uint PHASE = GDR_PHASE_NONE;

taskPayloadSharedEXT GdrTaskPayload payload;
shared uint visible_count;
shared uint deferred;       // early phase: the command's clusters behind last frame's pyramid
shared bool deferral_failed;

// Early phase: one retest command for the clusters behind last frame's pyramid; where the late
// region is full, they are drawn now instead.
void defer_hidden_clusters(GdrGpuFrameGlobals g, uint task_index, uint lane, inout GdrClusterResult cluster)
{
    if (lane == 0u) {
        deferred = 0u;
        deferral_failed = false;
    }
    barrier();
    if (cluster.occluded)
        atomicOr(deferred, 1u << lane);
    barrier();
    if (lane == 0u && deferred != 0u)
        deferral_failed = !gdr_defer_clusters(g, gdr_task_region(g, GDR_PHASE_EARLY).items[task_index], deferred);
    barrier();
    if (deferral_failed && cluster.occluded)
        cluster.visible = true;
}

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    uint task_index = gl_WorkGroupID.x + gl_WorkGroupID.y * GDR_TASK_GROUPS_PER_ROW;
    uint lane = gl_LocalInvocationIndex;
    if (lane == 0u)
        visible_count = 0u;
    GdrClusterResult cluster = gdr_cluster_test(g, PHASE, task_index, lane);
    if (PHASE == GDR_PHASE_EARLY)
        defer_hidden_clusters(g, task_index, lane, cluster);
    barrier();

    uvec4 ballot = subgroupBallot(cluster.visible);
    uint base = 0u;
    if (subgroupElect())
        base = atomicAdd(visible_count, subgroupBallotBitCount(ballot));
    base = subgroupBroadcastFirst(base);
    if (cluster.visible)
        payload.meshlets[base + subgroupBallotExclusiveBitCount(ballot)] = cluster.meshlet;
    if (lane == 0u)
        payload.instance = cluster.instance;
    gdr_cluster_count(g, PHASE, cluster);
    barrier();
    EmitMeshTasksEXT(visible_count, 1u, 1u);
}
