/* The LOD hierarchy (gdr/geometry.h "LOD hierarchy"): its contract over the built-in meshes and
 * real files (every group in exactly one leaf, every node's sphere and error bounds containing
 * its children's), and the hierarchical CPU cut equal to the flat cut for random views, with the
 * work it saves. Broken hierarchies (a shrunken sphere, a lowered error bound) must be refused by
 * the check and change some cut, so the comparison can fail. */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/scene.h"
#include "geometry/lod_cut.h"
#include "procedural/procedural_meshes.h"
#include "test_util.h"
#include "io/loaders.h"

#define ASSIMP_MODELS_DIR "/usr/share/assimp/models"

typedef struct cut_totals {
    uint64_t views, flat_tests, nodes_tested, clusters_tested, selected;
} cut_totals;

static void check_ok(gdr_status status, const gdr_error *err, const char *what)
{
    if (status != GDR_OK) {
        fprintf(stderr, "%s: %s\n", what, err->message);
        exit(1);
    }
}

/* A view of one instance: a random rotation, scale (sometimes tiny or huge) and translation (up to
 * far from the origin, where float rounding is coarse, unless near_origin), sometimes a shear, a camera from inside the
 * mesh to far away, a threshold from 0 to large. */
static gdr_lod_view random_view(const gdr_mesh *mesh, unsigned *rng, int near_origin)
{
    gdr_vec3 axis = gdr_vec3_normalize((gdr_vec3){test_random_range(rng, -1, 1), test_random_range(rng, -1, 1),
                                                  test_random_range(rng, -1, 1) + 0.01f});
    float s = powf(10.0f, test_random_range(rng, -2.0f, 2.0f));
    gdr_vec3 scale = {s, s * test_random_range(rng, 0.5f, 1.5f), s};
    float far = near_origin ? 0.0f : powf(10.0f, test_random_range(rng, 0.0f, 4.0f));
    gdr_vec3 t = {test_random_range(rng, -far, far), test_random_range(rng, -far, far), test_random_range(rng, -far, far)};
    float thresholds[4] = {0.0f, test_random_range(rng, 0.05f, 2.0f), test_random_range(rng, 0.5f, 40.0f), 1e6f};
    uint32_t pick = (uint32_t)(test_random(rng) * 8.0f);
    gdr_lod_view v = {.transform = gdr_mat4_from_trs(t, gdr_quat_from_axis_angle(axis, test_random(rng) * 6.28f), scale),
                      .projection_y = 1.0f / tanf(0.5f * test_random_range(rng, 0.3f, 1.6f)),
                      .viewport_height = test_random_range(rng, 240.0f, 2160.0f),
                      .znear = test_random_range(rng, 0.01f, 0.5f),
                      .threshold = thresholds[pick < 4 ? pick : (pick < 6 ? 1 : 2)]};
    if (test_random(rng) < (near_origin ? 0.5f : 0.25f)) { /* a shear, as nested glTF transforms make: the stretch bound matters */
        gdr_mat4 shear = gdr_mat4_identity();
        shear.m[4] = test_random_range(rng, -1.5f, 1.5f);
        shear.m[9] = test_random_range(rng, -1.5f, 1.5f);
        v.transform = gdr_mat4_mul(v.transform, shear);
    }
    gdr_vec3 dir = gdr_vec3_normalize((gdr_vec3){test_random_range(rng, -1, 1), test_random_range(rng, -1, 1),
                                                 test_random_range(rng, -1, 1) + 0.01f});
    float distance = mesh->bounds.w * s * powf(10.0f, test_random_range(rng, -1.5f, 2.5f));
    gdr_vec3 centre = gdr_mat4_transform_point(v.transform, (gdr_vec3){mesh->bounds.x, mesh->bounds.y, mesh->bounds.z});
    v.camera_position = gdr_vec3_add(centre, gdr_vec3_scale(dir, distance));
    return v;
}

/* Flat and hierarchical cuts for `views` random views; returns the number of views that differ. */
static uint32_t compare_cuts(const gdr_mesh *mesh, unsigned seed, uint32_t views, cut_totals *totals)
{
    const gdr_mesh_clusters *c = &mesh->clusters;
    uint8_t *flat = malloc(c->cluster_count), *tree = malloc(c->cluster_count);
    uint32_t differ = 0;
    for (uint32_t v = 0; v < views; v++) {
        gdr_lod_view view = random_view(mesh, &seed, 0);
        gdr_lod_traversal_stats st = {0};
        uint32_t a = gdr_lod_cut_select(c, &view, flat);
        uint32_t b = gdr_lod_cut_select_hierarchical(c, &view, tree, &st);
        if (a != b || memcmp(flat, tree, c->cluster_count) != 0)
            differ++;
        if (totals) {
            totals->views++;
            totals->flat_tests += c->cluster_count;
            totals->nodes_tested += st.nodes_tested;
            totals->clusters_tested += st.clusters_tested;
            totals->selected += a;
        }
    }
    free(flat);
    free(tree);
    return differ;
}

static float group_error_px(const gdr_mesh_clusters *c, uint32_t g, const gdr_lod_view *v)
{
    const float *m = v->transform.m;
    gdr_vec3 c0 = {m[0], m[1], m[2]}, c1 = {m[4], m[5], m[6]}, c2 = {m[8], m[9], m[10]}, c3 = {m[12], m[13], m[14]};
    return gdr_lod_group_projected_error(c->groups[g].sphere, c->groups[g].error, c0, c1, c2, c3, v->camera_position,
                                         v->znear, gdr_lod_projection_scale(v));
}

static bool node_test(const gdr_lod_node *n, float max_error, float min_refined_error, const gdr_lod_view *v,
                      float threshold)
{
    const float *m = v->transform.m;
    gdr_vec3 c0 = {m[0], m[1], m[2]}, c1 = {m[4], m[5], m[6]}, c2 = {m[8], m[9], m[10]}, c3 = {m[12], m[13], m[14]};
    return gdr_lod_node_may_draw(n->sphere, max_error, min_refined_error, c0, c1, c2, c3, v->camera_position,
                                 v->znear, gdr_lod_projection_scale(v), threshold);
}

/* Each side of the node test at the threshold where it is tightest: just below the largest
 * projected group error under the node (a group fails: the node must not be skipped as "every
 * group passes"), and at the smallest projected refined-group error (that group passes: the node
 * must not be skipped as "no refined group passes"). The errors are the float values the flat
 * cut computes, so this checks the rounding slack too. Returns the number of violations. */
static uint32_t check_node_bounds(const gdr_mesh *mesh, unsigned seed, uint32_t views)
{
    const gdr_mesh_clusters *c = &mesh->clusters;
    if (c->group_count == 0)
        return 0;
    float *own = malloc(sizeof *own * c->lod_node_count), *refined = malloc(sizeof *refined * c->lod_node_count);
    uint32_t violations = 0;
    for (uint32_t v = 0; v < views; v++) {
        gdr_lod_view view = random_view(mesh, &seed, (int)(v & 1));
        for (uint32_t i = c->lod_node_count; i-- > 0;) { /* children come after their parent */
            const gdr_lod_node *n = &c->lod_nodes[i];
            own[i] = -INFINITY;
            refined[i] = INFINITY; /* stays so when a cluster below has no refined group */
            int level0 = 0;
            for (uint32_t k = n->first; k < n->first + n->count; k++) {
                if (n->flags & GDR_LOD_NODE_LEAF) {
                    uint32_t r = c->clusters[k].refined_group;
                    level0 |= r == GDR_NO_INDEX;
                    if (r != GDR_NO_INDEX)
                        refined[i] = fminf(refined[i], group_error_px(c, r, &view));
                } else {
                    own[i] = fmaxf(own[i], own[k]);
                    refined[i] = fminf(refined[i], refined[k]);
                    level0 |= c->lod_nodes[k].min_refined_error == 0.0f;
                }
            }
            if (n->flags & GDR_LOD_NODE_LEAF)
                own[i] = group_error_px(c, n->group, &view);
            if (isfinite(own[i]) && !node_test(n, n->max_error, 0.0f, &view, nextafterf(own[i], -INFINITY)))
                violations++;
            if (!level0 && isfinite(refined[i]) && !node_test(n, INFINITY, n->min_refined_error, &view, refined[i]))
                violations++;
        }
    }
    free(own);
    free(refined);
    return violations;
}

static void check_mesh(const char *what, const gdr_mesh *mesh, cut_totals *totals, uint32_t views)
{
    char why[256] = "";
    int ok = gdr_mesh_clusters_check_hierarchy(&mesh->clusters, why, sizeof why);
    if (!ok)
        printf("%s: mesh '%s': %s\n", what, mesh->name, why);
    CHECK(ok);
    CHECK(mesh->clusters.cluster_count == 0 || mesh->clusters.lod_node_levels >= 1);
    uint32_t differ = compare_cuts(mesh, 1234u + mesh->index_count, views, totals);
    if (differ)
        printf("%s: mesh '%s': %u of %u views cut differently through the hierarchy\n", what, mesh->name, differ,
               views);
    CHECK(differ == 0);
    uint32_t violations = check_node_bounds(mesh, 77u + mesh->vertex_count, views / 4 + 1);
    if (violations)
        printf("%s: mesh '%s': %u node tests skipped a node at the threshold where one of its groups decides\n",
               what, mesh->name, violations);
    CHECK(violations == 0);
}

static void report(const char *what, const cut_totals *t)
{
    printf("%s: %llu views: flat cut tests %.0f clusters per view; hierarchy %.0f nodes + %.0f clusters "
           "(%.1f%% of flat) for %.0f selected\n", what, (unsigned long long)t->views,
           (double)t->flat_tests / (double)t->views, (double)t->nodes_tested / (double)t->views,
           (double)t->clusters_tested / (double)t->views,
           100.0 * (double)(t->nodes_tested + t->clusters_tested) / (double)t->flat_tests,
           (double)t->selected / (double)t->views);
}

/* The built-in meshes, with and without a DAG. */
static void test_builtin_meshes(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    check_ok(gdr_scene_create(&s, &err), &err, "scene");
    check_ok(gdr_procedural_sphere(s, 64, 32, NULL, &err), &err, "sphere");
    check_ok(gdr_procedural_torus(s, 1.0f, 0.3f, 96, 32, NULL, &err), &err, "torus");
    check_ok(gdr_procedural_box(s, (gdr_vec3){1, 2, 3}, NULL, &err), &err, "box");
    check_ok(gdr_procedural_blob(s, 5, NULL, &err), &err, "blob");
    check_ok(gdr_procedural_torus_knot(s, 256, 24, NULL, &err), &err, "knot");
    check_ok(gdr_procedural_ground(s, 50.0f, 96, NULL, &err), &err, "ground");
    check_ok(gdr_scene_build_clusters(s, NULL, &err), &err, "clusters");
    cut_totals level0 = {0};
    for (uint32_t m = 0; m < s->mesh_count; m++)
        check_mesh("level 0", &s->meshes[m], &level0, 20);
    check_ok(gdr_scene_build_lod(s, &(gdr_lod_options){.no_progress = 1}, NULL, &err), &err, "lod");
    cut_totals dag = {0};
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        const gdr_mesh_clusters *c = &s->meshes[m].clusters;
        printf("mesh '%s': %u clusters, %u groups, DAG depth %u -> %u nodes in %u levels\n", s->meshes[m].name,
               c->cluster_count, c->group_count, c->dag_depth, c->lod_node_count, c->lod_node_levels);
        check_mesh("built-in", &s->meshes[m], &dag, 300);
    }
    report("built-in meshes", &dag);
    gdr_scene_destroy(s);
}

/* Real files from assimp-testmodels. */
static void test_file(const char *relative, cut_totals *totals)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", ASSIMP_MODELS_DIR, relative);
    gdr_error err = {0};
    gdr_scene *s = NULL;
    gdr_import_options io = {.no_progress = 1};
    size_t n = strlen(path);
    gdr_status status = n > 4 && strcmp(path + n - 4, ".obj") == 0 ? gdr_import_obj(path, &io, &s, NULL, &err)
                                                                    : gdr_import_gltf(path, &io, &s, NULL, &err);
    if (status != GDR_OK) {
        printf("skipped %s: %s\n", relative, err.message);
        return;
    }
    check_ok(gdr_scene_build_lod(s, &(gdr_lod_options){.no_progress = 1}, NULL, &err), &err, relative);
    for (uint32_t m = 0; m < s->mesh_count; m++)
        check_mesh(relative, &s->meshes[m], totals, 40);
    gdr_scene_destroy(s);
}

/* Damage a copy of a good hierarchy: the check must refuse it and some cut must change. */
static void test_broken(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    check_ok(gdr_scene_create(&s, &err), &err, "scene");
    check_ok(gdr_procedural_blob(s, 5, NULL, &err), &err, "blob");
    check_ok(gdr_scene_build_lod(s, &(gdr_lod_options){.no_progress = 1}, NULL, &err), &err, "lod");
    gdr_mesh *mesh = &s->meshes[0];
    gdr_mesh_clusters *c = &mesh->clusters;
    gdr_lod_node *good = malloc(sizeof *good * c->lod_node_count);
    memcpy(good, c->lod_nodes, sizeof *good * c->lod_node_count);
    char why[256];
    for (int damage = 0; damage < 4; damage++) {
        for (uint32_t i = 0; i < c->lod_node_count; i++) {
            gdr_lod_node *n = &c->lod_nodes[i];
            if (damage == 0)
                n->sphere.w *= 0.5f; /* a shrunken sphere */
            else if (damage == 1)
                n->max_error *= 0.5f; /* a lowered upper error bound */
            else if (damage == 2 && n->min_refined_error > 0.0f)
                n->min_refined_error *= 2.0f; /* a raised lower error bound */
        }
        if (damage == 3) /* a group named by two leaves */
            for (uint32_t i = 1; i < c->lod_node_count; i++)
                if ((c->lod_nodes[i].flags & GDR_LOD_NODE_LEAF) && (c->lod_nodes[i - 1].flags & GDR_LOD_NODE_LEAF)) {
                    c->lod_nodes[i].group = c->lod_nodes[i - 1].group;
                    break;
                }
        CHECK(!gdr_mesh_clusters_check_hierarchy(c, why, sizeof why));
        printf("damage %d refused: %s\n", damage, why);
        if (damage < 3)
            CHECK(compare_cuts(mesh, 99u, 300, NULL) > 0);
        memcpy(c->lod_nodes, good, sizeof *good * c->lod_node_count);
    }
    CHECK(gdr_mesh_clusters_check_hierarchy(c, why, sizeof why));
    free(good);
    gdr_scene_destroy(s);
}

int main(void)
{
    test_builtin_meshes();
    cut_totals files = {0};
    test_file("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb", &files);
    test_file("OBJ/WusonOBJ.obj", &files);
    test_file("OBJ/spider.obj", &files);
    test_file("OBJ/regr01.obj", &files);
    if (files.views)
        report("assimp models", &files);
    test_broken();
    return test_finish("test_lod_hierarchy");
}
