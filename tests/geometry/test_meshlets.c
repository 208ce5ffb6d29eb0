/* Meshlets (level-0 clusters, gdr_meshlets_build): exact coverage of the input triangles, the
 * limits, spheres that contain every vertex, cone culling that never culls a front-facing
 * triangle, bad options and meshes refused with clear errors; the scene-level build: vertex
 * renumbering that keeps the geometry, the same result for every thread count, all-or-nothing
 * failure; a real glTF file. */
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cluster_checks.h"
#include "gdr/io.h"
#include "gdr/geometry.h"
#include "gdr/scene.h"
#include "procedural/procedural_meshes.h"
#include "test_util.h"
#include "io/loaders.h"

#define ASSIMP_MODELS_DIR "/usr/share/assimp/models"

static double now_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* --- test meshes ---------------------------------------------------------------------------- */

static void add_mesh(gdr_scene *s, const char *name, const gdr_vec3 *p, uint32_t vertex_count, const uint32_t *idx,
                     uint32_t index_count)
{
    gdr_error err = {0};
    CHECK(gdr_scene_add_mesh(s, name, p, NULL, NULL, vertex_count, idx, index_count, NULL, &err) == GDR_OK);
}

/* Unconnected random triangles: every triangle brings 3 new vertices (the vertex limit binds). */
static void add_soup(gdr_scene *s, unsigned seed, uint32_t triangles)
{
    gdr_vec3 *p = malloc(sizeof *p * 3 * triangles);
    uint32_t *idx = malloc(sizeof *idx * 3 * triangles);
    for (uint32_t i = 0; i < 3 * triangles; i++) {
        p[i] = (gdr_vec3){test_random_range(&seed, -5, 5), test_random_range(&seed, -5, 5),
                          test_random_range(&seed, -5, 5)};
        idx[i] = i;
    }
    add_mesh(s, "soup", p, 3 * triangles, idx, 3 * triangles);
    free(p);
    free(idx);
}

/* The two triangles of each cell of a grid of cells_x x cells_z cells whose vertex (x, z) is
 * base + z * side + x, counter-clockwise seen from +Y, appended at idx[n]; returns the new count. */
static uint32_t grid_quads(uint32_t *idx, uint32_t n, uint32_t base, uint32_t side, uint32_t cells_x,
                           uint32_t cells_z)
{
    for (uint32_t z = 0; z < cells_z; z++)
        for (uint32_t x = 0; x < cells_x; x++) {
            uint32_t a = base + z * side + x, b = a + 1, c = a + side, d = c + 1;
            uint32_t quad[6] = {a, c, b, b, c, d};
            memcpy(idx + n, quad, sizeof quad);
            n += 6;
        }
    return n;
}

/* A bumpy height field far from the origin: normal cones of all widths, float rounding at 1e4. */
static void add_terrain(gdr_scene *s, unsigned seed, uint32_t cells, float offset)
{
    uint32_t side = cells + 1;
    gdr_vec3 *p = malloc(sizeof *p * side * side);
    uint32_t *idx = malloc(sizeof *idx * 6 * cells * cells), n = 0;
    for (uint32_t z = 0; z < side; z++)
        for (uint32_t x = 0; x < side; x++)
            p[z * side + x] = (gdr_vec3){offset + 0.1f * (float)x, test_random_range(&seed, -0.08f, 0.08f),
                                         offset + 0.1f * (float)z};
    n = grid_quads(idx, n, 0, side, cells, cells);
    add_mesh(s, "terrain", p, side * side, idx, n);
    free(p);
    free(idx);
}

/* Triangles of zero area (repeated corners, collinear corners, all corners equal), a run of them
 * long enough to fill whole clusters, mixed with ordinary triangles; and duplicates of one
 * triangle in both windings. */
static void add_degenerate(gdr_scene *s)
{
    enum { LINE = 400 };
    gdr_vec3 p[LINE + 4];
    for (uint32_t i = 0; i < LINE; i++)
        p[i] = (gdr_vec3){0.01f * (float)i, 2.0f * 0.01f * (float)i, -0.5f * 0.01f * (float)i};
    p[LINE] = (gdr_vec3){0, 0, 0};
    p[LINE + 1] = (gdr_vec3){1, 0, 0};
    p[LINE + 2] = (gdr_vec3){0, 1, 0};
    p[LINE + 3] = (gdr_vec3){3, 3, 3};
    uint32_t idx[3 * 1200], n = 0;
    for (uint32_t i = 0; i + 2 < LINE; i++) { /* collinear */
        idx[n++] = i, idx[n++] = i + 1, idx[n++] = i + 2;
    }
    for (uint32_t i = 0; i + 1 < LINE; i += 2) { /* repeated corner */
        idx[n++] = i, idx[n++] = i, idx[n++] = i + 1;
    }
    for (int i = 0; i < 100; i++) { /* all corners equal */
        idx[n++] = LINE + 3, idx[n++] = LINE + 3, idx[n++] = LINE + 3;
    }
    for (int i = 0; i < 150; i++) { /* duplicates, both windings */
        idx[n++] = LINE, idx[n++] = LINE + 1, idx[n++] = LINE + 2;
        idx[n++] = LINE, idx[n++] = LINE + 2, idx[n++] = LINE + 1;
    }
    add_mesh(s, "degenerate", p, LINE + 4, idx, n);
}

/* The demo's meshes plus the ones above; `variant` changes the random ones. */
static gdr_scene *make_scene(unsigned variant)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create(&s, &err) == GDR_OK);
    CHECK(gdr_procedural_sphere(s, 32, 16, NULL, &err) == GDR_OK);
    CHECK(gdr_procedural_torus(s, 0.7f, 0.3f, 32, 16, NULL, &err) == GDR_OK);
    CHECK(gdr_procedural_box(s, (gdr_vec3){0.7f, 0.7f, 0.7f}, NULL, &err) == GDR_OK);
    CHECK(gdr_procedural_blob(s, 4, NULL, &err) == GDR_OK);
    CHECK(gdr_procedural_ground(s, 10.0f, 32, NULL, &err) == GDR_OK);
    add_soup(s, 17 + variant, 2000);
    add_terrain(s, 5 + variant, 60, 0.0f);
    add_terrain(s, 9 + variant, 30, 10000.0f);
    add_degenerate(s);
    gdr_vec3 none = {0, 0, 0};
    uint32_t no_index = 0;
    add_mesh(s, "empty", &none, 0, &no_index, 0);
    return s;
}

/* --- one mesh ------------------------------------------------------------------------------- */

typedef struct cone_stats {
    uint64_t points, culled, triangles_checked;
    double worst_cosine; /* the largest facing cosine of a triangle in a culled cluster */
    uint64_t clusters, with_cone;
} cone_stats;

/* Random points around each cluster with a cone, and points behind its apex (where the test
 * culls): whenever the test culls, no triangle of the cluster may face the point. */
static int check_cones(const gdr_mesh *mesh, const gdr_mesh_clusters *mc, unsigned seed, cone_stats *st)
{
    int ok = 1;
    for (uint32_t i = 0; i < mc->cluster_count; i++) {
        const gdr_cluster *c = &mc->clusters[i];
        st->clusters++;
        st->with_cone += c->cone_cutoff < 1.0f;
        if (c->cone_cutoff >= 1.0f) {
            if (c->cone_axis.x != 0.0f || c->cone_axis.y != 0.0f || c->cone_axis.z != 0.0f)
                ok = 0; /* "no cone" is a zero axis */
            continue;
        }
        float axis_length = sqrtf(c->cone_axis.x * c->cone_axis.x + c->cone_axis.y * c->cone_axis.y +
                                  c->cone_axis.z * c->cone_axis.z);
        if (fabsf(axis_length - 1.0f) > 1e-5f || !(c->cone_cutoff >= 0.0f))
            ok = 0;
        float r = c->sphere.w > 0 ? c->sphere.w : 1.0f;
        for (int k = 0; k < 96; k++) {
            gdr_vec3 p;
            if (k % 2 == 0) { /* anywhere, from inside the sphere to far away */
                float dist = r * (k % 8 == 0 ? test_random_range(&seed, 0.05f, 1.0f) : test_random_range(&seed, 1, 30));
                gdr_vec3 d = {test_random_range(&seed, -1, 1), test_random_range(&seed, -1, 1),
                              test_random_range(&seed, -1, 1)};
                float l = sqrtf(d.x * d.x + d.y * d.y + d.z * d.z) + 1e-6f;
                p = (gdr_vec3){c->sphere.x + d.x / l * dist, c->sphere.y + d.y / l * dist, c->sphere.z + d.z / l * dist};
            } else { /* behind the apex, inside the culling cone or near its edge */
                float back = r * test_random_range(&seed, 0.01f, 20.0f);
                float spread = back * test_random_range(&seed, 0.0f, 1.2f) * sqrtf(1 - c->cone_cutoff * c->cone_cutoff);
                gdr_vec3 d = {test_random_range(&seed, -1, 1), test_random_range(&seed, -1, 1),
                              test_random_range(&seed, -1, 1)};
                p = (gdr_vec3){c->cone_apex.x - c->cone_axis.x * back + d.x * spread,
                               c->cone_apex.y - c->cone_axis.y * back + d.y * spread,
                               c->cone_apex.z - c->cone_axis.z * back + d.z * spread};
            }
            st->points++;
            if (!cone_culls(c, p))
                continue;
            st->culled++;
            for (uint32_t t = 0; t < c->triangle_count; t++) {
                double cosine = facing_cosine(mesh, mc, c, t, p);
                st->triangles_checked++;
                if (cosine > st->worst_cosine)
                    st->worst_cosine = cosine;
                /* The builder guarantees cosine <= 0 in exact arithmetic on the stored floats
                 * (make_cone_conservative). 1e-6 allows for this test's own float evaluation
                 * (normalize and dot: a few ulps, ~1e-7), as a shader's; a wrong convention, a
                 * float-rounded apex far from the origin or a sliver's wrong normal (what
                 * meshoptimizer's bounds alone give: up to 0.03 on these meshes) is far above. */
                if (cosine > 1e-6) {
                    fprintf(stderr, "mesh '%s' cluster %u: culled from (%g %g %g) but triangle %u faces it "
                            "(cosine %g)\n", mesh->name, i, (double)p.x, (double)p.y, (double)p.z, t, cosine);
                    ok = 0;
                }
            }
        }
    }
    return ok;
}

static void check_mesh(const gdr_mesh *mesh, const gdr_meshlet_options *options, cone_stats *cones)
{
    gdr_mesh_clusters mc = {0};
    gdr_error err = {0};
    double t0 = now_seconds();
    gdr_status status = gdr_meshlets_build(mesh, options, &mc, &err);
    double ms = 1e3 * (now_seconds() - t0);
    CHECK(status == GDR_OK);
    if (status != GDR_OK) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    uint32_t max_v = options && options->max_vertices ? options->max_vertices : GDR_CLUSTER_MAX_VERTICES;
    uint32_t max_t = options && options->max_triangles ? options->max_triangles : GDR_CLUSTER_MAX_TRIANGLES;
    CHECK(check_cluster_layout(mesh, &mc, max_v, max_t));
    CHECK(check_cluster_coverage(mesh, &mc));
    CHECK(check_cluster_spheres(mesh, &mc));
    CHECK(check_cones(mesh, &mc, 99, cones));
    if (!options)
        printf("  %-10s %7u triangles -> %5u clusters (%.1f triangles, %.1f vertices each) in %.2f ms\n", mesh->name,
               mesh->index_count / 3, mc.cluster_count, (double)mesh->index_count / 3 / mc.cluster_count,
               (double)mc.vertex_count / mc.cluster_count, ms);
    gdr_mesh_clusters_free(&mc);
    CHECK(mc.clusters == NULL && mc.cluster_count == 0);
}

static void test_meshes(void)
{
    gdr_scene *s = make_scene(0);
    cone_stats cones = {.worst_cosine = -1.0};
    gdr_meshlet_options small = {.max_vertices = 32, .max_triangles = 64, .cone_weight = 0.9f};
    gdr_meshlet_options tiny = {.max_vertices = 3, .max_triangles = 4};
    for (uint32_t i = 0; s && i < s->mesh_count; i++) {
        if (s->meshes[i].index_count == 0)
            continue;
        check_mesh(&s->meshes[i], NULL, &cones);
        check_mesh(&s->meshes[i], &small, &cones);
        check_mesh(&s->meshes[i], &tiny, &cones);
    }
    printf("cones: %llu of %llu clusters have one; %llu points, %llu culled, %llu triangles checked, largest facing "
           "cosine when culled %.3g\n", (unsigned long long)cones.with_cone, (unsigned long long)cones.clusters,
           (unsigned long long)cones.points, (unsigned long long)cones.culled,
           (unsigned long long)cones.triangles_checked, cones.worst_cosine);
    /* The test is not vacuous: many points are culled. */
    CHECK(cones.culled > cones.points / 10);

    /* The degenerate mesh: clusters of zero-area triangles only have no cone and a real sphere. */
    gdr_mesh_clusters mc = {0};
    gdr_error err = {0};
    const gdr_mesh *degenerate = &s->meshes[s->mesh_count - 2];
    CHECK(gdr_meshlets_build(degenerate, NULL, &mc, &err) == GDR_OK);
    uint32_t no_cone = 0;
    for (uint32_t i = 0; i < mc.cluster_count; i++)
        no_cone += mc.clusters[i].cone_cutoff == 1.0f;
    CHECK(no_cone > 0);
    gdr_mesh_clusters_free(&mc);
    gdr_scene_destroy(s);
}

/* Far-apart patches: `patches` flat grids of 9 x 7 cells (126 triangles, 80 vertices: neither
 * divides the cluster limits), 1000 apart along x. meshoptimizer 0.18 fills a patch, then takes the
 * nearest free triangle however far: the last cluster of a patch reached into the next one. */
#define PATCH_CELLS_X 9u
#define PATCH_CELLS_Z 7u
#define PATCH_VERTICES ((PATCH_CELLS_X + 1) * (PATCH_CELLS_Z + 1))

static gdr_scene *make_patches(uint32_t patches)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create(&s, &err) == GDR_OK);
    uint32_t side = PATCH_CELLS_X + 1;
    gdr_vec3 *p = malloc(sizeof *p * PATCH_VERTICES * patches);
    uint32_t *idx = malloc(sizeof *idx * 6 * PATCH_CELLS_X * PATCH_CELLS_Z * patches), n = 0;
    for (uint32_t k = 0; k < patches; k++) {
        uint32_t base = k * PATCH_VERTICES;
        for (uint32_t z = 0; z <= PATCH_CELLS_Z; z++)
            for (uint32_t x = 0; x < side; x++)
                p[base + z * side + x] = (gdr_vec3){1000.0f * (float)k + 0.1f * (float)x, 0.0f, 0.1f * (float)z};
        n = grid_quads(idx, n, base, side, PATCH_CELLS_X, PATCH_CELLS_Z);
    }
    add_mesh(s, "patches", p, PATCH_VERTICES * patches, idx, n);
    free(p);
    free(idx);
    return s;
}

/* The number of clusters whose vertices lie in more than one patch. */
static uint32_t clusters_spanning_patches(const gdr_mesh_clusters *mc)
{
    uint32_t spanning = 0;
    for (uint32_t i = 0; i < mc->level0_cluster_count; i++) {
        const gdr_cluster *c = &mc->clusters[i];
        uint32_t patch = mc->vertices[c->vertex_offset] / PATCH_VERTICES;
        for (uint32_t v = 1; v < c->vertex_count; v++)
            if (mc->vertices[c->vertex_offset + v] / PATCH_VERTICES != patch) {
                spanning++;
                break;
            }
    }
    return spanning;
}

/* No level-0 cluster spans two far-apart patches, and the guarantees hold: two patches (one
 * chunk), and 300 patches (37,800 triangles: two chunks) with 1 and 3 threads, the same bytes. */
static void test_far_parts(void)
{
    gdr_scene *two = make_patches(2), *many = make_patches(300);
    gdr_error err = {0};
    gdr_mesh_clusters mc = {0}, threaded = {0};
    CHECK(gdr_meshlets_build(&two->meshes[0], NULL, &mc, &err) == GDR_OK);
    CHECK(check_cluster_layout(&two->meshes[0], &mc, GDR_CLUSTER_MAX_VERTICES, GDR_CLUSTER_MAX_TRIANGLES));
    CHECK(check_cluster_coverage(&two->meshes[0], &mc));
    CHECK(check_cluster_spheres(&two->meshes[0], &mc));
    uint32_t spanning = clusters_spanning_patches(&mc);
    printf("two patches: %u clusters, %u spanning both\n", mc.cluster_count, spanning);
    CHECK(spanning == 0);
    gdr_mesh_clusters_free(&mc);

    CHECK(gdr_meshlets_build(&many->meshes[0], &(gdr_meshlet_options){.thread_count = 1}, &mc, &err) == GDR_OK);
    CHECK(gdr_meshlets_build(&many->meshes[0], &(gdr_meshlet_options){.thread_count = 3}, &threaded, &err) ==
          GDR_OK);
    CHECK(check_cluster_layout(&many->meshes[0], &mc, GDR_CLUSTER_MAX_VERTICES, GDR_CLUSTER_MAX_TRIANGLES));
    CHECK(check_cluster_coverage(&many->meshes[0], &mc));
    CHECK(check_cluster_spheres(&many->meshes[0], &mc));
    spanning = clusters_spanning_patches(&mc);
    printf("300 patches: %u clusters, %u spanning two\n", mc.cluster_count, spanning);
    CHECK(spanning == 0);
    CHECK(mc.cluster_count == threaded.cluster_count && mc.triangle_byte_count == threaded.triangle_byte_count &&
          mc.vertex_count == threaded.vertex_count);
    CHECK(mc.cluster_count == threaded.cluster_count &&
          memcmp(mc.clusters, threaded.clusters, sizeof *mc.clusters * mc.cluster_count) == 0 &&
          memcmp(mc.vertices, threaded.vertices, sizeof *mc.vertices * mc.vertex_count) == 0 &&
          memcmp(mc.triangles, threaded.triangles, mc.triangle_byte_count) == 0);
    gdr_mesh_clusters_free(&mc);
    gdr_mesh_clusters_free(&threaded);
    gdr_scene_destroy(two);
    gdr_scene_destroy(many);
}

/* The convention, on a flat grid facing +Y: seen from below every cluster is culled, from above
 * none is. A reversed axis or comparison fails this. */
static void test_cone_convention(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create(&s, &err) == GDR_OK);
    CHECK(gdr_procedural_ground(s, 4.0f, 40, NULL, &err) == GDR_OK);
    gdr_mesh_clusters mc = {0};
    CHECK(gdr_meshlets_build(&s->meshes[0], NULL, &mc, &err) == GDR_OK);
    uint32_t below = 0, above = 0;
    for (uint32_t i = 0; i < mc.cluster_count; i++) {
        below += cone_culls(&mc.clusters[i], (gdr_vec3){0.3f, -2.0f, 0.7f});
        above += cone_culls(&mc.clusters[i], (gdr_vec3){0.3f, 2.0f, 0.7f});
        CHECK(fabsf(mc.clusters[i].cone_axis.y - 1.0f) < 1e-6f && mc.clusters[i].cone_cutoff < 1e-3f);
    }
    CHECK(mc.cluster_count > 10 && below == mc.cluster_count && above == 0);
    gdr_mesh_clusters_free(&mc);
    gdr_scene_destroy(s);
}

/* --- bad input -------------------------------------------------------------------------------- */

/* Refused as a bad argument, naming the option or the mesh and its bad value. */
static void expect_error(const gdr_mesh *mesh, gdr_meshlet_options o, const char *place)
{
    gdr_mesh_clusters mc = {0};
    gdr_error err = {0};
    CHECK_FAILS(gdr_meshlets_build(mesh, &o, &mc, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    CHECK_NAMES(err, place);
    CHECK(mc.clusters == NULL && mc.vertices == NULL && mc.triangles == NULL && mc.cluster_count == 0);
}

static void test_bad_input(void)
{
    gdr_vec3 p[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    uint32_t idx[6] = {0, 1, 2, 2, 1, 3};
    gdr_mesh mesh = {.name = "quad", .vertex_count = 4, .positions = p, .index_count = 6, .indices = idx};
    expect_error(&mesh, (gdr_meshlet_options){.max_vertices = 65}, "max_vertices 65");
    expect_error(&mesh, (gdr_meshlet_options){.max_vertices = 2}, "max_vertices 2");
    expect_error(&mesh, (gdr_meshlet_options){.max_triangles = 128}, "max_triangles 128");
    expect_error(&mesh, (gdr_meshlet_options){.max_triangles = 126}, "max_triangles 126");
    expect_error(&mesh, (gdr_meshlet_options){.max_triangles = 3}, "max_triangles 3");
    expect_error(&mesh, (gdr_meshlet_options){.cone_weight = 1.5f}, "cone_weight 1.5");
    expect_error(&mesh, (gdr_meshlet_options){.cone_weight = -0.5f}, "cone_weight -0.5");
    expect_error(&mesh, (gdr_meshlet_options){.cone_weight = NAN}, "cone_weight nan");
    expect_error(&mesh, (gdr_meshlet_options){.thread_count = 1000}, "thread_count 1000");
    gdr_mesh bad = mesh;
    bad.index_count = 0;
    expect_error(&bad, (gdr_meshlet_options){0}, "mesh 'quad': 0 indices");
    bad.index_count = 5;
    expect_error(&bad, (gdr_meshlet_options){0}, "5 indices");
    bad = mesh;
    bad.vertex_count = 3;
    expect_error(&bad, (gdr_meshlet_options){0}, "mesh 'quad': index 3 (at 5)");
    gdr_vec3 q[4] = {{0, 0, 0}, {1, 0, 0}, {0, INFINITY, 0}, {1, 1, 0}};
    bad = mesh;
    bad.positions = q;
    expect_error(&bad, (gdr_meshlet_options){0}, "mesh 'quad': position 2");
    /* An output that holds data is refused, not leaked or overwritten. */
    gdr_mesh_clusters mc = {0};
    gdr_error err = {0};
    CHECK(gdr_meshlets_build(&mesh, NULL, &mc, &err) == GDR_OK);
    gdr_cluster *kept = mc.clusters;
    CHECK_FAILS(gdr_meshlets_build(&mesh, NULL, &mc, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    CHECK(mc.clusters == kept);
    gdr_mesh_clusters_free(&mc);
}

/* --- the scene-level build ------------------------------------------------------------------ */

static int same_mesh_data(const gdr_mesh *a, const gdr_mesh *b)
{
    return a->vertex_count == b->vertex_count && a->index_count == b->index_count &&
           same_bytes(a->positions, b->positions, sizeof(gdr_vec3) * a->vertex_count) &&
           same_bytes(a->normals, b->normals, sizeof(gdr_vec3) * a->vertex_count) &&
           same_bytes(a->uvs, b->uvs, sizeof(gdr_vec2) * a->vertex_count) &&
           same_bytes(a->indices, b->indices, sizeof(uint32_t) * a->index_count) &&
           same_clusters(&a->clusters, &b->clusters);
}

typedef struct vertex_record {
    gdr_vec3 position, normal;
    gdr_vec2 uv;
} vertex_record;

static int compare_records(const void *a, const void *b) { return memcmp(a, b, sizeof(vertex_record)); }

static vertex_record *sorted_vertices(const gdr_mesh *m)
{
    vertex_record *r = malloc(sizeof *r * (m->vertex_count + 1));
    for (uint32_t i = 0; i < m->vertex_count; i++)
        r[i] = (vertex_record){m->positions[i], m->normals[i], m->uvs[i]};
    qsort(r, m->vertex_count, sizeof *r, compare_records);
    return r;
}

/* The renumbered mesh is the same mesh: corner by corner the same attributes, the same vertices
 * (a permutation); its clusters list vertices in first-use order 0, 1, 2, ... */
static void check_renumbered(const gdr_mesh *before, const gdr_mesh *after)
{
    CHECK(before->vertex_count == after->vertex_count && before->index_count == after->index_count);
    if (before->vertex_count != after->vertex_count || before->index_count != after->index_count)
        return;
    int same = 1;
    for (uint32_t i = 0; i < before->index_count && same; i++) {
        uint32_t u = before->indices[i], v = after->indices[i];
        same = memcmp(&before->positions[u], &after->positions[v], sizeof(gdr_vec3)) == 0 &&
               memcmp(&before->normals[u], &after->normals[v], sizeof(gdr_vec3)) == 0 &&
               memcmp(&before->uvs[u], &after->uvs[v], sizeof(gdr_vec2)) == 0;
    }
    CHECK(same);
    vertex_record *x = sorted_vertices(before), *y = sorted_vertices(after);
    CHECK(memcmp(x, y, sizeof *x * before->vertex_count) == 0);
    free(x);
    free(y);
    const gdr_mesh_clusters *mc = &after->clusters;
    uint8_t *seen = calloc(after->vertex_count + 1, 1);
    uint32_t next = 0;
    int first_use = 1;
    for (uint32_t i = 0; i < mc->vertex_count; i++) {
        uint32_t v = mc->vertices[i];
        if (!seen[v]) {
            first_use &= v == next;
            next++;
            seen[v] = 1;
        }
    }
    CHECK(first_use);
    free(seen);
    CHECK(check_cluster_layout(after, mc, GDR_CLUSTER_MAX_VERTICES, GDR_CLUSTER_MAX_TRIANGLES));
    CHECK(check_cluster_coverage(after, mc));
    CHECK(check_cluster_spheres(after, mc));
}

static void test_scene_build(void)
{
    gdr_error err = {0};
    gdr_scene *original = make_scene(1), *reference = make_scene(1);
    CHECK(gdr_scene_build_clusters(reference, &(gdr_meshlet_options){.thread_count = 1}, &err) == GDR_OK);
    for (uint32_t i = 0; i < reference->mesh_count; i++) {
        if (reference->meshes[i].index_count == 0) {
            CHECK(reference->meshes[i].clusters.cluster_count == 0 && reference->meshes[i].clusters.clusters == NULL);
            continue;
        }
        check_renumbered(&original->meshes[i], &reference->meshes[i]);
    }
    /* Any thread count gives the same bytes. */
    const uint32_t threads[] = {2, 3, 8, 0};
    for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++) {
        gdr_scene *s = make_scene(1);
        CHECK(gdr_scene_build_clusters(s, &(gdr_meshlet_options){.thread_count = threads[t]}, &err) == GDR_OK);
        int same = s->mesh_count == reference->mesh_count;
        for (uint32_t i = 0; same && i < s->mesh_count; i++)
            same = same_mesh_data(&s->meshes[i], &reference->meshes[i]);
        CHECK(same);
        gdr_scene_destroy(s);
    }
    /* Meshes that have clusters are left alone. */
    gdr_cluster *kept = reference->meshes[0].clusters.clusters;
    gdr_vec3 *positions = reference->meshes[0].positions;
    CHECK(gdr_scene_build_clusters(reference, NULL, &err) == GDR_OK);
    CHECK(reference->meshes[0].clusters.clusters == kept && reference->meshes[0].positions == positions);
    gdr_scene_destroy(original);
    gdr_scene_destroy(reference);
}

/* One bad mesh: the error names the first one, whatever the thread count, and no mesh keeps
 * clusters from the call; bad options are refused before any work. */
static void test_scene_failure(void)
{
    const uint32_t threads[] = {1, 2, 5};
    for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++) {
        gdr_scene *s = make_scene(2);
        s->meshes[6].indices[4] = s->meshes[6].vertex_count + 7; /* terrain */
        s->meshes[3].positions[2].y = NAN;                      /* blob */
        gdr_error err = {0};
        CHECK(gdr_scene_build_clusters(s, &(gdr_meshlet_options){.thread_count = threads[t]}, &err) ==
              GDR_ERROR_INVALID_ARGUMENT);
        CHECK_STATUS(err, GDR_ERROR_INVALID_ARGUMENT);
        CHECK_NAMES(err, "meshes[3]: mesh 'blob': position 2"); /* the first mesh that fails, whatever the threads */
        for (uint32_t i = 0; i < s->mesh_count; i++)
            CHECK(s->meshes[i].clusters.cluster_count == 0 && s->meshes[i].clusters.clusters == NULL);
        gdr_scene_destroy(s);
    }
    gdr_scene *s = make_scene(2);
    gdr_error err = {0};
    CHECK_FAILS(gdr_scene_build_clusters(s, &(gdr_meshlet_options){.max_triangles = 130}, &err), err,
                GDR_ERROR_INVALID_ARGUMENT);
    gdr_scene_destroy(s);
}

static gdr_status import_plain(const char *path, gdr_scene **out, gdr_error *err)
{
    gdr_import_options io = {.no_progress = 1};
    size_t n = strlen(path);
    if (n > 4 && strcmp(path + n - 4, ".obj") == 0)
        return gdr_import_obj(path, &io, out, NULL, err);
    return gdr_import_gltf(path, &io, out, NULL, err);
}

/* Real files from assimp-testmodels: every mesh. */
static void test_file(const char *relative)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", ASSIMP_MODELS_DIR, relative);
    gdr_error err = {0};
    gdr_scene *before = NULL, *after = NULL;
    if (import_plain(path, &before, &err) != GDR_OK) {
        printf("skipped %s: %s\n", relative, err.message);
        return;
    }
    CHECK(import_plain(path, &after, &err) == GDR_OK);
    uint64_t triangles = 0;
    for (uint32_t i = 0; i < after->mesh_count; i++)
        triangles += after->meshes[i].index_count / 3;
    double t0 = now_seconds();
    CHECK(gdr_scene_build_clusters(after, &(gdr_meshlet_options){.thread_count = 1}, &err) == GDR_OK);
    double seconds = now_seconds() - t0;
    uint64_t clusters = 0;
    for (uint32_t i = 0; i < after->mesh_count; i++) {
        clusters += after->meshes[i].clusters.cluster_count;
        if (after->meshes[i].index_count)
            check_renumbered(&before->meshes[i], &after->meshes[i]);
    }
    printf("%s: %u meshes, %llu triangles -> %llu clusters in %.1f ms (one thread, %.2f s per million triangles)\n",
           relative, after->mesh_count, (unsigned long long)triangles, (unsigned long long)clusters, 1e3 * seconds,
           triangles ? seconds * 1e6 / (double)triangles : 0.0);
    gdr_scene_destroy(before);
    gdr_scene_destroy(after);
}

int main(void)
{
    test_meshes();
    test_far_parts();
    test_cone_convention();
    test_bad_input();
    test_scene_build();
    test_scene_failure();
    test_file("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb");
    test_file("glTF2/ClearCoat-glTF/ClearCoatTest.gltf");
    test_file("OBJ/WusonOBJ.obj");
    return test_finish("test_meshlets");
}
