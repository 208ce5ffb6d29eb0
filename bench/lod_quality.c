/* LOD DAG quality and build benchmark: for each mesh of a benchmark set, gdr's build time (level 0 +
 * DAG, 1 and 2 threads), peak heap per input triangle, the share of clusters under half full, and
 * the quality curve: for thresholds from 0.01% to 3% of the bounding radius, the cut's triangle
 * count, its true deviation (symmetric Hausdorff distance to the full-detail mesh, from dense
 * samples of both surfaces) and the error the DAG states for it (the largest error of the groups
 * the drawn clusters were made from). From the curve: the fewest triangles of a cut whose true
 * deviation is within 0.1% and 1% of the radius. Also the run-time cut's triangles (projected
 * error, so group spheres count) for cameras at 1.5 to 30 radii.
 *
 * Another builder's DAG can be measured the same way: for mesh NAME, this program writes the
 * input to DIR/NAME.mesh, and reads DIR/NAME.dag when present (written by a program outside the
 * project; format below), printing its curve and figures beside gdr's.
 *
 * usage: lod_quality [--dir DIR] [--only NAME] [--repeat R] [--no-sweep] [--big] [--models DIR]
 *                    [--group-size N]
 *   --dir DIR   where NAME.mesh is written and NAME.dag read (default: no files)
 *   --only NAME one mesh of the set, or torus-UxV (torus-1m's shape with U x V quads)
 *   --repeat R  builds per thread count, the fastest counts (default 3)
 *   --no-sweep  times and fill only
 *   --big       adds the 1 M-triangle torus (slow to measure)
 *   --models DIR where the OBJ files are (default: assimp-testmodels, /usr/share/assimp/models/OBJ)
 *   --group-size N gdr_lod_options.group_size (default: gdr's)
 *
 * NAME.mesh: "GDRM", u32 vertex_count, u32 index_count, float xyz[vertex_count], u32 indices[].
 * NAME.dag:  "GDRD", u32 version 1, f64 build_seconds (one thread), f64 peak_heap_bytes,
 *            u32 cluster_count, then per cluster: f32 refined_error (0 for original geometry),
 *            f32 group_error (above every threshold for the root), u32 triangle_count,
 *            u32 indices[3 * triangle_count] (mesh vertices). A cluster is drawn at threshold t
 *            when refined_error <= t < group_error: the same rule as gdr's cut. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "heap_count.h"
#include "surface_distance.h"
#include "geometry/lod_cut.h"
#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/scene.h"
#include "procedural_set.h"
#include "io/loaders.h"

#define SWEEP_STEPS 21         /* thresholds 10^(-4 + i / 8) of the radius */
#define SAMPLE_BUDGET 200000.0 /* samples of the full surface: sets the sampling spacing */

/* A DAG reduced to what the cut and its measurement need. */
typedef struct flat_dag {
    uint32_t cluster_count;
    float *refined_error, *group_error;
    uint32_t *first_index, *index_count; /* into indices */
    uint32_t *indices;
    double build_seconds, peak_heap;
} flat_dag;

typedef struct curve_point {
    double threshold, triangles, deviation, stated;
} curve_point;

/* Process CPU time: on a shared machine the one-thread figures count only this program's work
 * (wall-clock time is reported for two threads). */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void die(const char *what, const char *message)
{
    fprintf(stderr, "lod_quality: %s: %s\n", what, message);
    exit(1);
}

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p)
        die("memory", "out of memory");
    return p;
}

/* --- the benchmark set --------------------------------------------------------------------------- */

/* Every mesh of an OBJ file as one mesh (mesh space), added to `into`. */
static void merge_file(gdr_scene *into, const char *name, const char *path)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_import_options o = {.no_progress = 1};
    if (gdr_import_obj(path, &o, &scene, NULL, &err) != GDR_OK)
        die(path, err.message);
    uint32_t vc = 0, ic = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        vc += scene->meshes[m].vertex_count;
        ic += scene->meshes[m].index_count;
    }
    gdr_vec3 *positions = xmalloc(vc * sizeof *positions);
    uint32_t *indices = xmalloc(ic * sizeof *indices);
    vc = ic = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh *in = &scene->meshes[m];
        memcpy(positions + vc, in->positions, in->vertex_count * sizeof *in->positions);
        for (uint32_t i = 0; i < in->index_count; i++)
            indices[ic + i] = in->indices[i] + vc;
        vc += in->vertex_count;
        ic += in->index_count;
    }
    gdr_scene_destroy(scene);
    uint32_t m = 0;
    if (gdr_scene_add_mesh(into, name, positions, NULL, NULL, vc, indices, ic, &m, &err) != GDR_OK)
        die(path, err.message);
    free(positions);
    free(indices);
}

static void compute_bounds(gdr_mesh *m)
{
    double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30}, r = 0;
    for (uint32_t v = 0; v < m->vertex_count; v++)
        for (int k = 0; k < 3; k++) {
            double x = (&m->positions[v].x)[k];
            lo[k] = x < lo[k] ? x : lo[k];
            hi[k] = x > hi[k] ? x : hi[k];
        }
    double c[3] = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        double dx = m->positions[v].x - c[0], dy = m->positions[v].y - c[1], dz = m->positions[v].z - c[2];
        r = fmax(r, sqrt(dx * dx + dy * dy + dz * dz));
    }
    m->bounds = (gdr_vec4){(float)c[0], (float)c[1], (float)c[2], (float)r};
}

/* Mesh `name` of the set in a scene of its own (mesh 0). */
static const char *models_dir = "/usr/share/assimp/models/OBJ";
static uint32_t group_size; /* 0: gdr's default */

static gdr_scene *load_mesh(const char *name)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    uint32_t m = 0;
    if (gdr_scene_create(&scene, &err) != GDR_OK)
        die(name, err.message);
    gdr_status s = GDR_OK;
    if (!bench_procedural_mesh(scene, name, &m, &s, &err)) {
        static const char *const files[][2] = {
            {"wuson", "WusonOBJ.obj"}, {"spider", "spider.obj"}, {"regr01", "regr01.obj"}};
        for (size_t i = 0; i < sizeof files / sizeof files[0]; i++)
            if (!strcmp(name, files[i][0])) {
                char path[512];
                snprintf(path, sizeof path, "%s/%s", models_dir, files[i][1]);
                merge_file(scene, name, path);
            }
    }
    if (s != GDR_OK || scene->mesh_count == 0)
        die(name, s != GDR_OK ? err.message : "unknown mesh");
    snprintf(scene->meshes[0].name, sizeof scene->meshes[0].name, "%s", name);
    compute_bounds(&scene->meshes[0]);
    return scene;
}

/* --- building ------------------------------------------------------------------------------------- */

typedef struct build_figures {
    double seconds[3]; /* by thread count 1, 2 (index 0 unused) */
    double level0_seconds[3];
    double peak_heap; /* bytes, one thread */
    double half_full; /* share of clusters under half full (all levels) */
    gdr_lod_stats stats;
} build_figures;

/* Level 0 + DAG of mesh 0 with `threads`; returns the seconds (level 0's in *level0). */
static double build_once(gdr_mesh *mesh, uint32_t threads, double *level0, gdr_lod_stats *stats)
{
    gdr_mesh_clusters_free(&mesh->clusters);
    gdr_error err = {0};
    double (*clock)(void) = threads == 1 ? cpu_now : now;
    double t0 = clock();
    if (gdr_meshlets_build(mesh, &(gdr_meshlet_options){.thread_count = threads}, &mesh->clusters, &err) != GDR_OK)
        die(mesh->name, err.message);
    double t1 = clock();
    /* The set's meshes are drawn untextured: their uvs ignored, as gdr_scene_build_lod builds them. */
    if (gdr_mesh_build_lod_dag(mesh, &(gdr_lod_options){.thread_count = threads, .group_size = group_size,
                                                     .no_progress = 1, .ignore_uvs = 1},
                               stats, &err) !=
        GDR_OK)
        die(mesh->name, err.message);
    *level0 = t1 - t0;
    return clock() - t0;
}

static build_figures build_gdr(gdr_mesh *mesh, int repeat)
{
    build_figures f = {.seconds = {0, 1e30, 1e30}};
    for (int k = 0; k < repeat; k++)
        for (uint32_t threads = 1; threads <= 2; threads++) {
            /* The previous build's DAG freed first: freed inside the build, it would be subtracted
             * from the peak (every repeat after the first read ~13 bytes a triangle low). */
            gdr_mesh_clusters_free(&mesh->clusters);
            long long before = heap_peak_reset();
            double level0, t = build_once(mesh, threads, &level0, &f.stats);
            if (threads == 1)
                f.peak_heap = (double)(heap_peak() - before);
            if (t < f.seconds[threads]) {
                f.seconds[threads] = t;
                f.level0_seconds[threads] = level0;
            }
        }
    const gdr_mesh_clusters *c = &mesh->clusters;
    uint32_t under = 0;
    for (uint32_t i = 0; i < c->cluster_count; i++)
        under += c->clusters[i].triangle_count * 2 < GDR_CLUSTER_MAX_TRIANGLES;
    f.half_full = (double)under / c->cluster_count;
    return f;
}

/* FNV-1a over n bytes, continuing from h. */
static uint64_t fnv1a(uint64_t h, const void *data, size_t n)
{
    const unsigned char *b = data;
    for (size_t i = 0; i < n; i++)
        h = (h ^ b[i]) * 0x100000001b3ull;
    return h;
}

/* A hash of every byte of the DAG (clusters, vertices, triangles, groups, hierarchy): a change meant
 * to keep the build's output can be checked bit for bit. */
static uint64_t dag_hash(const gdr_mesh_clusters *c)
{
    uint64_t h = 0xcbf29ce484222325ull;
    h = fnv1a(h, c->clusters, (size_t)c->cluster_count * sizeof *c->clusters);
    h = fnv1a(h, c->vertices, (size_t)c->vertex_count * sizeof *c->vertices);
    h = fnv1a(h, c->triangles, c->triangle_byte_count);
    h = fnv1a(h, c->groups, (size_t)c->group_count * sizeof *c->groups);
    h = fnv1a(h, c->lod_nodes, (size_t)c->lod_node_count * sizeof *c->lod_nodes);
    return fnv1a(h, &c->dag_depth, sizeof c->dag_depth);
}

/* gdr's DAG as a flat_dag (refined error 0 for level 0, group error infinite for the root). */
static flat_dag flatten(const gdr_mesh *mesh)
{
    const gdr_mesh_clusters *c = &mesh->clusters;
    flat_dag d = {.cluster_count = c->cluster_count};
    d.refined_error = xmalloc(c->cluster_count * sizeof(float));
    d.group_error = xmalloc(c->cluster_count * sizeof(float));
    d.first_index = xmalloc(c->cluster_count * sizeof(uint32_t));
    d.index_count = xmalloc(c->cluster_count * sizeof(uint32_t));
    size_t total = 0;
    for (uint32_t i = 0; i < c->cluster_count; i++)
        total += (size_t)c->clusters[i].triangle_count * 3;
    d.indices = xmalloc(total * sizeof(uint32_t));
    total = 0;
    for (uint32_t i = 0; i < c->cluster_count; i++) {
        const gdr_cluster *k = &c->clusters[i];
        d.refined_error[i] = k->refined_group == GDR_NO_INDEX ? 0.0f : c->groups[k->refined_group].error;
        d.group_error[i] = k->group == GDR_NO_INDEX ? INFINITY : c->groups[k->group].error;
        d.first_index[i] = (uint32_t)total;
        d.index_count[i] = k->triangle_count * 3;
        for (uint32_t j = 0; j < k->triangle_count * 3; j++)
            d.indices[total++] = c->vertices[k->vertex_offset + c->triangles[k->triangle_offset + j]];
    }
    return d;
}

static void flat_free(flat_dag *d)
{
    free(d->refined_error);
    free(d->group_error);
    free(d->first_index);
    free(d->index_count);
    free(d->indices);
}

/* --- files shared with an outside builder ---------------------------------------------------------- */

static void write_mesh(const char *dir, const gdr_mesh *m)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s.mesh", dir, m->name);
    FILE *f = fopen(path, "wb");
    if (!f)
        die(path, "cannot write");
    fwrite("GDRM", 1, 4, f);
    fwrite(&m->vertex_count, 4, 1, f);
    fwrite(&m->index_count, 4, 1, f);
    fwrite(m->positions, sizeof *m->positions, m->vertex_count, f);
    fwrite(m->indices, 4, m->index_count, f);
    if (fclose(f) != 0)
        die(path, "write failed");
}

static int read_u32(FILE *f, uint32_t *v) { return fread(v, 4, 1, f) == 1; }

/* NAME.dag, checked against the mesh's vertex count; returns 0 when absent. */
static int read_dag(const char *dir, const gdr_mesh *m, flat_dag *d)
{
    char path[512], magic[4];
    snprintf(path, sizeof path, "%s/%s.dag", dir, m->name);
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    uint32_t version = 0, n = 0;
    *d = (flat_dag){0};
    if (fread(magic, 1, 4, f) != 4 || memcmp(magic, "GDRD", 4) || !read_u32(f, &version) || version != 1 ||
        fread(&d->build_seconds, 8, 1, f) != 1 || fread(&d->peak_heap, 8, 1, f) != 1 || !read_u32(f, &n))
        die(path, "bad header");
    d->cluster_count = n;
    d->refined_error = xmalloc(n * sizeof(float));
    d->group_error = xmalloc(n * sizeof(float));
    d->first_index = xmalloc(n * sizeof(uint32_t));
    d->index_count = xmalloc(n * sizeof(uint32_t));
    size_t cap = 1 << 20, total = 0;
    d->indices = xmalloc(cap * sizeof(uint32_t));
    for (uint32_t i = 0; i < n; i++) {
        uint32_t tc = 0;
        if (fread(&d->refined_error[i], 4, 1, f) != 1 || fread(&d->group_error[i], 4, 1, f) != 1 || !read_u32(f, &tc))
            die(path, "truncated");
        while (total + (size_t)tc * 3 > cap)
            cap *= 2;
        d->indices = realloc(d->indices, cap * sizeof(uint32_t));
        if (!d->indices || fread(d->indices + total, 4, (size_t)tc * 3, f) != (size_t)tc * 3)
            die(path, "truncated");
        for (size_t j = 0; j < (size_t)tc * 3; j++)
            if (d->indices[total + j] >= m->vertex_count)
                die(path, "index out of range");
        d->first_index[i] = (uint32_t)total;
        d->index_count[i] = tc * 3;
        total += (size_t)tc * 3;
    }
    fclose(f);
    return 1;
}

/* --- the quality curve ------------------------------------------------------------------------------ */

/* The cut at threshold t: its triangles (mesh vertex indices) and the largest error it states. */
static size_t cut(const flat_dag *d, float t, uint32_t *indices, uint8_t *drawn, double *stated)
{
    size_t n = 0;
    *stated = 0;
    for (uint32_t i = 0; i < d->cluster_count; i++) {
        drawn[i] = d->refined_error[i] <= t && !(d->group_error[i] <= t);
        if (!drawn[i])
            continue;
        memcpy(indices + n, d->indices + d->first_index[i], d->index_count[i] * sizeof *indices);
        n += d->index_count[i];
        *stated = d->refined_error[i] > *stated ? d->refined_error[i] : *stated;
    }
    return n / 3;
}

/* Symmetric Hausdorff distance between a cut and the full mesh (whose grid is given). */
static double deviation(const gdr_mesh *m, const triangle_grid *full, const uint32_t *indices, size_t triangles,
                        double spacing)
{
    surface s = {m->positions, m->vertex_count, indices, triangles};
    surface f = {m->positions, m->vertex_count, m->indices, m->index_count / 3};
    triangle_grid *g = triangle_grid_create(s);
    double a = surface_one_sided(s, full, spacing), b = surface_one_sided(f, g, spacing);
    triangle_grid_destroy(g);
    if (getenv("LOD_QUALITY_DIRECTIONS"))
        printf("    (cut -> full %g, full -> cut %g)\n", a / m->bounds.w * 100, b / m->bounds.w * 100);
    return a > b ? a : b;
}

static void sweep(const gdr_mesh *m, const triangle_grid *full, double spacing, const flat_dag *d, curve_point *out)
{
    size_t total = 0;
    for (uint32_t i = 0; i < d->cluster_count; i++)
        total += d->index_count[i];
    uint32_t *indices = xmalloc(total * sizeof *indices);
    uint8_t *drawn = xmalloc(d->cluster_count), *previous = calloc(d->cluster_count + 1, 1);
    double last = -1;
    for (int i = 0; i < SWEEP_STEPS; i++) {
        double r = m->bounds.w, t = r * pow(10.0, -4.0 + i / 8.0);
        curve_point *p = &out[i];
        p->threshold = t / r;
        p->triangles = (double)cut(d, (float)t, indices, drawn, &p->stated);
        p->stated /= r;
        if (i == 0 || memcmp(drawn, previous, d->cluster_count))
            last = deviation(m, full, indices, (size_t)p->triangles, spacing) / r;
        p->deviation = last;
        memcpy(previous, drawn, d->cluster_count);
    }
    free(indices);
    free(drawn);
    free(previous);
}

/* The fewest triangles of a cut whose true deviation is within `limit` (of the radius). */
static double triangles_within(const curve_point *c, double limit)
{
    double best = INFINITY;
    for (int i = 0; i < SWEEP_STEPS; i++)
        if (c[i].deviation <= limit && c[i].triangles < best)
            best = c[i].triangles;
    return best;
}

/* The largest ratio of true deviation to stated error (above 1: the error understates). */
static double worst_understatement(const curve_point *c)
{
    double worst = 0;
    for (int i = 0; i < SWEEP_STEPS; i++)
        if (c[i].deviation > 1e-6) /* float rounding of the samples */
            worst = fmax(worst, c[i].stated > 0 ? c[i].deviation / c[i].stated : INFINITY);
    return worst;
}

/* --- cuts for views ---------------------------------------------------------------------------------- */

/* Triangles of the run-time cut (projected error, so group spheres count too) for a camera at
 * 1.5, 3, 10 and 30 radii from the centre, along three directions each, summed per distance:
 * 1 px at 1080 lines, 60 degrees vertical field of view. */
static void print_views(const gdr_mesh *m)
{
    static const float distances[] = {1.5f, 3.0f, 10.0f, 30.0f};
    static const gdr_vec3 directions[] = {{0.8f, 0.5f, 0.33f}, {-0.3f, 0.2f, 0.93f}, {0.1f, -0.99f, 0.1f}};
    const gdr_mesh_clusters *mc = &m->clusters;
    uint8_t *selected = xmalloc(mc->cluster_count + 1);
    printf("  views (1 px, 1080 lines, 60 deg):");
    for (size_t i = 0; i < sizeof distances / sizeof distances[0]; i++) {
        uint64_t total = 0;
        for (size_t j = 0; j < sizeof directions / sizeof directions[0]; j++) {
            gdr_vec3 d = gdr_vec3_normalize(directions[j]);
            float r = m->bounds.w * distances[i];
            gdr_lod_view v = {.transform = gdr_mat4_identity(),
                              .camera_position = {m->bounds.x + d.x * r, m->bounds.y + d.y * r, m->bounds.z + d.z * r},
                              .projection_y = 1.0f / tanf(0.5f * 1.0471976f),
                              .viewport_height = 1080.0f,
                              .znear = 1e-3f * m->bounds.w,
                              .threshold = 1.0f};
            gdr_lod_cut_select(mc, &v, selected);
            for (uint32_t c = 0; c < mc->cluster_count; c++)
                total += selected[c] ? mc->clusters[c].triangle_count : 0;
        }
        printf(" %.1f R %llu%s", (double)distances[i], (unsigned long long)total, i + 1 < 4 ? "," : " triangles\n");
    }
    free(selected);
}

/* --- report ------------------------------------------------------------------------------------------ */

static void print_curve(const char *builder, const curve_point *c)
{
    printf("  %-10s threshold%%: triangles / true deviation%% / stated%%\n", builder);
    for (int i = 0; i < SWEEP_STEPS; i++)
        printf("    %8.4f  %9.0f  %8.4f  %8.4f\n", c[i].threshold * 100, c[i].triangles, c[i].deviation * 100,
               c[i].stated * 100);
}

static void print_summary(const char *name, const char *builder, const curve_point *c, double seconds,
                          double triangles, double heap)
{
    printf("%-10s %-10s %10.0f %10.0f %10.3f %8.3f %9.1f\n", name, builder, triangles_within(c, 0.001),
           triangles_within(c, 0.01), worst_understatement(c), triangles / seconds / 1e6, heap / triangles);
}

static void measure_mesh(const char *name, const char *dir, int repeat, int do_sweep)
{
    gdr_scene *scene = load_mesh(name);
    gdr_mesh *m = &scene->meshes[0];
    double triangles = m->index_count / 3;
    if (dir)
        write_mesh(dir, m);
    build_figures f = build_gdr(m, repeat);
    printf("\n%s: %.0f triangles, radius %g\n", name, triangles, (double)m->bounds.w);
    printf("  gdr: level 0 + DAG %.3f s CPU (level 0 %.3f s) on 1 thread, %.3f s wall (%.3f s) on 2: %.3f and %.3f M "
           "triangles/s, 2-thread speed-up %.2fx; peak heap %.1f B/triangle; clusters %llu, under half full "
           "%.1f%%; depth %u; DAG %.2fx the input\n",
           f.seconds[1], f.level0_seconds[1], f.seconds[2], f.level0_seconds[2], triangles / f.seconds[1] / 1e6,
           triangles / f.seconds[2] / 1e6, f.seconds[1] / f.seconds[2], f.peak_heap / triangles,
           (unsigned long long)f.stats.cluster_count, f.half_full * 100, f.stats.max_depth,
           (double)f.stats.dag_triangles / triangles);
    printf("  DAG hash %016llx\n", (unsigned long long)dag_hash(&m->clusters));
    print_views(m);
    flat_dag other = {0};
    int has_other = dir && read_dag(dir, m, &other);
    if (has_other) {
        uint32_t under = 0;
        for (uint32_t i = 0; i < other.cluster_count; i++)
            under += other.index_count[i] * 2 < GDR_CLUSTER_MAX_TRIANGLES * 3;
        printf("  other: build %.3f s on 1 thread (%.3f M triangles/s; gdr 1 thread %.2fx, 2 threads %.2fx of "
               "it); peak heap %.1f B/triangle; clusters %u, under half full %.1f%%\n",
               other.build_seconds, triangles / other.build_seconds / 1e6, other.build_seconds / f.seconds[1],
               other.build_seconds / f.seconds[2], other.peak_heap / triangles, other.cluster_count,
               100.0 * under / other.cluster_count);
    }
    if (do_sweep) {
        surface full = {m->positions, m->vertex_count, m->indices, m->index_count / 3};
        triangle_grid *grid = triangle_grid_create(full);
        double spacing = sqrt(surface_area(full) / SAMPLE_BUDGET);
        curve_point gc[SWEEP_STEPS], oc[SWEEP_STEPS];
        flat_dag g = flatten(m);
        sweep(m, grid, spacing, &g, gc);
        print_curve("gdr", gc);
        if (has_other) {
            sweep(m, grid, spacing, &other, oc);
            print_curve("other", oc);
        }
        printf("%-10s %-10s %10s %10s %10s %8s %9s\n", "mesh", "builder", "tris@0.1%", "tris@1%", "dev/stated",
               "Mtris/s", "heap B/t");
        print_summary(name, "gdr", gc, f.seconds[1], triangles, f.peak_heap);
        if (has_other)
            print_summary(name, "other", oc, other.build_seconds, triangles, other.peak_heap);
        flat_free(&g);
        triangle_grid_destroy(grid);
    }
    if (has_other)
        flat_free(&other);
    gdr_scene_destroy(scene);
}

int main(int argc, char **argv)
{
    const char *dir = NULL, *only = NULL;
    int repeat = 3, do_sweep = 1, big = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--dir") && i + 1 < argc)
            dir = argv[++i];
        else if (!strcmp(argv[i], "--only") && i + 1 < argc)
            only = argv[++i];
        else if (!strcmp(argv[i], "--repeat") && i + 1 < argc)
            repeat = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--no-sweep"))
            do_sweep = 0;
        else if (!strcmp(argv[i], "--big"))
            big = 1;
        else if (!strcmp(argv[i], "--models") && i + 1 < argc)
            models_dir = argv[++i];
        else if (!strcmp(argv[i], "--group-size") && i + 1 < argc)
            group_size = (uint32_t)atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: lod_quality [--dir DIR] [--only NAME] [--repeat R] [--no-sweep] [--big] "
                            "[--models DIR] [--group-size N]\n");
            return 2;
        }
    }
    if (repeat < 1)
        die("--repeat", "must be at least 1");
    static const char *const set[] = {"blob", "knot", "wuson", "spider", "regr01", "torus-1m"};
    for (size_t i = 0; i < sizeof set / sizeof set[0]; i++) {
        int is_big = !strcmp(set[i], "torus-1m");
        if (only ? !strcmp(only, set[i]) : (!is_big || big))
            measure_mesh(set[i], dir, repeat, do_sweep);
    }
    if (only && !strncmp(only, "torus-", 6) && strcmp(only, "torus-1m"))
        measure_mesh(only, dir, repeat, do_sweep);
    return 0;
}
