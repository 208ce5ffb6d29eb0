#version 460
// The visibility buffer's resolve, one invocation per pixel in GDR_RESOLVE_TILE-square
// workgroups. Each pixel's id names a cluster of the frame's list and a triangle; the triangle's
// three vertices are fetched and transformed as the mesh shader does, the perspective-correct
// barycentrics of the pixel centre are recomputed, and the interpolated attributes are shaded by
// the material (shared/material.h), as the forward paths shade them. Writes every pixel's colour into the colour
// target (set 0, binding 1, a storage image; empty pixels get the background). The depth stays in
// the visibility buffer, where the depth pyramid reads it: a buffer-to-image copy of the colour and
// the depth cost 0.16 ms each at 1440p on the H100, three times the resolve.
// Launched indirectly (raster_submit.comp): in a frame's first raster phase, and in the late phase
// of occlusion culling only when it drew something, so that a late phase with nothing to draw costs
// no second resolve.
// A compute pass rather than a full-screen fragment pass: on the Hopper GPUs a fragment pass that
// writes depth costs about 1 ms at 1440p before any shading (docs/PERFORMANCE.md).
#extension GL_EXT_nonuniform_qualifier : require
#include "gpu_shared/glsl_buffers.h"
#include "gpu_shared/material.h"
#include "gpu_shared/meshlet_payload.h"
#include "gpu_shared/shading.h"
#include "gpu_shared/visbuffer.h"
#include "gpu_shared/point_level.h"

layout(local_size_x = GDR_RESOLVE_TILE, local_size_y = GDR_RESOLVE_TILE) in;
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D color_target;

uint triangle_byte(uint at)
{
    return (UintsRef(GDR_SCENE.meshlet_triangles).items[at >> 2] >> ((at & 3u) * 8u)) & 255u;
}

// Perspective-correct barycentrics from the rows of the linear system below (shade_pixel).
vec3 barycentrics(vec3 x_row, vec3 y_row)
{
    vec3 b = cross(x_row, y_row);
    return b / (b.x + b.y + b.z);
}

// Shades a pixel of instance `index`'s point level (shared/point_level.h): a disc facing the eye
// at the bounding sphere's centre, the material read at its coarsest mip (derivatives of a whole
// texture per pixel: the texture's mean), the instance colour without vertex colours.
vec4 shade_point(FrameGlobalsRef globals, uint index)
{
    GdrGpuInstance instance = InstancesRef(GDR_SCENE.instances).items[index];
    GdrGpuMesh mesh = MeshesRef(GDR_SCENE.meshes).items[instance.mesh];
    vec3 position = (instance.model * vec4(mesh.bounds.xyz, 1.0)).xyz;
    vec3 n = normalize(globals.value.eye_position.xyz - position);
    if (globals.value.view_mode != GDR_VIEW_SHADED) {
        uint root = mesh.meshlet_offset + mesh.root_first;
        vec3 albedo = gdr_view_albedo(globals.value.view_mode, instance.color.rgb, index, root, 0u,
                                      MeshletsRef(GDR_SCENE.meshlets).items[root].group_depth + 1);
        return gdr_shade(globals.value.light_direction.xyz, n, position, albedo);
    }
    // One pixel's step along the view's right and down axes at the centre's distance.
    mat4 view = globals.value.view;
    float pixel = length(globals.value.eye_position.xyz - position) / globals.value.lod_projection_scale;
    vec3 right = vec3(view[0][0], view[1][0], view[2][0]) * pixel;
    vec3 down = -vec3(view[0][1], view[1][1], view[2][1]) * pixel;
    GdrSurfacePoint point = GdrSurfacePoint(position, n, vec2(0.5), instance.color, vec2(1.0, 0.0), vec2(0.0, 1.0),
                                            right, down);
    return gdr_shade_material(instance.material, point, globals);
}

// Shades the pixel whose centre is `centre` (framebuffer pixels, y down) from its id.
vec4 shade_pixel(FrameGlobalsRef globals, vec2 viewport, vec2 centre, uint id)
{
    uint triangle = id & GDR_VISBUFFER_TRIANGLE_MASK;
    if (triangle == GDR_VISBUFFER_POINT_TRIANGLE)
        return shade_point(globals, id >> GDR_VISBUFFER_TRIANGLE_BITS);
    GdrGpuRasterCluster entry =
        RasterClustersRef(RasterParamsRef(GDR_FRAME.raster).value.clusters).items[id >> GDR_VISBUFFER_TRIANGLE_BITS];
    MeshletsRef meshlets = MeshletsRef(GDR_SCENE.meshlets);
    uint vertex_offset = meshlets.items[entry.meshlet].vertex_offset;
    uint at = meshlets.items[entry.meshlet].triangle_offset + triangle * 3u;
    mat4 model = InstancesRef(GDR_SCENE.instances).items[entry.instance].model;
    mat4 view_projection = globals.value.view_projection;
    uvec3 corners = uvec3(triangle_byte(at), triangle_byte(at + 1u), triangle_byte(at + 2u));

    // Perspective-correct barycentrics from clip space, valid for vertices behind the camera too:
    // the point b0 V0 + b1 V1 + b2 V2 (b summing to 1) projects to the pixel centre p when
    // sum b_i (x_i - p.x w_i) = 0 and sum b_i (y_i - p.y w_i) = 0, so b is parallel to X x Y.
    vec2 p = vec2(centre.x / (0.5 * viewport.x) - 1.0, 1.0 - centre.y / (0.5 * viewport.y));
    vec3 x_row, y_row, w_row;
    mat3 world, normal;
    mat3x2 uvs;
    uint vertex_index[3];
    for (int i = 0; i < 3; i++) {
        vertex_index[i] = UintsRef(GDR_SCENE.meshlet_vertices).items[vertex_offset + corners[i]];
        GdrGpuVertex vertex = VerticesRef(GDR_SCENE.vertices).items[vertex_index[i]];
        normal[i] = vertex.normal;
        uvs[i] = vertex.uv;
        vec4 w = model * vec4(vertex.position, 1.0);
        vec4 clip = view_projection * w;
        world[i] = w.xyz;
        x_row[i] = clip.x - p.x * clip.w;
        y_row[i] = clip.y - p.y * clip.w;
        w_row[i] = clip.w;
    }
    vec3 b = barycentrics(x_row, y_row);
    mat3 m = mat3(model);
    mat3 cofactor = mat3(cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1]));
    vec3 n = cofactor * (normal * b);
    vec3 position = world * b;
    GdrGpuInstance instance = InstancesRef(GDR_SCENE.instances).items[entry.instance];
    if (globals.value.view_mode != GDR_VIEW_SHADED) {
        GdrGpuMeshlet record = meshlets.items[entry.meshlet];
        vec3 albedo = gdr_view_albedo(globals.value.view_mode, instance.color.rgb, entry.instance, record.cluster_id,
                                      triangle, record.group_depth);
        return gdr_shade(globals.value.light_direction.xyz, n, position, albedo);
    }
    // The derivatives, analytically from the triangle: the barycentrics of the next pixel centre to
    // the right and of the next one down (NDC y falls as pixel y grows), as the forward path's
    // dFdx/dFdy difference neighbouring pixels; so both select the same mip level and tangent frame.
    vec3 bx = barycentrics(x_row - (2.0 / viewport.x) * w_row, y_row) - b;
    vec3 by = barycentrics(x_row, y_row + (2.0 / viewport.y) * w_row) - b;
    vec4 color = instance.color;
    if ((globals.value.flags & GDR_FRAME_VERTEX_COLORS) != 0u)
        color *= b.x * gdr_vertex_color(globals.value.flags, instance.mesh, vertex_index[0]) +
                 b.y * gdr_vertex_color(globals.value.flags, instance.mesh, vertex_index[1]) +
                 b.z * gdr_vertex_color(globals.value.flags, instance.mesh, vertex_index[2]);
    // A back face (only double-sided materials draw them) is shaded with the normal reversed; the
    // winding seen from the eye decides, as the rasteriser's facing does.
    vec3 geometric = cross(world[1] - world[0], world[2] - world[0]);
    if (dot(geometric, globals.value.eye_position.xyz - position) < 0.0)
        n = -n;
    GdrSurfacePoint point = GdrSurfacePoint(position, n, uvs * b, color, uvs * bx, uvs * by, world * bx, world * by);
    return gdr_shade_material(instance.material, point, globals);
}

void main()
{
    FrameGlobalsRef globals = FrameGlobalsRef(push.globals);
    vec2 viewport = globals.value.viewport;
    uvec2 size = uvec2(viewport);
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(pixel, size)))
        return;
    uint index = pixel.y * size.x + pixel.x;
    uint64_t value = push.visbuffer.items[index];
    uint depth_bits = uint(value >> 32);
    vec4 color = vec4(GDR_BACKGROUND_R, GDR_BACKGROUND_G, GDR_BACKGROUND_B, 1.0);
    if (depth_bits != 0u)
        color = shade_pixel(globals, viewport, vec2(pixel) + 0.5, uint(value));
    imageStore(color_target, ivec2(pixel), color);
}
