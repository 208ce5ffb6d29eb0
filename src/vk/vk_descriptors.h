/* Descriptor sets, for the passes that touch images: storage images and samplers cannot be reached
 * through buffer device addresses, so these passes bind a descriptor set besides (or instead of)
 * the push-constant block that every other gdr pipeline uses (vk_pipeline.h).
 *
 * The sets come from ordinary pools (no VK_KHR_push_descriptor, which is not core in 1.3): a pass
 * allocates its sets once, writes them once, and rewrites them only while no submitted command
 * buffer uses them. */
#ifndef GDR_VK_DESCRIPTORS_H
#define GDR_VK_DESCRIPTORS_H

#include "vk/vk_context.h"

gdr_status gdr_vk_descriptor_set_layout_create(gdr_vk_context *ctx, const VkDescriptorSetLayoutBinding *bindings,
                                               uint32_t binding_count, VkDescriptorSetLayout *out, gdr_error *err);

/* A pipeline layout with `set_count` set layouts (set i = sets[i]) and, when push_constant_size > 0,
 * one push-constant range of that size visible to `push_constant_stages`. */
gdr_status gdr_vk_pipeline_layout_create_with_sets(gdr_vk_context *ctx, const VkDescriptorSetLayout *sets,
                                                   uint32_t set_count, VkShaderStageFlags push_constant_stages,
                                                   uint32_t push_constant_size, VkPipelineLayout *out, gdr_error *err);

/* A pool for exactly `max_sets` sets holding at most `sizes` descriptors (sizes[i].descriptorCount
 * of sizes[i].type, summed over all the sets). Sets are freed with the pool. */
gdr_status gdr_vk_descriptor_pool_create(gdr_vk_context *ctx, uint32_t max_sets, const VkDescriptorPoolSize *sizes,
                                         uint32_t size_count, VkDescriptorPool *out, gdr_error *err);

/* Allocates `count` sets of one layout from `pool` into out[0..count). */
gdr_status gdr_vk_descriptor_sets_allocate(gdr_vk_context *ctx, VkDescriptorPool pool, VkDescriptorSetLayout layout,
                                           uint32_t count, VkDescriptorSet *out, gdr_error *err);

/* Writes one image descriptor (sampled image, storage image or combined image sampler; `sampler`
 * is used only by the last) at array element 0 of `binding`. `layout` is the layout the image is in
 * whenever a command that uses the set executes. */
void gdr_vk_write_image_descriptor(gdr_vk_context *ctx, VkDescriptorSet set, uint32_t binding, VkDescriptorType type,
                                   VkSampler sampler, VkImageView view, VkImageLayout layout);

/* Writes one storage or uniform buffer descriptor (the whole range from `offset`). */
void gdr_vk_write_buffer_descriptor(gdr_vk_context *ctx, VkDescriptorSet set, uint32_t binding, VkDescriptorType type,
                                    VkBuffer buffer, VkDeviceSize offset, VkDeviceSize range);

/* A clamp-to-edge sampler with `filter` for magnification and minification, nearest mip selection,
 * every level reachable, and `reduction` (VK_SAMPLER_REDUCTION_MODE_MIN/MAX need the
 * samplerFilterMinmax feature, which gdr_vk_context_create enables). */
gdr_status gdr_vk_sampler_create(gdr_vk_context *ctx, VkFilter filter, VkSamplerReductionMode reduction,
                                 VkSampler *out, gdr_error *err);

#endif
