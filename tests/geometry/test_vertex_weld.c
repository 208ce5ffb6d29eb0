/* Welding of bit-equal vertices before clustering (gdr_scene_build_clusters): a torus exploded into
 * a triangle soup (every triangle its own three vertices, attributes equal where the torus shared
 * them) comes out with the torus's vertex count, full clusters and a LOD DAG like the torus's; a
 * cube whose corners differ only in normal keeps its split vertices; a fan of 300 triangles keeps
 * at most 128 uses per vertex (the importers' split is not undone); an already welded mesh is left
 * as it is, bit for bit; every corner keeps its attributes, vertex colours included. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "gdr/scene.h"
#include "geometry/vertex_weld.h"
#include "procedural/procedural_meshes.h"
#include "test_util.h"

static void check_ok(gdr_status status, const gdr_error *err, const char *what)
{
    if (status != GDR_OK) {
        fprintf(stderr, "%s: %s\n", what, err->message);
        exit(1);
    }
}

/* One triangle corner's attributes, as the soup was given them. */
typedef struct corner {
    gdr_vec3 position, normal;
    gdr_vec2 uv;
    gdr_vec4 color;
} corner;

static gdr_vec4 color_of(gdr_vec3 p) { return (gdr_vec4){p.x * 0.35f + 0.5f, p.y * 0.35f + 0.5f, p.z * 0.35f + 0.5f, 1.0f}; }

static corner corner_of(const gdr_mesh *m, uint32_t v)
{
    corner c = {m->positions[v], m->normals[v], m->uvs[v], m->colors ? m->colors[v] : (gdr_vec4){1, 1, 1, 1}};
    return c;
}

/* The mesh's triangles as a list of corners, in index order (the builder keeps triangles and their
 * order). */
static corner *corners_of(const gdr_mesh *m)
{
    corner *c = malloc(sizeof *c * m->index_count);
    for (uint32_t i = 0; i < m->index_count; i++)
        c[i] = corner_of(m, m->indices[i]);
    return c;
}

/* Adds mesh `src` exploded: every triangle its own three vertices, with the source's attributes,
 * and a colour made of each position (equal where the position is). Returns the new mesh. */
static uint32_t add_exploded(gdr_scene *s, uint32_t src, const char *name)
{
    const gdr_mesh *m = &s->meshes[src];
    uint32_t n = m->index_count;
    gdr_vec3 *p = malloc(sizeof *p * n), *nn = malloc(sizeof *nn * n);
    gdr_vec2 *t = malloc(sizeof *t * n);
    gdr_vec4 *c = malloc(sizeof *c * n);
    uint32_t *idx = malloc(sizeof *idx * n), out = 0;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t v = m->indices[i];
        p[i] = m->positions[v], nn[i] = m->normals[v], t[i] = m->uvs[v], c[i] = color_of(p[i]);
        idx[i] = i;
    }
    gdr_error err = {0};
    check_ok(gdr_scene_add_mesh(s, name, p, nn, t, n, idx, n, &out, &err), &err, name);
    check_ok(gdr_scene_set_mesh_colors(s, out, c, &err), &err, name);
    free(p), free(nn), free(t), free(c), free(idx);
    return out;
}

static double mean_level0_triangles(const gdr_mesh *m)
{
    return (double)m->index_count / 3.0 / (double)m->clusters.level0_cluster_count;
}

/* Every corner still has the attributes it was given (same triangles, same order). */
static int keeps_corners(const gdr_mesh *m, const corner *before)
{
    for (uint32_t i = 0; i < m->index_count; i++) {
        corner now = corner_of(m, m->indices[i]);
        if (memcmp(&now, &before[i], sizeof now) != 0)
            return 0;
    }
    return 1;
}

static gdr_lod_stats build_dag(gdr_mesh *m)
{
    gdr_lod_stats st = {0};
    gdr_lod_options o = {.thread_count = 1, .no_progress = 1};
    gdr_error err = {0};
    check_ok(gdr_mesh_build_lod_dag(m, &o, &st, &err), &err, m->name);
    return st;
}

static void test_exploded_torus(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    uint32_t torus = 0;
    check_ok(gdr_scene_create(&s, &err), &err, "scene");
    check_ok(gdr_procedural_torus(s, 1.0f, 0.3f, 128, 64, &torus, &err), &err, "torus");
    uint32_t soup = add_exploded(s, torus, "soup");
    uint32_t welded_count = s->meshes[torus].vertex_count; /* every torus vertex is used */
    corner *before = corners_of(&s->meshes[soup]);
    check_ok(gdr_scene_build_clusters(s, NULL, &err), &err, "clusters");
    gdr_mesh *t = &s->meshes[torus], *m = &s->meshes[soup];
    CHECK(m->vertex_count == welded_count);
    CHECK(t->vertex_count == welded_count);
    CHECK(keeps_corners(m, before));
    double fill_t = mean_level0_triangles(t), fill_m = mean_level0_triangles(m);
    printf("torus: %u vertices, %.1f triangles per cluster; soup: %u vertices, %.1f per cluster\n", t->vertex_count,
           fill_t, m->vertex_count, fill_m);
    CHECK(fill_m >= 0.95 * fill_t && fill_m >= 90.0); /* near the 124 limit (21 unwelded) */
    gdr_lod_stats st_t = build_dag(t), st_m = build_dag(m);
    printf("DAG: torus depth %u, root %llu triangles; soup depth %u, root %llu triangles\n", t->clusters.dag_depth,
           (unsigned long long)st_t.root_triangles, m->clusters.dag_depth, (unsigned long long)st_m.root_triangles);
    CHECK(m->clusters.dag_depth + 1 >= t->clusters.dag_depth && m->clusters.dag_depth <= t->clusters.dag_depth + 1);
    CHECK(t->clusters.dag_depth >= 5); /* 16,384 triangles: the torus itself reduces */
    CHECK(st_m.root_triangles <= 2 * st_t.root_triangles && 2 * st_m.root_triangles >= st_t.root_triangles);
    CHECK(keeps_corners(m, before)); /* the DAG adds no vertex and moves none */
    free(before);
    gdr_scene_destroy(s);
}

/* A cube of 6 faces, 2 triangles each, every triangle its own vertices: the corners of one face
 * are equal, those of neighbouring faces differ in normal (and uv). 36 vertices weld into 24. */
static void test_hard_edged_cube(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    uint32_t box = 0;
    check_ok(gdr_scene_create(&s, &err), &err, "scene");
    check_ok(gdr_procedural_box(s, (gdr_vec3){1, 1, 1}, &box, &err), &err, "box");
    CHECK(s->meshes[box].vertex_count == 24);
    uint32_t soup = add_exploded(s, box, "cube soup");
    corner *before = corners_of(&s->meshes[soup]);
    CHECK(s->meshes[soup].vertex_count == 36);
    check_ok(gdr_scene_build_clusters(s, NULL, &err), &err, "clusters");
    const gdr_mesh *m = &s->meshes[soup];
    CHECK(m->vertex_count == 24);
    CHECK(keeps_corners(m, before));
    /* Each position is held by three vertices, one per face normal. */
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        uint32_t same_position = 0;
        for (uint32_t w = 0; w < m->vertex_count; w++)
            same_position += !memcmp(&m->positions[v], &m->positions[w], sizeof(gdr_vec3));
        CHECK(same_position == 3);
    }
    free(before);
    gdr_scene_destroy(s);
}

/* A fan of 300 triangles around one hub, every triangle its own vertices: the hub's 300 equal
 * copies weld into copies of at most 128 uses (128, 128, 44), the rim's into one vertex each. */
static void test_fan_keeps_valence(void)
{
    enum { FAN = 300 };
    gdr_vec3 p[3 * FAN], nn[3 * FAN];
    gdr_vec2 t[3 * FAN];
    uint32_t idx[3 * FAN], mesh = 0;
    for (uint32_t f = 0; f < FAN; f++) {
        float a0 = 6.2831853f * (float)f / FAN, a1 = 6.2831853f * (float)((f + 1) % FAN) / FAN;
        p[3 * f] = (gdr_vec3){0, 0, 0};
        p[3 * f + 1] = (gdr_vec3){cosf(a0), sinf(a0), 0};
        p[3 * f + 2] = (gdr_vec3){cosf(a1), sinf(a1), 0};
        for (int k = 0; k < 3; k++) {
            nn[3 * f + k] = (gdr_vec3){0, 0, 1};
            t[3 * f + k] = (gdr_vec2){p[3 * f + k].x, p[3 * f + k].y};
            idx[3 * f + k] = 3 * f + (uint32_t)k;
        }
    }
    gdr_scene *s = NULL;
    gdr_error err = {0};
    check_ok(gdr_scene_create(&s, &err), &err, "scene");
    check_ok(gdr_scene_add_mesh(s, "fan", p, nn, t, 3 * FAN, idx, 3 * FAN, &mesh, &err), &err, "fan");
    check_ok(gdr_scene_build_clusters(s, NULL, &err), &err, "clusters");
    const gdr_mesh *m = &s->meshes[mesh];
    CHECK(m->vertex_count == FAN + 3);
    uint32_t *uses = calloc(m->vertex_count, sizeof *uses), most = 0, hubs = 0;
    for (uint32_t i = 0; i < m->index_count; i++)
        uses[m->indices[i]]++;
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        most = uses[v] > most ? uses[v] : most;
        hubs += m->positions[v].x == 0.0f && m->positions[v].y == 0.0f;
    }
    CHECK(most == GDR_WELD_MAX_VERTEX_USES && hubs == 3);
    free(uses);
    gdr_scene_destroy(s);
}

/* Vertex counts that are not a multiple of 3 (meshoptimizer's remap wants a triangle list), and an
 * unused vertex equal to a used one: a quad of two triangles, exploded, and a copy of its first
 * vertex that no triangle uses (7 vertices) welds into the quad's 4. */
static void test_odd_vertex_count(void)
{
    const gdr_vec3 p[7] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 0}, {0, 0, 0}};
    const uint32_t idx[6] = {0, 1, 2, 3, 4, 5};
    gdr_vec3 nn[7];
    gdr_vec2 t[7];
    for (int v = 0; v < 7; v++)
        nn[v] = (gdr_vec3){0, 0, 1}, t[v] = (gdr_vec2){p[v].x, p[v].y};
    gdr_scene *s = NULL;
    gdr_error err = {0};
    uint32_t mesh = 0;
    check_ok(gdr_scene_create(&s, &err), &err, "scene");
    check_ok(gdr_scene_add_mesh(s, "quad", p, nn, t, 7, idx, 6, &mesh, &err), &err, "quad");
    corner *before = corners_of(&s->meshes[mesh]);
    check_ok(gdr_scene_build_clusters(s, NULL, &err), &err, "clusters");
    CHECK(s->meshes[mesh].vertex_count == 4);
    CHECK(keeps_corners(&s->meshes[mesh], before));
    free(before);
    gdr_scene_destroy(s);
}

/* A mesh with no two equal vertices is left as it is: the same arrays, bit for bit. */
static void test_welded_mesh_untouched(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    uint32_t torus = 0;
    check_ok(gdr_scene_create(&s, &err), &err, "scene");
    check_ok(gdr_procedural_torus(s, 1.0f, 0.3f, 32, 16, &torus, &err), &err, "torus");
    gdr_mesh *m = &s->meshes[torus];
    gdr_vec3 *p = m->positions;
    uint32_t *idx = malloc(sizeof *idx * m->index_count), n = m->vertex_count, welded = 99;
    memcpy(idx, m->indices, sizeof *idx * m->index_count);
    check_ok(gdr_mesh_weld_vertices(m, &welded, &err), &err, "weld");
    CHECK(welded == 0 && m->vertex_count == n && m->positions == p);
    CHECK(memcmp(idx, m->indices, sizeof *idx * m->index_count) == 0);
    /* A bad index: left for gdr_meshlets_build to report, nothing welded. */
    m->indices[0] = n + 5;
    check_ok(gdr_mesh_weld_vertices(m, &welded, &err), &err, "weld bad index");
    CHECK(welded == 0 && m->vertex_count == n);
    m->indices[0] = idx[0];
    free(idx);
    gdr_scene_destroy(s);
}

int main(void)
{
    test_exploded_torus();
    test_hard_edged_cube();
    test_fan_keeps_valence();
    test_welded_mesh_untouched();
    test_odd_vertex_count();
    return test_finish("test_vertex_weld");
}
