/* The built-in procedural scene: the default input, needing no file. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "gdr/procedural.h"
#include "gdr/scene.h"
#include "procedural/demo_materials.h"
#include "procedural/procedural_meshes.h"
#include "procedural/scene_random.h"

#define PI_F 3.14159265358979f

/* The desc with every zero field (or a NULL desc) given its default. */
static gdr_demo_desc demo_desc_defaults(const gdr_demo_desc *in)
{
    gdr_demo_desc d = in ? *in : (gdr_demo_desc){0};
    d.instances = d.instances ? d.instances : 10000;
    d.seed = d.seed ? d.seed : 1;
    d.spacing = d.spacing != 0.0f ? d.spacing : 4.0f;
    return d;
}

gdr_status gdr_scene_create_demo(const gdr_demo_desc *desc_in, gdr_scene **out, gdr_error *err)
{
    gdr_demo_desc desc = demo_desc_defaults(desc_in);
    if (!(desc.spacing >= 3.0f && desc.spacing <= 1000.0f))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "demo: spacing %g is outside [3, 1000]",
                             (double)desc.spacing);

    gdr_scene *scene;
    gdr_status status = gdr_scene_create(&scene, err);
    if (status != GDR_OK)
        return status;
    uint32_t shapes[4], ground;
    uint32_t side = (uint32_t)ceil(sqrt((double)desc.instances));
    float half = 0.5f * (float)side * desc.spacing + desc.spacing;
    if (status == GDR_OK) status = gdr_procedural_sphere(scene, 32, 16, &shapes[0], err);
    if (status == GDR_OK) status = gdr_procedural_torus(scene, 0.7f, 0.3f, 32, 16, &shapes[1], err);
    if (status == GDR_OK) status = gdr_procedural_box(scene, (gdr_vec3){0.7f, 0.7f, 0.7f}, &shapes[2], err);
    if (status == GDR_OK) status = gdr_procedural_blob(scene, 4, &shapes[3], err);
    if (status == GDR_OK) status = gdr_procedural_ground(scene, half, 32, &ground, err);

    uint32_t materials[5] = {GDR_NO_INDEX, GDR_NO_INDEX, GDR_NO_INDEX, GDR_NO_INDEX, GDR_NO_INDEX};
    if (status == GDR_OK && desc.textures)
        status = gdr_demo_add_materials(scene, 5, materials, err);
    if (status == GDR_OK && desc.textures) { /* the ground's uvs span it once: smaller tiles */
        gdr_material *g = &scene->materials[materials[4]];
        g->base_color_texture.scale = g->normal_texture.scale = g->metallic_roughness_texture.scale =
            (gdr_vec2){0.5f * half, 0.5f * half};
    }
    if (status == GDR_OK) {
        gdr_instance floor = {gdr_mat4_identity(), ground, materials[4], {0.55f, 0.55f, 0.5f, 1.0f}};
        status = gdr_scene_add_instance(scene, &floor, err);
    }
    for (uint32_t i = 0; i < desc.instances && status == GDR_OK; i++) {
        uint32_t shape = (uint32_t)(gdr_hash_unit(desc.seed, i, 0) * 4.0f) & 3u;
        float scale = 0.6f + 0.6f * gdr_hash_unit(desc.seed, i, 1); /* radius <= 1.2 * 1.25 < spacing / 2 */
        float yaw = 2.0f * PI_F * gdr_hash_unit(desc.seed, i, 2);
        float tilt = 0.5f * gdr_hash_unit(desc.seed, i, 3);
        const gdr_mesh *mesh = &scene->meshes[shapes[shape]];
        float x = ((float)(i % side) - 0.5f * (float)(side - 1)) * desc.spacing;
        float z = ((float)(i / side) - 0.5f * (float)(side - 1)) * desc.spacing;
        /* Rest above the ground: no shared depth with the floor, so draw order never matters. */
        float y = mesh->bounds.w * scale + 0.05f;
        gdr_quat rotation = gdr_quat_mul(gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, yaw),
                                         gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, tilt));
        gdr_instance instance = {
            .transform = gdr_mat4_from_trs((gdr_vec3){x, y, z}, rotation, (gdr_vec3){scale, scale, scale}),
            .mesh = shapes[shape],
            .material = materials[shape],
            .color = gdr_hue_color(gdr_hash_unit(desc.seed, i, 4)),
        };
        status = gdr_scene_add_instance(scene, &instance, err);
    }
    if (status == GDR_OK) {
        /* Inside the grid, a little above the objects, looking along a diagonal and slightly down. */
        gdr_quat yaw = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, 0.25f * PI_F);
        gdr_quat pitch = gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, -0.12f);
        /* Between grid points whatever the parity of the grid, above the tallest object (2.95 m). */
        float offset = (side % 2) ? 0.5f * desc.spacing : 0.0f;
        gdr_camera camera = {.name = "demo", .position = {offset, 3.5f, offset},
                             .rotation = gdr_quat_mul(yaw, pitch), .yfov = 60.0f * PI_F / 180.0f,
                             .znear = 0.1f, .zfar = 0.0f, .aspect = 0.0f};
        status = gdr_scene_add_camera(scene, &camera, err);
    }
    if (status == GDR_OK)
        status = gdr_scene_build_clusters(scene, NULL, err); /* meshlets (src/geometry) */
    if (status != GDR_OK) {
        gdr_scene_destroy(scene);
        return status;
    }
    *out = scene;
    return GDR_OK;
}
