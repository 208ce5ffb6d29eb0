/* LOD hierarchy benchmark: the work a traversal of the hierarchy saves over testing every cluster,
 * counted (not timed), for one instance of each mesh of a scene seen from cameras at distances
 * spread over three decades, at several thresholds; plus the hierarchy's build time and size.
 * Both cuts are compared byte for byte on every view. Prints a table and JSON.
 *
 * usage: lod_hierarchy_bench [--scene SPEC] [--views N] [--json FILE]
 *   --scene SPEC  any scene gdr_scene_load takes (default lod-field:instances=1: its 100k-triangle mesh)
 *   --views N     cameras per threshold (default 200)
 *
 * Columns: flat = clusters the flat cut tests (all of them); nodes, leaf clusters = node tests and
 * cluster tests of the hierarchical cut; drawn = clusters selected; ratio = (nodes + leaf clusters)
 * / drawn, the figure of merit of a traversal (the flat cut's is flat / drawn). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/scene.h"
#include "geometry/lod_cut.h"

static double now_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static float random01(unsigned *state)
{
    *state = *state * 1664525u + 1013904223u;
    return (float)(*state >> 8) / 16777216.0f;
}

typedef struct row {
    float threshold;
    double flat, nodes, leaf_clusters, drawn;
    unsigned mismatches;
} row;

/* One instance at the origin, the camera at distance 1.5 to 1500 mesh radii in a random direction. */
static gdr_lod_view make_view(const gdr_mesh *mesh, float threshold, unsigned *rng)
{
    gdr_lod_view v = {.transform = gdr_mat4_identity(), .projection_y = 1.0f / tanf(0.5f * 1.0f),
                      .viewport_height = 1440.0f, .znear = 0.01f, .threshold = threshold};
    gdr_vec3 dir = gdr_vec3_normalize((gdr_vec3){random01(rng) - 0.5f, random01(rng) - 0.5f, random01(rng) - 0.5f});
    float distance = mesh->bounds.w * 1.5f * powf(10.0f, 3.0f * random01(rng));
    v.camera_position = gdr_vec3_add((gdr_vec3){mesh->bounds.x, mesh->bounds.y, mesh->bounds.z},
                                     gdr_vec3_scale(dir, distance));
    return v;
}

static row measure(const gdr_mesh *mesh, float threshold, unsigned views)
{
    const gdr_mesh_clusters *c = &mesh->clusters;
    uint8_t *flat = malloc(c->cluster_count), *tree = malloc(c->cluster_count);
    row r = {.threshold = threshold};
    unsigned rng = 12345u;
    for (unsigned i = 0; i < views; i++) {
        gdr_lod_view v = make_view(mesh, threshold, &rng);
        gdr_lod_traversal_stats st = {0};
        uint32_t drawn = gdr_lod_cut_select(c, &v, flat);
        gdr_lod_cut_select_hierarchical(c, &v, tree, &st);
        r.mismatches += memcmp(flat, tree, c->cluster_count) != 0;
        r.flat += c->cluster_count;
        r.nodes += (double)st.nodes_tested;
        r.leaf_clusters += (double)st.clusters_tested;
        r.drawn += drawn;
    }
    free(flat);
    free(tree);
    r.flat /= views;
    r.nodes /= views;
    r.leaf_clusters /= views;
    r.drawn /= views;
    return r;
}

int main(int argc, char **argv)
{
    const char *spec = "lod-field:instances=1", *json_path = NULL;
    unsigned views = 200;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--scene") && i + 1 < argc)
            spec = argv[++i];
        else if (!strcmp(argv[i], "--views") && i + 1 < argc)
            views = (unsigned)strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--json") && i + 1 < argc)
            json_path = argv[++i];
        else {
            fprintf(stderr, "usage: lod_hierarchy_bench [--scene SPEC] [--views N] [--json FILE]\n");
            return 2;
        }
    }
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    if (gdr_scene_load(spec, NULL, &scene, &err) != GDR_OK) {
        fprintf(stderr, "lod_hierarchy_bench: %s\n", err.message);
        return 1;
    }
    FILE *json = json_path ? fopen(json_path, "w") : NULL;
    if (json)
        fprintf(json, "{\"scene\": \"%s\", \"views\": %u, \"meshes\": [", spec, views);
    const float thresholds[] = {0.5f, 1.0f, 4.0f};
    unsigned mismatches = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        gdr_mesh_clusters *c = &scene->meshes[m].clusters;
        if (c->cluster_count == 0)
            continue;
        double t0 = now_seconds();
        if (gdr_mesh_clusters_build_hierarchy(c, &err) != GDR_OK) {
            fprintf(stderr, "lod_hierarchy_bench: %s\n", err.message);
            return 1;
        }
        double build_ms = 1e3 * (now_seconds() - t0);
        printf("mesh '%s': %u triangles, %u clusters, %u groups -> %u nodes, %u levels, built in %.2f ms\n",
               scene->meshes[m].name, scene->meshes[m].index_count / 3, c->cluster_count, c->group_count,
               c->lod_node_count, c->lod_node_levels, build_ms);
        printf("  threshold |   flat | nodes | leaf clusters | drawn | flat/drawn | (nodes+leaf)/drawn\n");
        if (json)
            fprintf(json, "%s{\"name\": \"%s\", \"clusters\": %u, \"groups\": %u, \"nodes\": %u, \"levels\": %u, "
                    "\"build_ms\": %.3f, \"cuts\": [", m ? ", " : "", scene->meshes[m].name, c->cluster_count,
                    c->group_count, c->lod_node_count, c->lod_node_levels, build_ms);
        for (size_t t = 0; t < sizeof thresholds / sizeof thresholds[0]; t++) {
            row r = measure(&scene->meshes[m], thresholds[t], views);
            mismatches += r.mismatches;
            printf("  %6.1f px | %6.0f | %5.0f | %13.0f | %5.0f | %10.1f | %.2f\n", r.threshold, r.flat, r.nodes,
                   r.leaf_clusters, r.drawn, r.flat / r.drawn, (r.nodes + r.leaf_clusters) / r.drawn);
            if (json)
                fprintf(json, "%s{\"threshold_px\": %g, \"flat\": %.1f, \"nodes\": %.1f, \"leaf_clusters\": %.1f, "
                        "\"drawn\": %.1f}", t ? ", " : "", r.threshold, r.flat, r.nodes, r.leaf_clusters, r.drawn);
        }
        if (json)
            fprintf(json, "]}");
    }
    if (json) {
        fprintf(json, "], \"mismatches\": %u}\n", mismatches);
        fclose(json);
    }
    printf("views where the hierarchical cut differed from the flat cut: %u\n", mismatches);
    gdr_scene_destroy(scene);
    return mismatches ? 1 : 0;
}
