/* Two-phase occlusion culling (docs/OCCLUSION.md): the depth pyramid the culling shaders
 * sample (set 0, binding 0 of every frame pipeline), the occluded lists the early phase fills for
 * the late one, last frame's camera, and the recording of the pyramid's build. The culling logic
 * itself is in shared/occlusion_test.h and the culling shaders (drawcull, lodtraverse, clustercull,
 * meshlet.task). */
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
    /* What the early phase defers to the late one (GdrGpuFrameBuffers): instance indices (one per
     * instance), node visits (occluded_node_capacity) and a retest mask per late task command. */
    gdr_vk_buffer occluded_instances;
    gdr_vk_buffer occluded_nodes;
    gdr_vk_buffer retest_masks;
    uint32_t occluded_node_capacity;
    /* History: the pyramid of the last frame's depth and its camera. Valid after an occlusion frame of
     * the same scene and pipeline; a camera cut (gdr_frame_desc.occlusion_camera_cut) discards it. */
    bool history_valid;
    gdr_pipeline history_pipeline;
    gdr_mat4 previous_view;
    GdrOcclusionParams previous_params;
} gdr_occlusion;

/* The pyramid (over the renderer's depth image, which needs VK_IMAGE_USAGE_SAMPLED_BIT), its
 * descriptor set, and the pyramid's first layout transition; before the frame pipelines (their
 * layout takes set_layout). */
gdr_status gdr_occlusion_create(gdr_renderer *r, gdr_error *err);
void gdr_occlusion_destroy(gdr_renderer *r);
/* The occluded lists for the renderer's scene (after gdr_gpu_scene_upload, which sizes the task list
 * and the traversal); no history yet. */
gdr_status gdr_occlusion_scene_create(gdr_renderer *r, gdr_error *err);
void gdr_occlusion_scene_destroy(gdr_renderer *r);

/* The camera's and the pyramid's part of the occlusion test for the frame globals. */
void gdr_occlusion_params(const gdr_renderer *r, const gdr_mat4 *projection, float znear, GdrOcclusionParams *out);

#endif
