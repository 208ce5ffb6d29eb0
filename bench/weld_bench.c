/* Cost of welding equal vertices before clustering: a procedural torus of S x T quads, and the
 * same torus written as a triangle soup (every triangle its own three vertices, the torus's
 * attributes). Times, on one thread, gdr_mesh_weld_vertices on the soup and on the torus (nothing
 * to weld: the check alone), and gdr_scene_build_clusters on each (the soup's includes its weld).
 * usage: weld_bench [SEGMENTS SIDES [REPEAT]]   (default 1000 500 3: 1 M triangles) */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "gdr/geometry.h"
#include "gdr/scene.h"
#include "geometry/vertex_weld.h"
#include "procedural/procedural_meshes.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void check(gdr_status status, const gdr_error *err)
{
    if (status != GDR_OK) {
        fprintf(stderr, "weld_bench: %s\n", err->message);
        exit(1);
    }
}

/* A scene holding the torus, or the torus as a triangle soup. */
static gdr_scene *make_torus(int soup, uint32_t segments, uint32_t sides)
{
    gdr_scene *s = NULL, *out = NULL;
    gdr_error err = {0};
    uint32_t t = 0;
    check(gdr_scene_create(&s, &err), &err);
    check(gdr_procedural_torus(s, 1.0f, 0.3f, segments, sides, &t, &err), &err);
    if (!soup)
        return s;
    const gdr_mesh *m = &s->meshes[t];
    size_t n = m->index_count;
    gdr_vec3 *p = malloc(sizeof *p * n), *nn = malloc(sizeof *nn * n);
    gdr_vec2 *uv = malloc(sizeof *uv * n);
    uint32_t *idx = malloc(sizeof *idx * n);
    if (!p || !nn || !uv || !idx) {
        fprintf(stderr, "weld_bench: out of memory\n");
        exit(1);
    }
    for (size_t i = 0; i < n; i++) {
        uint32_t v = m->indices[i];
        p[i] = m->positions[v], nn[i] = m->normals[v], uv[i] = m->uvs[v], idx[i] = (uint32_t)i;
    }
    check(gdr_scene_create(&out, &err), &err);
    check(gdr_scene_add_mesh(out, "soup", p, nn, uv, (uint32_t)n, idx, (uint32_t)n, NULL, &err), &err);
    free(p), free(nn), free(uv), free(idx);
    gdr_scene_destroy(s);
    return out;
}

/* Seconds of gdr_mesh_weld_vertices on the scene's one mesh; *removed: the vertices it removed. */
static double time_weld(gdr_scene *s, uint32_t *removed)
{
    gdr_error err = {0};
    double t0 = now();
    check(gdr_mesh_weld_vertices(&s->meshes[0], removed, &err), &err);
    return now() - t0;
}

static double time_clusters(gdr_scene *s)
{
    gdr_meshlet_options o = {.thread_count = 1};
    gdr_error err = {0};
    double t0 = now();
    check(gdr_scene_build_clusters(s, &o, &err), &err);
    return now() - t0;
}

int main(int argc, char **argv)
{
    uint32_t segments = argc > 2 ? (uint32_t)atoi(argv[1]) : 1000, sides = argc > 2 ? (uint32_t)atoi(argv[2]) : 500;
    int repeat = argc > 3 ? atoi(argv[3]) : 3;
    if (segments < 3 || sides < 3 || segments > 4000 || sides > 4000 || repeat < 1) {
        fprintf(stderr, "usage: weld_bench [SEGMENTS SIDES [REPEAT]] (3..4000 each)\n");
        return 2;
    }
    double triangles = 2.0 * segments * sides;
    printf("torus %u x %u: %.0f triangles; one thread, ms (ns per triangle)\n", segments, sides, triangles);
    printf("%-4s %-22s %-22s %-22s %-22s\n", "run", "weld soup", "weld welded torus", "clusters soup",
           "clusters welded torus");
    for (int r = 0; r < repeat; r++) {
        uint32_t removed = 0, none = 0;
        gdr_scene *soup = make_torus(1, segments, sides), *torus = make_torus(0, segments, sides);
        double ws = time_weld(soup, &removed), wt = time_weld(torus, &none);
        gdr_scene_destroy(soup);
        soup = make_torus(1, segments, sides);
        double cs = time_clusters(soup), ct = time_clusters(torus);
        printf("%-4d %8.1f (%6.1f)      %8.1f (%6.1f)      %8.1f (%6.1f)      %8.1f (%6.1f)   removed %u / %u; "
               "clusters %u / %u\n",
               r, 1e3 * ws, 1e9 * ws / triangles, 1e3 * wt, 1e9 * wt / triangles, 1e3 * cs, 1e9 * cs / triangles,
               1e3 * ct, 1e9 * ct / triangles, removed, none, soup->meshes[0].clusters.cluster_count,
               torus->meshes[0].clusters.cluster_count);
        gdr_scene_destroy(soup);
        gdr_scene_destroy(torus);
    }
    return 0;
}
