#include "render/hzb.h"

#include <assert.h>
#include <string.h>

#include "shaders/embedded_shaders.h"
#include "vk/vk_descriptors.h"
#include "vk/vk_image.h"

/* Workgroup size of depthreduce.comp.glsl: a TILE x TILE tile of the first level of a dispatch. */
#define HZB_TILE 16u

_Static_assert(sizeof(GdrDepthReducePush) == 32 && offsetof(GdrDepthReducePush, visibility_buffer) == 24,
               "GdrDepthReducePush: six uints and an address, as the shader reads them");

uint32_t gdr_hzb_size_for(uint32_t depth_size)
{
    assert(depth_size > 0);
    uint32_t size = 1;
    while (size <= depth_size / 2)
        size *= 2;
    return size;
}

static uint32_t level_count_for(uint32_t width, uint32_t height)
{
    uint32_t largest = width > height ? width : height, levels = 1;
    while ((largest >> levels) != 0)
        levels++;
    return levels;
}

static uint32_t level_size(uint32_t size0, uint32_t level)
{
    return size0 >> level ? size0 >> level : 1;
}

static gdr_status check_format(gdr_vk_context *ctx, gdr_error *err)
{
    VkFormatProperties3 props3 = {.sType = VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_3};
    VkFormatProperties2 props = {.sType = VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_2, .pNext = &props3};
    vkGetPhysicalDeviceFormatProperties2(ctx->physical_device, GDR_HZB_FORMAT, &props);
    VkFormatFeatureFlags2 needed = VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT | VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT |
                                   VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_FILTER_MINMAX_BIT |
                                   VK_FORMAT_FEATURE_2_TRANSFER_SRC_BIT;
    if ((props3.optimalTilingFeatures & needed) != needed)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED,
                             "depth pyramid: R32_SFLOAT on '%s' lacks storage, sampling, copies or min/max filtering "
                             "(has format features 0x%llx)",
                             ctx->properties.deviceName, (unsigned long long)props3.optimalTilingFeatures);
    return GDR_OK;
}

static gdr_status create_image(gdr_hzb *hzb, gdr_vk_allocator *allocator, gdr_error *err)
{
    /* transfer source: tests and debug views read levels back */
    gdr_vk_image_desc desc = {.width = hzb->width, .height = hzb->height, .format = GDR_HZB_FORMAT,
                              .usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                       VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                              .mip_levels = hzb->level_count};
    gdr_status status = gdr_vk_image_create(allocator, &desc, &hzb->pyramid, err);
    if (status != GDR_OK)
        return status;
    hzb->image = hzb->pyramid.image;
    hzb->view = hzb->pyramid.view;
    VkImageViewCreateInfo view = {.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, .image = hzb->image,
                                  .viewType = VK_IMAGE_VIEW_TYPE_2D, .format = GDR_HZB_FORMAT,
                                  .subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1}};
    for (uint32_t level = 0; level < hzb->level_count; level++) {
        view.subresourceRange.baseMipLevel = level;
        GDR_VK_TRY(err, vkCreateImageView(hzb->ctx->device, &view, NULL, &hzb->level_views[level]));
    }
    return GDR_OK;
}

static uint32_t dispatch_count(const gdr_hzb *hzb)
{
    return (hzb->level_count + GDR_HZB_LEVELS_PER_DISPATCH - 1) / GDR_HZB_LEVELS_PER_DISPATCH;
}

static gdr_status create_pipeline(gdr_hzb *hzb, gdr_error *err)
{
    gdr_vk_context *ctx = hzb->ctx;
    VkDescriptorSetLayoutBinding bindings[2] = {
        {.binding = 0, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT},
        {.binding = 1, .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
         .descriptorCount = GDR_HZB_LEVELS_PER_DISPATCH, .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT},
    };
    gdr_status status = gdr_vk_descriptor_set_layout_create(ctx, bindings, 2, &hzb->set_layout, err);
    if (status == GDR_OK)
        status = gdr_vk_pipeline_layout_create_with_sets(ctx, &hzb->set_layout, 1, VK_SHADER_STAGE_COMPUTE_BIT,
                                                         sizeof(GdrDepthReducePush), &hzb->pipeline_layout, err);
    if (status != GDR_OK)
        return status;

    VkShaderModuleCreateInfo module_info = {.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
                                            .codeSize = gdr_shader_depthreduce_comp.size,
                                            .pCode = gdr_shader_depthreduce_comp.code};
    VkShaderModule module;
    GDR_VK_TRY(err, vkCreateShaderModule(ctx->device, &module_info, NULL, &module));
    VkComputePipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage = {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_COMPUTE_BIT,
                  .module = module, .pName = "main"},
        .layout = hzb->pipeline_layout,
    };
    VkResult result = vkCreateComputePipelines(ctx->device, VK_NULL_HANDLE, 1, &info, NULL, &hzb->pipeline);
    vkDestroyShaderModule(ctx->device, module, NULL);
    GDR_VK_TRY(err, result);
    return GDR_OK;
}

/* Set d: the source (the depth image, or the level before the dispatch's first) and the
 * GDR_HZB_LEVELS_PER_DISPATCH levels from 5d (past the last level: the last one again, never
 * written). */
static gdr_status create_descriptors(gdr_hzb *hzb, VkImageView depth_view, gdr_error *err)
{
    gdr_vk_context *ctx = hzb->ctx;
    uint32_t sets = dispatch_count(hzb);
    VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, sets},
                                     {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, sets * GDR_HZB_LEVELS_PER_DISPATCH}};
    gdr_status status = gdr_vk_descriptor_pool_create(ctx, sets, sizes, 2, &hzb->pool, err);
    if (status == GDR_OK)
        status = gdr_vk_descriptor_sets_allocate(ctx, hzb->pool, hzb->set_layout, sets, hzb->sets, err);
    if (status != GDR_OK)
        return status;
    for (uint32_t d = 0; d < sets; d++) {
        uint32_t first = d * GDR_HZB_LEVELS_PER_DISPATCH;
        if (d == 0)
            gdr_vk_write_image_descriptor(ctx, hzb->sets[0], 0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                          hzb->depth_sampler, depth_view, hzb->depth_layout);
        else
            gdr_vk_write_image_descriptor(ctx, hzb->sets[d], 0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                          hzb->min_sampler, hzb->level_views[first - 1], GDR_HZB_LAYOUT);
        VkDescriptorImageInfo levels[GDR_HZB_LEVELS_PER_DISPATCH];
        for (uint32_t k = 0; k < GDR_HZB_LEVELS_PER_DISPATCH; k++) {
            uint32_t level = first + k < hzb->level_count ? first + k : hzb->level_count - 1;
            levels[k] = (VkDescriptorImageInfo){.imageView = hzb->level_views[level], .imageLayout = GDR_HZB_LAYOUT};
        }
        VkWriteDescriptorSet write = {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = hzb->sets[d],
                                      .dstBinding = 1, .descriptorCount = GDR_HZB_LEVELS_PER_DISPATCH,
                                      .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, .pImageInfo = levels};
        vkUpdateDescriptorSets(ctx->device, 1, &write, 0, NULL);
    }
    return GDR_OK;
}

/* The desc with every zero field given its default. */
static gdr_hzb_desc hzb_desc_defaults(const gdr_hzb_desc *in)
{
    gdr_hzb_desc d = *in;
    d.depth_layout = d.depth_layout ? d.depth_layout : VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL;
    d.reader_stages = d.reader_stages ? d.reader_stages : VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    return d;
}

gdr_status gdr_hzb_create(gdr_vk_context *ctx, gdr_vk_allocator *allocator, const gdr_hzb_desc *desc_in,
                          gdr_hzb *out, gdr_error *err)
{
    memset(out, 0, sizeof *out);
    const gdr_hzb_desc d = hzb_desc_defaults(desc_in), *desc = &d;
    if (desc->depth_width == 0 || desc->depth_height == 0 || !desc->depth_view)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "depth pyramid: depth size %ux%u, view %p",
                             desc->depth_width, desc->depth_height, (void *)desc->depth_view);
    gdr_hzb hzb = {.ctx = ctx, .depth_width = desc->depth_width, .depth_height = desc->depth_height,
                   .width = gdr_hzb_size_for(desc->depth_width), .height = gdr_hzb_size_for(desc->depth_height),
                   .depth_layout = desc->depth_layout, .reader_stages = desc->reader_stages};
    hzb.level_count = level_count_for(hzb.width, hzb.height);
    if (hzb.level_count > GDR_HZB_MAX_LEVELS)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "depth pyramid: depth size %ux%u needs %u levels (at most %d)",
                             desc->depth_width, desc->depth_height, hzb.level_count, GDR_HZB_MAX_LEVELS);
    gdr_status status = check_format(ctx, err);
    if (status == GDR_OK)
        status = create_image(&hzb, allocator, err);
    if (status == GDR_OK)
        status = gdr_vk_sampler_create(ctx, VK_FILTER_LINEAR, VK_SAMPLER_REDUCTION_MODE_MIN, &hzb.min_sampler, err);
    if (status == GDR_OK)
        status = gdr_vk_sampler_create(ctx, VK_FILTER_NEAREST, VK_SAMPLER_REDUCTION_MODE_WEIGHTED_AVERAGE,
                                       &hzb.depth_sampler, err);
    if (status == GDR_OK)
        status = create_pipeline(&hzb, err);
    if (status == GDR_OK)
        status = create_descriptors(&hzb, desc->depth_view, err);
    if (status != GDR_OK) {
        gdr_hzb_destroy(&hzb);
        return status;
    }
    *out = hzb;
    return GDR_OK;
}

void gdr_hzb_destroy(gdr_hzb *hzb)
{
    if (!hzb->ctx)
        return;
    VkDevice device = hzb->ctx->device;
    if (hzb->pool)
        vkDestroyDescriptorPool(device, hzb->pool, NULL);
    if (hzb->pipeline)
        vkDestroyPipeline(device, hzb->pipeline, NULL);
    if (hzb->pipeline_layout)
        vkDestroyPipelineLayout(device, hzb->pipeline_layout, NULL);
    if (hzb->set_layout)
        vkDestroyDescriptorSetLayout(device, hzb->set_layout, NULL);
    if (hzb->min_sampler)
        vkDestroySampler(device, hzb->min_sampler, NULL);
    if (hzb->depth_sampler)
        vkDestroySampler(device, hzb->depth_sampler, NULL);
    for (uint32_t level = 0; level < GDR_HZB_MAX_LEVELS; level++)
        if (hzb->level_views[level])
            vkDestroyImageView(device, hzb->level_views[level], NULL);
    gdr_vk_image_destroy(hzb->ctx, &hzb->pyramid);
    memset(hzb, 0, sizeof *hzb);
}

static void pyramid_barrier(VkCommandBuffer cmd, const gdr_hzb *hzb, uint32_t first_level, uint32_t level_count,
                            VkImageLayout from, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                            VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access)
{
    gdr_vk_image_transition t = {.image = hzb->image, .aspect = VK_IMAGE_ASPECT_COLOR_BIT, .from = from,
                                 .to = GDR_HZB_LAYOUT, .src = {src_stage, src_access}, .dst = {dst_stage, dst_access},
                                 .first_mip = first_level, .mip_count = level_count};
    gdr_vk_barrier(cmd, &(gdr_vk_barrier_desc){.images = &t, .image_count = 1});
}

void gdr_hzb_record_build(const gdr_hzb *hzb, VkCommandBuffer cmd, VkDeviceAddress visibility_buffer)
{
    const VkPipelineStageFlags2 compute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    /* Discard the old pyramid once the previous build's writes and every read of them are done. */
    pyramid_barrier(cmd, hzb, 0, hzb->level_count, VK_IMAGE_LAYOUT_UNDEFINED, compute | hzb->reader_stages,
                    VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, compute,
                    VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, hzb->pipeline);
    for (uint32_t d = 0; d < dispatch_count(hzb); d++) {
        uint32_t first = d * GDR_HZB_LEVELS_PER_DISPATCH, left = hzb->level_count - first;
        GdrDepthReducePush push = {
            .source_width = d == 0 ? hzb->depth_width : level_size(hzb->width, first - 1),
            .source_height = d == 0 ? hzb->depth_height : level_size(hzb->height, first - 1),
            .destination_width = level_size(hzb->width, first),
            .destination_height = level_size(hzb->height, first),
            .from_depth = d == 0,
            .level_count = left < GDR_HZB_LEVELS_PER_DISPATCH ? left : GDR_HZB_LEVELS_PER_DISPATCH,
            .visibility_buffer = d == 0 ? visibility_buffer : 0,
        };
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, hzb->pipeline_layout, 0, 1, &hzb->sets[d], 0, NULL);
        vkCmdPushConstants(cmd, hzb->pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
        vkCmdDispatch(cmd, (push.destination_width + HZB_TILE - 1) / HZB_TILE,
                      (push.destination_height + HZB_TILE - 1) / HZB_TILE, 1);
        if (first + push.level_count < hzb->level_count) /* the next dispatch samples the last level written */
            pyramid_barrier(cmd, hzb, first, push.level_count, GDR_HZB_LAYOUT, compute,
                            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, compute, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    }
    pyramid_barrier(cmd, hzb, 0, hzb->level_count, GDR_HZB_LAYOUT, compute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                    hzb->reader_stages, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

void gdr_hzb_record_depth_to_read(const gdr_hzb *hzb, VkCommandBuffer cmd, VkImage depth_image, VkImageLayout from)
{
    gdr_vk_image_barrier(cmd, depth_image, VK_IMAGE_ASPECT_DEPTH_BIT, from, hzb->depth_layout,
                         VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                         VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, GDR_HZB_DEPTH_READ_STAGE,
                         GDR_HZB_DEPTH_READ_ACCESS);
}

void gdr_hzb_record_depth_to_attachment(const gdr_hzb *hzb, VkCommandBuffer cmd, VkImage depth_image, VkImageLayout to)
{
    gdr_vk_image_barrier(cmd, depth_image, VK_IMAGE_ASPECT_DEPTH_BIT, hzb->depth_layout, to, GDR_HZB_DEPTH_READ_STAGE,
                         VK_ACCESS_2_NONE, VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                                               VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                         VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
}

void gdr_hzb_occlusion_params(const gdr_hzb *hzb, GdrOcclusionParams *params)
{
    params->hzb_width = hzb->width;
    params->hzb_height = hzb->height;
    params->hzb_levels = hzb->level_count;
}
