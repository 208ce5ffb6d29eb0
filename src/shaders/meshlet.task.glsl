#version 460
// Meshlet culling (seeds 000/001/004): one task workgroup per task command (up to
// GDR_TASK_WORKGROUP_SIZE clusters of one visible instance), one thread per cluster: the LOD cut
// (issue 5: is the cluster part of the cut this view needs?), then the cluster's sphere against the
// frustum (the instance test's math), then its normal cone against the camera.
// Survivors are compacted into the payload with subgroup ballots; one mesh workgroup each.
#extension GL_EXT_mesh_shader : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "shared/glsl_buffers.h"
#include "shared/cull_math.h"
#include "shared/lod_math.h"
#include "shared/occlusion_test.h"
#include "shared/meshlet_payload.h"
#include "shared/raster_bin.h"

layout(local_size_x = GDR_TASK_WORKGROUP_SIZE) in;
// Occlusion culling phase (issue 6): none, or the early / late phase of the two-phase scheme.
layout(constant_id = 0) const uint PHASE = 0u;
#define PHASE_EARLY 1u
#define PHASE_LATE 2u

taskPayloadSharedEXT GdrTaskPayload payload;
layout(buffer_reference, scalar) writeonly buffer VisibleMeshletsRef { uvec2 items[]; };
shared uint visible_count;

// passes(group) of the cut rule (gdr/geometry.h): projected error within the threshold, or for the
// discrete debug cut, depth below N and not the root. Without a group the fields make "refined"
// always pass (error 0, depth -1) and "group" never (error INFINITY).
bool lod_passes(GdrGpuFrameGlobals g, vec4 sphere, float error, int depth, mat4 model)
{
    if ((g.flags & GDR_FRAME_LOD_DEPTH) != 0u)
        return depth < g.lod_depth && !isinf(error);
    return gdr_lod_group_projected_error(sphere, error, model[0].xyz, model[1].xyz, model[2].xyz, model[3].xyz,
                                         g.camera_position.xyz, g.znear, g.lod_projection_scale) <= g.lod_threshold;
}

// Two-phase occlusion culling of one cluster that passed the other tests (`candidate`), with one
// visibility bit per cluster of every instance. Early: draw it if it was visible at the end of the
// last frame. Late: test it against this frame's pyramid, record the result for the next frame and
// draw it if visible and not drawn early. (Clusters are not tested against last frame's pyramid in
// the early phase: the late phase could then not tell which ones the early phase drew.)
bool occlusion_phase(GdrGpuFrameGlobals g, GdrGpuInstance instance, GdrGpuTaskCommand task, uint lane, bool candidate,
                     vec3 center, float radius, out bool occluded)
{
    uint mesh_first = MeshesRef(push.meshes).items[instance.mesh].meshlet_offset;
    uint bit = instance.meshlet_visibility_offset + (task.meshlet_first + lane - mesh_first);
    VisibilityRef bits = VisibilityRef(g.meshlet_visibility);
    bool was_visible = (bits.items[bit >> 5] & (1u << (bit & 31u))) != 0u;
    occluded = false;
    if (PHASE == PHASE_EARLY)
        return candidate && was_visible;
    occluded = candidate && gdr_sphere_occluded(g, center, radius);
    bool visible = candidate && !occluded;
    if (visible != was_visible) {
        if (visible)
            atomicOr(bits.items[bit >> 5], 1u << (bit & 31u));
        else
            atomicAnd(bits.items[bit >> 5], ~(1u << (bit & 31u)));
    }
    bool drawn_early = (task.flags & GDR_TASK_DRAWN_EARLY) != 0u && was_visible && candidate;
    return visible && !drawn_early;
}

// Clusters and triangles drawn per DAG depth: one atomic per distinct depth in the subgroup.
void count_lod_depths(DrawStatsRef stats, bool visible, int depth, uint triangles)
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

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    DrawStatsRef stats = DrawStatsRef(push.draw_stats);
    uint task_index = gl_WorkGroupID.x + gl_WorkGroupID.y * GDR_TASK_GROUPS_PER_ROW;
    uint task_count = min(PHASE == PHASE_LATE ? stats.value.late_task_count : stats.value.task_count, g.task_capacity);
    uint lane = gl_LocalInvocationIndex;
    if (lane == 0u)
        visible_count = 0u;

    bool in_task = false, visible = false, lod_culled = false, frustum_culled = false, cone_culled = false;
    bool late_tested = false, occluded = false;
    int depth = 0;
    uint triangles = 0u;
    GdrGpuTaskCommand task = GdrGpuTaskCommand(0u, 0u, 0u, 0u);
    if (task_index < task_count) {
        // The late phase's commands follow the early phase's region (drawcull.comp).
        task = TaskCommandsRef(push.tasks + (PHASE == PHASE_LATE ? uint64_t(g.task_capacity) * 16ul : 0ul)).items[task_index];
        in_task = lane < task.meshlet_count;
    }
    if (in_task) {
        GdrGpuMeshlet meshlet = MeshletsRef(push.meshlets).items[task.meshlet_first + lane];
        GdrGpuInstance instance = InstancesRef(push.instances).items[task.instance];
        mat4 model = instance.model;
        vec3 center = (g.view * (model * vec4(meshlet.sphere.xyz, 1.0))).xyz;
        float radius = meshlet.sphere.w * gdr_max_axis_scale(model[0].xyz, model[1].xyz, model[2].xyz);
        depth = meshlet.group_depth;
        triangles = meshlet.triangle_count;
        visible = true;
        if ((g.flags & GDR_FRAME_LOD) != 0u && (task.flags & GDR_TASK_LOD_ACCEPTED) == 0u) {
            visible = lod_passes(g, meshlet.refined_sphere, meshlet.refined_error, meshlet.refined_depth, model) &&
                      !lod_passes(g, meshlet.group_sphere, meshlet.group_error, meshlet.group_depth, model);
            lod_culled = !visible;
        }
        bool cull = g.cull_enabled != 0u;
        if (visible && cull && (g.flags & GDR_FRAME_MESHLET_FRUSTUM) != 0u) {
            visible = gdr_sphere_visible(g.frustum, center, radius, g.znear, g.zfar);
            frustum_culled = !visible;
        }
        mat3 linear = mat3(model);
        if (visible && cull && (g.flags & GDR_FRAME_MESHLET_CONE) != 0u && determinant(linear) > 0.0) {
            vec3 camera = inverse(linear) * (g.camera_position.xyz - model[3].xyz);
            cone_culled = gdr_cone_backfacing(meshlet.cone_apex, meshlet.cone_axis, meshlet.cone_cutoff, camera);
            visible = !cone_culled;
        }
        late_tested = PHASE == PHASE_LATE && visible;
        if (PHASE != 0u)
            visible = occlusion_phase(g, instance, task, lane, visible, center, radius, occluded);
    }
    barrier();

    bool sw = gdr_raster_bin(g, visible, task.instance, task.meshlet_first + lane); // issue 8: compute raster
    uvec4 ballot = subgroupBallot(visible && !sw);
    uint base = 0u;
    if (subgroupElect())
        base = atomicAdd(visible_count, subgroupBallotBitCount(ballot));
    base = subgroupBroadcastFirst(base);
    if (visible && !sw)
        payload.meshlets[base + subgroupBallotExclusiveBitCount(ballot)] = task.meshlet_first + lane;
    if (lane == 0u)
        payload.instance = task.instance;
    if ((g.flags & GDR_FRAME_RECORD_MESHLETS) != 0u && visible) {
        uint at = atomicAdd(stats.value.meshlets_recorded, 1u);
        VisibleMeshletsRef(push.visible_meshlets).items[at] = uvec2(task.instance, task.meshlet_first + lane);
    }

    count_lod_depths(stats, visible, depth, triangles);
    if (PHASE == PHASE_EARLY) {
        uint n = subgroupAdd(visible ? 1u : 0u);
        if (subgroupElect() && n > 0u)
            atomicAdd(stats.value.meshlets_early_drawn, n);
    } else if (PHASE == PHASE_LATE) {
        uint n = subgroupAdd(visible ? 1u : 0u);
        uint t = subgroupAdd(late_tested ? 1u : 0u);
        uint o = subgroupAdd(occluded ? 1u : 0u);
        if (subgroupElect() && t > 0u) {
            atomicAdd(stats.value.meshlets_late_drawn, n);
            atomicAdd(stats.value.meshlets_late_tested, t);
            atomicAdd(stats.value.meshlets_late_occluded, o);
        }
    }
    uint tested = subgroupAdd(in_task ? 1u : 0u);
    uint lod = subgroupAdd(lod_culled ? 1u : 0u);
    uint frustum = subgroupAdd(frustum_culled ? 1u : 0u);
    uint cone = subgroupAdd(cone_culled ? 1u : 0u);
    uint drawn = subgroupAdd(visible ? 1u : 0u);
    if (subgroupElect() && tested > 0u) {
        atomicAdd(stats.value.meshlets_tested, tested);
        atomicAdd(stats.value.meshlets_frustum_culled, frustum);
        atomicAdd(stats.value.meshlets_cone_culled, cone);
        atomicAdd(stats.value.meshlets_visible, drawn);
        if (lod > 0u)
            atomicAdd(stats.value.meshlets_lod_culled, lod);
    }
    barrier();
    if (lane == 0u) // issue 8: the mesh-shader clusters' entries in the visible-cluster list
        payload.raster_first = gdr_raster_reserve_hw(visible_count);
    barrier();
    EmitMeshTasksEXT(visible_count, 1u, 1u);
}
