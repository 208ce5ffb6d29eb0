/* The depth pyramid (src/render/hzb.c) on the default device (lavapipe in CI), with the validation
 * layer and synchronization validation on: any message fails the test.
 *
 * For odd, even and non-power-of-two depth sizes, a D32 depth image is filled with known random
 * values, the pyramid is built, and every level is read back and compared, float for float, with
 * a CPU reference computed independently (each depth pixel scattered into every level-0 texel whose
 * area it overlaps, then 2x2 minima); conservativeness is also checked directly (every level-L
 * texel <= every depth pixel beneath it). Each size builds twice in one command buffer, between
 * depth-only rendering passes, to exercise the barriers. Finally the occlusion query of
 * occlusion_math.h runs in GLSL (tests/gpu/hzb_sample.comp.glsl) with the one fetch through the
 * pyramid's min-reduction sampler: the footprint must match the C version and the fetch must
 * equal the minimum of exactly the footprint's texels. */
#include <stdlib.h>
#include <string.h>

#include "render/hzb.h"
#include "test_util.h"
#include "vk/vk_buffer.h"
#include "vk/vk_descriptors.h"
#include "vk/vk_image.h"

static const uint32_t hzb_sample_code[] =
#include "hzb_sample.comp.spv.inc"
    ;

_Static_assert(sizeof(GdrOcclusionParams) == 32, "GdrOcclusionParams: 8 scalars, as hzb_sample.comp.glsl reads them");

#define SPHERES 4096

typedef struct sample_pass {
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline pipeline;
} sample_pass;

typedef struct sample_push {
    GdrOcclusionParams params;
    uint32_t count;
} sample_push;

/* --- CPU reference --- */

typedef struct pyramid {
    uint32_t width, height, levels;
    uint32_t level_width[GDR_HZB_MAX_LEVELS], level_height[GDR_HZB_MAX_LEVELS];
    size_t offset[GDR_HZB_MAX_LEVELS]; /* in floats, levels packed one after the other */
    size_t total;
} pyramid;

static uint32_t floor_pow2(uint32_t n)
{
    return 1u << (31 - __builtin_clz(n));
}

static void pyramid_shape(uint32_t depth_width, uint32_t depth_height, pyramid *p)
{
    p->width = floor_pow2(depth_width);
    p->height = floor_pow2(depth_height);
    p->levels = 32 - (uint32_t)__builtin_clz(p->width > p->height ? p->width : p->height);
    p->total = 0;
    for (uint32_t l = 0; l < p->levels; l++) {
        p->level_width[l] = p->width >> l ? p->width >> l : 1;
        p->level_height[l] = p->height >> l ? p->height >> l : 1;
        p->offset[l] = p->total;
        p->total += (size_t)p->level_width[l] * p->level_height[l];
    }
}

/* Level-0 texels (of `texels` over `pixels`) whose area [t pixels/texels, (t+1) pixels/texels)
 * overlaps pixel [x, x + 1): exact integer comparisons, at most 2 since a texel is >= 1 pixel. */
static uint32_t overlapping_texels(uint32_t x, uint32_t pixels, uint32_t texels, uint32_t out[2])
{
    uint32_t count = 0;
    uint64_t guess = (uint64_t)x * texels / pixels;
    for (uint64_t t = guess > 0 ? guess - 1 : 0; t <= guess + 2 && t < texels; t++)
        if (t * pixels < ((uint64_t)x + 1) * texels && (t + 1) * pixels > (uint64_t)x * texels) {
            if (count < 2)
                out[count] = (uint32_t)t;
            count++;
        }
    return count;
}

static float *reference_pyramid(const float *depth, uint32_t dw, uint32_t dh, const pyramid *p)
{
    float *r = malloc(p->total * sizeof *r);
    for (size_t i = 0; i < p->total; i++)
        r[i] = INFINITY;
    for (uint32_t y = 0; y < dh; y++) {
        uint32_t ty[2], ny = overlapping_texels(y, dh, p->height, ty);
        for (uint32_t x = 0; x < dw; x++) {
            uint32_t tx[2], nx = overlapping_texels(x, dw, p->width, tx);
            for (uint32_t j = 0; j < ny && j < 2; j++)
                for (uint32_t i = 0; i < nx && i < 2; i++)
                    r[ty[j] * p->width + tx[i]] = fminf(r[ty[j] * p->width + tx[i]], depth[y * dw + x]);
        }
    }
    for (uint32_t l = 1; l < p->levels; l++) {
        const float *src = r + p->offset[l - 1];
        float *dst = r + p->offset[l];
        uint32_t sw = p->level_width[l - 1], sh = p->level_height[l - 1];
        for (uint32_t y = 0; y < p->level_height[l]; y++)
            for (uint32_t x = 0; x < p->level_width[l]; x++) {
                float m = INFINITY;
                for (uint32_t j = 0; j < 2; j++)
                    for (uint32_t i = 0; i < 2; i++)
                        if (2 * x + i < sw && 2 * y + j < sh)
                            m = fminf(m, src[(2 * y + j) * sw + 2 * x + i]);
                dst[y * p->level_width[l] + x] = m;
            }
    }
    return r;
}

/* Every level-L texel <= every depth pixel in its footprint, straight from the GPU's levels; and
 * every depth pixel lies under some level-0 texel. */
static int count_conservative_violations(const float *gpu, const float *depth, uint32_t dw, uint32_t dh, const pyramid *p)
{
    int violations = 0;
    for (uint32_t y = 0; y < dh; y++) {
        uint32_t ty[2], ny = overlapping_texels(y, dh, p->height, ty);
        for (uint32_t x = 0; x < dw; x++) {
            uint32_t tx[2], nx = overlapping_texels(x, dw, p->width, tx);
            if (nx == 0 || ny == 0 || nx > 2 || ny > 2) {
                violations++;
                continue;
            }
            float d = depth[y * dw + x];
            for (uint32_t l = 0; l < p->levels; l++)
                for (uint32_t j = 0; j < ny; j++)
                    for (uint32_t i = 0; i < nx; i++)
                        violations += !(gpu[p->offset[l] + (ty[j] >> l) * p->level_width[l] + (tx[i] >> l)] <= d);
        }
    }
    return violations;
}

/* --- GPU side --- */

static gdr_status create_sample_pass(gdr_vk_context *ctx, sample_pass *pass, gdr_error *err)
{
    VkDescriptorSetLayoutBinding bindings[3] = {
        {0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
        {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
        {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
    };
    gdr_status status = gdr_vk_descriptor_set_layout_create(ctx, bindings, 3, &pass->set_layout, err);
    if (status == GDR_OK)
        status = gdr_vk_pipeline_layout_create_with_sets(ctx, &pass->set_layout, 1, VK_SHADER_STAGE_COMPUTE_BIT,
                                                         sizeof(sample_push), &pass->layout, err);
    if (status != GDR_OK)
        return status;
    VkShaderModuleCreateInfo module_info = {.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
                                            .codeSize = sizeof hzb_sample_code, .pCode = hzb_sample_code};
    VkShaderModule module;
    GDR_VK_TRY(err, vkCreateShaderModule(ctx->device, &module_info, NULL, &module));
    VkComputePipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage = {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_COMPUTE_BIT,
                  .module = module, .pName = "main"},
        .layout = pass->layout};
    VkResult result = vkCreateComputePipelines(ctx->device, VK_NULL_HANDLE, 1, &info, NULL, &pass->pipeline);
    vkDestroyShaderModule(ctx->device, module, NULL);
    GDR_VK_TRY(err, result);
    return GDR_OK;
}

static void destroy_sample_pass(gdr_vk_context *ctx, sample_pass *pass)
{
    vkDestroyPipeline(ctx->device, pass->pipeline, NULL);
    vkDestroyPipelineLayout(ctx->device, pass->layout, NULL);
    vkDestroyDescriptorSetLayout(ctx->device, pass->set_layout, NULL);
}

/* A depth-only rendering pass that loads and stores the depth: the raster phases of a frame, as far
 * as synchronization is concerned. */
static void depth_pass(VkCommandBuffer cmd, VkImageView view, uint32_t width, uint32_t height)
{
    VkRenderingAttachmentInfo depth = {.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = view,
                                       .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                                       .loadOp = VK_ATTACHMENT_LOAD_OP_LOAD, .storeOp = VK_ATTACHMENT_STORE_OP_STORE};
    VkRenderingInfo info = {.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = {{0, 0}, {width, height}},
                            .layerCount = 1, .pDepthAttachment = &depth};
    vkCmdBeginRendering(cmd, &info);
    vkCmdEndRendering(cmd);
}

static void copy_depth_in(VkCommandBuffer cmd, const gdr_vk_buffer *upload, const gdr_vk_image *depth)
{
    VkBufferImageCopy region = {.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1},
                                .imageExtent = {depth->width, depth->height, 1}};
    vkCmdCopyBufferToImage(cmd, upload->buffer, depth->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
}

/* Leaves the pyramid in TRANSFER_SRC_OPTIMAL: the next build starts from UNDEFINED anyway. */
static void copy_pyramid_out(VkCommandBuffer cmd, const gdr_hzb *hzb, const pyramid *p, const gdr_vk_buffer *readback)
{
    VkImageMemoryBarrier2 barrier = {.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
                                     .srcStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                     .srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                     .dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT,
                                     .dstAccessMask = VK_ACCESS_2_TRANSFER_READ_BIT, .oldLayout = GDR_HZB_LAYOUT,
                                     .newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
                                     .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .image = hzb->image,
                                     .subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, p->levels, 0, 1}};
    VkDependencyInfo dependency = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = 1,
                                   .pImageMemoryBarriers = &barrier};
    vkCmdPipelineBarrier2(cmd, &dependency);
    VkBufferImageCopy regions[GDR_HZB_MAX_LEVELS];
    for (uint32_t l = 0; l < p->levels; l++)
        regions[l] = (VkBufferImageCopy){.bufferOffset = p->offset[l] * sizeof(float),
                                         .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, 1},
                                         .imageExtent = {p->level_width[l], p->level_height[l], 1}};
    vkCmdCopyImageToBuffer(cmd, hzb->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback->buffer, p->levels, regions);
}

static int compare_levels(const char *what, const float *gpu, const float *ref, const pyramid *p)
{
    int mismatches = 0;
    for (uint32_t l = 0; l < p->levels; l++)
        for (size_t i = 0; i < (size_t)p->level_width[l] * p->level_height[l]; i++)
            if (gpu[p->offset[l] + i] != ref[p->offset[l] + i]) {
                if (mismatches++ < 5)
                    fprintf(stderr, "%s: level %u texel (%zu, %zu): GPU %.9g, reference %.9g\n", what, l,
                            i % p->level_width[l], i / p->level_width[l], gpu[p->offset[l] + i], ref[p->offset[l] + i]);
            }
    return mismatches;
}

static void random_depth(unsigned *rng, float *depth, size_t count)
{
    for (size_t i = 0; i < count; i++)
        depth[i] = test_random(rng); /* [0, 1), 24 bits, exact in D32 */
}

static GdrOcclusionParams camera_params(const gdr_hzb *hzb, bool infinite, float aspect)
{
    const float fovy = 1.0f, znear = 0.1f, zfar = 200.0f;
    gdr_mat4 p = infinite ? gdr_perspective_reverse_z_infinite(fovy, aspect, znear)
                          : gdr_perspective_reverse_z(fovy, aspect, znear, zfar);
    GdrOcclusionParams params = {.p00 = p.m[0], .p11 = p.m[5], .p22 = p.m[10], .p23 = p.m[14], .znear = znear};
    gdr_hzb_occlusion_params(hzb, &params);
    return params;
}

static void random_spheres(unsigned *rng, const GdrOcclusionParams *params, float *spheres)
{
    for (int i = 0; i < SPHERES; i++) {
        float distance = test_random_range(rng, 0.05f, 150.0f);
        float x = test_random_range(rng, -1.2f, 1.2f) / params->p00 * distance;
        float y = test_random_range(rng, -1.2f, 1.2f) / params->p11 * distance;
        float r = distance * (test_random(rng) < 0.5f ? test_random_range(rng, 0.0005f, 0.02f)
                                                      : test_random_range(rng, 0.02f, 0.9f));
        spheres[4 * i + 0] = x;
        spheres[4 * i + 1] = y;
        spheres[4 * i + 2] = -distance;
        spheres[4 * i + 3] = r;
    }
}

/* The GLSL query against the C one, and the fetched value against the footprint's minimum. */
static void check_samples(const uint32_t *results, const float *spheres, const GdrOcclusionParams *params,
                          const float *levels, const pyramid *p, int *testable_count)
{
    int footprint_differs = 0;
    for (int i = 0; i < SPHERES; i++) {
        const uint32_t *g = results + 8 * i;
        gdr_vec3 c = {spheres[4 * i], spheres[4 * i + 1], spheres[4 * i + 2]};
        GdrOcclusionQuery q = gdr_occlusion_query(c, spheres[4 * i + 3], *params);
        CHECK(g[0] == (q.testable ? 1u : 0u));
        if (!q.testable || g[0] != 1u)
            continue;
        (*testable_count)++;
        uint32_t level = g[1], x0 = g[2], y0 = g[3], x1 = g[4], y1 = g[5];
        bool same = level == (uint32_t)q.level && x0 == (uint32_t)q.x0 && y0 == (uint32_t)q.y0 &&
                    x1 == (uint32_t)q.x1 && y1 == (uint32_t)q.y1;
        if (!same) {
            /* A different log2 rounding may pick another level: still a valid footprint? */
            footprint_differs++;
            GdrSphereRect rect = gdr_sphere_screen_rect(c, spheres[4 * i + 3], params->znear, params->p00, params->p11);
            float lo_x = fminf(fmaxf(rect.u0 * p->width - GDR_HZB_RECT_PAD, 0), (float)p->width);
            float hi_x = fminf(fmaxf(rect.u1 * p->width + GDR_HZB_RECT_PAD, 0), (float)p->width);
            float lo_y = fminf(fmaxf(rect.v0 * p->height - GDR_HZB_RECT_PAD, 0), (float)p->height);
            float hi_y = fminf(fmaxf(rect.v1 * p->height + GDR_HZB_RECT_PAD, 0), (float)p->height);
            CHECK(level < p->levels && x1 - x0 <= 1 && y1 - y0 <= 1);
            CHECK(gdr_occ_texel(lo_x, (gdr_int)level, p->width) >= (gdr_int)x0 &&
                  gdr_occ_texel(hi_x, (gdr_int)level, p->width) <= (gdr_int)x1);
            CHECK(gdr_occ_texel(lo_y, (gdr_int)level, p->height) >= (gdr_int)y0 &&
                  gdr_occ_texel(hi_y, (gdr_int)level, p->height) <= (gdr_int)y1);
        }
        if (level >= p->levels || x1 >= p->level_width[level] || y1 >= p->level_height[level] || x0 > x1 || y0 > y1) {
            CHECK(false);
            continue;
        }
        float expected = INFINITY;
        for (uint32_t y = y0; y <= y1; y++)
            for (uint32_t x = x0; x <= x1; x++)
                expected = fminf(expected, levels[p->offset[level] + y * p->level_width[level] + x]);
        float fetched, nearest;
        memcpy(&fetched, &g[6], sizeof fetched);
        memcpy(&nearest, &g[7], sizeof nearest);
        if (fetched != expected)
            fprintf(stderr, "sphere %d: level %u texels [%u, %u] x [%u, %u]: fetched %.9g, minimum %.9g\n", i, level, x0,
                    x1, y0, y1, fetched, expected);
        CHECK(fetched == expected);
        CHECK_NEAR(nearest, q.nearest_depth, 1e-6 * (fabs(q.nearest_depth) + 1e-3));
    }
    if (footprint_differs)
        printf("  %d GPU footprints differ from the C ones (checked valid)\n", footprint_differs);
    CHECK(footprint_differs * 100 <= SPHERES);
}

static void test_size(gdr_vk_context *ctx, const sample_pass *pass, uint32_t dw, uint32_t dh, unsigned *rng)
{
    gdr_error err = {0};
    gdr_vk_allocator allocator;
    gdr_vk_allocator_init(&allocator, ctx);
    pyramid p;
    pyramid_shape(dw, dh, &p);
    size_t pixels = (size_t)dw * dh;
    gdr_vk_image depth = {0};
    gdr_vk_buffer upload[2] = {0}, readback[2] = {0}, spheres = {0}, results = {0};
    gdr_hzb hzb = {0};
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;
    gdr_status status = gdr_vk_image_create(&allocator, &(gdr_vk_image_desc){.width = dw, .height = dh, .format = VK_FORMAT_D32_SFLOAT,
                                  .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                           VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                                  .aspect = VK_IMAGE_ASPECT_DEPTH_BIT}, &depth, &err);
    for (int i = 0; i < 2 && status == GDR_OK; i++) {
        status = gdr_vk_buffer_create(&allocator, pixels * sizeof(float), VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                      GDR_VK_BUFFER_UPLOAD, &upload[i], &err);
        if (status == GDR_OK)
            status = gdr_vk_buffer_create(&allocator, p.total * sizeof(float), VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                          GDR_VK_BUFFER_READBACK, &readback[i], &err);
    }
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&allocator, SPHERES * 4 * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                      GDR_VK_BUFFER_UPLOAD, &spheres, &err);
    if (status == GDR_OK)
        status = gdr_vk_buffer_create(&allocator, SPHERES * 8 * sizeof(uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                      GDR_VK_BUFFER_READBACK, &results, &err);
    gdr_hzb_desc desc = {.depth_width = dw, .depth_height = dh, .depth_view = depth.view};
    if (status == GDR_OK)
        status = gdr_hzb_create(ctx, &allocator, &desc, &hzb, &err);
    VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2}};
    if (status == GDR_OK)
        status = gdr_vk_descriptor_pool_create(ctx, 1, sizes, 2, &pool, &err);
    if (status == GDR_OK)
        status = gdr_vk_descriptor_sets_allocate(ctx, pool, pass->set_layout, 1, &set, &err);
    if (status != GDR_OK) {
        fprintf(stderr, "%ux%u: %s\n", dw, dh, err.message);
        CHECK(false);
        goto done;
    }
    CHECK(hzb.width == p.width && hzb.height == p.height && hzb.level_count == p.levels);
    gdr_vk_write_image_descriptor(ctx, set, 0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, hzb.min_sampler, hzb.view,
                                  GDR_HZB_LAYOUT);
    gdr_vk_write_buffer_descriptor(ctx, set, 1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, spheres.buffer, 0, VK_WHOLE_SIZE);
    gdr_vk_write_buffer_descriptor(ctx, set, 2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, results.buffer, 0, VK_WHOLE_SIZE);

    float *depth_values[2];
    for (int i = 0; i < 2; i++) {
        depth_values[i] = upload[i].mapped;
        random_depth(rng, depth_values[i], pixels);
    }
    GdrOcclusionParams params = camera_params(&hzb, (dw + dh) % 2 == 0, (float)dw / (float)dh);
    random_spheres(rng, &params, spheres.mapped);

    VkCommandBuffer cmd;
    if (gdr_vk_begin_one_time(ctx, &cmd, &err) != GDR_OK) {
        fprintf(stderr, "%s\n", err.message);
        CHECK(false);
        goto done;
    }
    const VkPipelineStageFlags2 fragment_tests =
        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
    const VkAccessFlags2 depth_rw =
        VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    /* Round 1: depth from the first values, through an "early raster" pass, to the pyramid (helpers). */
    gdr_vk_image_barrier(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
                         VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    copy_depth_in(cmd, &upload[0], &depth);
    gdr_vk_image_barrier(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_TRANSFER_WRITE_BIT, fragment_tests, depth_rw);
    depth_pass(cmd, depth.view, dw, dh);
    gdr_hzb_record_depth_to_read(&hzb, cmd, depth.image, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
    gdr_hzb_record_build(&hzb, cmd, 0);
    /* The occlusion query and fetch, as a culling shader in reader_stages makes them. */
    sample_push push = {.params = params, .count = SPHERES};
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pass->pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pass->layout, 0, 1, &set, 0, NULL);
    vkCmdPushConstants(cmd, pass->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    vkCmdDispatch(cmd, (SPHERES + 63) / 64, 1, 1);
    copy_pyramid_out(cmd, &hzb, &p, &readback[0]);

    /* Round 2: back to rendering ("late raster"), new depth values by copy, the pyramid again. */
    gdr_hzb_record_depth_to_attachment(&hzb, cmd, depth.image, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
    depth_pass(cmd, depth.view, dw, dh);
    gdr_vk_image_barrier(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, fragment_tests,
                         VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_TRANSFER_WRITE_BIT);
    copy_depth_in(cmd, &upload[1], &depth);
    gdr_vk_image_barrier(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         hzb.depth_layout, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                         GDR_HZB_DEPTH_READ_STAGE, GDR_HZB_DEPTH_READ_ACCESS);
    /* The contract: reads of the pyramid outside reader_stages (the copy) are the caller's to wait for. */
    VkMemoryBarrier2 after_copy = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
                                   .srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT,
                                   .dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT};
    VkDependencyInfo after_copy_dependency = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1,
                                              .pMemoryBarriers = &after_copy};
    vkCmdPipelineBarrier2(cmd, &after_copy_dependency);
    gdr_hzb_record_build(&hzb, cmd, 0);
    copy_pyramid_out(cmd, &hzb, &p, &readback[1]);
    VkMemoryBarrier2 to_host = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
                                .srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                .srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                .dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT, .dstAccessMask = VK_ACCESS_2_HOST_READ_BIT};
    VkDependencyInfo to_host_dependency = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1,
                                           .pMemoryBarriers = &to_host};
    vkCmdPipelineBarrier2(cmd, &to_host_dependency);
    if (gdr_vk_end_one_time(ctx, cmd, &err) != GDR_OK) {
        fprintf(stderr, "%s\n", err.message);
        CHECK(false);
        goto done;
    }

    int mismatches = 0, violations = 0, testable = 0;
    for (int round = 0; round < 2; round++) {
        float *ref = reference_pyramid(depth_values[round], dw, dh, &p);
        char what[64];
        snprintf(what, sizeof what, "%ux%u round %d", dw, dh, round + 1);
        mismatches += compare_levels(what, readback[round].mapped, ref, &p);
        violations += count_conservative_violations(readback[round].mapped, depth_values[round], dw, dh, &p);
        free(ref);
    }
    check_samples(results.mapped, spheres.mapped, &params, readback[0].mapped, &p, &testable);
    printf("%4ux%-4u -> %4ux%-4u, %2u levels: %d mismatches, %d conservativeness violations, %d spheres tested\n", dw,
           dh, p.width, p.height, p.levels, mismatches, violations, testable);
    CHECK(mismatches == 0);
    CHECK(violations == 0);
    CHECK(testable > SPHERES / 4);

done:
    if (pool)
        vkDestroyDescriptorPool(ctx->device, pool, NULL);
    gdr_hzb_destroy(&hzb);
    for (int i = 0; i < 2; i++) {
        gdr_vk_buffer_destroy(ctx, &upload[i]);
        gdr_vk_buffer_destroy(ctx, &readback[i]);
    }
    gdr_vk_buffer_destroy(ctx, &spheres);
    gdr_vk_buffer_destroy(ctx, &results);
    gdr_vk_image_destroy(ctx, &depth);
    gdr_vk_allocator_destroy(&allocator);
}

/* Synchronization validation is really on: two unordered writes to one buffer must be reported. */
static void check_sync_validation_is_live(gdr_vk_context *ctx)
{
    gdr_error err = {0};
    gdr_vk_allocator allocator;
    gdr_vk_allocator_init(&allocator, ctx);
    gdr_vk_buffer buffer = {0};
    VkCommandBuffer cmd;
    unsigned before = ctx->validation_messages;
    if (gdr_vk_buffer_create(&allocator, 256, VK_BUFFER_USAGE_TRANSFER_DST_BIT, GDR_VK_BUFFER_DEVICE, &buffer, &err) ==
            GDR_OK &&
        gdr_vk_begin_one_time(ctx, &cmd, &err) == GDR_OK) {
        printf("(a synchronization hazard on purpose: the validation layer should report a WRITE_AFTER_WRITE)\n");
        vkCmdFillBuffer(cmd, buffer.buffer, 0, 256, 1u);
        vkCmdFillBuffer(cmd, buffer.buffer, 0, 256, 2u);
        CHECK(gdr_vk_end_one_time(ctx, cmd, &err) == GDR_OK);
    }
    CHECK(ctx->validation_messages > before);
    gdr_vk_buffer_destroy(ctx, &buffer);
    gdr_vk_allocator_destroy(&allocator);
}

int main(void)
{
    gdr_error err = {0};
    gdr_vk_context *ctx = NULL;
    gdr_vk_context_desc desc = {.validate = true, .synchronization_validation = true};
    if (gdr_vk_context_create(&desc, &ctx, &err) != GDR_OK) {
        fprintf(stderr, "context: %s\n", err.message);
        return 1;
    }
    printf("device: %s (%s)\n", ctx->properties.deviceName, ctx->driver_info);
    check_sync_validation_is_live(ctx);
    unsigned baseline = ctx->validation_messages;

    sample_pass pass = {0};
    if (create_sample_pass(ctx, &pass, &err) != GDR_OK) {
        fprintf(stderr, "sample pass: %s\n", err.message);
        CHECK(false);
    } else {
        unsigned rng = 2024;
        const uint32_t sizes[][2] = {{1, 1},     {2, 2},     {7, 5},    {3, 3},     {64, 64},    {333, 199},
                                     {1920, 1080}, {1023, 1}, {1, 1023}, {5, 9},    {129, 257},  {1024, 768}};
        for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++)
            test_size(ctx, &pass, sizes[i][0], sizes[i][1], &rng);
        destroy_sample_pass(ctx, &pass);
    }
    /* Bad input is refused, not crashed on. */
    gdr_hzb hzb;
    gdr_vk_allocator allocator;
    gdr_vk_allocator_init(&allocator, ctx);
    gdr_hzb_desc bad = {.depth_width = 0, .depth_height = 16};
    CHECK(gdr_hzb_create(ctx, &allocator, &bad, &hzb, &err) == GDR_ERROR_INVALID_ARGUMENT);
    gdr_hzb_destroy(&hzb);
    gdr_vk_allocator_destroy(&allocator);

    unsigned messages = ctx->validation_messages - baseline;
    if (messages)
        fprintf(stderr, "%u validation message(s)\n", messages);
    CHECK(messages == 0);
    gdr_vk_context_destroy(ctx);
    return test_finish("test_hzb");
}
