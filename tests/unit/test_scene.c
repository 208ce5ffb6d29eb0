/* Scene model and the built-in procedural scene. */
#include <string.h>

#include "gdr/io.h"
#include "gdr/scene.h"
#include "test_util.h"

/* Six times the signed volume enclosed by a triangle list: positive when faces wind CCW outward. */
static double signed_volume6(const gdr_mesh *m)
{
    double v = 0.0;
    for (uint32_t t = 0; t < m->index_count; t += 3) {
        gdr_vec3 a = m->positions[m->indices[t]], b = m->positions[m->indices[t + 1]], c = m->positions[m->indices[t + 2]];
        v += gdr_vec3_dot(a, gdr_vec3_cross(b, c));
    }
    return v;
}

static void test_demo_scene(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    CHECK(gdr_scene_load("demo:instances=300,seed=3", NULL, &scene, &err) == GDR_OK);
    if (!scene)
        return;
    CHECK(scene->instance_count == 301); /* the objects and the ground */
    CHECK(scene->camera_count == 1);
    CHECK(scene->mesh_count == 5);
    for (uint32_t i = 0; i < scene->mesh_count; i++) {
        const gdr_mesh *m = &scene->meshes[i];
        CHECK(m->index_count % 3 == 0 && m->index_count > 0);
        for (uint32_t v = 0; v < m->vertex_count; v++) {
            gdr_vec3 d = gdr_vec3_sub(m->positions[v], (gdr_vec3){m->bounds.x, m->bounds.y, m->bounds.z});
            CHECK(gdr_vec3_length(d) <= m->bounds.w);
            CHECK(fabsf(gdr_vec3_length(m->normals[v]) - 1.0f) < 1e-3f);
        }
        if (strcmp(m->name, "ground") != 0)
            CHECK(signed_volume6(m) > 0.0); /* closed and facing outward */
    }
    /* Objects never overlap each other: their world spheres are disjoint. */
    for (uint32_t a = 1; a < scene->instance_count; a++) {
        const gdr_instance *ia = &scene->instances[a];
        gdr_vec4 ba = scene->meshes[ia->mesh].bounds;
        gdr_vec3 ca = gdr_mat4_transform_point(ia->transform, (gdr_vec3){ba.x, ba.y, ba.z});
        float ra = ba.w * gdr_mat4_max_axis_scale(ia->transform);
        CHECK(ca.y - ra > 0.0f); /* above the ground */
        for (uint32_t b = a + 1; b < scene->instance_count && b < a + 40; b++) {
            const gdr_instance *ib = &scene->instances[b];
            gdr_vec4 bb = scene->meshes[ib->mesh].bounds;
            gdr_vec3 cb = gdr_mat4_transform_point(ib->transform, (gdr_vec3){bb.x, bb.y, bb.z});
            float rb = bb.w * gdr_mat4_max_axis_scale(ib->transform);
            CHECK(gdr_vec3_length(gdr_vec3_sub(ca, cb)) > ra + rb);
        }
    }
    /* The same specification gives the same scene. */
    gdr_scene *again = NULL;
    CHECK(gdr_scene_load("demo:seed=3,instances=300", NULL, &again, &err) == GDR_OK);
    if (again) {
        CHECK(memcmp(again->instances, scene->instances, sizeof(gdr_instance) * scene->instance_count) == 0);
        gdr_scene_destroy(again);
    }
    gdr_scene_destroy(scene);
}

static void test_bad_specs(void)
{
    const char *bad[] = {"demo:instances=0", "demo:instances=-5", "demo:instances=abc", "demo:bogus=1",
                         "demo:instances", "demo:spacing=0.5", "demo:instances=99999999999", "nothing.xyz"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        gdr_error err = {0};
        gdr_scene *scene = NULL;
        CHECK(gdr_scene_load(bad[i], NULL, &scene, &err) != GDR_OK);
        CHECK(scene == NULL);
        CHECK(err.message[0] != '\0');
    }
}

static void test_add_mesh_validation(void)
{
    gdr_error err = {0};
    gdr_scene *scene;
    CHECK(gdr_scene_create(&scene, &err) == GDR_OK);
    gdr_vec3 p[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    uint32_t bad_indices[3] = {0, 1, 3};
    CHECK_FAILS(gdr_scene_add_mesh(scene, "t", p, NULL, NULL, 3, bad_indices, 3, NULL, &err), err,
                GDR_ERROR_INVALID_ARGUMENT);
    uint32_t good[3] = {0, 1, 2};
    uint32_t index;
    CHECK(gdr_scene_add_mesh(scene, "t", p, NULL, NULL, 3, good, 3, &index, &err) == GDR_OK);
    CHECK(index == 0);
    CHECK_NEAR(scene->meshes[0].normals[0].z, 1.0, 1e-6); /* generated, CCW faces +Z */
    gdr_vec3 nan_p[3] = {{0, 0, 0}, {NAN, 0, 0}, {0, 1, 0}};
    CHECK(gdr_scene_add_mesh(scene, "n", nan_p, NULL, NULL, 3, good, 3, NULL, &err) == GDR_ERROR_INVALID_ARGUMENT);
    gdr_instance inst = {gdr_mat4_identity(), 5, GDR_NO_INDEX, {1, 1, 1, 1}};
    CHECK(gdr_scene_add_instance(scene, &inst, &err) == GDR_ERROR_INVALID_ARGUMENT);
    gdr_scene_destroy(scene);
}

int main(void)
{
    test_demo_scene();
    test_bad_specs();
    test_add_mesh_validation();
    return test_finish("test_scene");
}
