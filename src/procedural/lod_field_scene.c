/* The LOD field: one dense closed mesh, copied from near to far in front of the camera,
 * so that one view needs every level of the LOD DAG. */
#include <math.h>
#include <stdlib.h>

#include "gdr/geometry.h"
#include "gdr/procedural.h"
#include "gdr/scene.h"
#include "procedural/procedural_meshes.h"
#include "procedural/scene_random.h"

#define PI_F 3.14159265358979f
#define FIELD_NEAR 4.0f                    /* depth of the first grid row, metres */
#define FIELD_HALF_ANGLE (40.0f * PI_F / 180.0f) /* the wedge the grid fills, around -Z */

/* A rotation drawn uniformly from all rotations (Shoemake's method) from three numbers in [0, 1). */
static gdr_quat uniform_rotation(float u1, float u2, float u3)
{
    float a = sqrtf(1.0f - u1), b = sqrtf(u1);
    gdr_quat q = {a * sinf(2.0f * PI_F * u2), a * cosf(2.0f * PI_F * u2), b * sinf(2.0f * PI_F * u3),
                  b * cosf(2.0f * PI_F * u3)};
    return gdr_quat_normalize(q);
}

static gdr_status check_desc(const gdr_lod_field_desc *d, gdr_error *err)
{
    if (d->instances > 16000000u)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "lod-field: instances %u is outside [1, 16000000]",
                             d->instances);
    if (d->triangles < 1000u || d->triangles > 16000000u)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "lod-field: triangles %u is outside [1000, 16000000]",
                             d->triangles);
    if (!(d->spacing >= 2.5f && d->spacing <= 1000.0f))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "lod-field: spacing %g is outside [2.5, 1000]",
                             (double)d->spacing);
    return GDR_OK;
}

/* Instance i on the grid: rows at increasing depth, every other row shifted by half a cell (so
 * that no line of copies runs straight away from the camera), each filled from its middle out. */
static gdr_status add_field_instances(gdr_scene *scene, const gdr_lod_field_desc *d, uint32_t mesh, gdr_error *err)
{
    /* A ball around the mesh origin that holds the mesh's bounding sphere: jittered copies keep
     * their spheres apart. */
    gdr_vec4 b = scene->meshes[mesh].bounds;
    float reach = gdr_vec3_length((gdr_vec3){b.x, b.y, b.z}) + b.w;
    float jitter = fmaxf(0.0f, 0.5f * d->spacing - reach - 0.05f);
    gdr_status status = GDR_OK;
    uint32_t i = 0;
    for (uint32_t row = 0; i < d->instances && status == GDR_OK; row++) {
        float depth = FIELD_NEAR + (float)row * d->spacing;
        float reach_x = depth * tanf(FIELD_HALF_ANGLE) / d->spacing; /* in cells */
        bool shifted = row & 1;
        /* Cells at 0, -1, 1, -2, 2, ... or at -0.5, 0.5, -1.5, 1.5, ... */
        uint32_t cells = shifted ? (reach_x >= 0.5f ? 2u * ((uint32_t)floorf(reach_x - 0.5f) + 1u) : 0u)
                                 : 2u * (uint32_t)floorf(reach_x) + 1u;
        for (uint32_t m = 0; m < cells && i < d->instances && status == GDR_OK; m++, i++) {
            float column = shifted ? ((float)(m >> 1) + 0.5f) * ((m & 1) ? 1.0f : -1.0f)
                                   : (float)((m + 1) >> 1) * ((m & 1) ? -1.0f : 1.0f);
            gdr_vec3 position = {
                column * d->spacing + jitter * (2.0f * gdr_hash_unit(d->seed, i, 0) - 1.0f),
                reach + gdr_hash_unit(d->seed, i, 1), /* above y = 0, up to 1 m higher */
                -depth + jitter * (2.0f * gdr_hash_unit(d->seed, i, 2) - 1.0f),
            };
            gdr_quat rotation = uniform_rotation(gdr_hash_unit(d->seed, i, 3), gdr_hash_unit(d->seed, i, 4),
                                                 gdr_hash_unit(d->seed, i, 5));
            gdr_instance instance = {
                .transform = gdr_mat4_from_trs(position, rotation, (gdr_vec3){1.0f, 1.0f, 1.0f}),
                .mesh = mesh,
                .material = GDR_NO_INDEX,
                .color = gdr_hue_color(gdr_hash_unit(d->seed, i, 6)),
            };
            status = gdr_scene_add_instance(scene, &instance, err);
        }
    }
    return status;
}

/* The desc with every zero field (or a NULL desc) given its default. */
static gdr_lod_field_desc lod_field_desc_defaults(const gdr_lod_field_desc *in)
{
    gdr_lod_field_desc d = in ? *in : (gdr_lod_field_desc){0};
    d.instances = d.instances ? d.instances : 1000;
    d.seed = d.seed ? d.seed : 1;
    d.triangles = d.triangles ? d.triangles : 100000;
    d.spacing = d.spacing != 0.0f ? d.spacing : 3.0f;
    return d;
}

gdr_status gdr_scene_create_lod_field(const gdr_lod_field_desc *desc_in, gdr_scene **out, gdr_error *err)
{
    *out = NULL;
    gdr_lod_field_desc d = lod_field_desc_defaults(desc_in);
    gdr_status status = check_desc(&d, err);
    if (status != GDR_OK)
        return status;

    gdr_scene *scene;
    if ((status = gdr_scene_create(&scene, err)) != GDR_OK)
        return status;
    /* The tube is about 12 times longer than it is round: square-ish quads. */
    uint32_t sides = (uint32_t)lround(sqrt((double)d.triangles / 24.0));
    uint32_t segments = (uint32_t)lround((double)d.triangles / (2.0 * sides));
    uint32_t mesh = 0;
    status = gdr_procedural_torus_knot(scene, segments, sides, &mesh, err);
    if (status == GDR_OK)
        status = add_field_instances(scene, &d, mesh, err);
    if (status == GDR_OK) {
        /* Behind and above the first row, looking down the field: the far rows meet the horizon
         * near the top of the image, the near ones fill its bottom. */
        gdr_camera camera = {.name = "lod-field", .position = {0.0f, 4.5f, 1.0f},
                             .rotation = gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, -0.3f),
                             .yfov = 60.0f * PI_F / 180.0f, .znear = 0.1f, .zfar = 0.0f, .aspect = 0.0f};
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
