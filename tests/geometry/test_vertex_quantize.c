/* Vertices onto a grid (gdr_scene_quantize_vertices): the codec's normals stay within a small angle
 * and every decoded vertex encodes back to itself; on a scene with LOD DAGs, every vertex moves at
 * most the stated displacement and encodes exactly, cluster spheres still contain their vertices,
 * group errors above level 0 grow by twice the displacement (level 0 keeps 0), parents still state
 * at least their children's error, and the hierarchy is a valid one over the new bounds. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/gdr.h"
#include "geometry/vertex_quantize.h"
#include "test_util.h"

static double angle_degrees(gdr_vec3 a, gdr_vec3 b)
{
    double d = (double)a.x * b.x + (double)a.y * b.y + (double)a.z * b.z;
    return acos(fmin(1.0, fmax(-1.0, d))) * 180.0 / 3.14159265358979;
}

/* Random unit normals through the codec: the angle they turn, and the round trip of the result. */
static void test_normals(void)
{
    gdr_vertex_quantization q = {.enabled = 1};
    double worst = 0.0;
    uint32_t seed = 12345, inexact = 0;
    for (int i = 0; i < 200000; i++) {
        float v[3];
        for (int k = 0; k < 3; k++) {
            seed = seed * 1664525u + 1013904223u;
            v[k] = (float)((double)seed / 4294967296.0 * 2.0 - 1.0);
        }
        float length = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (length < 1e-3f)
            continue;
        gdr_vec3 n = {v[0] / length, v[1] / length, v[2] / length}, p, back;
        gdr_vec2 t;
        gdr_quantized_vertex code;
        (void)gdr_vertex_encode(&q, (gdr_vec3){0, 0, 0}, n, (gdr_vec2){0, 0}, &code);
        gdr_vertex_decode(&q, &code, &p, &back, &t);
        worst = fmax(worst, angle_degrees(n, back));
        inexact += !gdr_vertex_encode(&q, p, back, t, &code);
    }
    printf("octahedral normals: at most %.3f degrees off, %u decoded normals not encoding back\n", worst, inexact);
    CHECK(worst < 0.25 && inexact == 0);
}

static void check_mesh(const gdr_mesh *before, const gdr_mesh *after, uint32_t m)
{
    const gdr_vertex_quantization *q = &after->quantization;
    CHECK(q->enabled && q->max_displacement > 0.0f && q->max_displacement < 1e-4f * before->bounds.w);
    uint32_t far = 0, inexact = 0, outside = 0;
    for (uint32_t v = 0; v < after->vertex_count; v++) {
        gdr_vec3 a = before->positions[v], b = after->positions[v];
        double d = sqrt(pow((double)a.x - b.x, 2) + pow((double)a.y - b.y, 2) + pow((double)a.z - b.z, 2));
        far += d > q->max_displacement;
        gdr_quantized_vertex code;
        inexact += !gdr_vertex_encode(q, after->positions[v], after->normals[v], after->uvs[v], &code);
    }
    const gdr_mesh_clusters *c = &after->clusters;
    for (uint32_t k = 0; k < c->cluster_count; k++) {
        const gdr_cluster *cl = &c->clusters[k];
        for (uint32_t i = 0; i < cl->vertex_count; i++) {
            gdr_vec3 p = after->positions[c->vertices[cl->vertex_offset + i]];
            double d = sqrt(pow((double)p.x - cl->sphere.x, 2) + pow((double)p.y - cl->sphere.y, 2) +
                            pow((double)p.z - cl->sphere.z, 2));
            outside += d > cl->sphere.w;
        }
    }
    CHECK(far == 0 && inexact == 0 && outside == 0);
    uint32_t wrong_error = 0, not_monotone = 0;
    for (uint32_t g = 0; g < c->group_count; g++) {
        float was = before->clusters.groups[g].error, now = c->groups[g].error;
        float want = c->groups[g].depth == 0 || isinf(was) ? was : was + 2.0f * q->max_displacement;
        wrong_error += now != want;
    }
    for (uint32_t k = 0; k < c->cluster_count; k++) {
        const gdr_cluster *cl = &c->clusters[k];
        if (cl->refined_group != GDR_NO_INDEX && cl->group != GDR_NO_INDEX)
            not_monotone += c->groups[cl->group].error < c->groups[cl->refined_group].error;
    }
    char what[192] = "";
    int hierarchy = gdr_mesh_clusters_check_hierarchy(c, what, sizeof what);
    if (!hierarchy)
        printf("mesh %u: %s\n", m, what);
    CHECK(wrong_error == 0 && not_monotone == 0 && hierarchy && c->group_count > 1);
}

static void test_scene(void)
{
    gdr_scene *before = NULL, *after = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load("unique-field:meshes=2,triangles=4000,seed=9", &load, &before, &err) == GDR_OK);
    CHECK(gdr_scene_load("unique-field:meshes=2,triangles=4000,seed=9", &load, &after, &err) == GDR_OK);
    if (!before || !after)
        return;
    CHECK(gdr_scene_quantize_vertices(after, &err) == GDR_OK);
    for (uint32_t m = 0; m < after->mesh_count; m++)
        check_mesh(&before->meshes[m], &after->meshes[m], m);
    /* Quantizing again changes nothing. */
    gdr_vec3 first = after->meshes[0].positions[0];
    CHECK(gdr_scene_quantize_vertices(after, &err) == GDR_OK && !memcmp(&first, &after->meshes[0].positions[0], 12));
    gdr_scene_destroy(before);
    gdr_scene_destroy(after);
}

int main(void)
{
    test_normals();
    test_scene();
    return test_finish("test_vertex_quantize");
}
