/* Two-phase occlusion culling's resources and the passes between the phases (occlusion.h). */
#include "render/occlusion.h"

#include <stdlib.h>

#include "render/renderer_internal.h"
#include "vk/vk_descriptors.h"

gdr_status gdr_occlusion_create(gdr_renderer *r, gdr_error *err)
{
    gdr_occlusion *o = &r->occlusion;
    VkPipelineStageFlags2 readers = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    VkShaderStageFlags reader_shaders = VK_SHADER_STAGE_COMPUTE_BIT;
    if (r->ctx->has_mesh_shader) {
        readers |= VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT;
        reader_shaders |= VK_SHADER_STAGE_TASK_BIT_EXT;
    }
    gdr_hzb_desc desc = {.depth_width = r->width, .depth_height = r->height, .depth_view = r->depth.view,
                         .depth_layout = VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL, .reader_stages = readers};
    gdr_status status = gdr_hzb_create(r->ctx, &r->allocator, &desc, &o->hzb, err);
    /* Binding 1: the colour target, which the visibility buffer's resolve writes as a storage image. */
    VkDescriptorSetLayoutBinding bindings[2] = {
        {0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, reader_shaders, NULL},
        {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL}};
    VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1}, {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1}};
    if (status == GDR_OK)
        status = gdr_vk_descriptor_set_layout_create(r->ctx, bindings, 2, &o->set_layout, err);
    if (status == GDR_OK)
        status = gdr_vk_descriptor_pool_create(r->ctx, 1, sizes, 2, &o->pool, err);
    if (status == GDR_OK)
        status = gdr_vk_descriptor_sets_allocate(r->ctx, o->pool, o->set_layout, 1, &o->set, err);
    if (status != GDR_OK)
        return status;
    gdr_vk_write_image_descriptor(r->ctx, o->set, 0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, o->hzb.min_sampler,
                                  o->hzb.view, GDR_HZB_LAYOUT);
    gdr_vk_write_image_descriptor(r->ctx, o->set, 1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_NULL_HANDLE, r->color.view,
                                  VK_IMAGE_LAYOUT_GENERAL);
    /* The culling shaders read the pyramid's descriptor even in frames that skip the test: give it
     * its layout (and "nothing is hidden": depth 0 is infinitely far) before any frame. */
    VkCommandBuffer cmd;
    status = gdr_vk_begin_one_time(r->ctx, &cmd, err);
    if (status != GDR_OK)
        return status;
    VkImageSubresourceRange all = {VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0, 1};
    VkImageMemoryBarrier2 to_general = {.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
                                        .srcStageMask = VK_PIPELINE_STAGE_2_NONE, .dstStageMask = VK_PIPELINE_STAGE_2_CLEAR_BIT,
                                        .dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                        .oldLayout = VK_IMAGE_LAYOUT_UNDEFINED, .newLayout = GDR_HZB_LAYOUT,
                                        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
                                        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .image = o->hzb.image,
                                        .subresourceRange = all};
    VkDependencyInfo dependency = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = 1,
                                   .pImageMemoryBarriers = &to_general};
    vkCmdPipelineBarrier2(cmd, &dependency);
    VkClearColorValue zero = {{0.0f, 0.0f, 0.0f, 0.0f}};
    vkCmdClearColorImage(cmd, o->hzb.image, GDR_HZB_LAYOUT, &zero, 1, &all);
    /* The clear before any frame's reads (the end of the one-time submission waits for it anyway,
     * but synchronization validation looks at the barrier). */
    VkMemoryBarrier2 after = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2, .srcStageMask = VK_PIPELINE_STAGE_2_CLEAR_BIT,
                              .srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
                              .dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                              .dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT};
    dependency = (VkDependencyInfo){.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1,
                                    .pMemoryBarriers = &after};
    vkCmdPipelineBarrier2(cmd, &dependency);
    return gdr_vk_end_one_time(r->ctx, cmd, err);
}

void gdr_occlusion_destroy(gdr_renderer *r)
{
    gdr_occlusion *o = &r->occlusion;
    if (!r->ctx)
        return;
    gdr_occlusion_scene_destroy(r);
    if (o->pool)
        vkDestroyDescriptorPool(r->ctx->device, o->pool, NULL);
    if (o->set_layout)
        vkDestroyDescriptorSetLayout(r->ctx->device, o->set_layout, NULL);
    gdr_hzb_destroy(&o->hzb);
    o->pool = VK_NULL_HANDLE;
    o->set_layout = VK_NULL_HANDLE;
}

gdr_status gdr_occlusion_scene_create(gdr_renderer *r, gdr_error *err)
{
    gdr_occlusion *o = &r->occlusion;
    const gdr_gpu_scene *g = &r->scene;
    /* One level's worth of visits: a frame that defers more traverses the rest in its early phase. */
    o->occluded_node_capacity = r->debug.occluded_node_capacity ? r->debug.occluded_node_capacity : g->traversal_capacity;
    const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    gdr_status status = gdr_vk_buffer_create(&r->allocator, 4 * (VkDeviceSize)(g->instance_count ? g->instance_count : 1),
                                             usage, GDR_VK_BUFFER_DEVICE, &o->occluded_instances, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, sizeof(GdrGpuNodeVisit) * (VkDeviceSize)o->occluded_node_capacity,
                                      usage, GDR_VK_BUFFER_DEVICE, &o->occluded_nodes, err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&r->allocator, 4 * (VkDeviceSize)g->task_capacity, usage, GDR_VK_BUFFER_DEVICE,
                                      &o->retest_masks, err);
    o->history_valid = false;
    return status;
}

void gdr_occlusion_scene_destroy(gdr_renderer *r)
{
    gdr_vk_buffer_destroy(r->ctx, &r->occlusion.occluded_instances);
    gdr_vk_buffer_destroy(r->ctx, &r->occlusion.occluded_nodes);
    gdr_vk_buffer_destroy(r->ctx, &r->occlusion.retest_masks);
    r->occlusion.history_valid = false;
}

void gdr_occlusion_params(const gdr_renderer *r, const gdr_mat4 *projection, float znear, GdrOcclusionParams *out)
{
    const float *m = projection->m;
    *out = (GdrOcclusionParams){.p00 = m[0], .p11 = m[5], .p22 = m[10], .p23 = m[14], .znear = znear};
    gdr_hzb_occlusion_params(&r->occlusion.hzb, out);
}
