/* GLSL only: what the culling and raster passes ask of an instance's material, read only in
 * frames of scenes that have such materials (frame_flags: GdrGpuFrameGlobals.flags), so other
 * scenes pay nothing. */
#ifndef GDR_MATERIAL_FLAGS_H
#define GDR_MATERIAL_FLAGS_H

#include "gpu_shared/glsl_buffers.h"

/* MASK or BLEND: its fragments are alpha-tested, by the mesh shaders' raster only. */
bool gdr_material_alpha_tested(uint frame_flags, uint material)
{
    return (frame_flags & GDR_FRAME_ALPHA_TEST) != 0u &&
           MaterialsRef(GDR_SCENE.materials).items[material].alpha_mode != GDR_ALPHA_MODE_OPAQUE;
}

/* Double-sided: no back-face culling (cluster cones, triangles), its back faces shaded with the
 * normal reversed. */
bool gdr_material_double_sided(uint frame_flags, uint material)
{
    return (frame_flags & GDR_FRAME_DOUBLE_SIDED) != 0u && MaterialsRef(GDR_SCENE.materials).items[material].double_sided != 0u;
}

#endif
