/* GLSL only: the per-cluster tests of the mesh pipeline, shared by the task shader (forward raster)
 * and the cluster-cull compute pass (visibility-buffer raster). One invocation per cluster
 * of a task command (up to GDR_TASK_WORKGROUP_SIZE clusters of one visible instance):
 *  - the LOD cut: is the cluster part of the cut this view needs?
 *  - its sphere against the frustum (the instance test's math), then its normal cone against the
 *    camera;
 *  - two-phase occlusion culling (occlusion_test.h; the early phase's hidden clusters are retested in
 *    the late phase through retest commands).
 * Include after glsl_buffers.h, cull_math.h, lod_math.h, occlusion_test.h and meshlet_payload.h. */
#ifndef GDR_CLUSTER_CULL_H
#define GDR_CLUSTER_CULL_H

#include "gpu_shared/task_queue.h" // the occlusion culling phases
#include "gpu_shared/material_flags.h"
#include "gpu_shared/residency.h"


// What the tests decided for one invocation's cluster.
struct GdrClusterResult {
    bool in_task;        // the invocation has a cluster
    bool visible;        // draw it
    bool lod_culled, frustum_culled, cone_culled;
    bool late_tested;    // late phase: passed the other tests, so tested against the pyramid
    bool occluded;       // behind the phase's pyramid: early, deferred; late, culled
    uint instance;
    uint meshlet;        // global GdrGpuMeshlet index
    uint flags;          // the task command's GDR_TASK_* flags
    int depth;           // DAG depth of the cluster's group
    uint triangles;
};

// passes(group) of the cut rule (gdr/geometry.h): projected error within the threshold, or for the
// discrete debug cut, depth below N and not the root. Without a group the fields make "refined"
// always pass (error 0, depth -1) and "group" never (error INFINITY).
bool gdr_lod_passes(GdrGpuFrameGlobals g, vec4 sphere, float error, int depth, mat4 model)
{
    if ((g.flags & GDR_FRAME_LOD_DEPTH) != 0u)
        return depth < g.lod_depth && !isinf(error);
    return gdr_lod_group_projected_error(sphere, error, model[0].xyz, model[1].xyz, model[2].xyz, model[3].xyz,
                                         g.camera_position.xyz, g.lod_znear, g.lod_projection_scale) <= g.lod_threshold;
}

// The task commands of `phase`'s region of the task list: the late phase's follow the early
// phase's task_capacity entries (drawcull.comp). A macro: a function returning a reference makes
// glslang emit a pointer variable without the aliasing decoration that SPIR-V requires.
#define gdr_task_region(g, phase)                                                                          \
    TaskCommandsRef(uint64_t(GDR_FRAME.tasks) + ((phase) == GDR_PHASE_LATE ? uint64_t((g).task_capacity) * 16ul : 0ul))

// Early phase: a late task command that retests the clusters of `task` in `mask` (bit i: cluster
// meshlet_first + i), those behind last frame's pyramid. False when the late region is full: the
// caller then draws them now (counted as overflow), so nothing is lost.
bool gdr_defer_clusters(GdrGpuFrameGlobals g, GdrGpuTaskCommand task, uint mask)
{
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    uint slot = atomicAdd(stats.value.late_task_count, 1u);
    if (slot >= g.task_capacity) {
        atomicAdd(stats.value.occluded_overflow, bitCount(mask));
        return false;
    }
    uint flags = (task.flags & ~GDR_TASK_FIRST) | GDR_TASK_RETEST;
    gdr_task_region(g, GDR_PHASE_LATE).items[slot] = GdrGpuTaskCommand(task.instance, task.meshlet_first, task.meshlet_count, flags);
    WritableUintsRef(GDR_FRAME.retest_masks).items[slot] = mask;
    return true;
}

// The clusters of task command `task_index` of `phase`'s region of the task list (0 past its end).
uint gdr_cluster_task_size(GdrGpuFrameGlobals g, uint phase, uint task_index)
{
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    uint task_count = min(phase == GDR_PHASE_LATE ? stats.value.late_task_count : stats.value.task_count,
                          g.task_capacity);
    if (task_index >= task_count)
        return 0u;
    return gdr_task_region(g, phase).items[task_index].meshlet_count;
}

GdrClusterResult gdr_cluster_no_result()
{
    return GdrClusterResult(false, false, false, false, false, false, false, 0u, 0u, 0u, 0, 0u);
}

// The tests for cluster `lane` of command `task` (when `tested`: a retest command's clusters that
// the early phase did not defer are not). A retest command's clusters passed the other tests in the
// early phase (same camera), so only the occlusion test against this frame's pyramid is left.
GdrClusterResult gdr_cluster_test_command(GdrGpuFrameGlobals g, uint phase, GdrGpuTaskCommand task, uint lane,
                                          bool tested)
{
    GdrClusterResult result = gdr_cluster_no_result();
    result.instance = task.instance;
    result.flags = task.flags;
    result.meshlet = task.meshlet_first + lane;
    if (lane >= task.meshlet_count || !tested)
        return result;
    bool retest = phase == GDR_PHASE_LATE && (task.flags & GDR_TASK_RETEST) != 0u;
    result.in_task = true;

    GdrGpuMeshlet meshlet = MeshletsRef(GDR_SCENE.meshlets).items[result.meshlet];
    GdrGpuInstance instance = InstancesRef(GDR_SCENE.instances).items[task.instance];
    mat4 model = instance.model;
    vec3 world_center = (model * vec4(meshlet.sphere.xyz, 1.0)).xyz;
    vec3 center = (g.view * vec4(world_center, 1.0)).xyz;
    float radius = meshlet.sphere.w * gdr_max_axis_scale(model[0].xyz, model[1].xyz, model[2].xyz);
    result.depth = meshlet.group_depth;
    result.triangles = meshlet.triangle_count;
    bool visible = true;
    if (!retest && (g.flags & GDR_FRAME_LOD) != 0u && (task.flags & GDR_TASK_LOD_ACCEPTED) == 0u) {
        // passes' (shared/residency.h): an absent group counts as passing; drawn in the place of an
        // absent refined group that does not pass, the cluster asks for that group.
        bool refined_absent = gdr_group_absent(g, instance.mesh, meshlet.refined_group);
        bool refined_passes =
            gdr_lod_passes(g, meshlet.refined_sphere, meshlet.refined_error, meshlet.refined_depth, model);
        visible = (refined_absent || refined_passes) &&
                  !(gdr_group_absent(g, instance.mesh, meshlet.group) ||
                    gdr_lod_passes(g, meshlet.group_sphere, meshlet.group_error, meshlet.group_depth, model));
        if (visible && refined_absent && !refined_passes)
            gdr_request_group(g, task.instance, instance.mesh, meshlet.refined_group, meshlet.refined_sphere,
                              meshlet.refined_error, model);
        if (visible)
            gdr_mark_group_used(g, instance.mesh, meshlet.group);
        result.lod_culled = !visible;
    }
    bool cull = g.cull_enabled != 0u;
    if (!retest && visible && cull && (g.flags & GDR_FRAME_MESHLET_FRUSTUM) != 0u) {
        visible = gdr_sphere_visible_offset(g.frustum, g.frustum_offset, center, radius, g.znear, g.zfar);
        result.frustum_culled = !visible;
    }
    mat3 linear = mat3(model);
    if (!retest && visible && cull && (g.flags & GDR_FRAME_MESHLET_CONE) != 0u && determinant(linear) > 0.0 &&
        !gdr_material_double_sided(g.flags, instance.material)) {
        vec3 camera = inverse(linear) * (g.camera_position.xyz - model[3].xyz);
        result.cone_culled = gdr_cone_backfacing(meshlet.cone_apex, meshlet.cone_axis, meshlet.cone_cutoff, camera);
        visible = !result.cone_culled;
    }
    result.late_tested = phase == GDR_PHASE_LATE && visible;
    // Occlusion (occlusion_test.h): early, hidden behind last frame's pyramid means deferred to the
    // late phase (the caller appends a retest command); late, behind this frame's, culled.
    result.occluded = visible && gdr_phase_occluded(g, phase, world_center, radius);
    result.visible = visible && !result.occluded;
    return result;
}

// The tests for cluster `lane` of task command `task_index` of `phase`'s region of the task list.
GdrClusterResult gdr_cluster_test(GdrGpuFrameGlobals g, uint phase, uint task_index, uint lane)
{
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    uint task_count = min(phase == GDR_PHASE_LATE ? stats.value.late_task_count : stats.value.task_count,
                          g.task_capacity);
    if (task_index >= task_count)
        return gdr_cluster_no_result();
    GdrGpuTaskCommand task = gdr_task_region(g, phase).items[task_index];
    bool retest = phase == GDR_PHASE_LATE && (task.flags & GDR_TASK_RETEST) != 0u;
    bool deferred = retest && lane < 32u &&
                    (WritableUintsRef(GDR_FRAME.retest_masks).items[task_index] & (1u << lane)) != 0u;
    return gdr_cluster_test_command(g, phase, task, lane, !retest || deferred);
}

// Clusters and triangles drawn per DAG depth: one atomic per distinct depth in the subgroup.
void gdr_count_lod_depths(DrawStatsRef stats, bool visible, int depth, uint triangles)
{
    uint bucket = uint(clamp(depth, 0, GDR_LOD_STATS_DEPTHS - 1));
    bool pending = visible;
    for (;;) {
        uint current = subgroupMin(pending ? bucket : 0xffffffffu);
        if (current == 0xffffffffu)
            break;
        bool mine = pending && bucket == current;
        uint clusters = subgroupAdd(mine ? 1u : 0u);
        uint tris = subgroupAdd(mine ? triangles : 0u);
        if (subgroupElect()) {
            atomicAdd(stats.value.lod_clusters[current], clusters);
            atomicAdd(stats.value.lod_triangles[current], tris);
        }
        pending = pending && !mine;
    }
}

// Every invocation, in uniform control flow: the frame's statistics of the tests (one atomic per
// counter and subgroup), and for tests the visible clusters' list when the frame asks for it.
void gdr_cluster_count(GdrGpuFrameGlobals g, uint phase, GdrClusterResult r)
{
    DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
    if ((g.flags & GDR_FRAME_RECORD_MESHLETS) != 0u && r.visible) {
        uint at = atomicAdd(stats.value.meshlets_recorded, 1u);
        VisibleMeshletsRef(GDR_FRAME.visible_meshlets).items[at] = uvec2(r.instance, r.meshlet);
    }
    gdr_count_lod_depths(stats, r.visible, r.depth, r.triangles);
    if (phase == GDR_PHASE_EARLY) {
        GDR_COUNT(stats, meshlets_early_drawn, r.visible);
        GDR_COUNT(stats, meshlets_early_occluded, r.occluded);
    } else if (phase == GDR_PHASE_LATE) {
        uint n = subgroupAdd(r.visible ? 1u : 0u);
        uint t = subgroupAdd(r.late_tested ? 1u : 0u);
        uint o = subgroupAdd(r.occluded ? 1u : 0u);
        if (subgroupElect() && t > 0u) {
            atomicAdd(stats.value.meshlets_late_drawn, n);
            atomicAdd(stats.value.meshlets_late_tested, t);
            atomicAdd(stats.value.meshlets_late_occluded, o);
        }
    }
    uint tested = subgroupAdd(r.in_task ? 1u : 0u);
    uint lod = subgroupAdd(r.lod_culled ? 1u : 0u);
    uint frustum = subgroupAdd(r.frustum_culled ? 1u : 0u);
    uint cone = subgroupAdd(r.cone_culled ? 1u : 0u);
    uint drawn = subgroupAdd(r.visible ? 1u : 0u);
    if (subgroupElect() && tested > 0u) {
        atomicAdd(stats.value.meshlets_tested, tested);
        atomicAdd(stats.value.meshlets_frustum_culled, frustum);
        atomicAdd(stats.value.meshlets_cone_culled, cone);
        atomicAdd(stats.value.meshlets_visible, drawn);
        if (lod > 0u)
            atomicAdd(stats.value.meshlets_lod_culled, lod);
    }
}

#endif
