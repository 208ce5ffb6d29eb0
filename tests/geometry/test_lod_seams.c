/* The LOD DAG of UV-mapped meshes: a torus cut into many charts (every chart its own vertices, so
 * every chart border is a uv seam and every chart corner a position held by four vertices), half
 * of them with mirrored uvs, and hard normal edges between chart rows. The simplifier must cross
 * those seams (lod_simplify.c): every level about halves, the DAG ends in a single root cluster,
 * and every frontier of the build (a crack-free cut) has no open edge by position. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "gdr/scene.h"
#include "procedural/procedural_meshes.h"
#include "test_util.h"

#define CHARTS_U 12u
#define CHARTS_V 6u

static void check_ok(gdr_status s, const gdr_error *err, const char *what)
{
    if (s != GDR_OK) {
        fprintf(stderr, "%s: %s\n", what, err->message);
        exit(1);
    }
}

/* The torus's triangles, each chart (a cell of CHARTS_U x CHARTS_V in the torus's own uv) with its
 * own copy of every vertex it uses: uv in the chart's atlas tile (mirrored in u on odd charts), the
 * smooth normal, except that odd chart rows tilt theirs (a hard normal edge along each row
 * border). */
static uint32_t add_charted_torus(gdr_scene *s, uint32_t segments, uint32_t sides)
{
    gdr_scene *t = NULL;
    gdr_error err = {0};
    uint32_t torus;
    check_ok(gdr_scene_create(&t, &err), &err, "scene");
    check_ok(gdr_procedural_torus(t, 1.0f, 0.35f, segments, sides, &torus, &err), &err, "torus");
    const gdr_mesh *m = &t->meshes[torus];
    uint32_t n = m->index_count;
    gdr_vec3 *p = malloc(sizeof *p * n), *nr = malloc(sizeof *nr * n);
    gdr_vec2 *uv = malloc(sizeof *uv * n);
    uint32_t *idx = malloc(sizeof *idx * n);
    uint32_t *slot = malloc(sizeof *slot * (size_t)m->vertex_count * CHARTS_U * CHARTS_V);
    memset(slot, 0xff, sizeof *slot * (size_t)m->vertex_count * CHARTS_U * CHARTS_V);
    uint32_t count = 0;
    for (uint32_t i = 0; i < n; i += 3) {
        /* the chart of the triangle's centre, in the torus's (seam-free) parameter */
        float cu = 0.0f, cv = 0.0f;
        for (int k = 0; k < 3; k++) {
            gdr_vec3 q = m->positions[m->indices[i + k]];
            cu += atan2f(q.z, q.x);
            float ring = sqrtf(q.x * q.x + q.z * q.z) - 1.0f;
            cv += atan2f(q.y, ring);
        }
        /* centres of triangles spanning the angle's wrap fall back into range below */
        float fu = cu / 3.0f / 6.2831853f + 0.5f, fv = cv / 3.0f / 6.2831853f + 0.5f;
        uint32_t gu = (uint32_t)(fu * CHARTS_U) % CHARTS_U, gv = (uint32_t)(fv * CHARTS_V) % CHARTS_V;
        uint32_t chart = gv * CHARTS_U + gu;
        for (int k = 0; k < 3; k++) {
            uint32_t v = m->indices[i + k];
            uint32_t *sl = &slot[(size_t)v * CHARTS_U * CHARTS_V + chart];
            if (*sl == UINT32_MAX) {
                gdr_vec3 q = m->positions[v];
                float lu = atan2f(q.z, q.x) / 6.2831853f + 0.5f, ring = sqrtf(q.x * q.x + q.z * q.z) - 1.0f;
                float lv = atan2f(q.y, ring) / 6.2831853f + 0.5f;
                lu = lu * CHARTS_U - (float)gu, lv = lv * CHARTS_V - (float)gv;
                lu -= roundf(lu - 0.5f), lv -= roundf(lv - 0.5f); /* into the chart's cell across the wrap */
                if (chart % 2)
                    lu = 1.0f - lu;
                *sl = count;
                p[count] = q;
                uv[count] = (gdr_vec2){((float)gu + lu) / CHARTS_U, ((float)gv + lv) / CHARTS_V};
                gdr_vec3 nn = m->normals[v];
                if (gv % 2) {
                    nn = (gdr_vec3){nn.x + 0.5f, nn.y, nn.z};
                    float l = sqrtf(nn.x * nn.x + nn.y * nn.y + nn.z * nn.z);
                    nn = (gdr_vec3){nn.x / l, nn.y / l, nn.z / l};
                }
                nr[count++] = nn;
            }
            idx[i + k] = *sl;
        }
    }
    uint32_t out = 0;
    check_ok(gdr_scene_add_mesh(s, "charted", p, nr, uv, count, idx, n, &out, &err), &err, "charted torus");
    free(p), free(nr), free(uv), free(idx), free(slot);
    gdr_scene_destroy(t);
    return out;
}

/* The level a cluster was made at: 0, or one more than the depth of the group that made it. */
static uint32_t cluster_level(const gdr_mesh_clusters *mc, uint32_t c)
{
    uint32_t g = mc->clusters[c].refined_group;
    return g == GDR_NO_INDEX ? 0 : mc->groups[g].depth + 1;
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Edges of the clusters drawn after `steps` steps of the build (made at a level <= steps, not yet
 * taken by a group of an earlier step than that) that no drawn triangle runs the other way, by
 * position (coordinates within 1e-5 of the radius). */
static uint32_t open_edges_after(const gdr_mesh *m, uint32_t steps, uint64_t *triangles)
{
    const gdr_mesh_clusters *mc = &m->clusters;
    uint32_t *pos = malloc(sizeof *pos * m->vertex_count);
    const float tol = 1e-5f * m->bounds.w; /* the torus's seam closes by sinf(2 pi), not bit-equal */
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        pos[v] = v;
        for (uint32_t w = 0; w < v; w++)
            if (fabsf(m->positions[v].x - m->positions[w].x) <= tol &&
                fabsf(m->positions[v].y - m->positions[w].y) <= tol &&
                fabsf(m->positions[v].z - m->positions[w].z) <= tol) {
                pos[v] = pos[w];
                break;
            }
    }
    uint64_t *keys = malloc(sizeof *keys * 3 * (size_t)m->index_count * 2);
    size_t k = 0;
    *triangles = 0;
    uint32_t root = mc->group_count - 1;
    for (uint32_t c = 0; c < mc->cluster_count; c++) {
        const gdr_cluster *cl = &mc->clusters[c];
        uint32_t g = cl->group;
        int drawn = cluster_level(mc, c) <= steps && (g == root || mc->groups[g].depth >= steps);
        if (!drawn)
            continue;
        *triangles += cl->triangle_count;
        const uint8_t *t = mc->triangles + cl->triangle_offset;
        const uint32_t *v = mc->vertices + cl->vertex_offset;
        for (uint32_t i = 0; i < cl->triangle_count * 3u; i++) {
            uint32_t a = pos[v[t[i]]], b = pos[v[t[i - i % 3 + (i % 3 + 1) % 3]]];
            keys[k++] = (uint64_t)a << 32 | b;
        }
    }
    qsort(keys, k, sizeof *keys, compare_u64);
    uint32_t open = 0;
    for (size_t i = 0; i < k; i++) {
        uint64_t rev = keys[i] << 32 | keys[i] >> 32;
        size_t lo = 0, hi = k;
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            if (keys[mid] < rev)
                lo = mid + 1;
            else
                hi = mid;
        }
        open += !(lo < k && keys[lo] == rev);
    }
    free(keys);
    free(pos);
    return open;
}

static void test_charted_torus(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    check_ok(gdr_scene_create(&s, &err), &err, "scene");
    uint32_t mi = add_charted_torus(s, 192, 64);
    gdr_lod_options o = {.thread_count = 2, .no_progress = 1};
    gdr_lod_stats st = {0};
    check_ok(gdr_scene_build_lod(s, &o, &st, &err), &err, "build");
    const gdr_mesh *m = &s->meshes[mi];
    const gdr_mesh_clusters *mc = &m->clusters;
    const gdr_cluster_group *root = &mc->groups[mc->group_count - 1];
    uint32_t root_triangles = 0;
    for (uint32_t i = 0; i < root->cluster_count; i++)
        root_triangles += mc->clusters[root->first_cluster + i].triangle_count;
    printf("charted torus: %u triangles, %u vertices, depth %u, root %u clusters / %u triangles, stuck %llu\n",
           m->index_count / 3, m->vertex_count, mc->dag_depth, root->cluster_count, root_triangles,
           (unsigned long long)st.stuck_groups);
    CHECK(root->cluster_count == 1);
    /* every step about halves what it simplifies: the frontier after each step */
    uint64_t before = m->index_count / 3;
    for (uint32_t step = 0; step <= mc->dag_depth; step++) {
        uint64_t triangles;
        uint32_t open = open_edges_after(m, step, &triangles);
        printf("  after %u steps: %llu triangles, %u open edges\n", step, (unsigned long long)triangles, open);
        CHECK(open == 0);
        if (step > 0 && before > 4u * GDR_CLUSTER_MAX_TRIANGLES)
            CHECK(triangles <= before * 0.65);
        before = triangles;
    }
    gdr_scene_destroy(s);
}

int main(void)
{
    test_charted_torus();
    return test_finish("test_lod_seams");
}
