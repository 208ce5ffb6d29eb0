#version 460
// Instance culling (seeds 000/001/003): one thread per instance; visible instances are appended,
// compacted with subgroup ballots, as VkDrawIndexedIndirectCommands for one
// vkCmdDrawIndexedIndirectCount (first_instance carries the instance index to the vertex shader),
// or, for the meshlet pipeline (EMIT_TASKS), as task commands: one task workgroup per up to
// GDR_TASK_WORKGROUP_SIZE clusters of the instance (level 0, or the LOD DAG's clusters).
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "shared/glsl_buffers.h"
#include "shared/cull_math.h"
#include "shared/lod_math.h"

layout(local_size_x = GDR_CULL_WORKGROUP_SIZE) in;
layout(constant_id = 0) const bool EMIT_TASKS = false;

layout(buffer_reference, scalar) writeonly buffer TaskCommandsRef { GdrGpuTaskCommand items[]; };

// The clusters an instance's task workgroups test: level 0; with the LOD cut, every cluster of
// the DAG, or only the root group's when the root shortcut passes (issue 5).
struct TaskRange {
    uint first;  // global cluster index
    uint count;
    uint tasks;
    uint flags;  // GDR_TASK_*
};

TaskRange task_range(GdrGpuFrameGlobals g, GdrGpuMesh mesh, mat4 model)
{
    if ((g.flags & GDR_FRAME_LOD) == 0u)
        return TaskRange(mesh.meshlet_offset, mesh.meshlet_count, mesh.task_count, 0u);
    if ((g.flags & GDR_FRAME_LOD_DEPTH) == 0u && mesh.root_cluster_count > 0u &&
        gdr_lod_group_projected_error(mesh.root_refined_sphere, mesh.root_refined_error, model[0].xyz, model[1].xyz,
                                      model[2].xyz, model[3].xyz, g.camera_position.xyz, g.znear,
                                      g.lod_projection_scale) <= g.lod_threshold)
        return TaskRange(mesh.meshlet_offset + mesh.root_first, mesh.root_cluster_count, mesh.root_task_count,
                         GDR_TASK_LOD_ACCEPTED);
    return TaskRange(mesh.meshlet_offset, mesh.lod_cluster_count, mesh.lod_task_count, 0u);
}

void append_tasks(GdrGpuFrameGlobals g, bool visible, uint instance, TaskRange range)
{
    DrawStatsRef stats = DrawStatsRef(push.draw_stats);
    uint count = visible ? range.tasks : 0u;
    uint subgroup_total = subgroupAdd(count);
    uint base = 0u;
    if (subgroupElect() && subgroup_total > 0u)
        base = atomicAdd(stats.value.task_count, subgroup_total);
    base = subgroupBroadcastFirst(base) + subgroupExclusiveAdd(count);
    TaskCommandsRef tasks = TaskCommandsRef(push.tasks);
    for (uint t = 0u; t < count; t++) {
        uint slot = base + t;
        uint first = t * GDR_TASK_WORKGROUP_SIZE;
        if (slot < g.task_capacity)
            tasks.items[slot] = GdrGpuTaskCommand(instance, range.first + first,
                                                  min(range.count - first, GDR_TASK_WORKGROUP_SIZE), range.flags);
        else
            atomicAdd(stats.value.task_overflow, 1u);
    }
}

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    uint id = gl_GlobalInvocationID.x;
    bool visible = false;
    GdrGpuMesh mesh;
    mat4 model;
    if (id < g.instance_count) {
        model = InstancesRef(push.instances).items[id].model;
        mesh = MeshesRef(push.meshes).items[InstancesRef(push.instances).items[id].mesh];
        visible = mesh.index_count > 0u; // nothing to draw otherwise
        if (visible && g.cull_enabled != 0u) {
            vec3 center = (g.view * (model * vec4(mesh.bounds.xyz, 1.0))).xyz;
            float radius = mesh.bounds.w * gdr_max_axis_scale(model[0].xyz, model[1].xyz, model[2].xyz);
            visible = gdr_sphere_visible(g.frustum, center, radius, g.znear, g.zfar);
        }
    }

    DrawStatsRef stats = DrawStatsRef(push.draw_stats);
    uvec4 ballot = subgroupBallot(visible);
    uint subgroup_count = subgroupBallotBitCount(ballot);
    // The meshlet pipeline counts the triangles its mesh shader emits instead.
    uint triangles = EMIT_TASKS ? 0u : subgroupAdd(visible ? mesh.index_count / 3u : 0u);
    uint base = 0u;
    if (subgroupElect() && subgroup_count > 0u) {
        base = atomicAdd(stats.value.draw_count, subgroup_count);
        uint old = atomicAdd(stats.value.triangles_low, triangles);
        if (old + triangles < old)
            atomicAdd(stats.value.triangles_high, 1u);
    }
    base = subgroupBroadcastFirst(base);
    if (EMIT_TASKS) {
        append_tasks(g, visible, id, visible ? task_range(g, mesh, model) : TaskRange(0u, 0u, 0u, 0u));
    } else if (visible) {
        uint slot = base + subgroupBallotExclusiveBitCount(ballot);
        DrawCommandsRef(push.draws).items[slot] =
            GdrGpuDrawCommand(mesh.index_count, 1u, mesh.first_index, int(mesh.vertex_offset), id);
    }
}
