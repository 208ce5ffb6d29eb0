/* How far LOD cuts lie from the full-detail surface, for one model and one camera: a diagnostic of
 * where triangles go at equal image fidelity (docs/GEOMETRY.md, "Calibration on scans").
 *
 * usage: lod_cut_deviation FULL.obj CAMERA [--thresholds T,T,...] [--height H] [--ref T=CUT.obj ...]
 *                          [--calibration]
 *   FULL.obj    the model (its first mesh); gdr builds its DAG as `gdr render --no-cache` does
 *   CAMERA      px,py,pz,qx,qy,qz,qw (only the position counts: 45-degree vertical field of view)
 *   --thresholds pixel thresholds of gdr's run-time cut (default 0.5,1,2,3,4,6,8,12,16)
 *   --height H  image height in pixels (default 720)
 *   --ref T=F   another builder's cut: an OBJ (measured by its own positions and normals)
 *   --calibration the stated errors against the deviation, by depth (below; slow)
 *
 * For each cut: triangles, the largest error its groups state, and the distance between the cut
 * and the full mesh both ways, largest and root mean square over area (dense samples; in units of
 * 1e-4 of the bounding radius), and the root mean square difference between the cut's interpolated
 * unit normal and the full mesh's at the nearest point (what shading sees). Then, per DAG depth, how gdr's stated errors compare with the
 * measured one-sided deviation of each group's own triangles from the full mesh, carried up the DAG
 * by the max (the tightest monotone error those triangles allow): the stated error's looseness. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/scene.h"
#include "geometry/lod_cut.h"
#include "io/loaders.h"
#include "surface_distance.h"

static void die(const char *what, const char *why)
{
    fprintf(stderr, "lod_cut_deviation: %s: %s\n", what, why);
    exit(1);
}

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p)
        die("malloc", "out of memory");
    return p;
}

typedef struct stats {
    double max, sum2, area;
    double normal2; /* area-weighted squared difference of the interpolated unit normals */
} stats;

/* Normals where both sides have them: the sampled surface's and the measured-against surface's. */
typedef struct normals {
    const gdr_vec3 *from, *to;
    surface to_surface;
} normals;

/* The unit normal interpolated at barycentric w over corners i[0..2] of `n`. */
static void interpolate_normal(const gdr_vec3 *n, const uint32_t *i, const double w[3], double out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = w[0] * (&n[i[0]].x)[k] + w[1] * (&n[i[1]].x)[k] + w[2] * (&n[i[2]].x)[k];
    double l = sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
    for (int k = 0; k < 3; k++)
        out[k] = l > 0 ? out[k] / l : 0;
}

static double length3(double x, double y, double z) { return sqrt(x * x + y * y + z * z); }

/* Samples of surface `from` on a barycentric grid of about `spacing` (at most 16 steps an edge),
 * each weighted by its share of the triangle's area; distances to `to`. */
static stats one_sided(surface from, const triangle_grid *to, double spacing, const normals *nm)
{
    stats s = {0};
    for (size_t t = 0; t < from.triangle_count; t++) {
        const gdr_vec3 *p[3];
        for (int k = 0; k < 3; k++)
            p[k] = &from.positions[from.indices[3 * t + k]];
        double e[3] = {length3(p[1]->x - p[0]->x, p[1]->y - p[0]->y, p[1]->z - p[0]->z),
                       length3(p[2]->x - p[1]->x, p[2]->y - p[1]->y, p[2]->z - p[1]->z),
                       length3(p[0]->x - p[2]->x, p[0]->y - p[2]->y, p[0]->z - p[2]->z)};
        double longest = fmax(e[0], fmax(e[1], e[2]));
        int n = (int)ceil(longest / spacing);
        n = n < 1 ? 1 : n > 16 ? 16 : n;
        double ux = p[1]->x - p[0]->x, uy = p[1]->y - p[0]->y, uz = p[1]->z - p[0]->z;
        double vx = p[2]->x - p[0]->x, vy = p[2]->y - p[0]->y, vz = p[2]->z - p[0]->z;
        double area = 0.5 * length3(uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx);
        int points = (n + 1) * (n + 2) / 2;
        for (int i = 0; i <= n; i++)
            for (int j = 0; i + j <= n; j++) {
                double a = (double)i / n, b = (double)j / n, c = 1 - a - b;
                gdr_vec3 q = {(float)(c * p[0]->x + a * p[1]->x + b * p[2]->x),
                              (float)(c * p[0]->y + a * p[1]->y + b * p[2]->y),
                              (float)(c * p[0]->z + a * p[1]->z + b * p[2]->z)};
                uint32_t nearest;
                double w[3], here[3], there[3], bw[3] = {c, a, b};
                double d = triangle_grid_nearest(to, q, &nearest, nm ? w : NULL);
                s.max = fmax(s.max, d);
                s.sum2 += d * d * area / points;
                if (nm && nearest != UINT32_MAX) {
                    interpolate_normal(nm->from, from.indices + 3 * t, bw, here);
                    interpolate_normal(nm->to, nm->to_surface.indices + 3 * (size_t)nearest, w, there);
                    double dx = here[0] - there[0], dy = here[1] - there[1], dz = here[2] - there[2];
                    s.normal2 += (dx * dx + dy * dy + dz * dz) * area / points;
                }
            }
        s.area += area;
    }
    return s;
}

static double rms(stats s) { return s.area > 0 ? sqrt(s.sum2 / s.area) : 0; }

/* One cut against the full mesh: a line of the table. */
static void report(const char *who, double threshold, const gdr_mesh *m, const triangle_grid *full_grid,
                   surface cut, const gdr_vec3 *cut_normals, double stated, double spacing)
{
    surface full = {m->positions, m->vertex_count, m->indices, m->index_count / 3};
    triangle_grid *g = triangle_grid_create(cut);
    normals nm = {cut_normals, m->normals, full};
    stats a = one_sided(cut, full_grid, spacing, cut_normals && m->normals ? &nm : NULL),
          b = one_sided(full, g, spacing, NULL);
    triangle_grid_destroy(g);
    double u = m->bounds.w * 1e-4;
    printf("%-9s %7.2f %8zu %9.2f   %8.2f %7.3f   %8.2f %7.3f   %8.4f\n", who, threshold, cut.triangle_count,
           stated / u, a.max / u, rms(a) / u, b.max / u, rms(b) / u, a.area > 0 ? sqrt(a.normal2 / a.area) : 0);
}

/* gdr's run-time cut at `threshold` pixels: its triangles (mesh vertex indices) and stated error. */
static size_t gdr_cut(const gdr_mesh *m, const gdr_lod_view *view, uint8_t *selected, uint32_t *indices,
                      double *stated)
{
    const gdr_mesh_clusters *c = &m->clusters;
    gdr_lod_cut_select(c, view, selected);
    size_t n = 0;
    *stated = 0;
    for (uint32_t i = 0; i < c->cluster_count; i++) {
        const gdr_cluster *k = &c->clusters[i];
        if (!selected[i])
            continue;
        for (uint32_t j = 0; j < k->triangle_count * 3; j++)
            indices[n++] = c->vertices[k->vertex_offset + c->triangles[k->triangle_offset + j]];
        if (k->refined_group != GDR_NO_INDEX)
            *stated = fmax(*stated, c->groups[k->refined_group].error);
    }
    return n / 3;
}

/* --- another builder's cut ------------------------------------------------------------------------- */

/* The triangles of CUT.obj (its own vertices; positions are what is measured). */
static surface read_cut(const char *path, gdr_scene **keep)
{
    gdr_error err = {0};
    gdr_import_options o = {.no_progress = 1};
    if (gdr_import_obj(path, &o, keep, NULL, &err) != GDR_OK)
        die(path, err.message);
    if ((*keep)->mesh_count == 0 || (*keep)->meshes[0].index_count < 3)
        die(path, "holds no triangles");
    const gdr_mesh *m = &(*keep)->meshes[0];
    return (surface){m->positions, m->vertex_count, m->indices, m->index_count / 3};
}

/* --- calibration ------------------------------------------------------------------------------------ */

/* The cut at mesh-space threshold t with the groups' errors taken from `error` (the root: infinite):
 * its triangles. */
static size_t cut_by(const gdr_mesh *m, const double *error, double t, uint32_t *indices)
{
    const gdr_mesh_clusters *c = &m->clusters;
    size_t n = 0;
    for (uint32_t i = 0; i < c->cluster_count; i++) {
        const gdr_cluster *k = &c->clusters[i];
        double refined = k->refined_group == GDR_NO_INDEX ? 0 : error[k->refined_group];
        double own = k->group == GDR_NO_INDEX || !isfinite(c->groups[k->group].error) ? INFINITY : error[k->group];
        if (!(refined <= t && !(own <= t)))
            continue;
        for (uint32_t j = 0; j < k->triangle_count * 3; j++)
            indices[n++] = c->vertices[k->vertex_offset + c->triangles[k->triangle_offset + j]];
    }
    return n / 3;
}

/* Cuts by the stated errors and by the measured ones, side by side at mesh-space thresholds: what a
 * tighter error (in shape, not in scale: the thresholds differ) would gain at equal triangles. */
static void compare_cuts(const gdr_mesh *m, const triangle_grid *full_grid, const double *tight, double spacing)
{
    const gdr_mesh_clusters *c = &m->clusters;
    double *stated = xmalloc(c->group_count * sizeof *stated);
    for (uint32_t g = 0; g < c->group_count; g++)
        stated[g] = c->groups[g].error;
    size_t total = 0;
    for (uint32_t i = 0; i < c->cluster_count; i++)
        total += c->clusters[i].triangle_count * 3u;
    uint32_t *indices = xmalloc(total * sizeof *indices);
    printf("\ncuts by the stated errors and by the measured ones (mesh-space thresholds)\n");
    printf("errors    thresh  triangles  stated   cut->full: max  rms   full->cut: max  rms   normal rms\n");
    for (int pass = 0; pass < 2; pass++)
        for (int i = 0; i <= 16; i += 2) {
            double t = m->bounds.w * pow(10.0, -3.0 + i / 8.0);
            size_t n = cut_by(m, pass ? tight : stated, t, indices);
            report(pass ? "measured" : "stated", t / m->bounds.w * 1e4, m, full_grid,
                   (surface){m->positions, m->vertex_count, indices, n}, m->normals, 0, spacing);
        }
    free(indices);
    free(stated);
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Per group: the largest distance from its own clusters' triangles to the full mesh; then carried
 * up by the max over the groups its members came from (groups are numbered by step, children first). */
static void calibration(const gdr_mesh *m, const triangle_grid *full_grid, double spacing)
{
    const gdr_mesh_clusters *c = &m->clusters;
    double *own = calloc(c->group_count, sizeof *own), *tight = calloc(c->group_count, sizeof *tight);
    uint32_t *indices = xmalloc(GDR_CLUSTER_MAX_TRIANGLES * 3 * sizeof *indices);
    for (uint32_t i = c->level0_cluster_count; i < c->cluster_count; i++) {
        const gdr_cluster *k = &c->clusters[i];
        if (k->refined_group == GDR_NO_INDEX)
            continue;
        for (uint32_t j = 0; j < k->triangle_count * 3; j++)
            indices[j] = c->vertices[k->vertex_offset + c->triangles[k->triangle_offset + j]];
        surface s = {m->positions, m->vertex_count, indices, k->triangle_count};
        stats d = one_sided(s, full_grid, spacing, NULL);
        own[k->refined_group] = fmax(own[k->refined_group], d.max);
    }
    uint32_t depth = c->dag_depth;
    for (uint32_t level = 0; level <= depth; level++)
        for (uint32_t g = 0; g < c->group_count; g++) {
            if (c->groups[g].depth != level)
                continue;
            double t = own[g];
            const gdr_cluster_group *G = &c->groups[g];
            for (uint32_t i = G->first_cluster; i < G->first_cluster + G->cluster_count; i++)
                if (c->clusters[i].refined_group != GDR_NO_INDEX)
                    t = fmax(t, tight[c->clusters[i].refined_group]);
            tight[g] = t;
        }
    printf("\nstated error / tightest monotone one-sided deviation, by depth (groups, quantiles 10/50/90%%, max)\n");
    double *ratio = xmalloc(c->group_count * sizeof *ratio);
    for (uint32_t level = 0; level <= depth; level++) {
        uint32_t n = 0;
        double u = m->bounds.w * 1e-4, sum_stated = 0, sum_tight = 0;
        for (uint32_t g = 0; g < c->group_count; g++)
            if (c->groups[g].depth == level && isfinite(c->groups[g].error) && tight[g] > 0) {
                ratio[n++] = c->groups[g].error / tight[g];
                sum_stated += c->groups[g].error;
                sum_tight += tight[g];
            }
        if (!n)
            continue;
        qsort(ratio, n, sizeof *ratio, compare_double);
        printf("depth %2u: %5u groups  %6.2f %6.2f %6.2f %7.2f   mean stated %8.2f, tight %8.2f (1e-4 R)\n", level, n,
               ratio[n / 10], ratio[n / 2], ratio[n * 9 / 10], ratio[n - 1], sum_stated / n / u, sum_tight / n / u);
    }
    free(ratio);
    compare_cuts(m, full_grid, tight, spacing);
    free(indices);
    free(own);
    free(tight);
}

/* Whether `list` is pixel thresholds above 0 separated by commas. */
static int thresholds_valid(const char *list)
{
    for (const char *t = list;;) {
        char *end;
        double px = strtod(t, &end);
        if (end == t || (*end && *end != ',') || !(px > 0.0 && px <= 1e6))
            return 0;
        if (!*end)
            return 1;
        t = end + 1;
    }
}

/* Each --ref T=FILE.obj of the command line: another builder's cut, reported beside gdr's. */
static void report_references(int argc, char **argv, const gdr_mesh *m, const triangle_grid *full_grid,
                              double spacing)
{
    for (int i = 3; i + 1 < argc; i++)
        if (!strcmp(argv[i], "--ref")) {
            char *end;
            double px = strtod(argv[++i], &end);
            const char *path = strchr(argv[i], '=');
            if (!path || end != path || !(px > 0.0 && px <= 1e6))
                die(argv[i], "--ref: expected T=FILE.obj, T a pixel threshold above 0");
            gdr_scene *keep = NULL;
            surface s = read_cut(path + 1, &keep);
            report("reference", px, m, full_grid, s, keep->meshes[0].normals, 0, spacing);
            gdr_scene_destroy(keep);
        }
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: lod_cut_deviation FULL.obj CAMERA [--thresholds T,T,...] [--height H] "
                        "[--ref T=CUT.obj ...] [--calibration]\n");
        return 2;
    }
    float cam[7];
    if (sscanf(argv[2], "%f,%f,%f,%f,%f,%f,%f", &cam[0], &cam[1], &cam[2], &cam[3], &cam[4], &cam[5], &cam[6]) != 7)
        die(argv[2], "expected px,py,pz,qx,qy,qz,qw");
    const char *thresholds = "0.5,1,2,3,4,6,8,12,16";
    float height = 720;
    int with_calibration = 0;
    for (int i = 3; i < argc; i++)
        if (!strcmp(argv[i], "--calibration"))
            with_calibration = 1;
        else if (!strcmp(argv[i], "--thresholds") && i + 1 < argc)
            thresholds = argv[++i];
        else if (!strcmp(argv[i], "--height") && i + 1 < argc) {
            char *end;
            height = strtof(argv[++i], &end);
            if (end == argv[i] || *end || !(height >= 1.0f && height <= 16384.0f))
                die(argv[i], "--height: expected a number of pixels in [1, 16384]");
        }
        else if (!strcmp(argv[i], "--ref") && i + 1 < argc)
            i++;
        else {
            fprintf(stderr, "lod_cut_deviation: %s: unknown option\n", argv[i]);
            return 2;
        }
    if (!thresholds_valid(thresholds))
        die(thresholds, "--thresholds: expected pixel thresholds above 0, separated by commas");
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    if (gdr_import_file(argv[1], &(gdr_import_options){.no_progress = 1}, &scene, NULL, &err) != GDR_OK)
        die(argv[1], err.message);
    if (scene->mesh_count == 0 || scene->meshes[0].index_count < 3)
        die(argv[1], "holds no triangles");
    const gdr_mesh *m = &scene->meshes[0];
    surface full = {m->positions, m->vertex_count, m->indices, m->index_count / 3};
    triangle_grid *full_grid = triangle_grid_create(full);
    double spacing = 0.5 * sqrt(surface_area(full) / (double)full.triangle_count);
    printf("%s: %zu triangles, radius %g; distances in 1e-4 of the radius\n", argv[1], full.triangle_count,
           (double)m->bounds.w);
    printf("builder   thresh  triangles  stated   cut->full: max  rms   full->cut: max  rms   normal rms\n");
    uint8_t *selected = xmalloc(m->clusters.cluster_count);
    size_t total = 0;
    for (uint32_t i = 0; i < m->clusters.cluster_count; i++)
        total += m->clusters.clusters[i].triangle_count * 3u;
    uint32_t *indices = xmalloc(total * sizeof *indices);
    for (const char *t = thresholds; *t;) {
        char *end;
        double px = strtod(t, &end);
        gdr_lod_view view = {.transform = gdr_mat4_identity(),
                             .camera_position = {cam[0], cam[1], cam[2]},
                             .projection_y = 1.0f / tanf(0.5f * 0.785398163f),
                             .viewport_height = height,
                             .znear = 0.01f * m->bounds.w,
                             .threshold = (float)px};
        double stated;
        size_t n = gdr_cut(m, &view, selected, indices, &stated);
        report("gdr", px, m, full_grid, (surface){m->positions, m->vertex_count, indices, n}, m->normals, stated, spacing);
        t = *end == ',' ? end + 1 : end;
    }
    report_references(argc, argv, m, full_grid, spacing);
    if (with_calibration)
        calibration(m, full_grid, spacing);
    triangle_grid_destroy(full_grid);
    free(selected);
    free(indices);
    gdr_scene_destroy(scene);
    return 0;
}
