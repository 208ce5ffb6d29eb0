/* The CPU-driven baseline (seed 003's "before"): every frame the CPU culls the instances
 * with the gdr/cull.h library (octree, frustum planes, the precomputed visibility) and records, per visible instance, seed 003's
 * six commands: its own binds (pipeline, vertex buffer, index buffer, descriptor set, push
 * constants) and one vkCmdDrawIndexed. It exists to be
 * measured against the GPU-driven pipelines on the same scene and camera, and to draw the same image. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/cull.h"
#include "render/renderer_internal.h"
#include "render/cpu_driven.h"
#include "render/frame.h"
#include "render/pvs_frame.h"

/* The bounds of a moved instance: the mesh sphere under its transform, as the GPU culls it. */
static gdr_cull_object object_from_instance(const GdrGpuInstance *instance, const GdrGpuMesh *mesh)
{
    gdr_vec4 b = mesh->bounds;
    gdr_vec3 center = gdr_mat4_transform_point(instance->model, (gdr_vec3){b.x, b.y, b.z});
    float radius = b.w * gdr_mat4_max_axis_scale(instance->model);
    return (gdr_cull_object){.center = center, .radius = radius, .extent = {radius, radius, radius},
                             .min_screen_size = instance->min_screen_size,
                             .max_screen_size = instance->max_screen_size};
}

/* A mesh without its positions (a scene read for streaming): the box around its bounding sphere. */
static gdr_cull_mesh_bounds sphere_box(gdr_vec4 s)
{
    return (gdr_cull_mesh_bounds){.lo = {s.x - s.w, s.y - s.w, s.z - s.w}, .hi = {s.x + s.w, s.y + s.w, s.z + s.w},
                                  .sphere = s};
}

/* Keeps only what the instances' bounds need of the scene, per mesh (the renderer holds no pointer
 * into it; the instances' transforms are in r->scene.cpu_instances): the culling structures are
 * built when the pipeline is first used, so a renderer that never draws with it pays O(meshes). */
gdr_status gdr_cpu_path_create(gdr_renderer *r, const gdr_scene *scene, gdr_error *err)
{
    gdr_cpu_path *cpu = &r->cpu;
    cpu->mesh_bounds = malloc(sizeof *cpu->mesh_bounds * (scene->mesh_count ? scene->mesh_count : 1));
    if (!cpu->mesh_bounds)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "CPU pipeline: out of memory for %u meshes",
                             scene->mesh_count);
    cpu->mesh_count = scene->mesh_count;
    for (uint32_t m = 0; m < scene->mesh_count; m++)
        cpu->mesh_bounds[m] = scene->geometry_in_pages ? sphere_box(scene->meshes[m].bounds)
                                                       : gdr_cull_mesh_bounds_of(&scene->meshes[m]);
    return GDR_OK;
}

/* The library's own bounds of every instance (a box and a sphere from the transformed mesh box),
 * from the instances' current transforms, and the cull scene over them. */
static gdr_status build_cull_scene(gdr_renderer *r, gdr_error *err)
{
    gdr_cpu_path *cpu = &r->cpu;
    uint32_t count = r->scene.instance_count;
    gdr_cull_object *objects = malloc(sizeof *objects * (count ? count : 1));
    free(cpu->visible_bits); /* from an attempt that ran out of memory */
    free(cpu->visible);
    cpu->visible_bits = calloc(gdr_cull_word_count(count) + 1, sizeof(uint32_t));
    cpu->visible = malloc(sizeof(uint32_t) * (count ? count : 1));
    if (!objects || !cpu->visible_bits || !cpu->visible) {
        free(objects);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "CPU pipeline: out of memory for %u instances", count);
    }
    const gdr_cull_mesh_bounds none = {.lo = {1, 1, 1}, .hi = {0, 0, 0}};
    for (uint32_t i = 0; i < count; i++) {
        const GdrGpuInstance *instance = &r->scene.cpu_instances[i];
        const gdr_cull_mesh_bounds *b = instance->mesh < cpu->mesh_count ? &cpu->mesh_bounds[instance->mesh] : &none;
        objects[i] = gdr_cull_object_from_mesh_bounds(b, &instance->model);
        if (gdr_render_pvs_is_moved(r, i)) /* the precomputed visibility does not know where it is */
            objects[i].flags |= GDR_CULL_OBJECT_DYNAMIC;
        objects[i].min_screen_size = instance->min_screen_size;
        objects[i].max_screen_size = instance->max_screen_size;
    }
    gdr_cull_scene_desc desc = {.objects = objects, .object_count = count};
    gdr_status status = gdr_cull_scene_create(&desc, &cpu->cull_scene, err);
    free(objects);
    return status;
}

void gdr_cpu_path_destroy(gdr_renderer *r)
{
    free(r->cpu.mesh_bounds);
    gdr_cull_scene_destroy(r->cpu.cull_scene);
    free(r->cpu.visible_bits);
    free(r->cpu.visible);
    memset(&r->cpu, 0, sizeof r->cpu);
}

gdr_status gdr_cpu_path_update_instance(gdr_renderer *r, uint32_t index, gdr_error *err)
{
    if (!r->cpu.cull_scene)
        return GDR_OK; /* built from the current transforms when first used */
    const GdrGpuInstance *instance = &r->scene.cpu_instances[index];
    gdr_cull_object object = object_from_instance(instance, &r->scene.cpu_meshes[instance->mesh]);
    if (gdr_render_pvs_is_moved(r, index))
        object.flags |= GDR_CULL_OBJECT_DYNAMIC;
    return gdr_cull_scene_update(r->cpu.cull_scene, index, 1, &object, err);
}

gdr_status gdr_cpu_path_cull(gdr_renderer *r, const gdr_frame_desc *frame, gdr_error *err)
{
    gdr_cpu_path *cpu = &r->cpu;
    if (!cpu->cull_scene) { /* first use: not part of the frame's culling time */
        gdr_status built = build_cull_scene(r, err);
        if (built != GDR_OK)
            return built;
    }
    double start = gdr_now_ms();
    gdr_status status = GDR_OK;
    gdr_cull_stats cull_stats = {0};
    if (frame->cull == GDR_CULL_OFF) { /* nothing culled: every instance with something to draw */
        memset(cpu->visible_bits, 0, sizeof(uint32_t) * gdr_cull_word_count(r->scene.instance_count));
        for (uint32_t i = 0; i < r->scene.instance_count; i++)
            if (r->scene.cpu_meshes[r->scene.cpu_instances[i].mesh].index_count > 0)
                cpu->visible_bits[i / 32] |= 1u << (i % 32);
    } else {
        gdr_cull_view view = {.min_screen_size = frame->min_screen_size, .clip_plane = frame->clip_plane,
                              .visibility = gdr_render_pvs_wanted(r, frame) ? r->pvs.cache : NULL};
        gdr_frame_matrices(r, frame->cull_camera ? frame->cull_camera : &frame->camera, &view.projection,
                           &view.view);
        gdr_cull_result result = {.visible = cpu->visible_bits};
        status = gdr_cull_execute(cpu->cull_scene, &view, NULL, &result, &cull_stats, err);
    }
    cpu->pvs_culled = cull_stats.precomputed;
    cpu->pvs_cell_found = cull_stats.visibility_cell_found;
    if (status != GDR_OK)
        return status;
    uint32_t count = 0;
    uint64_t triangles = 0;
    for (uint32_t w = 0; w < gdr_cull_word_count(r->scene.instance_count); w++) {
        for (uint32_t bits = cpu->visible_bits[w]; bits; bits &= bits - 1) {
            uint32_t i = w * 32 + (uint32_t)__builtin_ctz(bits);
            cpu->visible[count++] = i;
            triangles += r->scene.cpu_meshes[r->scene.cpu_instances[i].mesh].index_count / 3;
        }
    }
    cpu->visible_count = count;
    cpu->triangles = triangles;
    cpu->cull_ms += gdr_now_ms() - start;
    return GDR_OK;
}

void gdr_cpu_path_record_draws(gdr_renderer *r, VkCommandBuffer cmd, const GdrGpuPushConstants *push)
{
    const gdr_gpu_scene *g = &r->scene;
    for (uint32_t v = 0; v < r->cpu.visible_count; v++) {
        uint32_t i = r->cpu.visible[v];
        const GdrGpuMesh *mesh = &g->cpu_meshes[g->cpu_instances[i].mesh];
        /* As seed 003's renderer does for every object: bindPipeline, bindVertexBuffers,
         * bindIndexBuffer, bindDescriptorSets, pushConstants, drawIndexed. gdr's scenes draw with
         * one pipeline and the frame's descriptor sets (0 and the bindless textures), so those two
         * binds name the same objects each time, as in an engine that binds per object without
         * sorting. */
        const VkDescriptorSet sets[2] = {r->occlusion.set, r->materials.set};
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, r->pipelines[GDR_PIPE_DRAW_INDEXED]);
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, r->layout, 0, 2, sets, 0, NULL);
        /* The vertex buffer from its start and the mesh's first vertex as the draw's vertexOffset, so
         * that gl_VertexIndex is the pool-global index the vertex colours are looked up by. */
        const VkDeviceSize buffer_start = 0;
        vkCmdBindVertexBuffers(cmd, 0, 1, &g->vertices.buffer, &buffer_start);
        vkCmdBindIndexBuffer(cmd, g->indices.buffer, (VkDeviceSize)mesh->first_index * sizeof(uint32_t),
                             VK_INDEX_TYPE_UINT32);
        vkCmdPushConstants(cmd, r->layout, VK_SHADER_STAGE_ALL, 0, sizeof *push, push);
        vkCmdDrawIndexed(cmd, mesh->index_count, 1, 0, (int32_t)mesh->vertex_offset, i);
    }
}
