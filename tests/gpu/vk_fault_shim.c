/* Fault injection for the GPU tests, preloaded (LD_PRELOAD) into gdr: a lavapipe device cannot
 * be lost on purpose, nor its memory exhausted cheaply, so this shim makes the Vulkan calls fail
 * the way a driver reports those faults.
 *   GDR_FAULT_DEVICE_LOST_AT=N   the N-th queue submission (1-based) and every later submission,
 *                                fence wait and fence query return VK_ERROR_DEVICE_LOST
 *   GDR_FAULT_DEVICE_MEMORY=B    vkAllocateMemory fails with VK_ERROR_OUT_OF_DEVICE_MEMORY once the
 *                                memory allocated would exceed B bytes
 *   GDR_FAULT_COUNT_SUBMITS=1    prints the submissions and the bytes allocated at exit
 * Calls are passed on to the real loader functions (dlsym RTLD_NEXT). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>

#include <vulkan/vulkan.h>

static unsigned long submissions;
static int lost;
static VkDeviceSize allocated;

static long env_number(const char *name)
{
    const char *text = getenv(name);
    return text ? strtol(text, NULL, 10) : 0;
}

__attribute__((destructor)) static void report_submissions(void)
{
    if (env_number("GDR_FAULT_COUNT_SUBMITS"))
        fprintf(stderr, "vk_fault_shim: submissions: %lu\nvk_fault_shim: allocated: %llu\n", submissions,
                (unsigned long long)allocated);
}

/* Counts a submission; true when the device is (now) lost. */
static int submit_loses_device(void)
{
    long at = env_number("GDR_FAULT_DEVICE_LOST_AT");
    ++submissions;
    if (at > 0 && (long)submissions >= at)
        lost = 1;
    return lost;
}

#define REAL(name) ((PFN_##name)dlsym(RTLD_NEXT, #name))

VKAPI_ATTR VkResult VKAPI_CALL vkQueueSubmit2(VkQueue queue, uint32_t count, const VkSubmitInfo2 *submits,
                                              VkFence fence)
{
    if (submit_loses_device())
        return VK_ERROR_DEVICE_LOST;
    return REAL(vkQueueSubmit2)(queue, count, submits, fence);
}

VKAPI_ATTR VkResult VKAPI_CALL vkQueueSubmit(VkQueue queue, uint32_t count, const VkSubmitInfo *submits,
                                             VkFence fence)
{
    if (submit_loses_device())
        return VK_ERROR_DEVICE_LOST;
    return REAL(vkQueueSubmit)(queue, count, submits, fence);
}

VKAPI_ATTR VkResult VKAPI_CALL vkWaitForFences(VkDevice device, uint32_t count, const VkFence *fences,
                                               VkBool32 all, uint64_t timeout)
{
    VkResult result = REAL(vkWaitForFences)(device, count, fences, all, timeout);
    return lost ? VK_ERROR_DEVICE_LOST : result;
}

VKAPI_ATTR VkResult VKAPI_CALL vkGetFenceStatus(VkDevice device, VkFence fence)
{
    VkResult result = REAL(vkGetFenceStatus)(device, fence);
    return lost ? VK_ERROR_DEVICE_LOST : result;
}

VKAPI_ATTR VkResult VKAPI_CALL vkQueueWaitIdle(VkQueue queue)
{
    VkResult result = REAL(vkQueueWaitIdle)(queue);
    return lost ? VK_ERROR_DEVICE_LOST : result;
}

VKAPI_ATTR VkResult VKAPI_CALL vkAllocateMemory(VkDevice device, const VkMemoryAllocateInfo *info,
                                                const VkAllocationCallbacks *callbacks, VkDeviceMemory *memory)
{
    long limit = env_number("GDR_FAULT_DEVICE_MEMORY");
    if (limit > 0 && allocated + info->allocationSize > (VkDeviceSize)limit)
        return VK_ERROR_OUT_OF_DEVICE_MEMORY;
    VkResult result = REAL(vkAllocateMemory)(device, info, callbacks, memory);
    if (result == VK_SUCCESS)
        allocated += info->allocationSize;
    return result;
}
