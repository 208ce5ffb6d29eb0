/* The LOD DAG's roots of a file's meshes: for each mesh its triangles, why its build stopped, its
 * depth, its root (clusters, triangles) and the groups simplified by vertex clustering, and the
 * time of the DAG build (one thread: gdr_mesh_build_lod_dag rebuilds each mesh's DAG), then the
 * sums. Public API only.
 *
 * usage: lod_levels [--levels] FILE...   (--levels: each mesh's groups and errors by depth) */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/scene.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static const char *stop_name(const gdr_lod_stats *st)
{
    return st->stop_counts[GDR_LOD_STOP_SINGLE_CLUSTER] ? "single cluster"
           : st->stop_counts[GDR_LOD_STOP_NO_PROGRESS] ? "no progress"
           : st->stop_counts[GDR_LOD_STOP_LEVEL_LIMIT] ? "level limit"
                                                       : "none";
}

/* Per DAG depth: the groups formed there, the triangles of the clusters they made and their
 * largest error in the mesh's bounding radius R. */
static void print_levels(const gdr_mesh *mesh)
{
    const gdr_mesh_clusters *mc = &mesh->clusters;
    for (uint32_t d = 0; d <= mc->dag_depth; d++) {
        uint64_t groups = 0, made = 0;
        float error = 0.0f;
        for (uint32_t g = 0; g < mc->group_count; g++)
            if (mc->groups[g].depth == d) {
                groups++;
                error = mc->groups[g].error > error ? mc->groups[g].error : error;
            }
        for (uint32_t c = 0; c < mc->cluster_count; c++)
            if (mc->clusters[c].refined_group != GDR_NO_INDEX && mc->groups[mc->clusters[c].refined_group].depth == d)
                made += mc->clusters[c].triangle_count;
        printf("    depth %2u: %4llu groups, made %7llu tris, largest error %.4g R\n", d, (unsigned long long)groups,
               (unsigned long long)made, (double)(error / mesh->bounds.w));
    }
}

static int roots(const char *path, int levels)
{
    gdr_load_options lo = {.no_cache = 1, .no_progress = 1};
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    if (gdr_scene_load(path, &lo, &scene, &err) != GDR_OK) {
        fprintf(stderr, "lod_levels: %s: %s\n", path, err.message);
        return 1;
    }
    uint64_t tris = 0, root_clusters = 0, root_tris = 0, sloppy = 0;
    double seconds = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        gdr_mesh *mesh = &scene->meshes[m];
        if (mesh->clusters.level0_cluster_count == 0)
            continue;
        gdr_lod_options o = {.thread_count = 1, .no_progress = 1};
        gdr_lod_stats st;
        double t0 = now();
        if (gdr_mesh_build_lod_dag(mesh, &o, &st, &err) != GDR_OK) {
            fprintf(stderr, "lod_levels: %s: mesh %u: %s\n", path, m, err.message);
            gdr_scene_destroy(scene);
            return 1;
        }
        seconds += now() - t0;
        if (levels)
            print_levels(mesh);
        printf("  mesh %3u %-24.24s %8llu tris  %-14s depth %2u  root %3llu clusters / %6llu tris  sloppy %llu\n", m,
               mesh->name, (unsigned long long)st.input_triangles, stop_name(&st), st.max_depth,
               (unsigned long long)st.root_clusters, (unsigned long long)st.root_triangles,
               (unsigned long long)st.sloppy_groups);
        tris += st.input_triangles;
        root_clusters += st.root_clusters;
        root_tris += st.root_triangles;
        sloppy += st.sloppy_groups;
    }
    printf("%s: %u meshes, %llu tris, roots %llu clusters / %llu tris, sloppy groups %llu, DAG build %.3f s (1 thread)\n",
           path, scene->mesh_count, (unsigned long long)tris, (unsigned long long)root_clusters,
           (unsigned long long)root_tris, (unsigned long long)sloppy, seconds);
    gdr_scene_destroy(scene);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: lod_levels FILE...\n");
        return 2;
    }
    int status = 0, levels = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--levels") == 0)
            levels = 1;
        else
            status |= roots(argv[i], levels);
    }
    return status;
}
