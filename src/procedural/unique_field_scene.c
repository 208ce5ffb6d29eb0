/* The unique field: many different dense meshes, one copy each, so that the processed geometry
 * grows with the mesh count and cannot be shared between instances (the scene that needs
 * geometry streaming). Each mesh is a closed torus whose tube radius follows its own sum of
 * waves, from a stateless hash of (seed, mesh). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "gdr/geometry.h"
#include "gdr/procedural.h"
#include "gdr/scene.h"
#include "procedural/scene_random.h"

#define PI_F 3.14159265358979f
#define UNIQUE_MAJOR 0.62f /* torus major radius before the waves, metres */
#define UNIQUE_MINOR 0.22f /* tube radius before the waves */

static gdr_status check_desc(const gdr_unique_field_desc *d, gdr_error *err)
{
    if (d->meshes > 100000u)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "unique-field: meshes %u is outside [1, 100000]",
                             d->meshes);
    if (d->triangles < 1000u || d->triangles > 16000000u)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "unique-field: triangles %u is outside [1000, 16000000]", d->triangles);
    if (!(d->spacing >= 2.5f && d->spacing <= 1000.0f))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "unique-field: spacing %g is outside [2.5, 1000]",
                             (double)d->spacing);
    return GDR_OK;
}

/* The tube radius of mesh `m` at lattice point (u, v) in [0, 1)^2: three waves whose frequencies
 * are whole numbers (so the lattice closes on itself) and whose phases and amplitudes are the
 * mesh's own. At most 1.45 times UNIQUE_MINOR: the tube never meets itself. */
static float tube_radius(uint32_t seed, uint32_t m, float u, float v)
{
    float k1 = 3.0f + floorf(9.0f * gdr_hash_unit(seed, m, 0)), k2 = 2.0f + floorf(5.0f * gdr_hash_unit(seed, m, 1));
    float k3 = 8.0f + floorf(24.0f * gdr_hash_unit(seed, m, 2));
    float p1 = 2.0f * PI_F * gdr_hash_unit(seed, m, 3), p2 = 2.0f * PI_F * gdr_hash_unit(seed, m, 4);
    float w = sinf(2.0f * PI_F * k1 * u + p1) * sinf(2.0f * PI_F * k2 * v + p2);
    float knobs = sinf(2.0f * PI_F * k3 * u) * sinf(2.0f * PI_F * 5.0f * v + p1);
    return UNIQUE_MINOR * (1.0f + 0.25f * w + 0.2f * knobs * fabsf(knobs));
}

/* Mesh m: a segments x sides torus lattice, welded (every edge has exactly two triangles). */
static gdr_status add_unique_mesh(gdr_scene *scene, uint32_t seed, uint32_t m, uint32_t segments, uint32_t sides,
                                  gdr_error *err)
{
    uint32_t vertex_count = segments * sides, index_count = 6 * segments * sides;
    gdr_vec3 *positions = malloc(sizeof *positions * vertex_count);
    gdr_vec2 *uvs = malloc(sizeof *uvs * vertex_count);
    uint32_t *indices = malloc(sizeof *indices * index_count);
    if (!positions || !uvs || !indices) {
        free(positions), free(uvs), free(indices);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "unique-field: mesh %u of %u vertices", m, vertex_count);
    }
    for (uint32_t i = 0; i < segments; i++)
        for (uint32_t j = 0; j < sides; j++) {
            float u = (float)i / (float)segments, v = (float)j / (float)sides;
            float theta = 2.0f * PI_F * u, phi = 2.0f * PI_F * v, r = tube_radius(seed, m, u, v);
            float ring = UNIQUE_MAJOR + r * cosf(phi);
            positions[i * sides + j] = (gdr_vec3){ring * cosf(theta), r * sinf(phi), ring * sinf(theta)};
            uvs[i * sides + j] = (gdr_vec2){u, v};
        }
    uint32_t *t = indices;
    for (uint32_t i = 0; i < segments; i++)
        for (uint32_t j = 0; j < sides; j++) {
            uint32_t i1 = (i + 1) % segments, j1 = (j + 1) % sides;
            uint32_t a = i * sides + j, b = i1 * sides + j, c = i1 * sides + j1, d = i * sides + j1;
            *t++ = a, *t++ = d, *t++ = c;
            *t++ = a, *t++ = c, *t++ = b;
        }
    char name[GDR_NAME_MAX];
    snprintf(name, sizeof name, "unique_%u", m);
    gdr_status status =
        gdr_scene_add_mesh(scene, name, positions, NULL, uvs, vertex_count, indices, index_count, NULL, err);
    free(positions), free(uvs), free(indices);
    return status;
}

/* Mesh m's one copy on a square grid in the XZ plane (rows along -Z), randomly turned about Y. */
static gdr_status add_unique_instance(gdr_scene *scene, const gdr_unique_field_desc *d, uint32_t m, gdr_error *err)
{
    uint32_t columns = (uint32_t)ceil(sqrt((double)d->meshes));
    float x = ((float)(m % columns) - 0.5f * (float)(columns - 1)) * d->spacing;
    float z = -4.0f - (float)(m / columns) * d->spacing;
    gdr_quat turn = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, 2.0f * PI_F * gdr_hash_unit(d->seed, m, 5));
    gdr_quat tilt = gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, 0.6f * (gdr_hash_unit(d->seed, m, 6) - 0.5f));
    gdr_instance instance = {
        .transform = gdr_mat4_from_trs((gdr_vec3){x, 1.0f, z}, gdr_quat_mul(turn, tilt), (gdr_vec3){1, 1, 1}),
        .mesh = m,
        .material = GDR_NO_INDEX,
        .color = gdr_hue_color(gdr_hash_unit(d->seed, m, 7)),
    };
    return gdr_scene_add_instance(scene, &instance, err);
}

static gdr_unique_field_desc unique_field_desc_defaults(const gdr_unique_field_desc *in)
{
    gdr_unique_field_desc d = in ? *in : (gdr_unique_field_desc){0};
    d.meshes = d.meshes ? d.meshes : 100;
    d.seed = d.seed ? d.seed : 1;
    d.triangles = d.triangles ? d.triangles : 100000;
    d.spacing = d.spacing != 0.0f ? d.spacing : 3.0f;
    return d;
}

/* The tube is about 2.8 times longer around the ring than it is round: square-ish quads. */
static void lattice(const gdr_unique_field_desc *d, uint32_t *segments, uint32_t *sides)
{
    *sides = (uint32_t)lround(sqrt((double)d->triangles / 5.6));
    *segments = (uint32_t)lround((double)d->triangles / (2.0 * *sides));
}

/* The instances and the camera, after the meshes. */
static gdr_status add_unique_view(gdr_scene *scene, const gdr_unique_field_desc *d, gdr_error *err)
{
    gdr_status status = GDR_OK;
    for (uint32_t m = 0; m < d->meshes && status == GDR_OK; m++)
        status = add_unique_instance(scene, d, m, err);
    if (status == GDR_OK) {
        /* Behind the first row, raised and looking down the field. */
        gdr_camera camera = {.name = "unique-field", .position = {0.0f, 3.5f, 0.0f},
                             .rotation = gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, -0.35f),
                             .yfov = 60.0f * PI_F / 180.0f, .znear = 0.1f, .zfar = 0.0f, .aspect = 0.0f};
        status = gdr_scene_add_camera(scene, &camera, err);
    }
    return status;
}

gdr_status gdr_scene_create_unique_field(const gdr_unique_field_desc *desc_in, gdr_scene **out, gdr_error *err)
{
    *out = NULL;
    gdr_unique_field_desc d = unique_field_desc_defaults(desc_in);
    gdr_status status = check_desc(&d, err);
    if (status != GDR_OK)
        return status;
    gdr_scene *scene;
    if ((status = gdr_scene_create(&scene, err)) != GDR_OK)
        return status;
    uint32_t segments, sides;
    lattice(&d, &segments, &sides);
    for (uint32_t m = 0; m < d.meshes && status == GDR_OK; m++)
        status = add_unique_mesh(scene, d.seed, m, segments, sides, err);
    if (status == GDR_OK)
        status = add_unique_view(scene, &d, err);
    if (status == GDR_OK)
        status = gdr_scene_build_clusters(scene, NULL, err);
    if (status != GDR_OK) {
        gdr_scene_destroy(scene);
        return status;
    }
    *out = scene;
    return GDR_OK;
}

gdr_status gdr_scene_create_unique_field_skeleton(const gdr_unique_field_desc *desc_in, gdr_scene **out,
                                                  gdr_error *err)
{
    *out = NULL;
    gdr_unique_field_desc d = unique_field_desc_defaults(desc_in);
    gdr_status status = check_desc(&d, err);
    gdr_scene *scene = NULL;
    if (status == GDR_OK && (status = gdr_scene_create(&scene, err)) == GDR_OK)
        scene->geometry_in_pages = 1; /* names only: each mesh's geometry comes from the _mesh call */
    for (uint32_t m = 0; m < d.meshes && status == GDR_OK; m++) {
        char name[GDR_NAME_MAX];
        snprintf(name, sizeof name, "unique_%u", m);
        status = gdr_scene_add_paged_mesh(scene, name, 0, 0, (gdr_vec4){0}, err);
    }
    if (status == GDR_OK)
        status = add_unique_view(scene, &d, err);
    if (status != GDR_OK) {
        gdr_scene_destroy(scene);
        return status;
    }
    *out = scene;
    return GDR_OK;
}

gdr_status gdr_scene_create_unique_field_mesh(const gdr_unique_field_desc *desc_in, uint32_t mesh, gdr_scene **out,
                                              gdr_error *err)
{
    *out = NULL;
    gdr_unique_field_desc d = unique_field_desc_defaults(desc_in);
    gdr_status status = check_desc(&d, err);
    if (status == GDR_OK && mesh >= d.meshes)
        status = gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "unique-field: mesh %u of %u", mesh, d.meshes);
    gdr_scene *scene = NULL;
    if (status == GDR_OK)
        status = gdr_scene_create(&scene, err);
    uint32_t segments, sides;
    lattice(&d, &segments, &sides);
    if (status == GDR_OK)
        status = add_unique_mesh(scene, d.seed, mesh, segments, sides, err);
    if (status != GDR_OK) {
        gdr_scene_destroy(scene);
        return status;
    }
    *out = scene;
    return GDR_OK;
}
