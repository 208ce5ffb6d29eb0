/* The render targets' memory, checked against the device before any is created. A target larger
 * than the device can back is refused with its numbers: lavapipe (a CPU device, whose memory is the
 * process's) reports its heap as the machine's RAM whatever the process may map, and under an
 * address-space limit a 16384 x 16384 target crashed inside the driver instead of failing. */
#include <stdint.h>
#include <stdio.h>
#include <sys/resource.h>

#include "render/renderer_internal.h"
#include "render/target_memory.h"

/* Bytes per pixel of the targets a renderer makes: colour (RGBA8) 4, depth (D32) 4, the colour
 * read-back 4, the overdraw counts 4, the visibility buffer 8, and the depth pyramid (R32F at most
 * the target's size, with its mips) under 5.4: 29.4, rounded up. */
#define TARGET_BYTES_PER_PIXEL 30u

/* The bytes this process may still map: its address-space limit less what it maps now (UINT64_MAX
 * without a limit). */
static uint64_t address_space_left(void)
{
    struct rlimit limit;
    if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY)
        return UINT64_MAX;
    unsigned long long pages = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        if (fscanf(f, "%llu", &pages) != 1)
            pages = 0;
        fclose(f);
    }
    uint64_t used = (uint64_t)pages * 4096u;
    return (uint64_t)limit.rlim_cur > used ? (uint64_t)limit.rlim_cur - used : 0;
}

gdr_status gdr_target_memory_check(const gdr_vk_context *ctx, uint32_t width, uint32_t height, gdr_error *err)
{
    uint64_t need = (uint64_t)width * height * TARGET_BYTES_PER_PIXEL, heap = 0;
    const VkPhysicalDeviceMemoryProperties *memory = &ctx->memory_properties;
    for (uint32_t i = 0; i < memory->memoryHeapCount; i++)
        if ((memory->memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) && memory->memoryHeaps[i].size > heap)
            heap = memory->memoryHeaps[i].size;
    uint64_t limit = heap;
    const char *what = "its largest device-local heap";
    if (ctx->properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) {
        uint64_t left = address_space_left();
        if (left < limit)
            limit = left, what = "the address space this process may still map (ulimit -v)";
    }
    if (need > limit)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "render size %ux%u needs about %llu MiB of render "
                             "targets; '%s' has %llu MiB in %s", width, height, (unsigned long long)(need >> 20),
                             ctx->properties.deviceName, (unsigned long long)(limit >> 20), what);
    return GDR_OK;
}
