#version 460
// The visibility buffer's resolve (issue 8): a full-screen pass. Each pixel's id names a cluster of
// the frame's list and a triangle; the triangle's three vertices are fetched and transformed as the
// mesh shader does, the perspective-correct barycentrics of the pixel centre are recomputed, and the
// interpolated normal and position are shaded by gdr_shade, as the forward path shades them. The
// depth the rasterisers stored is written to the depth buffer (for the depth pyramid); empty pixels
// are discarded and keep the cleared background and depth.
#include "shared/glsl_buffers.h"
#include "shared/meshlet_payload.h"
#include "shared/shading.h"
#include "shared/visbuffer.h"

layout(location = 0) out vec4 out_color;

uint triangle_byte(uint at)
{
    return (UintsRef(push.meshlet_triangles).items[at >> 2] >> ((at & 3u) * 8u)) & 255u;
}

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    GdrGpuRasterParams params = RasterParamsRef(push.raster).value;
    uvec2 pixel = uvec2(gl_FragCoord.xy);
    uint64_t value = VisbufferRef(push.visbuffer).items[pixel.y * uint(g.viewport.x) + pixel.x];
    uint depth_bits = uint(value >> 32);
    if (depth_bits == 0u)
        discard;
    uint id = uint(value);
    uint triangle = id & GDR_VISBUFFER_TRIANGLE_MASK;
    GdrGpuRasterCluster entry = RasterClustersRef(params.clusters).items[id >> GDR_VISBUFFER_TRIANGLE_BITS];
    GdrGpuMeshlet meshlet = MeshletsRef(push.meshlets).items[entry.meshlet];
    GdrGpuInstance instance = InstancesRef(push.instances).items[entry.instance];
    uint at = meshlet.triangle_offset + triangle * 3u;
    uvec3 corners = uvec3(triangle_byte(at), triangle_byte(at + 1u), triangle_byte(at + 2u));

    // Perspective-correct barycentrics from clip space, valid for vertices behind the camera too:
    // the point b0 V0 + b1 V1 + b2 V2 (b summing to 1) projects to the pixel centre p when
    // sum b_i (x_i - p.x w_i) = 0 and sum b_i (y_i - p.y w_i) = 0, so b is parallel to X x Y.
    vec2 p = vec2(gl_FragCoord.x / (0.5 * g.viewport.x) - 1.0, 1.0 - gl_FragCoord.y / (0.5 * g.viewport.y));
    vec3 world[3], normal[3], x_row, y_row;
    for (int i = 0; i < 3; i++) {
        uint vertex_index = UintsRef(push.meshlet_vertices).items[meshlet.vertex_offset + corners[i]];
        GdrGpuVertex vertex = VerticesRef(push.vertices).items[vertex_index];
        vec4 w = instance.model * vec4(vertex.position, 1.0);
        vec4 clip = g.view_projection * w;
        world[i] = w.xyz;
        normal[i] = vertex.normal;
        x_row[i] = clip.x - p.x * clip.w;
        y_row[i] = clip.y - p.y * clip.w;
    }
    vec3 b = cross(x_row, y_row);
    b /= b.x + b.y + b.z;

    mat3 m = mat3(instance.model);
    mat3 cofactor = mat3(cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1]));
    vec3 n = cofactor * (b.x * normal[0] + b.y * normal[1] + b.z * normal[2]);
    vec3 position = b.x * world[0] + b.y * world[1] + b.z * world[2];
    vec3 albedo = instance.color.rgb;
    if (g.view_mode == GDR_VIEW_MESHLETS)
        albedo = gdr_id_color(entry.meshlet);
    else if (g.view_mode == GDR_VIEW_INSTANCES)
        albedo = gdr_id_color(entry.instance);
    else if (g.view_mode == GDR_VIEW_TRIANGLES)
        albedo = gdr_id_color(entry.meshlet * 128u + triangle);
    else if (g.view_mode == GDR_VIEW_LOD)
        albedo = gdr_depth_color(meshlet.group_depth);
    out_color = gdr_shade(g, n, position, albedo);
    gl_FragDepth = uintBitsToFloat(depth_bits);
}
