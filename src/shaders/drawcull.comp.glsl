#version 460
// Instance culling (seeds 000/001/003): one thread per instance; visible instances are appended,
// compacted with subgroup ballots, as VkDrawIndexedIndirectCommands for one
// vkCmdDrawIndexedIndirectCount. first_instance carries the instance index to the vertex shader.
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "shared/glsl_buffers.h"
#include "shared/cull_math.h"

layout(local_size_x = GDR_CULL_WORKGROUP_SIZE) in;

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    uint id = gl_GlobalInvocationID.x;
    bool visible = false;
    GdrGpuMesh mesh;
    if (id < g.instance_count) {
        mat4 model = InstancesRef(push.instances).items[id].model;
        mesh = MeshesRef(push.meshes).items[InstancesRef(push.instances).items[id].mesh];
        visible = true;
        if (g.cull_enabled != 0u) {
            vec3 center = (g.view * (model * vec4(mesh.bounds.xyz, 1.0))).xyz;
            float radius = mesh.bounds.w * gdr_max_axis_scale(model[0].xyz, model[1].xyz, model[2].xyz);
            visible = gdr_sphere_visible(g.frustum, center, radius, g.znear, g.zfar);
        }
    }

    DrawStatsRef stats = DrawStatsRef(push.draw_stats);
    uvec4 ballot = subgroupBallot(visible);
    uint subgroup_count = subgroupBallotBitCount(ballot);
    uint triangles = subgroupAdd(visible ? mesh.index_count / 3u : 0u);
    uint base = 0u;
    if (subgroupElect() && subgroup_count > 0u) {
        base = atomicAdd(stats.value.draw_count, subgroup_count);
        uint old = atomicAdd(stats.value.triangles_low, triangles);
        if (old + triangles < old)
            atomicAdd(stats.value.triangles_high, 1u);
    }
    base = subgroupBroadcastFirst(base);
    if (visible) {
        uint slot = base + subgroupBallotExclusiveBitCount(ballot);
        DrawCommandsRef(push.draws).items[slot] =
            GdrGpuDrawCommand(mesh.index_count, 1u, mesh.first_index, int(mesh.vertex_offset), id);
    }
}
