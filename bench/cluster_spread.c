/* How compact level-0 clusters are, and what their spheres do to the LOD groups above them.
 *
 *   cluster_spread NAME|FILE
 *
 * NAME is one of lod_quality's procedural meshes (blob, knot, torus-1m, torus-UxV); FILE any model
 * gdr loads (built without the cache). Prints, over every mesh: level-0 clusters, triangles each,
 * the share under half full (fewer than 62 triangles), the cluster radius's median and the 99th
 * percentile and largest over the median; then, by DAG depth 0-5, the median group radius beside
 * the median radius that the group's own clusters need (a sphere about the mean of their centres
 * that encloses their spheres). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/scene.h"
#include "procedural_set.h"

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double at(double *v, size_t n, double q)
{
    qsort(v, n, sizeof *v, by_value);
    return n ? v[(size_t)(q * (double)(n - 1))] : 0.0;
}

static gdr_scene *load(const char *name)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    gdr_status st = gdr_scene_create(&s, &err);
    if (st == GDR_OK && bench_procedural_mesh(s, name, NULL, &st, &err)) {
        if (st == GDR_OK)
            st = gdr_scene_build_clusters(s, NULL, &err);
        if (st == GDR_OK)
            st = gdr_scene_build_lod(s, &(gdr_lod_options){.no_progress = 1}, NULL, &err);
    } else {
        gdr_scene_destroy(s);
        s = NULL;
        st = gdr_scene_load(name, &(gdr_load_options){.no_cache = 1, .no_progress = 1}, &s, &err);
    }
    if (st != GDR_OK) {
        fprintf(stderr, "cluster_spread: %s: %s\n", name, err.message);
        exit(1);
    }
    return s;
}

static void level0(const gdr_scene *s)
{
    size_t n = 0, under = 0, tris = 0, all = 0, all_under = 0;
    for (uint32_t m = 0; m < s->mesh_count; m++)
        n += s->meshes[m].clusters.level0_cluster_count;
    double *r = malloc((n + 1) * sizeof *r);
    size_t k = 0;
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        const gdr_mesh_clusters *mc = &s->meshes[m].clusters;
        for (uint32_t c = 0; c < mc->cluster_count; c++) {
            all++;
            all_under += mc->clusters[c].triangle_count < 62;
            if (c >= mc->level0_cluster_count)
                continue;
            r[k++] = mc->clusters[c].sphere.w;
            tris += mc->clusters[c].triangle_count;
            under += mc->clusters[c].triangle_count < 62;
        }
    }
    double median = at(r, n, 0.5), p99 = at(r, n, 0.99), largest = at(r, n, 1.0);
    size_t over3 = 0;
    for (size_t i = 0; i < n; i++)
        over3 += r[i] > 3.0 * median;
    printf("level 0: %zu clusters, %.1f triangles each, %.1f%% under half full; radius median %.4g, p99 %.2fx, "
           "largest %.2fx, %zu over 3x\nDAG: %zu clusters, %.1f%% under half full\n",
           n, (double)tris / (double)n, 100.0 * (double)under / (double)n, median, p99 / median, largest / median,
           over3, all, 100.0 * (double)all_under / (double)all);
    free(r);
}

/* The radius a group needs for its own clusters: about the mean of their centres. */
static double needed_radius(const gdr_mesh_clusters *mc, const gdr_cluster_group *g)
{
    double centre[3] = {0, 0, 0}, radius = 0.0;
    for (uint32_t i = 0; i < g->cluster_count; i++) {
        const gdr_vec4 q = mc->clusters[g->first_cluster + i].sphere;
        centre[0] += q.x / g->cluster_count, centre[1] += q.y / g->cluster_count, centre[2] += q.z / g->cluster_count;
    }
    for (uint32_t i = 0; i < g->cluster_count; i++) {
        const gdr_vec4 q = mc->clusters[g->first_cluster + i].sphere;
        double d = sqrt((q.x - centre[0]) * (q.x - centre[0]) + (q.y - centre[1]) * (q.y - centre[1]) +
                        (q.z - centre[2]) * (q.z - centre[2])) + q.w;
        radius = d > radius ? d : radius;
    }
    return radius;
}

static void groups(const gdr_scene *s)
{
    size_t n = 0;
    for (uint32_t m = 0; m < s->mesh_count; m++)
        n += s->meshes[m].clusters.group_count;
    double *have = malloc((n + 1) * sizeof *have), *need = malloc((n + 1) * sizeof *need);
    for (uint32_t d = 0; d <= 5; d++) {
        size_t k = 0;
        for (uint32_t m = 0; m < s->mesh_count; m++) {
            const gdr_mesh_clusters *mc = &s->meshes[m].clusters;
            for (uint32_t g = 0; g < mc->group_count; g++)
                if (mc->groups[g].depth == d && g + 1 < mc->group_count) {
                    have[k] = mc->groups[g].sphere.w;
                    need[k++] = needed_radius(mc, &mc->groups[g]);
                }
        }
        if (k)
            printf("depth %u: %zu groups, median sphere %.4g, own clusters need %.4g\n", d, k, at(have, k, 0.5),
                   at(need, k, 0.5));
    }
    free(have);
    free(need);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: cluster_spread NAME|FILE\n");
        return 2;
    }
    gdr_scene *s = load(argv[1]);
    level0(s);
    groups(s);
    gdr_scene_destroy(s);
    return 0;
}
