/* Hybrid rasterisation (issue 8): which rasteriser draws a visible cluster. The decision is shared
 * by C (tests, tools) and GLSL; the task shader's appends to the frame's visible-cluster list are
 * GLSL only (below). */
#ifndef GDR_RASTER_BIN_H
#define GDR_RASTER_BIN_H

#include "glsl_c_bridge.h"
#include "gpu_types.h"

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

#ifdef GDR_GLSL
#include "visbuffer.h"

/* Task shader, every invocation in uniform control flow, after culling: bins the invocation's
 * cluster (when visible) and appends compute-rasterised ones at the front of the frame's
 * visible-cluster list (one atomic per subgroup). Returns true for those: the caller leaves them out
 * of its mesh tasks. Needs MeshletsRef and InstancesRef (meshlet_payload.h, glsl_buffers.h). */
bool gdr_raster_bin(GdrGpuFrameGlobals g, bool visible, uint instance, uint meshlet_index)
{
    GdrGpuRasterParams params = RasterParamsRef(push.raster).value;
    if (params.mode == GDR_GPU_RASTER_FORWARD)
        return false;
    bool sw = false;
    uint triangles = 0u;
    if (visible) {
        GdrGpuMeshlet meshlet = MeshletsRef(push.meshlets).items[meshlet_index];
        mat4 model = InstancesRef(push.instances).items[instance].model;
        vec3 center = (g.view * (model * vec4(meshlet.sphere.xyz, 1.0))).xyz;
        float radius = meshlet.sphere.w * gdr_max_axis_scale(model[0].xyz, model[1].xyz, model[2].xyz);
        triangles = meshlet.triangle_count;
        sw = gdr_raster_bin_sw(params.mode, params.sw_threshold_px, center, radius, float(triangles), g.znear,
                               g.zfar, params.ndc_scale, g.viewport.y);
    }
    RasterCountersRef counters = RasterCountersRef(params.counters);
    uvec4 ballot = subgroupBallot(sw);
    uint count = subgroupBallotBitCount(ballot);
    uint sw_triangles = subgroupAdd(sw ? triangles : 0u);
    uint hw_triangles = subgroupAdd(visible && !sw ? triangles : 0u);
    uint base = 0u;
    bool fits = true;
    if (subgroupElect()) {
        if (count > 0u) {
            fits = atomicAdd(counters.value.used, count) + count <= params.capacity;
            if (fits)
                base = atomicAdd(counters.value.sw_clusters, count);
            else
                atomicAdd(counters.value.overflow, count);
        }
        if (sw_triangles > 0u)
            atomicAdd(counters.value.sw_triangles, sw_triangles);
        if (hw_triangles > 0u)
            atomicAdd(counters.value.hw_triangles, hw_triangles);
    }
    base = subgroupBroadcastFirst(base);
    fits = subgroupBroadcastFirst(fits);
    if (sw && fits)
        RasterClustersRef(params.clusters).items[base + subgroupBallotExclusiveBitCount(ballot)] =
            GdrGpuRasterCluster(instance, meshlet_index);
    return sw;
}

/* Task shader, one invocation: reserves `count` entries at the back of the list for the
 * workgroup's mesh-shader clusters. Returns the slot of the first (the mesh shaders write the
 * entries: slot + gl_WorkGroupID.x), or GDR_RASTER_NO_SLOT when they do not fit (the mesh shaders
 * then draw nothing). */
uint gdr_raster_reserve_hw(uint count)
{
    GdrGpuRasterParams params = RasterParamsRef(push.raster).value;
    if (params.mode == GDR_GPU_RASTER_FORWARD || count == 0u)
        return 0u;
    RasterCountersRef counters = RasterCountersRef(params.counters);
    if (atomicAdd(counters.value.used, count) + count > params.capacity) {
        atomicAdd(counters.value.overflow, count);
        return GDR_RASTER_NO_SLOT;
    }
    return params.capacity - atomicAdd(counters.value.hw_clusters, count) - count;
}
#endif

#endif
