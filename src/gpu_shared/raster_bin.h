/* Hybrid rasterisation: which rasteriser draws a visible cluster. The decision is shared
 * by C (tests, tools) and GLSL; the cluster cull's appends to the frame's visible-cluster list are
 * GLSL only (below). */
#ifndef GDR_RASTER_BIN_H
#define GDR_RASTER_BIN_H

#include "math/glsl_c_bridge.h"
#include "gpu_shared/gpu_types.h"

/* The compute rasteriser takes clusters whose projection stays within this many NDC units of the
 * centre (the viewport is [-1, 1]): fixed-point coordinates stay far from overflow. */
#define GDR_SW_GUARD_NDC 4.0f

/* Size on screen, in pixels, of the triangles of a cluster of `triangle_count` triangles whose
 * bounding sphere has view-space centre c (in front of the camera) and radius r: the sphere's
 * projected diameter over sqrt(triangle_count). For a flat patch of a regular grid seen face on,
 * that is the length of a triangle's leg. pixel_scale: P[1][1] * viewport height / 2. */
GDR_SHARED_FN float gdr_raster_triangle_px(gdr_vec3 c, float r, float triangle_count, float pixel_scale)
{
    return 2.0f * r * pixel_scale / (-c.z * gdr_sqrt(gdr_max(triangle_count, 1.0f)));
}

/* Whether the compute rasteriser can take a cluster at all. It does not clip, so the sphere must
 * lie wholly between the near and far planes (with a 1% margin for the rounding of the sphere's
 * transform), and its projection within the guard band. ndc_scale: P[0][0] and P[1][1]. */
GDR_SHARED_FN bool gdr_raster_sw_can_take(gdr_vec3 c, float r, float znear, float zfar, gdr_vec2 ndc_scale)
{
    float nearest = -c.z - r;
    if (!(nearest > 1.01f * znear) || !(-c.z + r < 0.99f * zfar))
        return false;
    float x = ndc_scale.x * (gdr_abs(c.x) + r) / nearest;
    float y = ndc_scale.y * (gdr_abs(c.y) + r) / nearest;
    return x <= GDR_SW_GUARD_NDC && y <= GDR_SW_GUARD_NDC;
}

/* True when a visible cluster goes to the compute rasteriser under `mode` (GDR_GPU_RASTER_*):
 * SW takes every cluster it can; HYBRID those whose triangles are smaller than threshold_px. */
GDR_SHARED_FN bool gdr_raster_bin_sw(gdr_uint mode, float threshold_px, gdr_vec3 c, float r, float triangle_count,
                                     float znear, float zfar, gdr_vec2 ndc_scale, float viewport_height)
{
    if (mode != GDR_GPU_RASTER_SW && mode != GDR_GPU_RASTER_HYBRID)
        return false;
    if (!gdr_raster_sw_can_take(c, r, znear, zfar, ndc_scale))
        return false;
    return mode == GDR_GPU_RASTER_SW ||
           gdr_raster_triangle_px(c, r, triangle_count, ndc_scale.y * 0.5f * viewport_height) < threshold_px;
}

/* The tiny size class of a cluster of these sizes (GDR_SW_TINY_*): the smallest whose clusters are no
 * larger, or GDR_SW_TINY_CLASSES for a cluster of a workgroup of its own. */
GDR_SHARED_FN gdr_uint gdr_raster_tiny_class(gdr_uint vertex_count, gdr_uint triangle_count)
{
    gdr_uint size = vertex_count > triangle_count ? vertex_count : triangle_count;
    gdr_uint k = 0u;
    while (k < GDR_SW_TINY_CLASSES && size > (GDR_SW_TINY_LANES << k))
        k++;
    return k;
}

#ifdef GDR_GLSL
#include "gpu_shared/material_flags.h"
#include "gpu_shared/visbuffer.h"

/* The cluster cull (clustercull.comp), every invocation in uniform control flow, after the tests:
 * bins the invocation's cluster when visible and appends it to the frame's visible-cluster list,
 * compute-rasterised clusters at the front, mesh-shader clusters at the back and tiny
 * compute-rasterised clusters in the part of their size class after both (one atomic per part and
 * subgroup; the tiny clusters beyond their part's end join the front). Entries that do not fit are
 * dropped and counted. Needs MeshletsRef and InstancesRef (meshlet_payload.h, glsl_buffers.h). */
void gdr_raster_append(GdrGpuFrameGlobals g, bool visible, uint instance, uint meshlet_index)
{
    RasterParamsRef params = GDR_FRAME.raster;
    bool sw = false;
    uint triangles = 0u, tiny_class = GDR_SW_TINY_CLASSES;
    if (visible) {
        GdrGpuMeshlet meshlet = MeshletsRef(GDR_SCENE.meshlets).items[meshlet_index];
        mat4 model = InstancesRef(GDR_SCENE.instances).items[instance].model;
        vec3 center = (g.view * (model * vec4(meshlet.sphere.xyz, 1.0))).xyz;
        float radius = meshlet.sphere.w * gdr_max_axis_scale(model[0].xyz, model[1].xyz, model[2].xyz);
        triangles = meshlet.triangle_count;
        // The binning's projection of a cluster is perspective's: an orthographic camera's clusters all
        // go to the mesh shaders.
        sw = g.orthographic == 0u && gdr_raster_bin_sw(params.value.mode, params.value.sw_threshold_px, center, radius, float(triangles), g.znear,
                               g.zfar, params.value.ndc_scale, g.viewport.y);
        // Alpha-tested and double-sided materials are rasterised by the mesh shaders, whose
        // fragments sample the mask and whose pipelines then cull back faces per material.
        if (sw && (g.flags & (GDR_FRAME_ALPHA_TEST | GDR_FRAME_DOUBLE_SIDED)) != 0u) {
            uint material = InstancesRef(GDR_SCENE.instances).items[instance].material;
            sw = !gdr_material_alpha_tested(g.flags, material) && !gdr_material_double_sided(g.flags, material);
        }
        if (sw)
            tiny_class = gdr_raster_tiny_class(meshlet.vertex_count, triangles);
    }
    RasterCountersRef counters = RasterCountersRef(params.value.counters);
    RasterClustersRef list = RasterClustersRef(params.value.clusters);
    // The tiny classes first, those the subgroup has: a cluster beyond its part's end joins the front.
    bool has_part = tiny_class < GDR_SW_TINY_CLASSES && params.value.tiny_capacity[tiny_class] > 0u;
    uint classes = subgroupOr(has_part ? 1u << tiny_class : 0u);
    while (classes != 0u) {
        uint k = uint(findLSB(classes));
        classes &= classes - 1u;
        bool tiny = has_part && tiny_class == k;
        uvec4 ballot = subgroupBallot(tiny);
        uint count = subgroupBallotBitCount(ballot);
        uint base = 0u;
        if (subgroupElect())
            base = atomicAdd(counters.value.tiny_clusters[k], count);
        uint at = subgroupBroadcastFirst(base) + subgroupBallotExclusiveBitCount(ballot);
        if (tiny && at < params.value.tiny_capacity[k]) {
            list.items[params.value.tiny_base[k] + at] = GdrGpuRasterCluster(instance, meshlet_index);
            sw = false;
        }
    }
    bool tiny = tiny_class < GDR_SW_TINY_CLASSES && !sw;

    bool hw = visible && !sw && !tiny;
    uvec4 sw_ballot = subgroupBallot(sw), hw_ballot = subgroupBallot(hw);
    uint sw_count = subgroupBallotBitCount(sw_ballot), hw_count = subgroupBallotBitCount(hw_ballot);
    uint sw_triangles = subgroupAdd(sw || tiny ? triangles : 0u);
    uint hw_triangles = subgroupAdd(hw ? triangles : 0u);
    uint sw_base = 0u, hw_base = 0u;
    bool sw_fits = true, hw_fits = true;
    if (subgroupElect()) {
        if (sw_count > 0u) {
            sw_fits = atomicAdd(counters.value.used, sw_count) + sw_count <= params.value.capacity;
            if (sw_fits)
                sw_base = atomicAdd(counters.value.sw_clusters, sw_count);
            else
                atomicAdd(counters.value.overflow, sw_count);
        }
        if (hw_count > 0u) {
            hw_fits = atomicAdd(counters.value.used, hw_count) + hw_count <= params.value.capacity;
            if (hw_fits)
                hw_base = params.value.capacity - atomicAdd(counters.value.hw_clusters, hw_count) - hw_count;
            else
                atomicAdd(counters.value.overflow, hw_count);
        }
        if (sw_triangles > 0u)
            atomicAdd(counters.value.sw_triangles, sw_triangles);
        if (hw_triangles > 0u)
            atomicAdd(counters.value.hw_triangles, hw_triangles);
    }
    sw_base = subgroupBroadcastFirst(sw_base);
    hw_base = subgroupBroadcastFirst(hw_base);
    sw_fits = subgroupBroadcastFirst(sw_fits);
    hw_fits = subgroupBroadcastFirst(hw_fits);
    if (sw && sw_fits)
        list.items[sw_base + subgroupBallotExclusiveBitCount(sw_ballot)] = GdrGpuRasterCluster(instance, meshlet_index);
    if (hw && hw_fits)
        list.items[hw_base + subgroupBallotExclusiveBitCount(hw_ballot)] = GdrGpuRasterCluster(instance, meshlet_index);
}
#endif

#endif
