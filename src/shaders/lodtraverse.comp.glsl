#version 460
// The LOD hierarchy traversal: one dispatch per level of the instances' hierarchies, one
// invocation per node visit (instance, node), launched with what the level before queued
// (shared/task_queue.h; level 0: the roots, queued by the instance cull). A node is skipped when no
// cluster below it can be in the LOD cut (gdr_lod_node_may_draw: its error bounds against the
// threshold), when its sphere is outside the frustum, or in the late phase when it is behind this
// frame's depth pyramid; otherwise an inner node queues its children for the next level and a leaf
// appends task commands for its clusters, which the cluster tests then decide one by one (the cut
// is the flat rule's: the hierarchy only decides what is tested).
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "shared/glsl_buffers.h"
#include "shared/cull_math.h"
#include "shared/lod_math.h"
#include "shared/occlusion_test.h"
#include "shared/task_queue.h"

layout(local_size_x = GDR_TRAVERSE_WORKGROUP_SIZE) in;
layout(constant_id = 0) const uint PHASE = GDR_PHASE_NONE;

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    uint level = push.step;
    uint queued = stats.value.traversal[(PHASE == GDR_PHASE_LATE ? GDR_LOD_TREE_LEVELS : 0u) + level].count;
    bool in_level = gl_GlobalInvocationID.x < min(queued, g.traversal_capacity);
    GdrGpuNodeVisit visit = GdrGpuNodeVisit(0u, 0u, 0u);
    GdrGpuLodNode node;
    GdrGpuMesh mesh;
    bool lod_culled = false, frustum_culled = false, occluded = false;
    if (in_level) {
        NodeVisitsRef visits = NodeVisitsRef(uint64_t(GDR_FRAME.traversal) +
                                             uint64_t((level & 1u) * g.traversal_capacity) * 12ul);
        visit = visits.items[gl_GlobalInvocationID.x];
        GdrGpuInstance instance = GDR_SCENE.instances.items[visit.instance];
        mesh = GDR_SCENE.meshes.items[instance.mesh];
        node = GDR_SCENE.lod_nodes.items[mesh.lod_node_offset + visit.node];
        if ((g.flags & GDR_FRAME_DEBUG_SHRINK_NODES) != 0u)
            node.sphere.w *= 0.25;
        mat4 model = instance.model;
        lod_culled = !gdr_lod_node_may_draw(node.sphere, node.max_error, node.min_refined_error, model[0].xyz,
                                            model[1].xyz, model[2].xyz, model[3].xyz, g.camera_position.xyz, g.znear,
                                            g.lod_projection_scale, g.lod_threshold);
        vec3 center = (g.view * (model * vec4(node.sphere.xyz, 1.0))).xyz;
        float radius = node.sphere.w * gdr_max_axis_scale(model[0].xyz, model[1].xyz, model[2].xyz);
        bool cull = g.cull_enabled != 0u && (g.flags & GDR_FRAME_MESHLET_FRUSTUM) != 0u;
        frustum_culled = !lod_culled && cull && !gdr_sphere_visible(g.frustum, center, radius, g.znear, g.zfar);
        occluded = PHASE == GDR_PHASE_LATE && !lod_culled && !frustum_culled && g.cull_enabled != 0u &&
                   gdr_sphere_occluded(g, center, radius);
    }
    bool passes = in_level && !lod_culled && !frustum_culled && !occluded;
    bool leaf = passes && (node.flags & GDR_GPU_LOD_NODE_LEAF) != 0u;
    gdr_queue_visits(g, PHASE, level + 1u, passes && !leaf ? node.count : 0u, visit.instance, node.first, visit.flags);
    GdrTaskRange range = leaf ? gdr_task_range(mesh.meshlet_offset + node.first, node.count, visit.flags)
                              : GdrTaskRange(0u, 0u, 0u, 0u);
    gdr_append_tasks(g, PHASE, leaf, visit.instance, range);
    GDR_COUNT(stats, nodes_tested, in_level);
    GDR_COUNT(stats, nodes_lod_culled, lod_culled);
    GDR_COUNT(stats, nodes_frustum_culled, frustum_culled);
    GDR_COUNT(stats, nodes_occluded, occluded);
    if (PHASE == GDR_PHASE_LATE)
        GDR_COUNT(stats, late_nodes_tested, in_level);
}
