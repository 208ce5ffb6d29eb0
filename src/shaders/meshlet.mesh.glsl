#version 460
// Draws one cluster per workgroup (seed 004): vertices transformed once, then per triangle the
// back-face test and the "covers no sample" test (seed 000) mark triangles culled before raster.
// Both tests are conservative against the rasteriser: a triangle is culled only when its 8-bit
// sub-pixel snapped form (Vulkan's minimum precision) could not produce a fragment either.
// Two variants (src/shaders/CMakeLists.txt): the forward one draws the clusters its task workgroup
// hands over in the payload; the visibility-buffer one (GDR_MESH_FROM_LIST) is launched
// without a task shader, one workgroup per mesh-shader entry that clustercull.comp appended to the
// frame's visible-cluster list, and its fragments write the visibility buffer.
#extension GL_EXT_mesh_shader : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_EXT_nonuniform_qualifier : require

#include "gpu_shared/glsl_buffers.h"
#include "gpu_shared/material.h"
#include "gpu_shared/material_flags.h"
#include "gpu_shared/meshlet_payload.h"
#include "gpu_shared/shading.h"
#include "gpu_shared/visbuffer.h"

layout(local_size_x = GDR_MESH_WORKGROUP_SIZE) in;
layout(triangles, max_vertices = GDR_MESH_MAX_VERTICES, max_primitives = GDR_MESH_MAX_TRIANGLES) out;

#ifndef GDR_MESH_FROM_LIST
taskPayloadSharedEXT GdrTaskPayload payload;
#endif

// Only the built-ins used: the implicit blocks would also declare the shading-rate built-in, whose
// capability the device does not enable.
out gl_MeshPerVertexEXT { vec4 gl_Position; } gl_MeshVerticesEXT[];
out gl_MeshPerPrimitiveEXT { perprimitiveEXT bool gl_CullPrimitiveEXT; } gl_MeshPrimitivesEXT[];

layout(location = 0) out vec3 out_normal[];
layout(location = 1) out vec3 out_world_position[];
layout(location = 2) perprimitiveEXT flat out vec4 out_color[];
layout(location = 4) out vec2 out_uv[];
layout(location = 5) perprimitiveEXT flat out uint out_material[];
layout(location = 6) out vec4 out_vertex_color[];
#ifdef GDR_MESH_FROM_LIST
layout(location = 3) perprimitiveEXT flat out uint out_visibility_id[]; // list slot and triangle
#endif

shared vec3 screen[GDR_MESH_MAX_VERTICES]; // pixels (y up) and clip w

UintsRef triangle_bytes; // read once per invocation

uint triangle_byte(uint at)
{
    return (triangle_bytes.items[at >> 2] >> ((at & 3u) * 8u)) & 255u;
}

// Non-zero when the triangle surely produces no fragment: 1 when back-facing beyond the snapping
// error, 2 when its bounding box (grown by the snapping error) holds no pixel centre. Only for
// triangles wholly in front of the camera; others are left to the clipper.
uint triangle_culled(vec3 a, vec3 b, vec3 c)
{
    if (a.z <= 0.0 || b.z <= 0.0 || c.z <= 0.0)
        return 0u;
    const float snap = 1.0 / 256.0;
    vec2 ab = b.xy - a.xy, ac = c.xy - a.xy;
    float area = ab.x * ac.y - ab.y * ac.x; // counter-clockwise (front, y up) is positive
    float perimeter = length(ab) + length(ac) + length(c.xy - b.xy);
    if (area < -2.0 * snap * perimeter)
        return 1u;
    vec2 lo = min(a.xy, min(b.xy, c.xy)) - snap, hi = max(a.xy, max(b.xy, c.xy)) + snap;
    // Pixel centres sit at k + 0.5; none in [lo, hi] on some axis means no sample is covered.
    return any(lessThan(floor(hi - 0.5), ceil(lo - 0.5))) ? 2u : 0u;
}

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    uint lane = gl_LocalInvocationIndex;
    // The scene's references at once, before the loads that depend on them.
    MeshletsRef meshlets = GDR_SCENE.meshlets;
    InstancesRef instances = GDR_SCENE.instances;
    UintsRef vertex_refs = GDR_SCENE.meshlet_vertices;
    VerticesRef vertices = GDR_SCENE.vertices;
    triangle_bytes = GDR_SCENE.meshlet_triangles;
#ifdef GDR_MESH_FROM_LIST
    // This launch's entries: [hw_first, hw_first + hw_count) (raster_submit.comp), in rows.
    RasterParamsRef raster = GDR_FRAME.raster;
    RasterCountersRef counters = RasterCountersRef(raster.value.counters);
    uint launched = gl_WorkGroupID.x + gl_WorkGroupID.y * GDR_MESH_GROUPS_PER_ROW;
    if (launched >= counters.value.hw_count) {
        SetMeshOutputsEXT(0u, 0u); // the tail of the last row
        return;
    }
    uint slot = counters.value.hw_first + launched;
    GdrGpuRasterCluster entry = RasterClustersRef(raster.value.clusters).items[slot];
    uint instance_index = entry.instance, meshlet_index = entry.meshlet;
#else
    uint instance_index = payload.instance, meshlet_index = payload.meshlets[gl_WorkGroupID.x];
#endif
    GdrGpuMeshlet meshlet = meshlets.items[meshlet_index];
    GdrGpuInstance instance = instances.items[instance_index];
    SetMeshOutputsEXT(meshlet.vertex_count, meshlet.triangle_count);

    mat3 m = mat3(instance.model);
    mat3 cofactor = mat3(cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1]));
    for (uint v = lane; v < meshlet.vertex_count; v += GDR_MESH_WORKGROUP_SIZE) {
        uint vertex_index = vertex_refs.items[meshlet.vertex_offset + v];
        GdrGpuVertex vertex = vertices.items[vertex_index];
        vec4 world = instance.model * vec4(vertex.position, 1.0);
        vec4 clip = g.view_projection * world;
        gl_MeshVerticesEXT[v].gl_Position = clip;
        out_normal[v] = cofactor * vertex.normal;
        out_world_position[v] = world.xyz;
        out_uv[v] = vertex.uv;
#ifdef GDR_MESH_FROM_LIST
        // The visibility buffer's fragments need the attributes only to alpha-test.
        if ((g.flags & GDR_FRAME_ALPHA_TEST) != 0u)
#endif
            out_vertex_color[v] = gdr_vertex_color(g.flags, instance.mesh, vertex_index);
        vec2 ndc = clip.xy / clip.w;
        screen[v] = vec3((ndc * 0.5 + 0.5) * g.viewport, clip.w);
    }
    barrier();

    bool cull = g.cull_enabled != 0u && (g.flags & GDR_FRAME_TRIANGLE_CULL) != 0u;
    bool double_sided = gdr_material_double_sided(g.flags, instance.material);
    uint emitted = 0u, backfacing = 0u, small = 0u;
    for (uint t = lane; t < meshlet.triangle_count; t += GDR_MESH_WORKGROUP_SIZE) {
        uint at = meshlet.triangle_offset + t * 3u;
        uvec3 corners = uvec3(triangle_byte(at), triangle_byte(at + 1u), triangle_byte(at + 2u));
        gl_PrimitiveTriangleIndicesEXT[t] = corners;
        uint why = cull ? triangle_culled(screen[corners.x], screen[corners.y], screen[corners.z]) : 0u;
        why = why == 1u && double_sided ? 0u : why;
        gl_MeshPrimitivesEXT[t].gl_CullPrimitiveEXT = why != 0u;
        out_color[t] = vec4(gdr_view_albedo(g.view_mode, instance.color.rgb, instance_index, meshlet.cluster_id, t,
                                            meshlet.group_depth), 1.0);
        out_material[t] = instance.material;
#ifdef GDR_MESH_FROM_LIST
        out_visibility_id[t] = gdr_visbuffer_id(slot, t);
#endif
        emitted += why == 0u ? 1u : 0u;
        backfacing += why == 1u ? 1u : 0u;
        small += why == 2u ? 1u : 0u;
    }
    uint total_emitted = subgroupAdd(emitted);
    uint total_backfacing = subgroupAdd(backfacing);
    uint total_small = subgroupAdd(small);
    if (subgroupElect()) {
        DrawStatsRef stats = DrawStatsRef(GDR_FRAME.draw_stats);
        uint old = atomicAdd(stats.value.triangles_low, total_emitted);
        if (old + total_emitted < old)
            atomicAdd(stats.value.triangles_high, 1u);
        if (total_backfacing > 0u)
            atomicAdd(stats.value.triangles_backface_culled, total_backfacing);
        if (total_small > 0u)
            atomicAdd(stats.value.triangles_small_culled, total_small);
    }
}
