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
#include "charted_torus.h"
#include "test_util.h"

static void check_ok(gdr_status s, const gdr_error *err, const char *what)
{
    if (s != GDR_OK) {
        fprintf(stderr, "%s: %s\n", what, err->message);
        exit(1);
    }
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
