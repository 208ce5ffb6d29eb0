#version 460
// The compute rasteriser: one workgroup per cluster that the cluster cull binned to it
// (shared/raster_bin.h), the cluster's vertices transformed once into shared memory, then one
// invocation per triangle. The tiny variants (one per size class, GDR_SW_TINY_*) draw their class's
// part of the list several clusters to a workgroup, CLUSTER_LANES invocations and as many shared
// vertices each; the rasterisation below is the same for all. Coverage follows Vulkan's rules as
// the hardware applies them, so the two rasterisers agree pixel for pixel where their clusters meet:
//  - the frame's viewport transform (negative height: framebuffer y down), vertices snapped to
//    GDR_SW_SUBPIXEL_BITS fractional bits, rounding to nearest even;
//  - back faces culled (front faces are counter-clockwise as seen), zero-area triangles draw nothing;
//  - a pixel is covered when its centre is inside all three edges, decided exactly with integer
//    edge functions; a centre exactly on an edge belongs to the triangle for which it is a top or a
//    left edge (the top-left rule), so an edge shared by two triangles covers each pixel once;
//  - depth is interpolated at the pixel centre on the plane through the unsnapped vertices.
// Each covered pixel does one 64-bit atomicMax of (depth, visibility id) into the visibility buffer.
// The clusters never cross the near or far plane and stay inside a guard band (raster_bin.h), so
// nothing is clipped here.
#extension GL_EXT_shader_atomic_int64 : require

#include "gpu_shared/glsl_buffers.h"
#include "gpu_shared/meshlet_payload.h"
#include "gpu_shared/visbuffer.h"

layout(local_size_x = GDR_SW_RASTER_WORKGROUP_SIZE) in;
// Invocations per cluster: the whole workgroup, or GDR_SW_TINY_LANES << TINY_CLASS for a tiny class
// (GDR_SW_TINY_CLASSES: none, the front of the list).
layout(constant_id = 0) const uint CLUSTER_LANES = GDR_SW_RASTER_WORKGROUP_SIZE;
layout(constant_id = 1) const uint TINY_CLASS = GDR_SW_TINY_CLASSES;
const uint CLUSTERS_PER_GROUP = GDR_SW_RASTER_WORKGROUP_SIZE / CLUSTER_LANES;
const uint SLICE_VERTICES = GDR_MESH_MAX_VERTICES / CLUSTERS_PER_GROUP; // each cluster's shared vertices

const int SUBPIXEL = 1 << GDR_SW_SUBPIXEL_BITS;
const int HALF_PIXEL = SUBPIXEL / 2;
// Triangles whose bounding box spans at most this many sub-pixel units evaluate their edge
// functions in 32 bits (|E| <= 2 * 2^14 * (2^14 + 2^8) < 2^31); larger ones in 64 bits.
const int SMALL_EXTENT = 64 * SUBPIXEL;

shared ivec2 corner_fixed[GDR_MESH_MAX_VERTICES]; // framebuffer position in sub-pixel units
shared vec3 corner_float[GDR_MESH_MAX_VERTICES];  // framebuffer position and depth, unsnapped

// Per invocation, read once (a reference reloaded after every atomic would cost a load per pixel):
// the target's width, the overdraw counts and the triangles' bytes.
uint target_width;
bool count_overdraw;
OverdrawRef target_overdraw;
UintsRef triangle_bytes;
// The depth plane of the current triangle: depth = x + y * (px - ax) + z * (py - ay), in pixels.
vec3 depth_plane;
vec2 depth_origin;

uint triangle_byte(uint at)
{
    return (triangle_bytes.items[at >> 2] >> ((at & 3u) * 8u)) & 255u;
}

void write_pixel(int x, int y, uint id)
{
    vec2 centre = vec2(x, y) + 0.5 - depth_origin;
    float depth = clamp(depth_plane.x + depth_plane.y * centre.x + depth_plane.z * centre.y, 0.0, 1.0);
    uint pixel = uint(y) * target_width + uint(x);
    atomicMax(push.visbuffer.items[pixel], gdr_visbuffer_pack(depth, id));
    if (count_overdraw)
        atomicAdd(target_overdraw.items[pixel], 1u);
}

// 0 for a top or left edge of a clockwise-as-seen triangle (framebuffer y down), else 1: the edge
// function must then be strictly positive.
int edge_bias(ivec2 d)
{
    return d.y < 0 || (d.y == 0 && d.x > 0) ? 0 : 1;
}

// The edge function of p -> q at the first pixel centre s, E = (q - p) x (s - p) minus the bias,
// and its steps per pixel in x and y; positive inside a clockwise-as-seen triangle. One body for
// the 32- and 64-bit variants.
#define GDR_DEFINE_RASTER(NAME, T)                                                                    \
    void NAME(ivec2 a, ivec2 b, ivec2 c, ivec2 first, ivec2 last, uint id)                            \
    {                                                                                                 \
        ivec2 s = first * SUBPIXEL + HALF_PIXEL;                                                      \
        ivec2 ab = b - a, bc = c - b, ca = a - c;                                                     \
        T row0 = T(ab.x) * T(s.y - a.y) - T(ab.y) * T(s.x - a.x) - T(edge_bias(ab));                  \
        T row1 = T(bc.x) * T(s.y - b.y) - T(bc.y) * T(s.x - b.x) - T(edge_bias(bc));                  \
        T row2 = T(ca.x) * T(s.y - c.y) - T(ca.y) * T(s.x - c.x) - T(edge_bias(ca));                  \
        T step_x0 = -T(ab.y) * T(SUBPIXEL), step_y0 = T(ab.x) * T(SUBPIXEL);                         \
        T step_x1 = -T(bc.y) * T(SUBPIXEL), step_y1 = T(bc.x) * T(SUBPIXEL);                         \
        T step_x2 = -T(ca.y) * T(SUBPIXEL), step_y2 = T(ca.x) * T(SUBPIXEL);                         \
        for (int y = first.y; y <= last.y; y++) {                                                     \
            T e0 = row0, e1 = row1, e2 = row2;                                                        \
            for (int x = first.x; x <= last.x; x++) {                                                 \
                if ((e0 | e1 | e2) >= T(0))                                                           \
                    write_pixel(x, y, id);                                                            \
                e0 += step_x0;                                                                        \
                e1 += step_x1;                                                                        \
                e2 += step_x2;                                                                        \
            }                                                                                         \
            row0 += step_y0;                                                                          \
            row1 += step_y1;                                                                          \
            row2 += step_y2;                                                                          \
        }                                                                                             \
    }

GDR_DEFINE_RASTER(raster_small, int)
GDR_DEFINE_RASTER(raster_large, int64_t)

// corners: indices into the shared vertices (the cluster's slice).
void raster_triangle(uvec3 corners, uint id, ivec2 size)
{
    ivec2 a = corner_fixed[corners.x], b = corner_fixed[corners.y], c = corner_fixed[corners.z];
    // Twice the signed area with y down: front faces (counter-clockwise as seen) are negative.
    int64_t area = int64_t(b.x - a.x) * int64_t(c.y - a.y) - int64_t(b.y - a.y) * int64_t(c.x - a.x);
    if (area >= 0)
        return;
    // Clockwise as seen from here on: the inside is where all three edge functions are positive.
    uint swap = corners.y;
    corners.y = corners.z;
    corners.z = swap;
    ivec2 t = b;
    b = c;
    c = t;
    ivec2 lo = min(a, min(b, c)), hi = max(a, max(b, c));
    // Pixels whose centres (k + 1/2) lie in [lo, hi], inside the target.
    ivec2 first = max((lo - HALF_PIXEL + (SUBPIXEL - 1)) >> GDR_SW_SUBPIXEL_BITS, ivec2(0));
    ivec2 last = min((hi - HALF_PIXEL) >> GDR_SW_SUBPIXEL_BITS, size - 1);
    if (any(greaterThan(first, last)))
        return;

    vec3 pa = corner_float[corners.x], pb = corner_float[corners.y], pc = corner_float[corners.z];
    vec2 u = pb.xy - pa.xy, v = pc.xy - pa.xy;
    float det = u.x * v.y - u.y * v.x;
    depth_origin = pa.xy;
    if (det != 0.0)
        depth_plane = vec3(pa.z, ((pb.z - pa.z) * v.y - (pc.z - pa.z) * u.y) / det,
                           (u.x * (pc.z - pa.z) - v.x * (pb.z - pa.z)) / det);
    else // snapped to a triangle, but too thin to orient unsnapped: the nearest depth
        depth_plane = vec3(max(pa.z, max(pb.z, pc.z)), 0.0, 0.0);

    ivec2 extent = hi - lo;
    if (max(extent.x, extent.y) <= SMALL_EXTENT)
        raster_small(a, b, c, first, last, id);
    else
        raster_large(a, b, c, first, last, id);
}

// The slot of the workgroup's cluster, or of this invocation's in a tiny variant, in the list; false
// past the end of the current dispatch (the tail of the last row or workgroup).
bool find_entry(RasterParamsRef params, out uint slot)
{
    RasterCountersRef counters = RasterCountersRef(params.value.counters);
    uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * GDR_SW_GROUPS_PER_ROW;
    if (TINY_CLASS >= GDR_SW_TINY_CLASSES) {
        slot = counters.value.sw_first + group;
        return slot < counters.value.sw_clusters;
    }
    uint index = counters.value.tiny_first[TINY_CLASS] + group * CLUSTERS_PER_GROUP +
                 gl_LocalInvocationIndex / CLUSTER_LANES;
    slot = params.value.tiny_base[TINY_CLASS] + index;
    return index < min(counters.value.tiny_clusters[TINY_CLASS], params.value.tiny_capacity[TINY_CLASS]);
}

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    // The references at once, before the loads that depend on them.
    RasterParamsRef params = GDR_FRAME.raster;
    MeshletsRef meshlets = GDR_SCENE.meshlets;
    InstancesRef instances = GDR_SCENE.instances;
    UintsRef vertex_refs = GDR_SCENE.meshlet_vertices;
    VerticesRef vertices = GDR_SCENE.vertices;
    target_overdraw = GDR_FRAME.overdraw;
    triangle_bytes = GDR_SCENE.meshlet_triangles;
    uint slot;
    bool has_entry = find_entry(params, slot);
    // A workgroup of one cluster leaves as a whole; the tiny variant's idle slices wait at the barrier.
    if (CLUSTERS_PER_GROUP == 1u && !has_entry)
        return;
    GdrGpuMeshlet meshlet;
    mat4 model = mat4(1.0);
    if (has_entry) {
        GdrGpuRasterCluster entry = RasterClustersRef(params.value.clusters).items[slot];
        meshlet = meshlets.items[entry.meshlet];
        model = instances.items[entry.instance].model;
    } else {
        meshlet.vertex_count = 0u;
        meshlet.triangle_count = 0u;
    }
    uint lane = gl_LocalInvocationIndex % CLUSTER_LANES;
    uint slice = gl_LocalInvocationIndex / CLUSTER_LANES * SLICE_VERTICES;
    target_width = uint(g.viewport.x);
    count_overdraw = g.view_mode == GDR_VIEW_OVERDRAW;

    // The vertices, as the mesh shader transforms them, then the viewport transform.
    vec2 half_size = 0.5 * g.viewport;
    for (uint v = lane; v < meshlet.vertex_count; v += CLUSTER_LANES) {
        uint vertex_index = vertex_refs.items[meshlet.vertex_offset + v];
        vec3 position = vertices.items[vertex_index].position;
        vec4 world = model * vec4(position, 1.0);
        vec4 clip = g.view_projection * world;
        vec3 ndc = clip.xyz / clip.w;
        vec2 framebuffer = vec2(half_size.x + half_size.x * ndc.x, half_size.y - half_size.y * ndc.y);
        corner_fixed[slice + v] = ivec2(roundEven(framebuffer * float(SUBPIXEL)));
        corner_float[slice + v] = vec3(framebuffer, ndc.z);
    }
    barrier();

    ivec2 size = ivec2(g.viewport);
    for (uint t = lane; t < meshlet.triangle_count; t += CLUSTER_LANES) {
        uint at = meshlet.triangle_offset + t * 3u;
        uvec3 corners = uvec3(triangle_byte(at), triangle_byte(at + 1u), triangle_byte(at + 2u));
        raster_triangle(corners + slice, gdr_visbuffer_id(slot, t), size);
    }
}
