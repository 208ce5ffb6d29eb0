/* LOD DAG build benchmark: build throughput in input triangles per second with 1 and 2
 * threads, peak heap memory per input triangle and DAG triangles / input triangles, for a dense
 * procedural mesh (the displaced icosphere of the demo scene), the largest mesh of a real file and
 * that file's whole scene (gdr_scene_build_lod: small meshes are built side by side). Prints a
 * table and JSON.
 *
 * usage: lod_bench [--levels N] [--file PATH] [--repeat R] [--json FILE]
 *   --levels N  icosphere subdivisions of the procedural mesh (default 8: 1,310,720 triangles)
 *   --file PATH glTF/GLB/OBJ whose largest mesh, then whole scene, is built
 *               (default: assimp-testmodels' 2CylinderEngine.glb when installed)
 *   --repeat R  builds per configuration, the fastest is reported (default 1)
 *
 * Peak memory is counted exactly (heap_count.c wraps the allocator in every library, meshoptimizer
 * and METIS included), and the benchmark reports the most in use during a build minus what was in use when it started
 * ("heap B/t": per input triangle; the DAG's own arrays are part of it). Columns: meshlet_s is the
 * level-0 build (gdr_meshlets_build, one thread), dag_s the DAG build; Mtris/s counts input
 * triangles per second of the DAG build, "+meshlets" of both together. */
#define _GNU_SOURCE
#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "heap_count.h"
#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/scene.h"
#include "procedural/procedural_meshes.h"
#include "io/loaders.h"

/* --- helpers -------------------------------------------------------------------------------------- */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static long max_rss_kib(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss;
}

static void die(const char *what, const gdr_error *err)
{
    fprintf(stderr, "lod_bench: %s: %s\n", what, err->message);
    exit(1);
}

static void *copy_array(const void *p, size_t bytes)
{
    void *q = malloc(bytes ? bytes : 1);
    if (!q) {
        fprintf(stderr, "lod_bench: out of memory\n");
        exit(1);
    }
    memcpy(q, p, bytes);
    return q;
}

static gdr_mesh_clusters copy_level0(const gdr_mesh_clusters *c)
{
    gdr_mesh_clusters out = *c;
    out.clusters = copy_array(c->clusters, sizeof *c->clusters * c->cluster_count);
    out.vertices = copy_array(c->vertices, sizeof *c->vertices * c->vertex_count);
    out.triangles = copy_array(c->triangles, c->triangle_byte_count);
    /* level 0's hierarchy too: the DAG build frees and replaces it */
    out.lod_nodes = c->lod_nodes ? copy_array(c->lod_nodes, sizeof *c->lod_nodes * c->lod_node_count) : NULL;
    return out;
}

typedef struct result {
    const char *input;
    uint32_t threads;
    uint64_t triangles;
    double meshlet_s, dag_s;
    double heap_bytes_per_triangle;
    gdr_lod_stats stats;
} result;

/* Builds the DAG of `mesh` (whose level 0 is `level0`, copied for each run) with `threads`. */
static result run(const char *input, gdr_mesh *mesh, const gdr_mesh_clusters *level0, double meshlet_s,
                  uint32_t threads, int repeat)
{
    result r = {.input = input, .threads = threads, .triangles = mesh->index_count / 3, .meshlet_s = meshlet_s,
                .dag_s = 1e30};
    for (int k = 0; k < repeat; k++) {
        gdr_mesh_clusters_free(&mesh->clusters);
        mesh->clusters = copy_level0(level0);
        gdr_error err = {0};
        gdr_lod_options o = {.thread_count = threads, .no_progress = 1};
        long long heap_before = heap_peak_reset();
        double t0 = now();
        if (gdr_mesh_build_lod_dag(mesh, &o, &r.stats, &err) != GDR_OK)
            die(input, &err);
        double t = now() - t0;
        r.dag_s = t < r.dag_s ? t : r.dag_s;
        r.heap_bytes_per_triangle = (double)(heap_peak() - heap_before) / (double)r.triangles;
    }
    return r;
}

static void print_row(const result *r)
{
    char stop[64];
    const uint32_t *n = r->stats.stop_counts;
    if (r->stats.mesh_count == 1)
        snprintf(stop, sizeof stop, "%s", n[GDR_LOD_STOP_SINGLE_CLUSTER] ? "single" : n[GDR_LOD_STOP_NO_PROGRESS] ? "no-progress" : "limit");
    else
        snprintf(stop, sizeof stop, "%u single, %u no-progress, %u limit", n[GDR_LOD_STOP_SINGLE_CLUSTER],
                 n[GDR_LOD_STOP_NO_PROGRESS], n[GDR_LOD_STOP_LEVEL_LIMIT]);
    double dag_rate = (double)r->triangles / r->dag_s / 1e6;
    double all_rate = (double)r->triangles / (r->dag_s + r->meshlet_s) / 1e6;
    printf("%-28s %7u %10llu %9.3f %9.3f %10.3f %10.3f %10.3f %8.2fx %9.1f %5u %s\n", r->input, r->threads,
           (unsigned long long)r->triangles, r->meshlet_s, r->dag_s, dag_rate, dag_rate / r->threads, all_rate,
           (double)r->stats.dag_triangles / (double)r->triangles, r->heap_bytes_per_triangle, r->stats.max_depth, stop);
}

static void json_row(FILE *f, const result *r, int last)
{
    fprintf(f,
            "  {\"input\": \"%s\", \"threads\": %u, \"triangles\": %llu, \"meshlet_s\": %.4f, \"dag_s\": %.4f, "
            "\"dag_mtris_per_s\": %.4f, \"dag_mtris_per_s_per_thread\": %.4f, \"dag_ratio\": %.4f, "
            "\"peak_heap_bytes_per_triangle\": %.1f, \"depth\": %u, \"groups\": %llu, "
            "\"clusters\": %llu, \"root_clusters\": %llu, \"stuck_groups\": %llu, \"border_rejects\": %llu, "
            "\"meshes\": %u, \"stopped_single\": %u, \"stopped_no_progress\": %u}%s\n",
            r->input, r->threads, (unsigned long long)r->triangles, r->meshlet_s, r->dag_s,
            (double)r->triangles / r->dag_s / 1e6, (double)r->triangles / r->dag_s / 1e6 / r->threads,
            (double)r->stats.dag_triangles / (double)r->triangles, r->heap_bytes_per_triangle, r->stats.max_depth, (unsigned long long)r->stats.group_count,
            (unsigned long long)r->stats.cluster_count, (unsigned long long)r->stats.root_clusters,
            (unsigned long long)r->stats.stuck_groups, (unsigned long long)r->stats.border_rejects, r->stats.mesh_count,
            r->stats.stop_counts[GDR_LOD_STOP_SINGLE_CLUSTER], r->stats.stop_counts[GDR_LOD_STOP_NO_PROGRESS],
            last ? "" : ",");
}

/* Level 0 of `mesh`, timed. */
static gdr_mesh_clusters level0_of(gdr_mesh *mesh, double *seconds)
{
    gdr_error err = {0};
    gdr_mesh_clusters c = {0};
    double t0 = now();
    if (gdr_meshlets_build(mesh, NULL, &c, &err) != GDR_OK)
        die(mesh->name, &err);
    *seconds = now() - t0;
    return c;
}

static gdr_scene *import(const char *path);

/* The whole scene of `file` through gdr_scene_build_lod (small meshes side by side, one per
 * thread): level 0 is built first with gdr_scene_build_clusters and timed apart. */
static result run_scene(const char *name, const char *file, uint32_t threads, int repeat)
{
    result r = {.input = name, .threads = threads, .dag_s = 1e30};
    for (int k = 0; k < repeat; k++) {
        gdr_scene *scene = import(file);
        gdr_error err = {0};
        double t0 = now();
        if (gdr_scene_build_clusters(scene, &(gdr_meshlet_options){.thread_count = threads}, &err) != GDR_OK)
            die(file, &err);
        r.meshlet_s = now() - t0;
        r.triangles = 0;
        for (uint32_t m = 0; m < scene->mesh_count; m++)
            r.triangles += scene->meshes[m].index_count / 3;
        gdr_lod_options o = {.thread_count = threads, .no_progress = 1};
        long long heap_before = heap_peak_reset();
        t0 = now();
        if (gdr_scene_build_lod(scene, &o, &r.stats, &err) != GDR_OK)
            die(file, &err);
        double t = now() - t0;
        r.dag_s = t < r.dag_s ? t : r.dag_s;
        r.heap_bytes_per_triangle = (double)(heap_peak() - heap_before) / (double)r.triangles;
        gdr_scene_destroy(scene);
    }
    return r;
}

static gdr_scene *import(const char *path)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_import_options o = {.no_progress = 1};
    size_t n = strlen(path);
    int obj = n > 4 && strcmp(path + n - 4, ".obj") == 0;
    gdr_status s = obj ? gdr_import_obj(path, &o, &scene, NULL, &err) : gdr_import_gltf(path, &o, &scene, NULL, &err);
    if (s != GDR_OK)
        die(path, &err);
    return scene;
}

int main(int argc, char **argv)
{
    uint32_t levels = 8;
    int repeat = 1;
    const char *file = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
    const char *json = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--levels") && i + 1 < argc)
            levels = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--file") && i + 1 < argc)
            file = argv[++i];
        else if (!strcmp(argv[i], "--repeat") && i + 1 < argc)
            repeat = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--json") && i + 1 < argc)
            json = argv[++i];
        else {
            fprintf(stderr, "usage: lod_bench [--levels N] [--file PATH] [--repeat R] [--json FILE]\n");
            return 2;
        }
    }
    if (levels > 9 || repeat < 1) {
        fprintf(stderr, "lod_bench: --levels at most 9, --repeat at least 1\n");
        return 2;
    }
    result results[6];
    int count = 0;
    gdr_error err = {0};

    /* The procedural mesh. */
    gdr_scene *scene = NULL;
    uint32_t m = 0;
    if (gdr_scene_create(&scene, &err) != GDR_OK || gdr_procedural_blob(scene, levels, &m, &err) != GDR_OK)
        die("procedural mesh", &err);
    char name[64];
    snprintf(name, sizeof name, "displaced icosphere L%u", levels);
    double meshlet_s = 0;
    gdr_mesh_clusters level0 = level0_of(&scene->meshes[m], &meshlet_s);
    for (uint32_t threads = 1; threads <= 2; threads++)
        results[count++] = run(name, &scene->meshes[m], &level0, meshlet_s, threads, repeat);
    gdr_mesh_clusters_free(&level0);
    gdr_scene_destroy(scene);

    /* The largest mesh of a real file. */
    FILE *probe = fopen(file, "rb");
    char real_name[96] = "";
    if (probe) {
        fclose(probe);
        scene = import(file);
        uint32_t largest = 0;
        for (uint32_t i = 1; i < scene->mesh_count; i++)
            if (scene->meshes[i].index_count > scene->meshes[largest].index_count)
                largest = i;
        const char *base = strrchr(file, '/') ? strrchr(file, '/') + 1 : file;
        snprintf(real_name, sizeof real_name, "%.40s mesh %u", base, largest);
        level0 = level0_of(&scene->meshes[largest], &meshlet_s);
        for (uint32_t threads = 1; threads <= 2; threads++)
            results[count++] = run(real_name, &scene->meshes[largest], &level0, meshlet_s, threads, repeat);
        gdr_mesh_clusters_free(&level0);
        gdr_scene_destroy(scene);
        static char scene_name[96];
        snprintf(scene_name, sizeof scene_name, "%.40s all meshes", base);
        for (uint32_t threads = 1; threads <= 2; threads++)
            results[count++] = run_scene(scene_name, file, threads, repeat);
    } else {
        fprintf(stderr, "lod_bench: %s not found: real mesh skipped\n", file);
    }

    printf("%-28s %7s %10s %9s %9s %10s %10s %10s %9s %9s %5s %s\n", "input", "threads", "triangles", "meshlet_s",
           "dag_s", "Mtris/s", "Mtris/s/th", "+meshlets", "DAG/in", "heap B/t", "depth", "stop");
    for (int i = 0; i < count; i++)
        print_row(&results[i]);
    printf("process peak RSS: %.1f MiB\n", (double)max_rss_kib() / 1024.0);
    FILE *f = json ? fopen(json, "w") : stdout;
    if (!f) {
        perror(json);
        return 1;
    }
    fprintf(f, "[\n");
    for (int i = 0; i < count; i++)
        json_row(f, &results[i], i + 1 == count);
    fprintf(f, "]\n");
    if (json)
        fclose(f);
    return 0;
}
