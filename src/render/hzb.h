/* The depth pyramid (HZB) for occlusion culling (docs/OCCLUSION.md).
 *
 * R32_SFLOAT, level 0 the depth size rounded DOWN to powers of two per axis (so one texel covers at
 * least one depth pixel), every level down to 1x1, each texel the minimum of the depth beneath it
 * (reverse-Z: the farthest). Level 0 takes the minimum over every depth pixel its area overlaps, so
 * odd and non-power-of-two depth sizes lose no row or column.
 *
 * Built by compute, one dispatch per GDR_HZB_LEVELS_PER_DISPATCH levels (depthreduce.comp.glsl). Sampling it for the occlusion
 * test: src/gpu_shared/occlusion_math.h.
 *
 * Synchronization contract of gdr_hzb_record_build:
 *  - Before: the depth image is in desc.depth_layout and its writes are visible to
 *    GDR_HZB_DEPTH_READ_STAGE / GDR_HZB_DEPTH_READ_ACCESS (gdr_hzb_record_depth_to_read records
 *    exactly that barrier for a depth image just rendered). Accesses to the pyramid since the
 *    last build by stages other than desc.reader_stages (a copy, say) must be complete: a barrier
 *    from those stages to VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT.
 *  - The build itself waits for every earlier build and every earlier read by reader_stages
 *    (the pyramid goes UNDEFINED -> GENERAL: its old contents are discarded), and orders its levels.
 *  - After: the whole pyramid is in VK_IMAGE_LAYOUT_GENERAL (GDR_HZB_LAYOUT), its writes visible
 *    to SHADER_SAMPLED_READ in reader_stages. The depth image was read in GDR_HZB_DEPTH_READ_STAGE:
 *    a later depth write (the next raster phase) must wait for that stage
 *    (gdr_hzb_record_depth_to_attachment does). */
#ifndef GDR_HZB_H
#define GDR_HZB_H

#include "gpu_shared/occlusion_math.h"
#include "vk/vk_image.h"

#define GDR_HZB_FORMAT VK_FORMAT_R32_SFLOAT
#define GDR_HZB_LAYOUT VK_IMAGE_LAYOUT_GENERAL
#define GDR_HZB_MAX_LEVELS 15 /* 16384 (maxImageDimension2D of the largest devices) -> 1 */
#define GDR_HZB_DEPTH_READ_STAGE VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT
#define GDR_HZB_DEPTH_READ_ACCESS VK_ACCESS_2_SHADER_SAMPLED_READ_BIT

typedef struct gdr_hzb_desc {
    uint32_t depth_width, depth_height; /* > 0 */
    /* The depth buffer: a depth-aspect view of a single-level 2D image created with
     * VK_IMAGE_USAGE_SAMPLED_BIT. Written into descriptor sets at create: a renderer that replaces
     * its depth image (a resize) recreates the pyramid. */
    VkImageView depth_view;
    /* Layout of the depth image during builds: READ_ONLY_OPTIMAL (0 means that),
     * DEPTH_READ_ONLY_OPTIMAL, DEPTH_STENCIL_READ_ONLY_OPTIMAL, SHADER_READ_ONLY_OPTIMAL or GENERAL. */
    VkImageLayout depth_layout;
    /* Stages that sample the pyramid between builds (0 means VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
     * add VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT when task shaders read it (needs the taskShader
     * feature enabled, which gdr_vk_context does where ctx->has_mesh_shader). */
    VkPipelineStageFlags2 reader_stages;
} gdr_hzb_desc;

typedef struct gdr_hzb {
    gdr_vk_context *ctx;
    uint32_t depth_width, depth_height;
    uint32_t width, height;  /* level 0: powers of two, <= the depth size */
    uint32_t level_count;    /* floor(log2(max(width, height))) + 1; the last level is 1x1 */
    gdr_vk_image pyramid;
    VkImage image;           /* pyramid.image */
    VkImageView view;        /* pyramid.view: every level, for sampling: pair it with min_sampler */
    VkImageView level_views[GDR_HZB_MAX_LEVELS];
    /* Linear filter with VK_SAMPLER_REDUCTION_MODE_MIN, nearest mip, clamp to edge: one fetch gives
     * the minimum of the 2x2 texels around the coordinate that have a non-zero weight. */
    VkSampler min_sampler;
    VkSampler depth_sampler; /* nearest, for texelFetch from the depth buffer */
    VkImageLayout depth_layout;
    VkPipelineStageFlags2 reader_stages;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout pipeline_layout;
    VkPipeline pipeline;
    VkDescriptorPool pool;
    VkDescriptorSet sets[GDR_HZB_MAX_LEVELS]; /* set d: source (depth or level 5d - 1) -> levels 5d .. 5d + 4 */
} gdr_hzb;

/* Level-0 size for a depth size: the largest power of two <= depth_size (depth_size > 0). */
uint32_t gdr_hzb_size_for(uint32_t depth_size);

/* Creates the pyramid, its views and samplers and the build pipeline. Fails with
 * GDR_ERROR_UNSUPPORTED if R32_SFLOAT lacks storage or min/max filtering on the device. On failure
 * *out holds nothing that needs destroying. */
gdr_status gdr_hzb_create(gdr_vk_context *ctx, gdr_vk_allocator *allocator, const gdr_hzb_desc *desc, gdr_hzb *out,
                          gdr_error *err);
/* Frees what gdr_hzb_create made (not the memory: that goes with the allocator). The device must
 * be done with it. Accepts a zeroed gdr_hzb. */
void gdr_hzb_destroy(gdr_hzb *hzb);

/* Records the whole build into `cmd` (outside a render pass), with every barrier it needs; see the
 * synchronization contract above. With a `visibility_buffer` address (else 0), level 0 comes from
 * the depth in that buffer (GdrDepthReducePush.visibility_buffer, the depth image's size) instead
 * of the depth image: its writes must be visible to compute shader reads, and the depth image must
 * still be in the layout given at create (its descriptor stays bound; it is not read). */
void gdr_hzb_record_build(const gdr_hzb *hzb, VkCommandBuffer cmd, VkDeviceAddress visibility_buffer);

/* Records the barrier that makes a depth image that was just rendered (in `from`, typically
 * DEPTH_ATTACHMENT_OPTIMAL, written by the fragment tests) readable by the build, in the layout
 * given at create. */
void gdr_hzb_record_depth_to_read(const gdr_hzb *hzb, VkCommandBuffer cmd, VkImage depth_image, VkImageLayout from);
/* Records the barrier that gives the depth image back to rendering (`to`, typically
 * DEPTH_ATTACHMENT_OPTIMAL; contents kept), after the build's reads. */
void gdr_hzb_record_depth_to_attachment(const gdr_hzb *hzb, VkCommandBuffer cmd, VkImage depth_image, VkImageLayout to);

/* The pyramid's part of GdrOcclusionParams (the camera's part is the caller's). */
void gdr_hzb_occlusion_params(const gdr_hzb *hzb, GdrOcclusionParams *params);

#endif
