#version 460
// Instance culling (seeds 000/001/002/003): one thread per instance, which tests its bounds (invalid
// or empty, frustum, precomputed visibility, screen size, the global clip plane, occlusion); visible instances are appended,
// compacted with subgroup ballots, as VkDrawIndexedIndirectCommands for one
// vkCmdDrawIndexedIndirectCount (first_instance carries the instance index to the vertex shader),
// or, for the meshlet pipeline (EMIT_TASKS), as task commands: one task workgroup per up to
// GDR_TASK_WORKGROUP_SIZE clusters of the instance (level 0, the LOD DAG's clusters, the root
// group's), or as the root of its LOD hierarchy queued for the traversal (lodtraverse.comp).
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#ifdef GDR_POINT_SPLATS
#extension GL_EXT_shader_atomic_int64 : require
#endif

#include "gpu_shared/glsl_buffers.h"
#include "math/cull_math.h"
#include "gpu_shared/lod_math.h"
#include "gpu_shared/occlusion_test.h"
#include "gpu_shared/task_queue.h"
#include "gpu_shared/meshlet_payload.h"
#include "gpu_shared/cluster_cull.h"
#include "gpu_shared/raster_bin.h"
#ifdef GDR_POINT_SPLATS
#include "gpu_shared/point_level.h"
#endif

layout(local_size_x = GDR_CULL_WORKGROUP_SIZE) in;
layout(constant_id = 0) const bool EMIT_TASKS = false;
// Occlusion culling phase: none, or the early / late phase of the two-phase scheme.
layout(constant_id = 1) const uint PHASE = GDR_PHASE_NONE;

// Whether the group cluster m was made from passes the cut.
bool chain_refined_passes(GdrGpuFrameGlobals g, GdrGpuMeshlet m, mat4 model)
{
    return gdr_lod_group_projected_error(m.refined_sphere, m.refined_error, model[0].xyz, model[1].xyz,
                                         model[2].xyz, model[3].xyz, g.camera_position.xyz, g.znear,
                                         g.lod_projection_scale) <= g.lod_threshold;
}

// The root chain (GdrGpuMesh.root_chain), below a root whose refined group does not pass: the
// first lone cluster whose refined group passes is the whole cut (the group it was made from held
// the whole mesh, so every other group is below it and passes). With groups absent (streaming),
// the cluster test's rule decides instead, which draws in an absent group's place and asks for it.
// Returns the mesh-local cluster, or GDR_GPU_NO_GROUP when the chain does not decide the cut.
uint root_chain_cluster(GdrGpuFrameGlobals g, uint mesh_index, GdrGpuMesh mesh, mat4 model)
{
    uint chain = min(mesh.root_chain, uint(GDR_LOD_ROOT_CHAIN));
    // The finest first: where its refined group does not pass, no coarser one does (errors and
    // spheres grow towards the root), and a nearer instance leaves after one read.
    if (chain < 2u)
        return GDR_GPU_NO_GROUP;
    uint finest = mesh.meshlet_offset + mesh.root_first - (chain - 1u);
    if (!chain_refined_passes(g, MeshletsRef(GDR_SCENE.meshlets).items[finest], model))
        return GDR_GPU_NO_GROUP;
    for (uint i = 1u; i < chain; i++) {
        uint cluster = mesh.root_first - i;
        GdrGpuMeshlet m = MeshletsRef(GDR_SCENE.meshlets).items[mesh.meshlet_offset + cluster];
        if (gdr_group_absent(g, mesh_index, m.group) || gdr_group_absent(g, mesh_index, m.refined_group))
            break;
        if (chain_refined_passes(g, m, model)) {
            gdr_mark_group_used(g, mesh_index, m.group);
            return cluster;
        }
    }
    return GDR_GPU_NO_GROUP;
}

// The clusters an instance's task workgroups test: level 0; with the LOD cut, only the root
// group's when the root shortcut passes, one cluster of the root chain when one decides the cut,
// else those the traversal of its LOD hierarchy finds (`traverse`: none here), or every cluster of
// the DAG (flat, or the discrete debug cut).
GdrTaskRange task_range(GdrGpuFrameGlobals g, uint mesh_index, GdrGpuMesh mesh, mat4 model, out bool traverse)
{
    traverse = false;
    if ((g.flags & GDR_FRAME_LOD) == 0u)
        return gdr_task_range(mesh.meshlet_offset, mesh.meshlet_count, 0u);
    if ((g.flags & GDR_FRAME_LOD_DEPTH) != 0u)
        return gdr_task_range(mesh.meshlet_offset, mesh.lod_cluster_count, 0u);
    // Streamed (GDR_FRAME_PAGED_RECORDS): root_first is the root's first record in the record pool.
    bool paged = (g.flags & GDR_FRAME_PAGED_RECORDS) != 0u;
    uint base = paged ? 0u : mesh.meshlet_offset;
    if (mesh.root_cluster_count > 0u &&
        gdr_lod_group_projected_error(mesh.root_refined_sphere, mesh.root_refined_error, model[0].xyz, model[1].xyz,
                                      model[2].xyz, model[3].xyz, g.camera_position.xyz, g.lod_znear,
                                      g.lod_projection_scale) <= g.lod_threshold)
        return gdr_task_range(base + mesh.root_first, mesh.root_cluster_count, GDR_TASK_LOD_ACCEPTED);
    uint chained = root_chain_cluster(g, mesh_index, mesh, model);
    if (chained != GDR_GPU_NO_GROUP)
        return gdr_task_range(mesh.meshlet_offset + chained, 1u, GDR_TASK_LOD_ACCEPTED);
    // Where the records live in their pages' slots, every mesh is traversed: a flat range would read
    // records that are not there.
    traverse = (g.flags & GDR_FRAME_LOD_HIERARCHY) != 0u && mesh.lod_node_count > 0u &&
               (mesh.lod_task_count > GDR_TRAVERSE_MIN_TASKS || paged);
    return traverse ? GdrTaskRange(0u, 0u, 0u, 0u) : gdr_task_range(mesh.meshlet_offset, mesh.lod_cluster_count, 0u);
}

// Screen-size culling (seed 002): the bounding sphere's screen size (GdrGpuFrameGlobals) within the
// instance's [min, max) and not below the frame's minimum; a zero limit is no limit.
bool screen_size_visible(GdrGpuFrameGlobals g, GdrGpuInstance instance, vec3 world_center, float radius)
{
    float distance = length(world_center - g.camera_position.xyz);
    float size = distance <= radius ? 3.0e38 : g.screen_scale * radius / distance; // inside: covers the screen
    if (instance.min_screen_size > 0.0 && size < instance.min_screen_size)
        return false;
    if (g.min_screen_size > 0.0 && size < g.min_screen_size)
        return false;
    return !(instance.max_screen_size > 0.0 && size >= instance.max_screen_size);
}

// Precomputed visibility (seed 002): whether the culling camera's cell lists the instance.
bool pvs_listed(uint instance)
{
    uint word = UintsRef(GDR_FRAME.pvs_visible).items[instance >> 5u];
    return (word & (1u << (instance & 31u))) != 0u;
}

// The global clip plane (seed 002): true when the sphere lies entirely on its negative side.
bool behind_clip_plane(GdrGpuFrameGlobals g, vec3 world_center, float radius)
{
    vec4 plane = g.clip_plane;
    return plane.xyz != vec3(0.0) && dot(plane.xyz, world_center) + plane.w < -radius * length(plane.xyz);
}

// The instance this invocation culls: the early (or only) phase's, one per instance; the late
// phase's, one per instance the early phase deferred.
uint instance_of_invocation(GdrGpuFrameGlobals g, DrawStatsRef stats)
{
    uint id = gl_GlobalInvocationID.x;
    if (PHASE != GDR_PHASE_LATE)
        return id;
    return id < stats.value.late_instances.count ? WritableUintsRef(GDR_FRAME.occluded_instances).items[id]
                                                 : g.instance_count;
}

// The clusters of a visible instance that needs at most GDR_DIRECT_CLUSTERS (`direct`): the cluster
// cull's tests and binning, here. The early phase defers those behind last frame's pyramid with a
// retest command (drawn now where the late region is full). Uniform control flow.
void cull_direct_clusters(GdrGpuFrameGlobals g, bool direct, uint instance, GdrTaskRange range)
{
    GdrGpuTaskCommand task = GdrGpuTaskCommand(instance, range.first, direct ? range.count : 0u, range.flags | GDR_TASK_FIRST);
    uint deferred = 0u;
    for (uint c = 0u; c < GDR_DIRECT_CLUSTERS; c++) {
        GdrClusterResult cluster = gdr_cluster_test_command(g, PHASE, task, c, true);
        gdr_raster_append(g, cluster.visible, cluster.instance, cluster.meshlet);
        gdr_cluster_count(g, PHASE, cluster);
        if (PHASE == GDR_PHASE_EARLY && cluster.occluded)
            deferred |= 1u << c;
    }
    bool failed = PHASE == GDR_PHASE_EARLY && deferred != 0u && !gdr_defer_clusters(g, task, deferred);
    if (PHASE == GDR_PHASE_EARLY && subgroupBallotBitCount(subgroupBallot(failed)) > 0u)
        for (uint c = 0u; c < GDR_DIRECT_CLUSTERS; c++)
            gdr_raster_append(g, failed && (deferred & (1u << c)) != 0u, instance, range.first + c);
}

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    uint id = instance_of_invocation(g, stats);
    bool visible = false;
    GdrGpuMesh mesh;
    uint mesh_index = 0u;
    mat4 model;
    vec3 world_center = vec3(0.0);
    float radius = 0.0;
    bool invalid = false, pvs_hidden = false, small_or_large = false, clipped = false;
    if (id < g.instance_count) {
        GdrGpuInstance instance = InstancesRef(GDR_SCENE.instances).items[id];
        model = instance.model;
        mesh_index = instance.mesh;
        mesh = MeshesRef(GDR_SCENE.meshes).items[mesh_index];
        world_center = (model * vec4(mesh.bounds.xyz, 1.0)).xyz;
        radius = mesh.bounds.w * gdr_max_axis_scale(model[0].xyz, model[1].xyz, model[2].xyz);
        vec3 center = (g.view * vec4(world_center, 1.0)).xyz;
        // Nothing to draw, or bounds that are not finite or hold no volume (seed 002's first test).
        invalid = mesh.index_count == 0u || !(radius > 0.0) || isinf(radius) || any(isnan(world_center)) ||
                  any(isinf(world_center));
        visible = !invalid;
        if (visible && g.cull_enabled != 0u) {
            visible = gdr_sphere_visible_offset(g.frustum, g.frustum_offset, center, radius, g.znear, g.zfar);
            pvs_hidden = visible && (g.flags & GDR_FRAME_PVS) != 0u && !pvs_listed(id);
            visible = visible && !pvs_hidden;
            small_or_large = visible && !screen_size_visible(g, instance, world_center, radius);
            clipped = visible && !small_or_large && behind_clip_plane(g, world_center, radius);
            visible = visible && !small_or_large && !clipped;
        }
    }
    GDR_COUNT(stats, instances_pvs_culled, pvs_hidden);
    GDR_COUNT(stats, instances_invalid, invalid);
    GDR_COUNT(stats, instances_screen_size_culled, small_or_large);
    GDR_COUNT(stats, instances_clip_plane_culled, clipped);

    // Two-phase occlusion culling (occlusion_test.h): the early phase defers what last frame's
    // pyramid hides; the late phase retests those against this frame's.
    if (PHASE != GDR_PHASE_NONE) {
        bool occluded = visible && gdr_phase_occluded(g, PHASE, world_center, radius);
        if (PHASE == GDR_PHASE_EARLY) {
            gdr_defer_instances(occluded, id);
            GDR_COUNT(stats, instances_early_occluded, occluded);
            GDR_COUNT(stats, instances_early_drawn, visible && !occluded);
        } else {
            GDR_COUNT(stats, instances_late_tested, id < g.instance_count);
            GDR_COUNT(stats, instances_late_occluded, occluded);
            GDR_COUNT(stats, instances_late_drawn, visible && !occluded);
        }
        visible = visible && !occluded;
    }

    // The point level (the visibility buffer's variant): an instance within a pixel is its splat,
    // drawn here; its clusters are not.
    bool point = false;
#ifdef GDR_POINT_SPLATS
    point = visible && (g.flags & GDR_FRAME_POINTS) != 0u &&
            gdr_point_level_passes(mesh.bounds, mesh.point_error, model[0].xyz, model[1].xyz, model[2].xyz,
                                   model[3].xyz, g.camera_position.xyz, g.lod_znear, g.lod_projection_scale,
                                   g.lod_threshold);
    if (point)
        gdr_point_splat(g, id, world_center,
                        mesh.point_radius * gdr_max_axis_scale(model[0].xyz, model[1].xyz, model[2].xyz));
    GDR_COUNT(stats, instances_points, point);
#endif
    bool clusters = visible && !point;

    uvec4 ballot = subgroupBallot(visible);
    uint subgroup_count = subgroupBallotBitCount(ballot);
    // The meshlet pipeline counts the triangles its mesh shader emits instead.
    uint triangles = EMIT_TASKS ? 0u : subgroupAdd(visible ? mesh.index_count / 3u : 0u);
    uint base = 0u;
    if (subgroupElect() && subgroup_count > 0u) {
        if (PHASE == GDR_PHASE_LATE)
            base = atomicAdd(stats.value.late_draw_count, subgroup_count);
        else
            base = atomicAdd(stats.value.draw_count, subgroup_count);
        uint old = atomicAdd(stats.value.triangles_low, triangles);
        if (old + triangles < old)
            atomicAdd(stats.value.triangles_high, 1u);
    }
    base = subgroupBroadcastFirst(base);
    if (EMIT_TASKS) {
        bool traverse = false;
        GdrTaskRange range = clusters ? task_range(g, mesh_index, mesh, model, traverse) : GdrTaskRange(0u, 0u, 0u, 0u);
        bool direct_frame = (g.flags & GDR_FRAME_DIRECT_CLUSTERS) != 0u;
        bool direct = direct_frame && clusters && !traverse && range.count <= GDR_DIRECT_CLUSTERS;
        gdr_append_tasks(g, PHASE, clusters && !direct, id, range);
        gdr_queue_visits(g, PHASE, 0u, traverse && clusters ? 1u : 0u, id, 0u, 0u);
        if (direct_frame)
            cull_direct_clusters(g, direct, id, range);
        // The visible instances, for read-backs (each is drawn in one phase only).
        uvec4 listed_ballot = subgroupBallot(visible);
        uint list_base = 0u;
        if (subgroupElect() && subgroupBallotBitCount(listed_ballot) > 0u)
            list_base = atomicAdd(stats.value.instances_listed, subgroupBallotBitCount(listed_ballot));
        list_base = subgroupBroadcastFirst(list_base) + subgroupBallotExclusiveBitCount(listed_ballot);
        if (visible)
            DrawCommandsRef(GDR_FRAME.draws).items[list_base] = GdrGpuDrawCommand(0u, 0u, 0u, 0, id);
    } else if (visible) {
        // The late phase's draws follow the early phase's region (instance_count entries).
        uint slot = base + subgroupBallotExclusiveBitCount(ballot) + (PHASE == GDR_PHASE_LATE ? g.instance_count : 0u);
        DrawCommandsRef(GDR_FRAME.draws).items[slot] =
            GdrGpuDrawCommand(mesh.index_count, 1u, mesh.first_index, int(mesh.vertex_offset), id);
    }
}
