/* GLSL only: the visibility buffer and the frame's visible-cluster list (the layout is
 * described in gpu_types.h). Include after glsl_buffers.h. */
#ifndef GDR_VISBUFFER_H
#define GDR_VISBUFFER_H


#define GDR_RASTER_NO_SLOT 0xffffffffu
#define GDR_VISBUFFER_TRIANGLE_MASK ((1u << GDR_VISBUFFER_TRIANGLE_BITS) - 1u)

/* Depth in [0, 1] (reverse-Z: larger is nearer), so its float bits order like the depths. */
uint64_t gdr_visbuffer_pack(float depth, uint id)
{
    return (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(id);
}

uint gdr_visbuffer_id(uint slot, uint triangle)
{
    return (slot << GDR_VISBUFFER_TRIANGLE_BITS) | triangle;
}

#endif
