/* Two-phase occlusion culling (docs/OCCLUSION.md): the depth pyramid the culling shaders
 * sample (set 0, binding 0 of every frame pipeline), the visibility history of instances and
 * clusters, and the recording of the passes between the two phases. The culling logic itself is in
 * drawcull.comp (instances) and meshlet.task (clusters). */
#ifndef GDR_RENDER_OCCLUSION_H
#define GDR_RENDER_OCCLUSION_H

#include "gdr/renderer.h"
#include "render/hzb.h"
#include "vk/vk_buffer.h"

typedef struct gdr_renderer gdr_renderer;

typedef struct gdr_occlusion {
    gdr_hzb hzb;
    VkDescriptorSetLayout set_layout; /* binding 0: the pyramid with its min-reduction sampler */
    VkDescriptorPool pool;
    VkDescriptorSet set;
    /* History: one uint per instance (GDR_INSTANCE_VISIBLE_*), one bit per cluster of every instance
     * (GdrGpuInstance.meshlet_visibility_offset). Valid after an occlusion frame of the same scene
     * and pipeline; a camera cut (gdr_frame_desc.occlusion_camera_cut) discards it. */
    gdr_vk_buffer instance_visibility;
    gdr_vk_buffer meshlet_visibility;
    bool history_valid;
    gdr_pipeline history_pipeline;
} gdr_occlusion;

/* The pyramid (over the renderer's depth image, which needs VK_IMAGE_USAGE_SAMPLED_BIT), its
 * descriptor set, and the pyramid's first layout transition; before the frame pipelines (their
 * layout takes set_layout). */
gdr_status gdr_occlusion_create(gdr_renderer *r, gdr_error *err);
void gdr_occlusion_destroy(gdr_renderer *r);
/* The history buffers for the renderer's scene (after gdr_gpu_scene_upload), zeroed. */
gdr_status gdr_occlusion_scene_create(gdr_renderer *r, gdr_error *err);
void gdr_occlusion_scene_destroy(gdr_renderer *r);

/* Records the pyramid's build from the depth image just rendered (DEPTH_ATTACHMENT_OPTIMAL) and
 * gives the depth image back to rendering. */
void gdr_occlusion_record_pyramid(gdr_renderer *r, VkCommandBuffer cmd);
/* The camera's and the pyramid's part of the occlusion test for the frame globals. */
void gdr_occlusion_params(const gdr_renderer *r, const gdr_mat4 *projection, float znear, GdrOcclusionParams *out);

#endif
