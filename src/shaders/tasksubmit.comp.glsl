#version 460
// The meshlet pipeline's "submit" pass (seed 000): one thread turns the number of task commands the
// instance cull appended into the VkDrawMeshTasksIndirectCommandEXT that launches them. Launches
// wider than GDR_TASK_GROUPS_PER_ROW use rows (y); the task shader skips the tail of the last row.
#include "shared/glsl_buffers.h"

layout(local_size_x = 1) in;
// The late phase of occlusion culling (issue 6) launches its own task commands.
layout(constant_id = 0) const bool LATE = false;

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    DrawStatsRef stats = DrawStatsRef(push.draw_stats);
    uint count = min(LATE ? stats.value.late_task_count : stats.value.task_count, g.task_capacity);
    uint rows = (count + GDR_TASK_GROUPS_PER_ROW - 1u) / GDR_TASK_GROUPS_PER_ROW;
    uvec3 groups = uvec3(rows > 1u ? GDR_TASK_GROUPS_PER_ROW : count, rows, 1u);
    if (LATE) {
        stats.value.late_task_groups_x = groups.x;
        stats.value.late_task_groups_y = groups.y;
        stats.value.late_task_groups_z = groups.z;
    } else {
        stats.value.task_groups_x = groups.x;
        stats.value.task_groups_y = groups.y;
        stats.value.task_groups_z = groups.z;
    }
}
