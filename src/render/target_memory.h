/* The render targets' memory against the device (target_memory.c). */
#ifndef GDR_RENDER_TARGET_MEMORY_H
#define GDR_RENDER_TARGET_MEMORY_H

#include "render/renderer_internal.h"

/* Refuses (GDR_ERROR_INVALID_ARGUMENT) a render size whose targets the device cannot back: its
 * largest device-local heap, and for a CPU device (lavapipe) the address space the process may still
 * map (target_memory.c). */
gdr_status gdr_target_memory_check(const gdr_vk_context *ctx, uint32_t width, uint32_t height, gdr_error *err);

#endif
