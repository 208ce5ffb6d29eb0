/* GLSL only: what the instance cull and the LOD hierarchy traversal append for the cluster tests:
 * task commands (one per up to GDR_TASK_WORKGROUP_SIZE clusters of one instance) and node visits
 * (the traversal's next level). Every invocation of a subgroup calls these in uniform control flow
 * (one atomic per subgroup). Include after glsl_buffers.h; needs the subgroup ballot and arithmetic
 * extensions. */
#ifndef GDR_TASK_QUEUE_H
#define GDR_TASK_QUEUE_H

// Occlusion culling phases (the culling shaders' specialisation constant PHASE): none, early, late.
#define GDR_PHASE_NONE 0u
#define GDR_PHASE_EARLY 1u
#define GDR_PHASE_LATE 2u

// Adds each lane's 0/1 to the counter `field` of DrawStatsRef `stats`, one atomic per subgroup.
#define GDR_COUNT(stats, field, condition)                             \
    {                                                                  \
        uint n_ = subgroupAdd((condition) ? 1u : 0u);                  \
        if (subgroupElect() && n_ > 0u)                                \
            atomicAdd(stats.value.field, n_);                          \
    }

// A run of clusters of one instance: `tasks` commands of up to GDR_TASK_WORKGROUP_SIZE clusters.
struct GdrTaskRange {
    uint first;  // global cluster index
    uint count;
    uint tasks;
    uint flags;  // GDR_TASK_*
};

GdrTaskRange gdr_task_range(uint first, uint count, uint flags)
{
    return GdrTaskRange(first, count, (count + GDR_TASK_WORKGROUP_SIZE - 1u) / GDR_TASK_WORKGROUP_SIZE, flags);
}

// Appends the commands of `range` (none when !append) to `phase`'s region of the task list (the
// late phase's follows the early phase's task_capacity entries); what does not fit is counted.
void gdr_append_tasks(GdrGpuFrameGlobals g, uint phase, bool append, uint instance, GdrTaskRange range)
{
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    uint count = append ? range.tasks : 0u;
    uint subgroup_total = subgroupAdd(count);
    uint base = 0u;
    if (subgroupElect() && subgroup_total > 0u)
        base = phase == GDR_PHASE_LATE ? atomicAdd(stats.value.late_task_count, subgroup_total)
                                       : atomicAdd(stats.value.task_count, subgroup_total);
    base = subgroupBroadcastFirst(base) + subgroupExclusiveAdd(count);
    TaskCommandsRef tasks = TaskCommandsRef(uint64_t(GDR_FRAME.tasks) +
                                            (phase == GDR_PHASE_LATE ? uint64_t(g.task_capacity) * 16ul : 0ul));
    for (uint t = 0u; t < count; t++) {
        uint slot = base + t;
        uint first = t * GDR_TASK_WORKGROUP_SIZE;
        if (slot < g.task_capacity)
            tasks.items[slot] = GdrGpuTaskCommand(instance, range.first + first,
                                                  min(range.count - first, GDR_TASK_WORKGROUP_SIZE),
                                                  range.flags | (t == 0u ? GDR_TASK_FIRST : 0u));
        else
            atomicAdd(stats.value.task_overflow, 1u);
    }
}

// Queues `count` visits of instance `instance`: nodes first_node .. + count (mesh-local) at traversal
// level `level` of `phase`, with their launch; what does not fit the level is counted.
void gdr_queue_visits(GdrGpuFrameGlobals g, uint phase, uint level, uint count, uint instance, uint first_node,
                      uint flags)
{
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    if (level >= GDR_LOD_TREE_LEVELS) { // never: the deepest level of a hierarchy holds only leaves
        if (count > 0u)
            atomicAdd(stats.value.traversal_overflow, count);
        count = 0u;
    }
    uint index = (phase == GDR_PHASE_LATE ? GDR_LOD_TREE_LEVELS : 0u) + min(level, GDR_LOD_TREE_LEVELS - 1u);
    uint subgroup_total = subgroupAdd(count);
    uint base = 0u;
    if (subgroupElect() && subgroup_total > 0u) {
        base = atomicAdd(stats.value.traversal[index].count, subgroup_total);
        uint queued = min(base + subgroup_total, g.traversal_capacity);
        // A late level also visits the nodes the early phase deferred to it (final by now).
        if (phase == GDR_PHASE_LATE)
            queued += stats.value.occluded_nodes[min(level, GDR_LOD_TREE_LEVELS - 1u)];
        atomicMax(stats.value.traversal[index].dispatch_x,
                  (queued + GDR_TRAVERSE_WORKGROUP_SIZE - 1u) / GDR_TRAVERSE_WORKGROUP_SIZE);
        atomicMax(stats.value.traversal[index].dispatch_y, 1u);
        atomicMax(stats.value.traversal[index].dispatch_z, 1u);
    }
    base = subgroupBroadcastFirst(base) + subgroupExclusiveAdd(count);
    // Even levels in the first half of the queue, odd ones in the second.
    NodeVisitsRef visits = NodeVisitsRef(uint64_t(GDR_FRAME.traversal) +
                                         uint64_t((level & 1u) * g.traversal_capacity) * 12ul);
    for (uint c = 0u; c < count; c++) {
        if (base + c < g.traversal_capacity)
            visits.items[base + c] = GdrGpuNodeVisit(instance, first_node + c, flags);
        else
            atomicAdd(stats.value.traversal_overflow, 1u);
    }
}

// Early phase: appends the instances hidden behind last frame's pyramid (`occluded`) to the
// occluded-instance list, which holds every instance, and sizes the late instance cull's launch.
void gdr_defer_instances(bool occluded, uint instance)
{
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    uvec4 ballot = subgroupBallot(occluded);
    uint total = subgroupBallotBitCount(ballot);
    uint base = 0u;
    if (subgroupElect() && total > 0u) {
        base = atomicAdd(stats.value.late_instances.count, total);
        atomicMax(stats.value.late_instances.dispatch_x,
                  (base + total + GDR_CULL_WORKGROUP_SIZE - 1u) / GDR_CULL_WORKGROUP_SIZE);
        atomicMax(stats.value.late_instances.dispatch_y, 1u);
        atomicMax(stats.value.late_instances.dispatch_z, 1u);
    }
    base = subgroupBroadcastFirst(base) + subgroupBallotExclusiveBitCount(ballot);
    if (occluded)
        WritableUintsRef(GDR_FRAME.occluded_instances).items[base] = instance;
}

// Early phase: appends the node visits hidden behind last frame's pyramid (`occluded`) to the
// occluded-node list for late level `level`, with that level's launch. Returns whether this lane's
// visit was stored: one that found no room is traversed now instead (counted as overflow), so
// nothing is lost. Levels run one after another, so each level's visits follow the level before's.
bool gdr_defer_nodes(GdrGpuFrameGlobals g, bool occluded, uint level, GdrGpuNodeVisit visit)
{
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    uvec4 ballot = subgroupBallot(occluded);
    uint total = subgroupBallotBitCount(ballot);
    uint base = 0u;
    if (subgroupElect() && total > 0u)
        base = atomicAdd(stats.value.occluded_node_total, total);
    base = subgroupBroadcastFirst(base);
    uint slot = base + subgroupBallotExclusiveBitCount(ballot);
    bool stored = occluded && slot < g.occluded_node_capacity;
    if (stored)
        NodeVisitsRef(GDR_FRAME.occluded_nodes).items[slot] = visit;
    uint stored_total = subgroupAdd(stored ? 1u : 0u);
    GDR_COUNT(stats, occluded_overflow, occluded && !stored);
    if (subgroupElect() && stored_total > 0u) {
        uint before = atomicAdd(stats.value.occluded_nodes[level], stored_total);
        uint index = GDR_LOD_TREE_LEVELS + level;
        atomicMax(stats.value.traversal[index].dispatch_x,
                  (before + stored_total + GDR_TRAVERSE_WORKGROUP_SIZE - 1u) / GDR_TRAVERSE_WORKGROUP_SIZE);
        atomicMax(stats.value.traversal[index].dispatch_y, 1u);
        atomicMax(stats.value.traversal[index].dispatch_z, 1u);
    }
    return stored;
}

#endif
