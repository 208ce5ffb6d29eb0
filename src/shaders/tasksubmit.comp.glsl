#version 460
// The meshlet pipeline's "submit" pass (seed 000): one thread turns the number of task commands the
// instance cull appended into the VkDrawMeshTasksIndirectCommandEXT that launches them, and into the
// VkDispatchIndirectCommand of the cluster cull (visibility-buffer modes: GDR_CLUSTER_CULL_TASKS per
// workgroup). Launches wider than GDR_TASK_GROUPS_PER_ROW use rows (y); the shaders skip the tail of
// the last row.
#include "gpu_shared/glsl_buffers.h"

layout(local_size_x = 1) in;
// The late phase of occlusion culling launches its own task commands.
layout(constant_id = 0) const bool LATE = false;

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    uint count = min(LATE ? stats.value.late_task_count : stats.value.task_count, g.task_capacity);
    uint rows = (count + GDR_TASK_GROUPS_PER_ROW - 1u) / GDR_TASK_GROUPS_PER_ROW;
    uvec3 groups = uvec3(rows > 1u ? GDR_TASK_GROUPS_PER_ROW : count, rows, 1u);
    uint cull_count = (count + GDR_CLUSTER_CULL_TASKS - 1u) / GDR_CLUSTER_CULL_TASKS;
    uint cull_rows = (cull_count + GDR_TASK_GROUPS_PER_ROW - 1u) / GDR_TASK_GROUPS_PER_ROW;
    uvec3 cull_groups = uvec3(cull_rows > 1u ? GDR_TASK_GROUPS_PER_ROW : cull_count, cull_rows, 1u);
    if (LATE) {
        stats.value.late_task_groups_x = groups.x;
        stats.value.late_task_groups_y = groups.y;
        stats.value.late_task_groups_z = groups.z;
        stats.value.late_cull_groups_x = cull_groups.x;
        stats.value.late_cull_groups_y = cull_groups.y;
        stats.value.late_cull_groups_z = cull_groups.z;
    } else {
        stats.value.task_groups_x = groups.x;
        stats.value.task_groups_y = groups.y;
        stats.value.task_groups_z = groups.z;
        stats.value.cull_groups_x = cull_groups.x;
        stats.value.cull_groups_y = cull_groups.y;
        stats.value.cull_groups_z = cull_groups.z;
    }
}
