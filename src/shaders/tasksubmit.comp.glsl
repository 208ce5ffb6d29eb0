#version 460
// The meshlet pipeline's "submit" pass (seed 000): one thread turns the number of task commands the
// instance cull appended into the VkDrawMeshTasksIndirectCommandEXT that launches them. Launches
// wider than GDR_TASK_GROUPS_PER_ROW use rows (y); the task shader skips the tail of the last row.
#include "shared/glsl_buffers.h"

layout(local_size_x = 1) in;

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    DrawStatsRef stats = DrawStatsRef(push.draw_stats);
    uint count = min(stats.value.task_count, g.task_capacity);
    uint rows = (count + GDR_TASK_GROUPS_PER_ROW - 1u) / GDR_TASK_GROUPS_PER_ROW;
    stats.value.task_groups_x = rows > 1u ? GDR_TASK_GROUPS_PER_ROW : count;
    stats.value.task_groups_y = rows;
    stats.value.task_groups_z = 1u;
}
