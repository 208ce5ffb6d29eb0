#version 460
// The LOD hierarchy traversal: one dispatch per level of the instances' hierarchies, one
// invocation per node visit (instance, node), launched with what the level before queued
// (shared/task_queue.h; level 0: the roots, queued by the instance cull). A node is skipped when no
// cluster below it can be in the LOD cut (gdr_lod_node_may_draw: its error bounds against the
// threshold) or when its sphere is outside the frustum. With occlusion culling, the early phase
// defers a node behind last frame's pyramid to the late phase's level (the occluded-node list),
// whose visits are those deferred nodes and the children its level before queued; the late phase
// skips a node behind this frame's pyramid. Otherwise an inner node queues its children for the next
// level and a leaf appends task commands for its clusters, which the cluster tests then decide one by
// one (the cut is the flat rule's: the hierarchy only decides what is tested).
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "gpu_shared/glsl_buffers.h"
#include "math/cull_math.h"
#include "gpu_shared/lod_math.h"
#include "gpu_shared/occlusion_test.h"
#include "gpu_shared/task_queue.h"
#include "gpu_shared/residency.h"

layout(local_size_x = GDR_TRAVERSE_WORKGROUP_SIZE) in;
layout(constant_id = 0) const uint PHASE = GDR_PHASE_NONE;

// The visit of this invocation at `level`: one the level before queued, or in the late phase first
// the visits the early phase deferred to this level.
bool visit_of_invocation(GdrGpuFrameGlobals g, DrawStatsRef stats, uint level, out GdrGpuNodeVisit visit)
{
    visit = GdrGpuNodeVisit(0u, 0u, 0u);
    uint i = gl_GlobalInvocationID.x;
    if (PHASE == GDR_PHASE_LATE) {
        uint deferred = stats.value.occluded_nodes[level];
        if (i < deferred) {
            uint first = 0u; // the levels before stored theirs first
            for (uint l = 0u; l < level; l++)
                first += stats.value.occluded_nodes[l];
            visit = NodeVisitsRef(GDR_FRAME.occluded_nodes).items[first + i];
            return true;
        }
        i -= deferred;
    }
    uint queued = stats.value.traversal[(PHASE == GDR_PHASE_LATE ? GDR_LOD_TREE_LEVELS : 0u) + level].count;
    if (i >= min(queued, g.traversal_capacity))
        return false;
    visit = NodeVisitsRef(uint64_t(GDR_FRAME.traversal) + uint64_t((level & 1u) * g.traversal_capacity) * 12ul).items[i];
    return true;
}

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    uint level = push.step;
    GdrGpuNodeVisit visit;
    bool in_level = visit_of_invocation(g, stats, level, visit);
    GdrGpuLodNode node;
    GdrGpuMesh mesh;
    uint mesh_index = 0u;
    bool lod_culled = false, frustum_culled = false, occluded = false;
    vec3 world_center = vec3(0.0);
    float radius = 0.0;
    if (in_level) {
        GdrGpuInstance instance = GDR_SCENE.instances.items[visit.instance];
        mesh_index = instance.mesh;
        mesh = GDR_SCENE.meshes.items[instance.mesh];
        node = GDR_SCENE.lod_nodes.items[mesh.lod_node_offset + visit.node];
        if ((g.flags & GDR_FRAME_DEBUG_SHRINK_NODES) != 0u) {
            node.sphere.w *= 0.25;
            node.bounds.w *= 0.25;
        }
        mat4 model = instance.model;
        float min_refined_error = gdr_node_min_refined_error(g, mesh.lod_node_offset + visit.node, node.min_refined_error);
        lod_culled = !gdr_lod_node_may_draw(node.sphere, node.max_error, min_refined_error, model[0].xyz,
                                            model[1].xyz, model[2].xyz, model[3].xyz, g.camera_position.xyz, g.lod_znear,
                                            g.lod_projection_scale, g.lod_threshold);
        world_center = (model * vec4(node.bounds.xyz, 1.0)).xyz;
        radius = node.bounds.w * gdr_max_axis_scale(model[0].xyz, model[1].xyz, model[2].xyz);
        vec3 center = (g.view * vec4(world_center, 1.0)).xyz;
        bool cull = g.cull_enabled != 0u && (g.flags & GDR_FRAME_MESHLET_FRUSTUM) != 0u;
        frustum_culled = !lod_culled && cull && !gdr_sphere_visible_offset(g.frustum, g.frustum_offset, center, radius, g.znear, g.zfar);
        occluded = PHASE != GDR_PHASE_NONE && !lod_culled && !frustum_culled && g.cull_enabled != 0u &&
                   gdr_phase_occluded(g, PHASE, world_center, radius);
    }
    // The early phase defers hidden nodes (those that find no room in the list go on now).
    bool deferred = false;
    if (PHASE == GDR_PHASE_EARLY) {
        deferred = gdr_defer_nodes(g, occluded, level, visit);
        occluded = deferred;
    }
    bool passes = in_level && !lod_culled && !frustum_culled && !occluded;
    // Streamed, the records live in their pages' slots: a leaf's clusters are records node.first ..
    // of its group's slot (the page-table word), and a leaf of an absent group, which draws none of
    // its clusters (an absent group counts as passing), emits none.
    bool paged = (g.flags & GDR_FRAME_PAGED_RECORDS) != 0u;
    bool leaf = passes && (node.flags & GDR_GPU_LOD_NODE_LEAF) != 0u;
    uint slot = paged && leaf && node.group != GDR_GPU_NO_GROUP
                    ? UintsRef(GDR_SCENE.page_table).items[mesh.page_table_offset + node.group]
                    : GDR_GPU_PAGE_ABSENT;
    bool emits = leaf && !(paged && slot == GDR_GPU_PAGE_ABSENT);
    uint first = paged ? slot * g.records_per_slot + node.first : mesh.meshlet_offset + node.first;
    gdr_queue_visits(g, PHASE, level + 1u, passes && !leaf ? node.count : 0u, visit.instance, node.first, visit.flags);
    GdrTaskRange range = emits ? gdr_task_range(first, node.count, visit.flags)
                               : GdrTaskRange(0u, 0u, 0u, 0u);
    gdr_append_tasks(g, PHASE, emits, visit.instance, range);
    GDR_COUNT(stats, nodes_tested, in_level);
    GDR_COUNT(stats, nodes_lod_culled, lod_culled);
    GDR_COUNT(stats, nodes_frustum_culled, frustum_culled);
    if (PHASE == GDR_PHASE_EARLY) {
        GDR_COUNT(stats, nodes_early_occluded, deferred);
    } else {
        GDR_COUNT(stats, nodes_occluded, occluded);
    }
    if (PHASE == GDR_PHASE_LATE)
        GDR_COUNT(stats, late_nodes_tested, in_level);
}
