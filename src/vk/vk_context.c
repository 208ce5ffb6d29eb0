#include "vk/vk_context.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gdr/mesh_clusters.h"

const char *gdr_vk_result_name(VkResult result)
{
    switch (result) {
#define NAME(x) case x: return #x
    NAME(VK_SUCCESS); NAME(VK_NOT_READY); NAME(VK_TIMEOUT); NAME(VK_INCOMPLETE);
    NAME(VK_ERROR_OUT_OF_HOST_MEMORY); NAME(VK_ERROR_OUT_OF_DEVICE_MEMORY);
    NAME(VK_ERROR_INITIALIZATION_FAILED); NAME(VK_ERROR_DEVICE_LOST); NAME(VK_ERROR_MEMORY_MAP_FAILED);
    NAME(VK_ERROR_LAYER_NOT_PRESENT); NAME(VK_ERROR_EXTENSION_NOT_PRESENT); NAME(VK_ERROR_FEATURE_NOT_PRESENT);
    NAME(VK_ERROR_INCOMPATIBLE_DRIVER); NAME(VK_ERROR_TOO_MANY_OBJECTS); NAME(VK_ERROR_FORMAT_NOT_SUPPORTED);
    NAME(VK_ERROR_FRAGMENTED_POOL); NAME(VK_ERROR_OUT_OF_POOL_MEMORY); NAME(VK_ERROR_UNKNOWN);
#undef NAME
    default: return "VkResult(unknown)";
    }
}

static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                            VkDebugUtilsMessageTypeFlagsEXT type,
                                                            const VkDebugUtilsMessengerCallbackDataEXT *data,
                                                            void *user)
{
    (void)type;
    gdr_vk_context *ctx = user;
    __atomic_add_fetch(&ctx->validation_messages, 1, __ATOMIC_RELAXED);
    fprintf(stderr, "gdr: validation %s: %s\n",
            severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
            data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
}

static bool layer_available(const char *name)
{
    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, NULL);
    VkLayerProperties *layers = calloc(count ? count : 1, sizeof *layers);
    bool found = false;
    if (layers && vkEnumerateInstanceLayerProperties(&count, layers) == VK_SUCCESS)
        for (uint32_t i = 0; i < count && !found; i++)
            found = strcmp(layers[i].layerName, name) == 0;
    free(layers);
    return found;
}

static bool device_extension_available(VkPhysicalDevice device, const char *name)
{
    uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(device, NULL, &count, NULL);
    VkExtensionProperties *extensions = calloc(count ? count : 1, sizeof *extensions);
    bool found = false;
    if (extensions && vkEnumerateDeviceExtensionProperties(device, NULL, &count, extensions) == VK_SUCCESS)
        for (uint32_t i = 0; i < count && !found; i++)
            found = strcmp(extensions[i].extensionName, name) == 0;
    free(extensions);
    return found;
}

static bool contains_ignoring_case(const char *haystack, const char *needle)
{
    size_t n = strlen(needle);
    for (; *haystack; haystack++) {
        size_t i = 0;
        while (i < n && haystack[i] && tolower((unsigned char)haystack[i]) == tolower((unsigned char)needle[i]))
            i++;
        if (i == n)
            return true;
    }
    return n == 0;
}

static gdr_status create_instance(gdr_vk_context *ctx, const gdr_vk_context_desc *desc, gdr_error *err)
{
    VkApplicationInfo app = {.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO, .pApplicationName = "gdr",
                             .pEngineName = "gdr", .apiVersion = VK_API_VERSION_1_3};
    const char *layers[1] = {"VK_LAYER_KHRONOS_validation"};
    const char *extensions[GDR_VK_MAX_INSTANCE_EXTENSIONS + 1];
    uint32_t extension_count = 0;
    bool validate = desc->validate;
    if (desc->instance_extension_count > GDR_VK_MAX_INSTANCE_EXTENSIONS)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%u instance extensions asked for, at most %d",
                             desc->instance_extension_count, GDR_VK_MAX_INSTANCE_EXTENSIONS);
    for (uint32_t i = 0; i < desc->instance_extension_count; i++)
        extensions[extension_count++] = desc->instance_extensions[i];
    if (validate)
        extensions[extension_count++] = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    if (validate && !layer_available(layers[0]))
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED,
                             "validation requested but VK_LAYER_KHRONOS_validation is not installed "
                             "(Debian package vulkan-validationlayers)");
    VkValidationFeatureEnableEXT sync_feature = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT features = {.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT,
                                        .enabledValidationFeatureCount = 1,
                                        .pEnabledValidationFeatures = &sync_feature};
    VkDebugUtilsMessengerCreateInfoEXT messenger_info = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
        .pNext = desc->synchronization_validation ? &features : NULL,
        .messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
        .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT,
        .pfnUserCallback = on_validation_message,
        .pUserData = ctx,
    };
    VkInstanceCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO,
        .pNext = validate ? &messenger_info : NULL,
        .pApplicationInfo = &app,
        .enabledLayerCount = validate ? 1u : 0u,
        .ppEnabledLayerNames = layers,
        .enabledExtensionCount = extension_count,
        .ppEnabledExtensionNames = extensions,
    };
    VkResult result = vkCreateInstance(&info, NULL, &ctx->instance);
    if (result == VK_ERROR_EXTENSION_NOT_PRESENT && desc->instance_extension_count > 0)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED,
                             "the Vulkan loader lacks an instance extension for presenting (%s%s): no presentable "
                             "Vulkan driver", desc->instance_extensions[0],
                             desc->instance_extension_count > 1 ? ", ..." : "");
    if (result == VK_ERROR_INCOMPATIBLE_DRIVER || result == VK_ERROR_INITIALIZATION_FAILED)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED,
                             "no Vulkan 1.3 driver found (%s); install mesa-vulkan-drivers for lavapipe",
                             gdr_vk_result_name(result));
    GDR_VK_TRY(err, result);
    if (validate) {
        PFN_vkCreateDebugUtilsMessengerEXT create_messenger =
            (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(ctx->instance, "vkCreateDebugUtilsMessengerEXT");
        if (!create_messenger)
            return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "VK_EXT_debug_utils is not available");
        messenger_info.pNext = NULL;
        GDR_VK_TRY(err, create_messenger(ctx->instance, &messenger_info, NULL, &ctx->messenger));
    }
    return GDR_OK;
}

static gdr_status choose_physical_device(gdr_vk_context *ctx, const char *wanted, gdr_error *err)
{
    uint32_t count = 0;
    GDR_VK_TRY(err, vkEnumeratePhysicalDevices(ctx->instance, &count, NULL));
    if (count == 0)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "no Vulkan device found");
    VkPhysicalDevice devices[16];
    if (count > 16)
        count = 16;
    VkResult result = vkEnumeratePhysicalDevices(ctx->instance, &count, devices);
    if (result != VK_SUCCESS && result != VK_INCOMPLETE)
        GDR_VK_TRY(err, result);

    int chosen = -1;
    if (!wanted) {
        for (uint32_t i = 0; i < count && chosen < 0; i++) {
            VkPhysicalDeviceProperties p;
            vkGetPhysicalDeviceProperties(devices[i], &p);
            if (p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU)
                chosen = (int)i;
        }
        if (chosen < 0)
            chosen = 0;
    } else {
        char *end;
        long index = strtol(wanted, &end, 10);
        if (*wanted && *end == '\0') {
            if (index < 0 || index >= (long)count)
                return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "--device %s: there are %u device(s), 0..%u",
                                     wanted, count, count - 1);
            chosen = (int)index;
        } else {
            for (uint32_t i = 0; i < count && chosen < 0; i++) {
                VkPhysicalDeviceProperties p;
                vkGetPhysicalDeviceProperties(devices[i], &p);
                if (contains_ignoring_case(p.deviceName, wanted))
                    chosen = (int)i;
            }
            if (chosen < 0) {
                char names[512] = "";
                for (uint32_t i = 0; i < count; i++) {
                    VkPhysicalDeviceProperties p;
                    vkGetPhysicalDeviceProperties(devices[i], &p);
                    size_t used = strlen(names);
                    snprintf(names + used, sizeof names - used, "%s%u: %s", i ? ", " : "", i, p.deviceName);
                }
                return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "--device %s: no such device (have %s)",
                                     wanted, names);
            }
        }
    }
    ctx->physical_device = devices[chosen];
    vkGetPhysicalDeviceProperties(ctx->physical_device, &ctx->properties);
    vkGetPhysicalDeviceMemoryProperties(ctx->physical_device, &ctx->memory_properties);
    return GDR_OK;
}

/* The meshlet pipeline needs task + mesh shaders, subgroup ballots in task shaders and room for a
 * cluster (GDR_MESH_* in gpu_config.h) in one mesh workgroup. */
static void check_mesh_shader_support(gdr_vk_context *ctx, VkShaderStageFlags subgroup_stages, bool disabled)
{
    ctx->has_mesh_shader = false;
    const char *why = NULL;
    VkPhysicalDeviceMeshShaderFeaturesEXT features = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT};
    VkPhysicalDeviceFeatures2 f2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &features};
    ctx->mesh_shader_properties = (VkPhysicalDeviceMeshShaderPropertiesEXT){
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_PROPERTIES_EXT};
    VkPhysicalDeviceProperties2 p2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2,
                                      .pNext = &ctx->mesh_shader_properties};
    if (disabled)
        why = "mesh shaders disabled by the caller";
    else if (!device_extension_available(ctx->physical_device, VK_EXT_MESH_SHADER_EXTENSION_NAME))
        why = "the device has no VK_EXT_mesh_shader";
    if (!why) {
        vkGetPhysicalDeviceFeatures2(ctx->physical_device, &f2);
        vkGetPhysicalDeviceProperties2(ctx->physical_device, &p2);
        ctx->mesh_shader_properties.pNext = NULL;
        const VkPhysicalDeviceMeshShaderPropertiesEXT *m = &ctx->mesh_shader_properties;
        if (!features.taskShader || !features.meshShader)
            why = "VK_EXT_mesh_shader without task or mesh shaders";
        else if (!(subgroup_stages & VK_SHADER_STAGE_TASK_BIT_EXT))
            why = "no subgroup operations in task shaders";
        else if (m->maxMeshOutputVertices < GDR_CLUSTER_MAX_VERTICES || m->maxMeshOutputPrimitives < GDR_CLUSTER_MAX_TRIANGLES)
            why = "mesh shaders cannot output a whole cluster";
    }
    if (why) {
        snprintf(ctx->mesh_shader_missing, sizeof ctx->mesh_shader_missing, "%s", why);
        return;
    }
    ctx->has_mesh_shader = true;
    ctx->mesh_shader_missing[0] = '\0';
}

/* Appends "name" to a comma-separated list of missing features. */
static void note_missing(char *list, size_t size, bool present, const char *name)
{
    if (present)
        return;
    size_t used = strlen(list);
    snprintf(list + used, size - used, "%s%s", used ? ", " : "", name);
}

static gdr_status create_device(gdr_vk_context *ctx, bool disable_mesh_shaders, bool disable_bc, bool swapchain,
                                gdr_error *err)
{
    VkPhysicalDevice pd = ctx->physical_device;
    if (ctx->properties.apiVersion < VK_API_VERSION_1_3)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "device '%s' supports Vulkan %u.%u; gdr needs 1.3",
                             ctx->properties.deviceName, VK_API_VERSION_MAJOR(ctx->properties.apiVersion),
                             VK_API_VERSION_MINOR(ctx->properties.apiVersion));

    VkPhysicalDeviceVulkan13Features f13 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    VkPhysicalDeviceVulkan12Features f12 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, .pNext = &f13};
    VkPhysicalDeviceVulkan11Features f11 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES, .pNext = &f12};
    VkPhysicalDeviceFeatures2 f2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &f11};
    vkGetPhysicalDeviceFeatures2(pd, &f2);

    VkPhysicalDeviceSubgroupProperties subgroup = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    VkPhysicalDeviceDriverProperties driver = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES, .pNext = &subgroup};
    VkPhysicalDeviceProperties2 p2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &driver};
    vkGetPhysicalDeviceProperties2(pd, &p2);
    ctx->subgroup_size = subgroup.subgroupSize;
    snprintf(ctx->driver_info, sizeof ctx->driver_info, "%s %s", driver.driverName, driver.driverInfo);

    char missing[512] = "";
    note_missing(missing, sizeof missing, f2.features.multiDrawIndirect, "multiDrawIndirect");
    note_missing(missing, sizeof missing, f2.features.drawIndirectFirstInstance, "drawIndirectFirstInstance");
    note_missing(missing, sizeof missing, f2.features.shaderInt64, "shaderInt64");
    note_missing(missing, sizeof missing, f2.features.fragmentStoresAndAtomics, "fragmentStoresAndAtomics");
    note_missing(missing, sizeof missing, f11.shaderDrawParameters, "shaderDrawParameters");
    note_missing(missing, sizeof missing, f12.drawIndirectCount, "drawIndirectCount");
    note_missing(missing, sizeof missing, f12.bufferDeviceAddress, "bufferDeviceAddress");
    note_missing(missing, sizeof missing, f12.scalarBlockLayout, "scalarBlockLayout");
    note_missing(missing, sizeof missing, f12.hostQueryReset, "hostQueryReset");
    note_missing(missing, sizeof missing, f12.samplerFilterMinmax, "samplerFilterMinmax"); /* depth pyramid */
    /* the bindless textures */
    note_missing(missing, sizeof missing, f12.runtimeDescriptorArray, "runtimeDescriptorArray");
    note_missing(missing, sizeof missing, f12.descriptorBindingPartiallyBound, "descriptorBindingPartiallyBound");
    note_missing(missing, sizeof missing, f12.shaderSampledImageArrayNonUniformIndexing,
                 "shaderSampledImageArrayNonUniformIndexing");
    note_missing(missing, sizeof missing, f13.dynamicRendering, "dynamicRendering");
    note_missing(missing, sizeof missing, f13.synchronization2, "synchronization2");
    note_missing(missing, sizeof missing, f13.maintenance4, "maintenance4");
    note_missing(missing, sizeof missing, (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0,
                 "subgroup operations in compute shaders");
    note_missing(missing, sizeof missing, (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_BALLOT_BIT) != 0,
                 "subgroup ballot");
    note_missing(missing, sizeof missing, (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT) != 0,
                 "subgroup arithmetic");
    note_missing(missing, sizeof missing, ctx->properties.limits.timestampComputeAndGraphics, "timestampComputeAndGraphics");
    if (missing[0])
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "device '%s' lacks required features: %s",
                             ctx->properties.deviceName, missing);

    uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &family_count, NULL);
    VkQueueFamilyProperties families[32];
    if (family_count > 32)
        family_count = 32;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &family_count, families);
    ctx->queue_family = UINT32_MAX;
    for (uint32_t i = 0; i < family_count && ctx->queue_family == UINT32_MAX; i++)
        if ((families[i].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) ==
                (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT) && families[i].timestampValidBits > 0)
            ctx->queue_family = i;
    if (ctx->queue_family == UINT32_MAX)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "device '%s' has no graphics+compute queue with timestamps",
                             ctx->properties.deviceName);

    /* Enable exactly what gdr uses. */
    VkPhysicalDeviceVulkan13Features e13 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES,
                                            .dynamicRendering = VK_TRUE, .synchronization2 = VK_TRUE,
                                            .maintenance4 = VK_TRUE};
    VkPhysicalDeviceVulkan12Features e12 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, .pNext = &e13,
                                            .drawIndirectCount = VK_TRUE, .bufferDeviceAddress = VK_TRUE,
                                            .scalarBlockLayout = VK_TRUE, .hostQueryReset = VK_TRUE,
                                            .samplerFilterMinmax = VK_TRUE, .runtimeDescriptorArray = VK_TRUE,
                                            .descriptorBindingPartiallyBound = VK_TRUE,
                                            .shaderSampledImageArrayNonUniformIndexing = VK_TRUE,
                                            /* the visibility buffer, where the device has it */
                                            .shaderBufferInt64Atomics = f12.shaderBufferInt64Atomics};
    ctx->has_buffer_int64_atomics = f12.shaderBufferInt64Atomics == VK_TRUE;
    VkPhysicalDeviceVulkan11Features e11 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES, .pNext = &e12,
                                            .shaderDrawParameters = VK_TRUE};
    VkPhysicalDeviceFeatures2 e2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &e11};
    e2.features.multiDrawIndirect = VK_TRUE;
    e2.features.drawIndirectFirstInstance = VK_TRUE;
    e2.features.shaderInt64 = VK_TRUE;
    e2.features.fragmentStoresAndAtomics = VK_TRUE; /* the overdraw view counts fragments */
    /* block-compressed textures where the device samples them, else they are decoded at upload */
    ctx->has_texture_compression_bc = f2.features.textureCompressionBC == VK_TRUE && !disable_bc;
    e2.features.textureCompressionBC = ctx->has_texture_compression_bc ? VK_TRUE : VK_FALSE;
    VkPhysicalDeviceMeshShaderFeaturesEXT mesh = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT,
                                                  .taskShader = VK_TRUE, .meshShader = VK_TRUE};
    check_mesh_shader_support(ctx, subgroup.supportedStages, disable_mesh_shaders);
    const char *extensions[2];
    uint32_t extension_count = 0;
    if (swapchain && !device_extension_available(pd, VK_KHR_SWAPCHAIN_EXTENSION_NAME))
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "device '%s' cannot present: it has no %s",
                             ctx->properties.deviceName, VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    if (swapchain)
        extensions[extension_count++] = VK_KHR_SWAPCHAIN_EXTENSION_NAME;
    if (ctx->has_mesh_shader) {
        extensions[extension_count++] = VK_EXT_MESH_SHADER_EXTENSION_NAME;
        e13.pNext = &mesh;
    }
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info = {.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
                                          .queueFamilyIndex = ctx->queue_family, .queueCount = 1,
                                          .pQueuePriorities = &priority};
    VkDeviceCreateInfo info = {.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, .pNext = &e2, .queueCreateInfoCount = 1,
                               .pQueueCreateInfos = &queue_info, .enabledExtensionCount = extension_count,
                               .ppEnabledExtensionNames = extensions};
    GDR_VK_TRY(err, vkCreateDevice(pd, &info, NULL, &ctx->device));
    if (ctx->has_mesh_shader) {
        ctx->cmd_draw_mesh_tasks_indirect =
            (PFN_vkCmdDrawMeshTasksIndirectEXT)vkGetDeviceProcAddr(ctx->device, "vkCmdDrawMeshTasksIndirectEXT");
        if (!ctx->cmd_draw_mesh_tasks_indirect) {
            ctx->has_mesh_shader = false;
            snprintf(ctx->mesh_shader_missing, sizeof ctx->mesh_shader_missing,
                     "vkCmdDrawMeshTasksIndirectEXT could not be loaded");
        }
    }
    vkGetDeviceQueue(ctx->device, ctx->queue_family, 0, &ctx->queue);
    VkCommandPoolCreateInfo pool_info = {.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
                                         .flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
                                         .queueFamilyIndex = ctx->queue_family};
    GDR_VK_TRY(err, vkCreateCommandPool(ctx->device, &pool_info, NULL, &ctx->command_pool));
    return GDR_OK;
}

/* The desc with its implied fields resolved (a NULL desc: the defaults). */
static gdr_vk_context_desc context_desc_defaults(const gdr_vk_context_desc *in)
{
    gdr_vk_context_desc d = in ? *in : (gdr_vk_context_desc){0};
    d.validate = d.validate || d.synchronization_validation; /* the layer carries the feature */
    return d;
}

gdr_status gdr_vk_context_create(const gdr_vk_context_desc *desc_in, gdr_vk_context **out, gdr_error *err)
{
    const gdr_vk_context_desc d = context_desc_defaults(desc_in), *desc = &d;
    gdr_vk_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
    gdr_status status = create_instance(ctx, desc, err);
    if (status == GDR_OK)
        status = choose_physical_device(ctx, desc->device, err);
    if (status == GDR_OK)
        status = create_device(ctx, desc->disable_mesh_shaders, desc->disable_texture_compression_bc, desc->swapchain,
                               err);
    if (status != GDR_OK) {
        gdr_vk_context_destroy(ctx);
        return status;
    }
    *out = ctx;
    return GDR_OK;
}

void gdr_vk_context_destroy(gdr_vk_context *ctx)
{
    if (!ctx)
        return;
    if (ctx->device) {
        vkDeviceWaitIdle(ctx->device);
        if (ctx->command_pool)
            vkDestroyCommandPool(ctx->device, ctx->command_pool, NULL);
        vkDestroyDevice(ctx->device, NULL);
    }
    if (ctx->messenger) {
        PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger =
            (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(ctx->instance, "vkDestroyDebugUtilsMessengerEXT");
        if (destroy_messenger)
            destroy_messenger(ctx->instance, ctx->messenger, NULL);
    }
    if (ctx->instance)
        vkDestroyInstance(ctx->instance, NULL);
    free(ctx);
}

gdr_status gdr_vk_begin_one_time(gdr_vk_context *ctx, VkCommandBuffer *out, gdr_error *err)
{
    VkCommandBufferAllocateInfo alloc = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                         .commandPool = ctx->command_pool,
                                         .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, .commandBufferCount = 1};
    GDR_VK_TRY(err, vkAllocateCommandBuffers(ctx->device, &alloc, out));
    VkCommandBufferBeginInfo begin = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                      .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
    GDR_VK_TRY(err, vkBeginCommandBuffer(*out, &begin));
    return GDR_OK;
}

gdr_status gdr_vk_end_one_time(gdr_vk_context *ctx, VkCommandBuffer cmd, gdr_error *err)
{
    gdr_status status = GDR_OK;
    VkResult result = vkEndCommandBuffer(cmd);
    if (result == VK_SUCCESS) {
        VkSubmitInfo submit = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO, .commandBufferCount = 1, .pCommandBuffers = &cmd};
        result = vkQueueSubmit(ctx->queue, 1, &submit, VK_NULL_HANDLE);
        if (result == VK_SUCCESS)
            result = vkQueueWaitIdle(ctx->queue);
    }
    if (result != VK_SUCCESS)
        status = gdr_error_set(err, GDR_ERROR_VULKAN, "one-time command buffer failed: %s", gdr_vk_result_name(result));
    vkFreeCommandBuffers(ctx->device, ctx->command_pool, 1, &cmd);
    return status;
}
