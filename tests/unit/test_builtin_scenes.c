/* The built-in scenes made for tests and benchmarks: "lod-field" and "occlusion".
 * Small sizes: the LOD DAG of the field's mesh costs about 0.2 s per 100k triangles. */
#include <stdlib.h>
#include <string.h>

#include "gdr/procedural.h"
#include "gdr/io.h"
#include "gdr/scene.h"
#include "test_util.h"

#define PI_F 3.14159265358979f

/* --- helpers ---------------------------------------------------------------------------------- */

static gdr_vec4 world_sphere(const gdr_scene *s, uint32_t i)
{
    const gdr_instance *inst = &s->instances[i];
    gdr_vec4 b = s->meshes[inst->mesh].bounds;
    gdr_vec3 c = gdr_mat4_transform_point(inst->transform, (gdr_vec3){b.x, b.y, b.z});
    return (gdr_vec4){c.x, c.y, c.z, b.w * gdr_mat4_max_axis_scale(inst->transform)};
}

static float sphere_gap(gdr_vec4 a, gdr_vec4 b)
{
    return gdr_vec3_length(gdr_vec3_sub((gdr_vec3){a.x, a.y, a.z}, (gdr_vec3){b.x, b.y, b.z})) - a.w - b.w;
}

static int mesh_named(const gdr_scene *s, const char *name)
{
    for (uint32_t i = 0; i < s->mesh_count; i++)
        if (strcmp(s->meshes[i].name, name) == 0)
            return (int)i;
    return -1;
}

/* Same meshes (geometry and clusters), instances and cameras, byte for byte. */
static bool scenes_equal(const gdr_scene *a, const gdr_scene *b)
{
    if (a->mesh_count != b->mesh_count || a->instance_count != b->instance_count ||
        a->camera_count != b->camera_count || a->material_count != b->material_count)
        return false;
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        const gdr_mesh *x = &a->meshes[i], *y = &b->meshes[i];
        const gdr_mesh_clusters *cx = &x->clusters, *cy = &y->clusters;
        if (x->vertex_count != y->vertex_count || x->index_count != y->index_count ||
            memcmp(&x->bounds, &y->bounds, sizeof x->bounds) != 0 ||
            memcmp(x->positions, y->positions, sizeof(gdr_vec3) * x->vertex_count) != 0 ||
            memcmp(x->normals, y->normals, sizeof(gdr_vec3) * x->vertex_count) != 0 ||
            memcmp(x->uvs, y->uvs, sizeof(gdr_vec2) * x->vertex_count) != 0 ||
            memcmp(x->indices, y->indices, sizeof(uint32_t) * x->index_count) != 0)
            return false;
        if (cx->cluster_count != cy->cluster_count || cx->vertex_count != cy->vertex_count ||
            cx->triangle_byte_count != cy->triangle_byte_count || cx->group_count != cy->group_count ||
            memcmp(cx->clusters, cy->clusters, sizeof(gdr_cluster) * cx->cluster_count) != 0 ||
            memcmp(cx->vertices, cy->vertices, sizeof(uint32_t) * cx->vertex_count) != 0 ||
            memcmp(cx->triangles, cy->triangles, cx->triangle_byte_count) != 0 ||
            (cx->group_count && memcmp(cx->groups, cy->groups, sizeof(gdr_cluster_group) * cx->group_count) != 0))
            return false;
    }
    return memcmp(a->instances, b->instances, sizeof(gdr_instance) * a->instance_count) == 0 &&
           memcmp(a->cameras, b->cameras, sizeof(gdr_camera) * a->camera_count) == 0;
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Closed and consistently wound: every directed edge appears exactly once and its reverse too. */
static bool watertight(const gdr_mesh *m)
{
    uint64_t *edges = malloc(sizeof(uint64_t) * m->index_count);
    if (!edges)
        return false;
    for (uint32_t t = 0; t < m->index_count; t += 3)
        for (int k = 0; k < 3; k++)
            edges[t + k] = (uint64_t)m->indices[t + k] << 32 | m->indices[t + (k + 1) % 3];
    qsort(edges, m->index_count, sizeof(uint64_t), compare_u64);
    bool ok = true;
    for (uint32_t e = 0; e < m->index_count && ok; e++) {
        if (e > 0 && edges[e] == edges[e - 1])
            ok = false; /* a directed edge twice: a non-manifold edge or flipped winding */
        uint64_t reverse = edges[e] << 32 | edges[e] >> 32;
        ok = ok && bsearch(&reverse, edges, m->index_count, sizeof(uint64_t), compare_u64) != NULL;
    }
    free(edges);
    return ok;
}

static double signed_volume6(const gdr_mesh *m)
{
    double v = 0.0;
    for (uint32_t t = 0; t < m->index_count; t += 3) {
        gdr_vec3 a = m->positions[m->indices[t]], b = m->positions[m->indices[t + 1]];
        gdr_vec3 c = m->positions[m->indices[t + 2]];
        v += gdr_vec3_dot(a, gdr_vec3_cross(b, c));
    }
    return v;
}

static void check_bad_specs(const char *const *bad, size_t count, const char *prefix)
{
    for (size_t i = 0; i < count; i++) {
        gdr_error err = {0};
        gdr_scene *scene = NULL;
        gdr_status status = gdr_scene_load(bad[i], NULL, &scene, &err);
        CHECK(status == GDR_ERROR_INVALID_ARGUMENT);
        CHECK(scene == NULL);
        if (status == GDR_OK || strncmp(err.message, prefix, strlen(prefix)) != 0) {
            fprintf(stderr, "  spec '%s': status %d, message '%s'\n", bad[i], (int)status, err.message);
            test_failure_count++;
        }
        gdr_scene_destroy(scene);
    }
}

/* --- lod-field -------------------------------------------------------------------------------- */

static void test_lod_field_load(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL, *again = NULL, *other = NULL;
    CHECK(gdr_scene_load("lod-field:instances=60,triangles=3000,seed=7", NULL, &scene, &err) == GDR_OK);
    if (!scene) {
        fprintf(stderr, "%s\n", err.message);
        test_failure_count++;
        return;
    }
    CHECK(scene->mesh_count == 1 && scene->instance_count == 60 && scene->camera_count == 1);
    const gdr_mesh *m = &scene->meshes[0];
    CHECK(strcmp(m->name, "torus_knot") == 0);
    CHECK(m->index_count / 3 >= 2700 && m->index_count / 3 <= 3300); /* about the triangles asked for */
    CHECK(watertight(m));
    CHECK(signed_volume6(m) > 0.0); /* faces wind outward */
    for (uint32_t v = 0; v < m->vertex_count; v++)
        CHECK(gdr_vec3_length(m->positions[v]) <= 1.0001f);
    /* gdr_scene_load builds the LOD DAG. */
    CHECK(m->clusters.level0_cluster_count > 0 && m->clusters.cluster_count > m->clusters.level0_cluster_count);
    CHECK(m->clusters.group_count > 1 && m->clusters.dag_depth > 0);

    /* The same specification, options in another order, gives the same bytes; another seed moves
     * the copies but keeps the mesh. */
    CHECK(gdr_scene_load("lod-field:seed=7,triangles=3000,instances=60", NULL, &again, &err) == GDR_OK);
    CHECK(again && scenes_equal(scene, again));
    CHECK(gdr_scene_load("lod-field:instances=60,triangles=3000,seed=8", NULL, &other, &err) == GDR_OK);
    if (other) {
        CHECK(memcmp(other->meshes[0].positions, m->positions, sizeof(gdr_vec3) * m->vertex_count) == 0);
        CHECK(memcmp(other->instances, scene->instances, sizeof(gdr_instance) * 60) != 0);
    }
    gdr_scene_destroy(other);
    gdr_scene_destroy(again);
    gdr_scene_destroy(scene);
}

/* Defaults, through the create function (level-0 clusters only: no DAG). */
static void test_lod_field_layout(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_lod_field_desc desc = {.triangles = 1000}; /* instances 1000, seed 1, spacing 3 */
    CHECK(gdr_scene_create_lod_field(&desc, &scene, &err) == GDR_OK);
    if (!scene)
        return;
    CHECK(scene->instance_count == 1000);
    CHECK(scene->meshes[0].clusters.level0_cluster_count > 0 && scene->meshes[0].clusters.group_count == 0);
    gdr_camera cam = scene->cameras[0];
    CHECK(cam.yfov > 0.5f && cam.znear > 0.0f && cam.zfar == 0.0f);
    /* Every copy is in front of the camera, inside a 45-degree half-angle around its view
     * direction's horizontal (16:9 shows 45.8), nearer rows first, spread from near to far. */
    gdr_mat4 view = gdr_view_from_pose(cam.position, cam.rotation);
    float nearest = INFINITY, farthest = 0.0f, previous_depth = 0.0f;
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        gdr_vec4 s = world_sphere(scene, i);
        gdr_vec3 c = gdr_mat4_transform_point(view, (gdr_vec3){s.x, s.y, s.z});
        CHECK(c.z < -s.w - cam.znear);
        float depth = cam.position.z - s.z;
        CHECK(fabsf(s.x - cam.position.x) <= depth * tanf(45.0f * PI_F / 180.0f));
        CHECK(s.y - s.w >= -1e-3f); /* above y = 0 */
        CHECK(depth >= previous_depth - 3.0f); /* rows: at most one spacing back */
        previous_depth = fmaxf(previous_depth, depth);
        nearest = fminf(nearest, depth);
        farthest = fmaxf(farthest, depth);
        for (uint32_t j = i + 1; j < scene->instance_count; j++)
            if (sphere_gap(s, world_sphere(scene, j)) <= 0.0f) {
                fprintf(stderr, "  lod-field: copies %u and %u overlap\n", i, j);
                test_failure_count++;
            }
    }
    CHECK(nearest > 3.0f && nearest < 8.0f);
    CHECK(farthest > 80.0f && farthest < 130.0f); /* "from 4 m to about 100 m" */
    /* Random rotations: not all the same. */
    CHECK(memcmp(scene->instances[0].transform.m, scene->instances[1].transform.m, sizeof(float) * 12) != 0);
    gdr_scene_destroy(scene);

    /* The default mesh: about 100k triangles. */
    CHECK(gdr_scene_create_lod_field(&(gdr_lod_field_desc){.instances = 2}, &scene, &err) == GDR_OK);
    if (scene) {
        uint32_t triangles = scene->meshes[0].index_count / 3;
        CHECK(triangles > 99000 && triangles < 101000);
        CHECK(scene->instance_count == 2);
        gdr_scene_destroy(scene);
    }
}

static void test_lod_field_bad(void)
{
    static const char *const bad[] = {
        "lod-field:instances=0",      "lod-field:instances=-3",       "lod-field:instances=16000001",
        "lod-field:triangles=999",    "lod-field:triangles=abc",      "lod-field:triangles=16000001",
        "lod-field:spacing=2",        "lod-field:spacing=x",          "lod-field:spacing=nan",
        "lod-field:seed=0",           "lod-field:bogus=1",            "lod-field:seed",
        "lod-field:seed=1,seed=2",    "lod-field:instances=+5",       "lod-field:spacing=1e9",
    };
    check_bad_specs(bad, sizeof bad / sizeof bad[0], "lod-field: ");
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    const gdr_lod_field_desc bad_descs[] = {{.triangles = 10}, {.triangles = 16000001}, {.spacing = -1.0f},
                                            {.spacing = NAN}, {.instances = 20000000}};
    for (size_t i = 0; i < sizeof bad_descs / sizeof bad_descs[0]; i++) {
        CHECK(gdr_scene_create_lod_field(&bad_descs[i], &scene, &err) == GDR_ERROR_INVALID_ARGUMENT);
        CHECK(strncmp(err.message, "lod-field: ", 11) == 0);
    }
    CHECK(scene == NULL);
    /* Unknown-option messages list the known ones. */
    CHECK_FAILS(gdr_scene_load("lod-field:size=3", NULL, &scene, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    CHECK_NAMES(err, "instances, seed, triangles, spacing");
}

/* --- occlusion -------------------------------------------------------------------------------- */

typedef struct occlusion_layout {
    uint32_t buildings, first_visible, first_hidden;
    gdr_vec3 lo[64], hi[64]; /* building boxes */
} occlusion_layout;

/* Buildings are axis-aligned: a scaled 2 m cube (mesh "building"). */
static bool read_layout(const gdr_scene *s, uint32_t visible, uint32_t hidden, occlusion_layout *out)
{
    int building = mesh_named(s, "building");
    if (building < 0 || s->instances[0].mesh != (uint32_t)mesh_named(s, "ground"))
        return false;
    uint32_t n = 1;
    while (n < s->instance_count && s->instances[n].mesh == (uint32_t)building)
        n++;
    out->buildings = n - 1;
    out->first_visible = n;
    out->first_hidden = n + visible;
    if (out->buildings > 64 || s->instance_count != n + visible + hidden)
        return false;
    for (uint32_t b = 0; b < out->buildings; b++) {
        const float *m = s->instances[1 + b].transform.m;
        if (m[1] != 0.0f || m[2] != 0.0f || m[4] != 0.0f || m[6] != 0.0f || m[8] != 0.0f || m[9] != 0.0f)
            return false;
        out->lo[b] = (gdr_vec3){m[12] - m[0], m[13] - m[5], m[14] - m[10]};
        out->hi[b] = (gdr_vec3){m[12] + m[0], m[13] + m[5], m[14] + m[10]};
    }
    return true;
}

/* Does the segment from p to q pass through a building (slab test)? */
static bool segment_blocked(const occlusion_layout *l, gdr_vec3 p, gdr_vec3 q)
{
    float ps[3] = {p.x, p.y, p.z}, d[3] = {q.x - p.x, q.y - p.y, q.z - p.z};
    for (uint32_t b = 0; b < l->buildings; b++) {
        float lo[3] = {l->lo[b].x, l->lo[b].y, l->lo[b].z}, hi[3] = {l->hi[b].x, l->hi[b].y, l->hi[b].z};
        float t0 = 0.0f, t1 = 1.0f;
        for (int a = 0; a < 3 && t0 <= t1; a++) {
            if (fabsf(d[a]) < 1e-12f) {
                if (ps[a] < lo[a] || ps[a] > hi[a])
                    t1 = -1.0f;
                continue;
            }
            float ta = (lo[a] - ps[a]) / d[a], tb = (hi[a] - ps[a]) / d[a];
            t0 = fmaxf(t0, fminf(ta, tb));
            t1 = fminf(t1, fmaxf(ta, tb));
        }
        if (t0 <= t1)
            return true;
    }
    return false;
}

static float box_distance(const occlusion_layout *l, uint32_t b, gdr_vec3 p)
{
    gdr_vec3 d = {fmaxf(fmaxf(l->lo[b].x - p.x, p.x - l->hi[b].x), 0.0f),
                  fmaxf(fmaxf(l->lo[b].y - p.y, p.y - l->hi[b].y), 0.0f),
                  fmaxf(fmaxf(l->lo[b].z - p.z, p.z - l->hi[b].z), 0.0f)};
    return gdr_vec3_length(d);
}

/* Hidden objects whose centre a camera sees: inside a 16:9 frustum and no building in between. */
static uint32_t hidden_seen(const gdr_scene *s, const occlusion_layout *l, gdr_camera cam)
{
    gdr_mat4 view = gdr_view_from_pose(cam.position, cam.rotation);
    float tan_y = tanf(0.5f * cam.yfov), tan_x = tan_y * 16.0f / 9.0f;
    uint32_t seen = 0;
    for (uint32_t i = l->first_hidden; i < s->instance_count; i++) {
        gdr_vec4 w = world_sphere(s, i);
        gdr_vec3 c = gdr_mat4_transform_point(view, (gdr_vec3){w.x, w.y, w.z});
        if (c.z < -cam.znear && fabsf(c.x) < -c.z * tan_x && fabsf(c.y) < -c.z * tan_y &&
            !segment_blocked(l, cam.position, (gdr_vec3){w.x, w.y, w.z}))
            seen++;
    }
    return seen;
}

static void check_region(const gdr_scene *s, uint32_t first, uint32_t end, float x0, float x1, float z0, float z1,
                         float top)
{
    for (uint32_t i = first; i < end; i++) {
        gdr_vec4 w = world_sphere(s, i);
        if (!(w.x - w.w >= x0 && w.x + w.w <= x1 && w.z - w.w >= z0 && w.z + w.w <= z1 && w.y - w.w > 0.0f &&
              w.y + w.w <= top && w.w <= 0.6f * 1.25f)) {
            fprintf(stderr, "  occlusion: object %u (%g %g %g r %g) outside its region\n", i, (double)w.x,
                    (double)w.y, (double)w.z, (double)w.w);
            test_failure_count++;
        }
    }
}

static void test_occlusion_layout(void)
{
    const uint32_t visible = 80, hidden = 700;
    gdr_error err = {0};
    gdr_scene *scene = NULL, *again = NULL, *other = NULL;
    CHECK(gdr_scene_load("occlusion:hidden=700,visible=80,seed=5", NULL, &scene, &err) == GDR_OK);
    if (!scene) {
        fprintf(stderr, "%s\n", err.message);
        test_failure_count++;
        return;
    }
    static occlusion_layout layout;
    occlusion_layout *l = &layout;
    CHECK(read_layout(scene, visible, hidden, l));
    CHECK(l->buildings >= 12 && l->buildings <= 40);
    CHECK(scene->camera_count == 6);
    for (uint32_t i = 0; i < scene->mesh_count; i++) {
        CHECK(scene->meshes[i].clusters.cluster_count > 0); /* meshlets and DAG */
        CHECK(scene->meshes[i].clusters.group_count > 0);
    }

    /* The wall: within x [-70, 70], front at z in [-21.5, -20], 10 m high at least, the two fixed
     * gaps open, x in [-6, 7] closed, every x of [-70, 70] outside the gaps covered or in a gap
     * no wider than 3 m. */
    for (uint32_t b = 0; b < l->buildings; b++) {
        CHECK(l->lo[b].x >= -70.0f - 1e-3f && l->hi[b].x <= 70.0f + 1e-3f);
        CHECK(l->hi[b].z <= -20.0f + 1e-3f && l->hi[b].z >= -21.5f - 1e-3f && l->lo[b].z >= -31.5f - 1e-3f);
        CHECK(l->hi[b].y >= 9.8f && l->lo[b].y < 0.0f);
        CHECK(l->hi[b].x <= -9.0f + 1e-3f || l->lo[b].x >= -6.0f - 1e-3f);
        CHECK(l->hi[b].x <= 7.0f + 1e-3f || l->lo[b].x >= 10.5f - 1e-3f);
    }
    float open_run = 0.0f;
    for (float x = -69.95f; x < 70.0f; x += 0.1f) {
        bool covered = false;
        for (uint32_t b = 0; b < l->buildings && !covered; b++)
            covered = x >= l->lo[b].x && x <= l->hi[b].x;
        bool fixed_gap = (x > -9.0f && x < -6.0f) || (x > 7.0f && x < 10.5f);
        CHECK(covered || fixed_gap || fabsf(x) > 14.0f);
        open_run = covered ? 0.0f : open_run + 0.1f;
        CHECK(open_run <= 3.6f);
        CHECK(!(covered && fixed_gap));
    }

    /* Small objects stay in their regions, apart from each other and from the wall. */
    check_region(scene, l->first_visible, l->first_hidden, -40.0f, 40.0f, -17.0f, -3.0f, 1.3f);
    check_region(scene, l->first_hidden, scene->instance_count, -60.0f, 60.0f, -100.0f, -36.0f, 4.0f);
    for (uint32_t i = l->first_visible; i < scene->instance_count; i++) {
        gdr_vec4 a = world_sphere(scene, i);
        for (uint32_t j = i + 1; j < scene->instance_count; j++)
            if (sphere_gap(a, world_sphere(scene, j)) <= 0.0f) {
                fprintf(stderr, "  occlusion: objects %u and %u overlap\n", i, j);
                test_failure_count++;
            }
        for (uint32_t b = 0; b < l->buildings; b++)
            CHECK(box_distance(l, b, (gdr_vec3){a.x, a.y, a.z}) > a.w);
    }

    /* From the default camera the wall hides most hidden objects, some show through the gaps, and
     * no building stands in front of the visible objects. */
    gdr_camera cam = scene->cameras[0];
    uint32_t blocked = 0, in_front = 0;
    for (uint32_t i = l->first_hidden; i < scene->instance_count; i++) {
        gdr_vec4 w = world_sphere(scene, i);
        blocked += segment_blocked(l, cam.position, (gdr_vec3){w.x, w.y, w.z});
    }
    for (uint32_t i = l->first_visible; i < l->first_hidden; i++) {
        gdr_vec4 w = world_sphere(scene, i);
        in_front += !segment_blocked(l, cam.position, (gdr_vec3){w.x, w.y, w.z});
    }
    printf("occlusion: %u buildings; default camera: %u of %u hidden objects behind the wall, %u seen\n",
           l->buildings, blocked, hidden, hidden_seen(scene, l, cam));
    CHECK(blocked >= hidden * 9 / 10 && blocked < hidden);
    CHECK(hidden_seen(scene, l, cam) > 0);
    CHECK(in_front == visible);

    /* Deterministic; the seed changes the details but not the regions. */
    CHECK(gdr_scene_load("occlusion:seed=5,visible=80,hidden=700", NULL, &again, &err) == GDR_OK);
    CHECK(again && scenes_equal(scene, again));
    CHECK(gdr_scene_load("occlusion:hidden=700,visible=80,seed=6", NULL, &other, &err) == GDR_OK);
    CHECK(other && !scenes_equal(scene, other));
    gdr_scene_destroy(other);
    gdr_scene_destroy(again);
    gdr_scene_destroy(scene);
}

static void test_occlusion_camera_path(void)
{
    const uint32_t visible = 120, hidden = 1500;
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_occlusion_scene_desc desc = {.visible = visible, .hidden = hidden, .seed = 11};
    CHECK(gdr_scene_create_occlusion(&desc, &scene, &err) == GDR_OK);
    static occlusion_layout layout;
    if (!scene || !read_layout(scene, visible, hidden, &layout)) {
        test_failure_count++;
        gdr_scene_destroy(scene);
        return;
    }
    const occlusion_layout *l = &layout;
    const uint32_t cuts[] = {0, 70, 110, 160, 200, 216};
    uint32_t cut_count = 0;
    gdr_camera previous = {0};
    for (uint32_t f = 0; f < GDR_OCCLUSION_PATH_FRAMES; f++) {
        bool cut = false;
        gdr_camera cam = gdr_scene_occlusion_camera_path(f, &cut);
        bool expected = false;
        for (size_t k = 0; k < sizeof cuts / sizeof cuts[0]; k++)
            expected = expected || cuts[k] == f;
        CHECK(cut == expected);
        cut_count += cut;
        gdr_quat q = cam.rotation;
        CHECK(fabsf(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w - 1.0f) < 1e-4f);
        CHECK(cam.yfov > 0.5f && cam.znear > 0.0f && cam.zfar == 0.0f);
        /* Never inside a building or an object, never below the ground. */
        CHECK(cam.position.y > 1.0f);
        for (uint32_t b = 0; b < l->buildings; b++)
            CHECK(box_distance(l, b, cam.position) > cam.znear);
        for (uint32_t i = l->first_visible; i < scene->instance_count; i++) {
            gdr_vec4 w = world_sphere(scene, i);
            CHECK(gdr_vec3_length(gdr_vec3_sub(cam.position, (gdr_vec3){w.x, w.y, w.z})) > w.w + cam.znear);
        }
        /* Cuts jump; elsewhere the camera moves less than 2 m a frame. */
        if (f > 0) {
            float moved = gdr_vec3_length(gdr_vec3_sub(cam.position, previous.position));
            CHECK(cut ? moved > 5.0f : moved < 2.0f);
        }
        previous = cam;
    }
    CHECK(cut_count == 6);
    /* The path repeats, and the scene's cameras are on it. */
    bool cut = false;
    gdr_camera wrapped = gdr_scene_occlusion_camera_path(GDR_OCCLUSION_PATH_FRAMES, &cut);
    gdr_camera first = gdr_scene_occlusion_camera_path(0, NULL);
    CHECK(cut && memcmp(&wrapped.position, &first.position, sizeof first.position) == 0);
    CHECK(memcmp(&scene->cameras[0].position, &first.position, sizeof first.position) == 0);
    /* The spin turns 22.5 degrees a frame. */
    gdr_vec3 f0 = gdr_quat_rotate(gdr_scene_occlusion_camera_path(203, NULL).rotation, (gdr_vec3){0, 0, -1});
    gdr_vec3 f1 = gdr_quat_rotate(gdr_scene_occlusion_camera_path(204, NULL).rotation, (gdr_vec3){0, 0, -1});
    CHECK_NEAR(gdr_vec3_dot(f0, f1), cosf(22.5f * PI_F / 180.0f), 1e-4);

    /* Hidden objects come out: past the wall's end and above it more are seen at the end of the
     * shot than at its start; facing the wall, none; behind it, most. */
    uint32_t strafe0 = hidden_seen(scene, l, gdr_scene_occlusion_camera_path(110, NULL));
    uint32_t strafe1 = hidden_seen(scene, l, gdr_scene_occlusion_camera_path(159, NULL));
    uint32_t crane0 = hidden_seen(scene, l, gdr_scene_occlusion_camera_path(160, NULL));
    uint32_t crane1 = hidden_seen(scene, l, gdr_scene_occlusion_camera_path(199, NULL));
    uint32_t close = hidden_seen(scene, l, gdr_scene_occlusion_camera_path(200, NULL));
    uint32_t behind = hidden_seen(scene, l, gdr_scene_occlusion_camera_path(70, NULL));
    uint32_t gap_min = hidden, gap_max = 0;
    for (uint32_t f = 216; f < 240; f++) {
        uint32_t n = hidden_seen(scene, l, gdr_scene_occlusion_camera_path(f, NULL));
        gap_min = n < gap_min ? n : gap_min;
        gap_max = n > gap_max ? n : gap_max;
    }
    printf("occlusion path: hidden objects seen: strafe %u -> %u, crane %u -> %u, close %u, behind %u, "
           "gap %u .. %u\n", strafe0, strafe1, crane0, crane1, close, behind, gap_min, gap_max);
    CHECK(strafe1 > strafe0 + 20 && crane1 > crane0 + hidden / 4);
    CHECK(close == 0 && behind > hidden / 2);
    CHECK(gap_max > gap_min + 5);
    gdr_scene_destroy(scene);
}

static void test_occlusion_defaults_and_bad(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    CHECK(gdr_scene_create_occlusion(NULL, &scene, &err) == GDR_OK);
    static occlusion_layout layout;
    CHECK(scene && read_layout(scene, 300, 4000, &layout)); /* defaults: 300 visible, 4000 hidden */
    gdr_scene_destroy(scene);
    static const char *const bad[] = {
        "occlusion:hidden=0",  "occlusion:visible=1000001", "occlusion:instances=5", "occlusion:seed=abc",
        "occlusion:hidden=5,hidden=6", "occlusion:hidden=", "occlusion:visible=-1", "occlusion:seed=1.5",
    };
    check_bad_specs(bad, sizeof bad / sizeof bad[0], "occlusion: ");
    scene = NULL;
    CHECK(gdr_scene_create_occlusion(&(gdr_occlusion_scene_desc){.hidden = 2000000}, &scene, &err) ==
          GDR_ERROR_INVALID_ARGUMENT);
    CHECK(scene == NULL);
    CHECK_FAILS(gdr_scene_load("occlusion:size=3", NULL, &scene, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    CHECK_NAMES(err, "seed, hidden, visible");
}

/* --- unique-field ------------------------------------------------------------------------------ */

static void test_unique_field(void)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL, *again = NULL, *other = NULL;
    CHECK(gdr_scene_load("unique-field:meshes=5,triangles=2000,seed=2", NULL, &scene, &err) == GDR_OK);
    if (!scene)
        return;
    CHECK(scene->mesh_count == 5 && scene->instance_count == 5 && scene->camera_count == 1);
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh *mesh = &scene->meshes[m];
        CHECK(scene->instances[m].mesh == m);
        CHECK(mesh->index_count / 3 >= 1800 && mesh->index_count / 3 <= 2200);
        CHECK(watertight(mesh));
        for (uint32_t v = 0; v < mesh->vertex_count; v++)
            CHECK(gdr_vec3_length(mesh->positions[v]) <= 0.95f);
        CHECK(mesh->clusters.group_count > 0); /* gdr_scene_load builds the LOD DAG */
        for (uint32_t k = 0; k < m; k++) /* every mesh its own shape */
            CHECK(memcmp(mesh->positions, scene->meshes[k].positions, 12 * (size_t)mesh->vertex_count) != 0);
    }
    CHECK(gdr_scene_load("unique-field:seed=2,triangles=2000,meshes=5", NULL, &again, &err) == GDR_OK);
    CHECK(gdr_scene_load("unique-field:meshes=5,triangles=2000,seed=3", NULL, &other, &err) == GDR_OK);
    if (again && other) {
        CHECK(memcmp(again->meshes[4].positions, scene->meshes[4].positions, 12 * (size_t)scene->meshes[4].vertex_count) == 0);
        CHECK(memcmp(other->meshes[4].positions, scene->meshes[4].positions, 12 * (size_t)scene->meshes[4].vertex_count) != 0);
    }
    gdr_scene_destroy(scene), gdr_scene_destroy(again), gdr_scene_destroy(other);
    static const char *const bad[] = {"unique-field:meshes=0", "unique-field:meshes=100001",
                                      "unique-field:triangles=999", "unique-field:spacing=1",
                                      "unique-field:instances=3", "unique-field:seed=0"};
    check_bad_specs(bad, sizeof bad / sizeof bad[0], "unique-field: ");
}

static void test_spec_names(void)
{
    CHECK(gdr_scene_spec_is_builtin("demo"));
    CHECK(gdr_scene_spec_is_builtin("demo:instances=3"));
    CHECK(gdr_scene_spec_is_builtin("lod-field"));
    CHECK(gdr_scene_spec_is_builtin("lod-field:triangles=5000"));
    CHECK(gdr_scene_spec_is_builtin("occlusion"));
    CHECK(gdr_scene_spec_is_builtin("occlusion:seed=2"));
    CHECK(gdr_scene_spec_is_builtin("unique-field:meshes=2"));
    CHECK(!gdr_scene_spec_is_builtin("demos"));
    CHECK(!gdr_scene_spec_is_builtin("lod-field.gltf"));
    CHECK(!gdr_scene_spec_is_builtin("occlusion.obj"));
    CHECK(!gdr_scene_spec_is_builtin("models/demo.glb"));
    CHECK(!gdr_scene_spec_is_builtin(""));
    /* The demo keeps its options and messages. */
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    CHECK(gdr_scene_load("demo:instances=0", NULL, &scene, &err) == GDR_ERROR_INVALID_ARGUMENT);
    CHECK(strcmp(err.message, "demo: instances=0 is not an integer in [1, 16000000]") == 0);
    CHECK(gdr_scene_load("demo:bogus=1", NULL, &scene, &err) == GDR_ERROR_INVALID_ARGUMENT);
    CHECK(strcmp(err.message, "demo: unknown option 'bogus' (instances, seed, spacing, textures)") == 0);
}

int main(void)
{
    test_spec_names();
    test_lod_field_load();
    test_lod_field_layout();
    test_lod_field_bad();
    test_occlusion_layout();
    test_occlusion_camera_path();
    test_occlusion_defaults_and_bad();
    test_unique_field();
    return test_finish("test_builtin_scenes");
}
