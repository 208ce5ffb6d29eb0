/* The occlusion scene: a wall of buildings between the camera and thousands of small
 * objects, with gaps, objects in front, and a camera path that cuts, turns and looks past the wall. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "gdr/geometry.h"
#include "gdr/procedural.h"
#include "gdr/scene.h"
#include "procedural/procedural_meshes.h"
#include "procedural/scene_random.h"

#define PI_F 3.14159265358979f
#define DEG(x) ((x) * PI_F / 180.0f)

enum { SHAPE_SPHERE, SHAPE_TORUS, SHAPE_BOX, SHAPE_COUNT };

typedef struct occlusion_builder {
    gdr_scene *scene;
    uint32_t seed;
    uint32_t building_mesh;
    uint32_t building_count;
    uint32_t shapes[SHAPE_COUNT];
    float shape_reach[SHAPE_COUNT]; /* radius of a ball around the mesh origin holding the mesh */
    uint32_t object_count;          /* small objects so far: their hash index */
} occlusion_builder;

/* The fixed gaps of the wall, from -x to +x; the wall is built between them. */
static const float wall_intervals[3][2] = {{-70.0f, -9.0f}, {-6.0f, 7.0f}, {10.5f, 70.0f}};

static gdr_status add_building(occlusion_builder *b, float x0, float x1, gdr_error *err)
{
    uint32_t k = b->building_count++;
    float front = -20.0f - 1.5f * gdr_hash_unit(b->seed ^ 0xB1D6u, k, 0);
    float depth = 6.0f + 4.0f * gdr_hash_unit(b->seed ^ 0xB1D6u, k, 1);
    float height = 10.0f + 14.0f * gdr_hash_unit(b->seed ^ 0xB1D6u, k, 2);
    float grey = 0.5f + 0.25f * gdr_hash_unit(b->seed ^ 0xB1D6u, k, 3);
    /* Sunk 0.1 m into the ground: no face shares the ground's plane. */
    gdr_vec3 centre = {0.5f * (x0 + x1), 0.5f * height - 0.1f, front - 0.5f * depth};
    gdr_vec3 half = {0.5f * (x1 - x0), 0.5f * height, 0.5f * depth};
    gdr_instance instance = {
        .transform = gdr_mat4_from_trs(centre, gdr_quat_identity(), half), /* the mesh is a 2 m cube */
        .mesh = b->building_mesh,
        .material = GDR_NO_INDEX,
        .color = {grey, grey * 0.95f, grey * 0.9f, 1.0f},
    };
    return gdr_scene_add_instance(b->scene, &instance, err);
}

/* Buildings 5 to 12 m wide side by side over [x0, x1]; away from the middle of the view a few
 * narrower random gaps. Neighbours overlap by 0.1 m so that no two faces meet edge to edge. */
static gdr_status add_wall_section(occlusion_builder *b, float x0, float x1, gdr_error *err)
{
    gdr_status status = GDR_OK;
    float x = x0, overlap_left = 0.0f;
    while (x1 - x > 1e-3f && status == GDR_OK) {
        uint32_t k = b->building_count;
        float width = 5.0f + 7.0f * gdr_hash_unit(b->seed ^ 0xB1D6u, k, 4);
        if (x1 - x - width < 5.0f)
            width = x1 - x; /* the last one takes the rest */
        float end = x + width;
        float gap_width = 1.5f + 1.5f * gdr_hash_unit(b->seed ^ 0xB1D6u, k, 6);
        bool gap = gdr_hash_unit(b->seed ^ 0xB1D6u, k, 5) < 0.3f && x1 - end - gap_width >= 6.0f &&
                   (end > 14.0f || end + gap_width < -14.0f); /* the middle of the view keeps its two gaps */
        float overlap_right = (end < x1 && !gap) ? 0.1f : 0.0f;
        status = add_building(b, x - overlap_left, end + overlap_right, err);
        overlap_left = overlap_right;
        x = gap ? end + gap_width : end;
    }
    return status;
}

/* `count` small objects on a jittered grid over x in [x0, x1], z in [z_near, z_far] (z_far <
 * z_near), filled row by row from z_near; lifted up to `lift` metres above the ground. */
static gdr_status add_objects(occlusion_builder *b, float x0, float x1, float z_near, float z_far, uint32_t count,
                              float lift, gdr_error *err)
{
    float width = x1 - x0, depth = z_near - z_far;
    float cell = sqrtf(width * depth / (float)count);
    uint32_t columns = (uint32_t)fmaxf(1.0f, roundf(width / cell));
    uint32_t rows = (count + columns - 1) / columns;
    float cell_x = width / (float)columns, cell_z = depth / (float)rows;
    float max_radius = fminf(0.6f, 0.35f * fminf(cell_x, cell_z));
    gdr_status status = GDR_OK;
    for (uint32_t i = 0; i < count && status == GDR_OK; i++) {
        uint32_t n = b->object_count++, seed = b->seed ^ 0x0B7Eu;
        uint32_t shape = (uint32_t)(gdr_hash_unit(seed, n, 0) * (float)SHAPE_COUNT) % SHAPE_COUNT;
        float radius = max_radius * (0.7f + 0.3f * gdr_hash_unit(seed, n, 1));
        float room_x = 0.5f * cell_x - radius, room_z = 0.5f * cell_z - radius; /* > 0: 0.35 < 0.5 */
        gdr_vec3 position = {
            x0 + ((float)(i % columns) + 0.5f) * cell_x + room_x * (2.0f * gdr_hash_unit(seed, n, 2) - 1.0f),
            radius + 0.05f + lift * gdr_hash_unit(seed, n, 3),
            z_near - ((float)(i / columns) + 0.5f) * cell_z + room_z * (2.0f * gdr_hash_unit(seed, n, 4) - 1.0f),
        };
        float yaw = 2.0f * PI_F * gdr_hash_unit(seed, n, 5), tilt = 0.6f * gdr_hash_unit(seed, n, 6);
        gdr_quat rotation = gdr_quat_mul(gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, yaw),
                                         gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, tilt));
        float scale = radius / b->shape_reach[shape];
        gdr_instance instance = {
            .transform = gdr_mat4_from_trs(position, rotation, (gdr_vec3){scale, scale, scale}),
            .mesh = b->shapes[shape],
            .material = GDR_NO_INDEX,
            .color = gdr_hue_color(gdr_hash_unit(seed, n, 7)),
        };
        status = gdr_scene_add_instance(b->scene, &instance, err);
    }
    return status;
}

static gdr_status add_meshes(occlusion_builder *b, gdr_error *err)
{
    gdr_scene *s = b->scene;
    uint32_t ground;
    gdr_status status = gdr_procedural_ground(s, 130.0f, 32, &ground, err);
    if (status == GDR_OK) status = gdr_procedural_box(s, (gdr_vec3){1.0f, 1.0f, 1.0f}, &b->building_mesh, err);
    if (status == GDR_OK) status = gdr_procedural_sphere(s, 12, 6, &b->shapes[SHAPE_SPHERE], err);
    if (status == GDR_OK) status = gdr_procedural_torus(s, 0.7f, 0.3f, 12, 6, &b->shapes[SHAPE_TORUS], err);
    if (status == GDR_OK) status = gdr_procedural_box(s, (gdr_vec3){0.6f, 0.6f, 0.6f}, &b->shapes[SHAPE_BOX], err);
    if (status != GDR_OK)
        return status;
    snprintf(s->meshes[b->building_mesh].name, GDR_NAME_MAX, "building");
    for (int i = 0; i < SHAPE_COUNT; i++) {
        gdr_vec4 bounds = s->meshes[b->shapes[i]].bounds;
        b->shape_reach[i] = gdr_vec3_length((gdr_vec3){bounds.x, bounds.y, bounds.z}) + bounds.w;
    }
    gdr_instance floor = {gdr_mat4_identity(), ground, GDR_NO_INDEX, {0.5f, 0.52f, 0.45f, 1.0f}};
    return gdr_scene_add_instance(s, &floor, err);
}

/* Path frames shown as the scene's extra cameras, with their names. */
static const struct { uint32_t frame; const char *name; } path_cameras[] = {
    {0, "front"}, {70, "behind"}, {159, "past-end"}, {199, "above"}, {200, "close"}, {228, "gap"},
};

/* The desc with every zero field (or a NULL desc) given its default. */
static gdr_occlusion_scene_desc occlusion_desc_defaults(const gdr_occlusion_scene_desc *in)
{
    gdr_occlusion_scene_desc d = in ? *in : (gdr_occlusion_scene_desc){0};
    d.seed = d.seed ? d.seed : 1;
    d.hidden = d.hidden ? d.hidden : 4000;
    d.visible = d.visible ? d.visible : 300;
    return d;
}

gdr_status gdr_scene_create_occlusion(const gdr_occlusion_scene_desc *desc_in, gdr_scene **out, gdr_error *err)
{
    *out = NULL;
    gdr_occlusion_scene_desc d = occlusion_desc_defaults(desc_in);
    if (d.hidden > 1000000u || d.visible > 1000000u)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "occlusion: %s %u is outside [1, 1000000]",
                             d.hidden > 1000000u ? "hidden" : "visible", d.hidden > 1000000u ? d.hidden : d.visible);

    occlusion_builder b = {.seed = d.seed};
    gdr_status status = gdr_scene_create(&b.scene, err);
    if (status != GDR_OK)
        return status;
    status = add_meshes(&b, err);
    for (int i = 0; i < 3 && status == GDR_OK; i++)
        status = add_wall_section(&b, wall_intervals[i][0], wall_intervals[i][1], err);
    if (status == GDR_OK)
        status = add_objects(&b, -40.0f, 40.0f, -3.0f, -17.0f, d.visible, 0.0f, err);
    if (status == GDR_OK)
        status = add_objects(&b, -60.0f, 60.0f, -36.0f, -100.0f, d.hidden, 2.5f, err);
    for (size_t i = 0; i < sizeof path_cameras / sizeof path_cameras[0] && status == GDR_OK; i++) {
        gdr_camera camera = gdr_scene_occlusion_camera_path(path_cameras[i].frame, NULL);
        snprintf(camera.name, GDR_NAME_MAX, "%s", path_cameras[i].name);
        status = gdr_scene_add_camera(b.scene, &camera, err);
    }
    if (status == GDR_OK)
        status = gdr_scene_build_clusters(b.scene, NULL, err); /* meshlets (src/geometry) */
    if (status != GDR_OK) {
        gdr_scene_destroy(b.scene);
        return status;
    }
    *out = b.scene;
    return GDR_OK;
}

/* --- The camera path ------------------------------------------------------------------------ */

static gdr_camera path_camera(gdr_vec3 position, float yaw, float pitch)
{
    /* Yaw about +Y (positive turns left, from -Z towards -X), then pitch about the camera's X. */
    gdr_quat rotation = gdr_quat_mul(gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, yaw),
                                     gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, pitch));
    return (gdr_camera){.name = "path", .position = position, .rotation = rotation, .yfov = DEG(60.0f),
                        .znear = 0.1f, .zfar = 0.0f, .aspect = 0.0f};
}

static float mix(float a, float b, float t) { return a + (b - a) * t; }

gdr_camera gdr_scene_occlusion_camera_path(uint32_t frame, bool *camera_cut)
{
    static const uint32_t shot_starts[] = {0, 40, 70, 110, 160, 200, 216, GDR_OCCLUSION_PATH_FRAMES};
    uint32_t f = frame % GDR_OCCLUSION_PATH_FRAMES, shot = 0;
    while (f >= shot_starts[shot + 1])
        shot++;
    uint32_t first = shot_starts[shot], length = shot_starts[shot + 1] - first;
    float t = (float)(f - first) / (float)(length - 1); /* 0 .. 1 over the shot */
    if (camera_cut)
        *camera_cut = f == first && shot != 1; /* shot 1 continues where shot 0 ends */
    switch (shot) {
    case 0: /* dolly towards the wall */
        return path_camera((gdr_vec3){0.0f, 1.7f, -10.0f * t}, DEG(5.0f) * sinf(2.0f * PI_F * t), 0.0f);
    case 1: /* turn left, then right */
        return path_camera((gdr_vec3){0.0f, 1.7f, -10.0f},
                           t < 0.5f ? mix(0.0f, DEG(75.0f), 2.0f * t) : mix(DEG(75.0f), DEG(-30.0f), 2.0f * t - 1.0f),
                           0.0f);
    case 2: /* behind the wall, above the hidden objects (at most 4 m high), looking back */
        return path_camera((gdr_vec3){0.0f, 5.0f, mix(-115.0f, -45.0f, t)}, PI_F, DEG(-8.0f));
    case 3: /* past the wall's end, turning to look behind it */
        return path_camera((gdr_vec3){mix(40.0f, 95.0f, t), 1.7f, -8.0f}, mix(0.0f, DEG(40.0f), t), 0.0f);
    case 4: /* crane up over the wall */
        return path_camera((gdr_vec3){0.0f, mix(1.7f, 45.0f, t), -12.0f}, 0.0f, mix(0.0f, DEG(-40.0f), t));
    case 5: /* facing the wall (x in [-6, 7] is always a building, its front at most -20), spinning */
        return path_camera((gdr_vec3){0.0f, 1.7f, -18.5f}, DEG(22.5f) * (float)(f - first), 0.0f);
    default: /* strafing past the gap at x in [-9, -6] */
        return path_camera((gdr_vec3){mix(-13.0f, -2.0f, t), 1.7f, -14.0f}, 0.0f, 0.0f);
    }
}
