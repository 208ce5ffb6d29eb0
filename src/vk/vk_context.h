/* Vulkan core: a headless instance and device (no surface), validation, device choice. */
#ifndef GDR_VK_CONTEXT_H
#define GDR_VK_CONTEXT_H

#include <stdbool.h>
#include <vulkan/vulkan.h>

#include "gdr/core.h"

#define GDR_VK_MAX_INSTANCE_EXTENSIONS 8

typedef struct gdr_vk_context_desc {
    const char *device;   /* NULL: first discrete GPU, else the first device; "N": index; else a name substring */
    bool validate;        /* enable VK_LAYER_KHRONOS_validation and count its messages */
    bool synchronization_validation; /* also enable synchronization validation (implies validate) */
    bool disable_mesh_shaders; /* behave as a device without VK_EXT_mesh_shader (tests of the fallback) */
    bool disable_texture_compression_bc; /* behave as a device without BC sampling (tests of the fallback) */
    /* Presentation: instance extensions a window system needs (VK_KHR_surface, ...), and whether the
     * device must have VK_KHR_swapchain (enabled; its absence is an error naming the device). */
    const char *const *instance_extensions;
    uint32_t instance_extension_count;
    bool swapchain;
} gdr_vk_context_desc;

typedef struct gdr_vk_context {
    VkInstance instance;
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDevice physical_device;
    VkPhysicalDeviceProperties properties;
    VkPhysicalDeviceMemoryProperties memory_properties;
    VkDevice device;
    VkQueue queue;
    uint32_t queue_family;
    VkCommandPool command_pool;
    /* VK_EXT_mesh_shader with task shaders, enabled when the device has it (and subgroup ballots in
     * task shaders); otherwise mesh_shader_missing says why. */
    bool has_mesh_shader;
    char mesh_shader_missing[128];
    VkPhysicalDeviceMeshShaderPropertiesEXT mesh_shader_properties;
    PFN_vkCmdDrawMeshTasksIndirectEXT cmd_draw_mesh_tasks_indirect;
    /* 64-bit atomics on storage buffers (shaderBufferInt64Atomics), enabled when present: the
     * visibility buffer of the hybrid rasteriser needs them. */
    bool has_buffer_int64_atomics;
    bool has_texture_compression_bc; /* textureCompressionBC enabled (each format's features still checked) */
    uint32_t subgroup_size;
    char driver_info[VK_MAX_DRIVER_NAME_SIZE + VK_MAX_DRIVER_INFO_SIZE + 2]; /* driver name and version, for stats and PERFORMANCE.md */
    /* Validation messages seen so far (warnings and errors); every one is also printed. */
    volatile unsigned validation_messages;
} gdr_vk_context;

gdr_status gdr_vk_context_create(const gdr_vk_context_desc *desc, gdr_vk_context **out, gdr_error *err);
void gdr_vk_context_destroy(gdr_vk_context *ctx);

/* Names the Vulkan result, e.g. "VK_ERROR_OUT_OF_DEVICE_MEMORY". */
const char *gdr_vk_result_name(VkResult result);

/* Turns a failed VkResult into a gdr_error naming the call; checked in every build type. */
#define GDR_VK_TRY(err, call)                                                                         \
    do {                                                                                              \
        VkResult gdr_vk_result_ = (call);                                                             \
        if (gdr_vk_result_ != VK_SUCCESS)                                                             \
            return gdr_error_set((err), gdr_vk_result_ == VK_ERROR_OUT_OF_DEVICE_MEMORY ||             \
                                            gdr_vk_result_ == VK_ERROR_OUT_OF_HOST_MEMORY              \
                                        ? GDR_ERROR_OUT_OF_MEMORY                                     \
                                        : GDR_ERROR_VULKAN,                                           \
                                 "%s failed: %s (%s:%d)", #call, gdr_vk_result_name(gdr_vk_result_),  \
                                 __FILE__, __LINE__);                                                 \
    } while (0)

/* One-time command buffer: begin, record with the callback's work, submit and wait. */
gdr_status gdr_vk_begin_one_time(gdr_vk_context *ctx, VkCommandBuffer *out, gdr_error *err);
gdr_status gdr_vk_end_one_time(gdr_vk_context *ctx, VkCommandBuffer cmd, gdr_error *err);

#endif
