/* The cluster LOD DAG: the invariants of gdr/geometry.h on closed, open, seamed,
 * degenerate and disconnected meshes, the CPU cut (exactly level 0 at threshold 0, exactly the
 * root at a huge one, every source-to-sink path of the DAG crossed exactly once and no crack for
 * random views), the discrete depth cut, determinism over thread counts, options and bad input. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cluster_checks.h"
#include "point_distance.h"
#include "gdr/geometry.h"
#include "gdr/procedural.h"
#include "gdr/scene.h"
#include "geometry/lod_cut.h"
#include "geometry/lod_grid.h"
#include "procedural/procedural_meshes.h"
#include "test_util.h"

/* --- meshes --------------------------------------------------------------------------------- */

static gdr_scene *new_scene(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    if (gdr_scene_create(&s, &err) != GDR_OK) {
        fprintf(stderr, "gdr_scene_create: %s\n", err.message);
        exit(1);
    }
    return s;
}

static void check_ok(gdr_status status, const gdr_error *err, const char *what)
{
    if (status != GDR_OK) {
        fprintf(stderr, "%s: %s\n", what, err->message);
        exit(1);
    }
}

static uint32_t add_mesh(gdr_scene *s, const char *name, const gdr_vec3 *p, uint32_t vertex_count, const uint32_t *idx,
                         uint32_t index_count)
{
    uint32_t m = 0;
    gdr_error err = {0};
    check_ok(gdr_scene_add_mesh(s, name, p, NULL, NULL, vertex_count, idx, index_count, &m, &err), &err, name);
    return m;
}

static uint32_t add_single_triangle(gdr_scene *s)
{
    const gdr_vec3 p[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const uint32_t idx[3] = {0, 1, 2};
    return add_mesh(s, "triangle", p, 3, idx, 3);
}

/* Many separate pieces in one mesh: small closed octahedra on a lattice and loose triangles. */
static uint32_t add_pieces(gdr_scene *s, uint32_t count)
{
    gdr_vec3 *p = malloc(sizeof *p * count * 6 + sizeof *p * 3 * count);
    uint32_t *idx = malloc(sizeof *idx * count * 24 + sizeof *idx * 3 * count);
    uint32_t v = 0, k = 0;
    static const uint32_t faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                         {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    for (uint32_t i = 0; i < count; i++) {
        float x = (float)(i % 8) * 3.0f, y = (float)(i / 8 % 8) * 3.0f, z = (float)(i / 64) * 3.0f;
        const gdr_vec3 o[6] = {{x + 1, y, z}, {x - 1, y, z}, {x, y + 1, z}, {x, y - 1, z}, {x, y, z + 1}, {x, y, z - 1}};
        for (int j = 0; j < 6; j++)
            p[v + j] = o[j];
        for (int f = 0; f < 8; f++)
            for (int c = 0; c < 3; c++)
                idx[k++] = v + faces[f][c];
        v += 6;
        if (i % 3 == 0) { /* a loose triangle next to it */
            p[v] = (gdr_vec3){x + 1.5f, y, z};
            p[v + 1] = (gdr_vec3){x + 1.5f, y + 1, z};
            p[v + 2] = (gdr_vec3){x + 1.5f, y, z + 1};
            idx[k++] = v, idx[k++] = v + 1, idx[k++] = v + 2;
            v += 3;
        }
    }
    uint32_t m = add_mesh(s, "pieces", p, v, idx, k);
    free(p);
    free(idx);
    return m;
}

/* The blob with a seam: triangles on the +Z side use their own copies of their vertices, with the
 * same coordinates (as UV seams do), so the mesh is closed by position but not by index. */
static uint32_t add_seamed_blob(gdr_scene *s)
{
    gdr_scene *t = new_scene();
    gdr_error err = {0};
    uint32_t b;
    check_ok(gdr_procedural_blob(t, 4, &b, &err), &err, "blob");
    const gdr_mesh *m = &t->meshes[b];
    gdr_vec3 *p = malloc(sizeof *p * m->vertex_count * 2);
    uint32_t *idx = malloc(sizeof *idx * m->index_count);
    memcpy(p, m->positions, sizeof *p * m->vertex_count);
    memcpy(p + m->vertex_count, m->positions, sizeof *p * m->vertex_count);
    for (uint32_t i = 0; i < m->index_count; i += 3) {
        float z = 0.0f;
        for (int k = 0; k < 3; k++)
            z += m->positions[m->indices[i + k]].z;
        for (int k = 0; k < 3; k++)
            idx[i + k] = m->indices[i + k] + (z > 0.0f ? m->vertex_count : 0);
    }
    uint32_t out = add_mesh(s, "seamed", p, m->vertex_count * 2, idx, m->index_count);
    free(p);
    free(idx);
    gdr_scene_destroy(t);
    return out;
}

/* A blob among closed tetrahedra (no collapse can reduce one: it would repeat a triangle): groups
 * of tetrahedra alone cannot simplify, so step 0 passes them through and the build ends with them
 * in the root. (Hard-edged boxes did this until the simplifier learnt to move positions held by
 * three vertices.) */
static uint32_t add_blob_and_boxes(gdr_scene *s, uint32_t boxes)
{
    static const gdr_vec3 corner[4] = {{0, 0, 0}, {0.2f, 0, 0}, {0, 0.2f, 0}, {0, 0, 0.2f}};
    static const uint32_t face[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    gdr_scene *t = new_scene();
    gdr_error err = {0};
    uint32_t blob;
    check_ok(gdr_procedural_blob(t, 4, &blob, &err), &err, "blob");
    const gdr_mesh *mb = &t->meshes[blob];
    uint32_t vertices = mb->vertex_count + boxes * 4, indices = mb->index_count + boxes * 12;
    gdr_vec3 *p = malloc(sizeof *p * vertices);
    uint32_t *idx = malloc(sizeof *idx * indices);
    memcpy(p, mb->positions, sizeof *p * mb->vertex_count);
    memcpy(idx, mb->indices, sizeof *idx * mb->index_count);
    uint32_t v = mb->vertex_count, k = mb->index_count;
    for (uint32_t i = 0; i < boxes; i++) {
        gdr_vec3 o = {3.0f + (float)(i % 10), (float)(i / 10 % 10), (float)(i / 100)};
        for (uint32_t j = 0; j < 4; j++)
            p[v + j] = gdr_vec3_add(corner[j], o);
        for (uint32_t j = 0; j < 12; j++)
            idx[k++] = v + face[j];
        v += 4;
    }
    uint32_t out = add_mesh(s, "boxes", p, vertices, idx, indices);
    free(p);
    free(idx);
    gdr_scene_destroy(t);
    return out;
}

/* `count` separate small closed pieces of different sizes on a grid, 3 units apart, each with hard
 * edges (a vertex per face corner): boxes (gdr_procedural_box) and tetrahedra in turn. Every corner
 * position is held by three vertices, which meshoptimizer 0.18 never moves, a tetrahedron is the
 * smallest closed surface, and nothing joins the pieces: edge collapses leave at least a
 * tetrahedron per piece. */
static uint32_t add_separate_pieces(gdr_scene *s, uint32_t count)
{
    static const gdr_vec3 corner[4] = {{0.4f, 0.4f, 0.4f}, {0.4f, -0.4f, -0.4f}, {-0.4f, 0.4f, -0.4f}, {-0.4f, -0.4f, 0.4f}};
    static const uint32_t face[12] = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};
    gdr_scene *t = new_scene();
    gdr_error err = {0};
    uint32_t box;
    check_ok(gdr_procedural_box(t, (gdr_vec3){0.5f, 0.3f, 0.4f}, &box, &err), &err, "box");
    const gdr_mesh *mb = &t->meshes[box];
    gdr_vec3 *p = malloc(sizeof *p * (mb->vertex_count + 12) * count);
    uint32_t *idx = malloc(sizeof *idx * (mb->index_count + 12) * count);
    uint32_t v = 0, k = 0;
    for (uint32_t i = 0; i < count; i++) {
        gdr_vec3 o = {3.0f * (float)(i % 5), 3.0f * (float)(i / 5 % 5), 3.0f * (float)(i / 25)};
        float scale = 0.5f + 0.1f * (float)(i % 7);
        if (i % 2 == 0) {
            for (uint32_t j = 0; j < mb->vertex_count; j++)
                p[v + j] = gdr_vec3_add(gdr_vec3_scale(mb->positions[j], scale), o);
            for (uint32_t j = 0; j < mb->index_count; j++)
                idx[k++] = v + mb->indices[j];
            v += mb->vertex_count;
        } else {
            for (uint32_t j = 0; j < 12; j++, v++) { /* each face its own three vertices */
                p[v] = gdr_vec3_add(gdr_vec3_scale(corner[face[j]], scale), o);
                idx[k++] = v;
            }
        }
    }
    uint32_t out = add_mesh(s, "separate", p, v, idx, k);
    free(p);
    free(idx);
    gdr_scene_destroy(t);
    return out;
}

static void build_level0(gdr_mesh *mesh)
{
    gdr_error err = {0};
    check_ok(gdr_meshlets_build(mesh, NULL, &mesh->clusters, &err), &err, mesh->name);
}

static gdr_lod_stats build_dag(gdr_mesh *mesh, uint32_t threads)
{
    gdr_error err = {0};
    gdr_lod_stats stats;
    gdr_lod_options o = {.thread_count = threads, .no_progress = 1};
    check_ok(gdr_mesh_build_lod_dag(mesh, &o, &stats, &err), &err, mesh->name);
    return stats;
}

/* --- invariants ------------------------------------------------------------------------------- */

typedef struct tri_key {
    uint32_t v[3];
} tri_key;

static int compare_tri(const void *a, const void *b) { return memcmp(a, b, sizeof(tri_key)); }

/* The corners rotated so the smallest index comes first (same triangle, same winding). */
static tri_key canonical(uint32_t a, uint32_t b, uint32_t c)
{
    if (b < a && b <= c)
        return (tri_key){{b, c, a}};
    if (c < a && c < b)
        return (tri_key){{c, a, b}};
    return (tri_key){{a, b, c}};
}

static int level0_covers_input(const gdr_mesh *mesh)
{
    const gdr_mesh_clusters *mc = &mesh->clusters;
    uint32_t n = mesh->index_count / 3, k = 0;
    tri_key *a = malloc(sizeof *a * n), *b = malloc(sizeof *b * n);
    for (uint32_t t = 0; t < n; t++)
        a[t] = canonical(mesh->indices[3 * t], mesh->indices[3 * t + 1], mesh->indices[3 * t + 2]);
    int ok = 1;
    for (uint32_t i = 0; i < mc->level0_cluster_count && ok; i++) {
        const gdr_cluster *c = &mc->clusters[i];
        for (uint32_t t = 0; t < c->triangle_count && ok; t++) {
            ok = k < n;
            if (ok)
                b[k++] = canonical(cluster_corner(mc, c, t, 0), cluster_corner(mc, c, t, 1),
                                   cluster_corner(mc, c, t, 2));
        }
    }
    ok = ok && k == n;
    if (ok) {
        qsort(a, n, sizeof *a, compare_tri);
        qsort(b, n, sizeof *b, compare_tri);
        ok = memcmp(a, b, sizeof *a * n) == 0;
    }
    free(a);
    free(b);
    return ok;
}

/* Sphere b inside sphere a (with the builder's relative slack to spare). */
static int sphere_contains(gdr_vec4 a, gdr_vec4 b)
{
    double dx = (double)a.x - b.x, dy = (double)a.y - b.y, dz = (double)a.z - b.z;
    return sqrt(dx * dx + dy * dy + dz * dz) + b.w <= (double)a.w * (1.0 + 1e-6) + 1e-30;
}

static uint64_t triangles_of(const gdr_mesh_clusters *mc, uint32_t first, uint32_t count)
{
    uint64_t t = 0;
    for (uint32_t i = first; i < first + count; i++)
        t += mc->clusters[i].triangle_count;
    return t;
}

/* Seen from points just inside the region the cone test culls (on its boundary cone behind the
 * apex, in 8 directions around the axis, near and far), every triangle of the cluster must be
 * back-facing or edge-on, in double on the stored floats. */
static int cone_is_conservative(const gdr_mesh *mesh, const gdr_mesh_clusters *mc, const gdr_cluster *c)
{
    if (c->cone_cutoff >= 1.0f)
        return 1;
    double axis[3] = {c->cone_axis.x, c->cone_axis.y, c->cone_axis.z};
    double length = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    for (int k = 0; k < 3; k++)
        axis[k] /= length;
    /* Two unit vectors perpendicular to the axis. */
    double helper[3] = {fabs(axis[0]) < 0.9 ? 1.0 : 0.0, fabs(axis[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    double u[3] = {axis[1] * helper[2] - axis[2] * helper[1], axis[2] * helper[0] - axis[0] * helper[2],
                   axis[0] * helper[1] - axis[1] * helper[0]};
    double ul = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int k = 0; k < 3; k++)
        u[k] /= ul;
    double w[3] = {axis[1] * u[2] - axis[2] * u[1], axis[2] * u[0] - axis[0] * u[2], axis[0] * u[1] - axis[1] * u[0]};
    /* The test culls p when dot(normalize(apex - p), axis_stored) >= cutoff. */
    double cos_edge = fmin(1.0, (double)c->cone_cutoff / length + 1e-6), sin_edge = sqrt(1.0 - cos_edge * cos_edge);
    for (int around = 0; around < 8; around++) {
        double angle = around * 0.785398163397448;
        double d[3];
        for (int k = 0; k < 3; k++)
            d[k] = axis[k] * cos_edge + (u[k] * cos(angle) + w[k] * sin(angle)) * sin_edge;
        for (int far = 0; far < 2; far++) {
            double t = (far ? 100.0 : 0.01) * (c->sphere.w + 1e-3);
            double p[3] = {c->cone_apex.x - d[0] * t, c->cone_apex.y - d[1] * t, c->cone_apex.z - d[2] * t};
            for (uint32_t k = 0; k < c->triangle_count; k++) {
                double v[3][3];
                for (int j = 0; j < 3; j++) {
                    gdr_vec3 q = mesh->positions[cluster_corner(mc, c, k, (uint32_t)j)];
                    v[j][0] = q.x, v[j][1] = q.y, v[j][2] = q.z;
                }
                double e1[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
                double e2[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
                double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                               e1[0] * e2[1] - e1[1] * e2[0]};
                double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                double facing = n[0] * (p[0] - v[0][0]) + n[1] * (p[1] - v[0][1]) + n[2] * (p[2] - v[0][2]);
                if (facing > 1e-9 * nl * t) {
                    fprintf(stderr, "mesh '%s': a cluster's triangle %u faces a point its cone culls\n", mesh->name,
                            k);
                    return 0;
                }
            }
        }
    }
    return 1;
}

/* Every cluster in range (4-byte aligned triangles, indices within it and the mesh), its cone
 * conservative, level 0 first, and up the DAG error, depth and spheres only grow. Returns 0 where a
 * cluster is out of range (nothing more can be read safely). */
static int check_clusters(const gdr_mesh *mesh, uint32_t root)
{
    const gdr_mesh_clusters *mc = &mesh->clusters;
    for (uint32_t i = 0; i < mc->cluster_count; i++) {
        const gdr_cluster *c = &mc->clusters[i];
        int in_range = c->vertex_count >= 1 && c->vertex_count <= GDR_CLUSTER_MAX_VERTICES &&
                       c->triangle_count >= 1 && c->triangle_count <= GDR_CLUSTER_MAX_TRIANGLES &&
                       c->triangle_offset % 4 == 0 && c->reserved == 0 &&
                       (uint64_t)c->vertex_offset + c->vertex_count <= mc->vertex_count &&
                       (uint64_t)c->triangle_offset + 3ull * c->triangle_count <= mc->triangle_byte_count &&
                       c->group < mc->group_count;
        CHECK(in_range);
        if (!in_range)
            return 0;
        for (uint32_t k = 0; k < 3 * c->triangle_count; k++)
            CHECK(mc->triangles[c->triangle_offset + k] < c->vertex_count);
        for (uint32_t v = 0; v < c->vertex_count; v++)
            CHECK(mc->vertices[c->vertex_offset + v] < mesh->vertex_count);
        CHECK(cone_is_conservative(mesh, mc, c));
        if (i < mc->level0_cluster_count) {
            CHECK(c->refined_group == GDR_NO_INDEX);
            CHECK(mc->groups[c->group].depth == 0);
        } else {
            CHECK(c->refined_group < mc->group_count);
            if (c->refined_group >= mc->group_count)
                return 0;
            const gdr_cluster_group *from = &mc->groups[c->refined_group], *to = &mc->groups[c->group];
            /* Monotonic: error, depth and spheres only grow up the DAG. */
            CHECK(to->error >= from->error);
            CHECK(to->depth > from->depth);
            CHECK(sphere_contains(to->sphere, from->sphere));
            CHECK(c->refined_group != root);
        }
        CHECK(sphere_contains(mc->groups[c->group].sphere, c->sphere));
    }
    return 1;
}

/* Group g's new clusters: a step-0 group that did not simplify passed its clusters on unchanged;
 * any other kept at most 85% of its triangles; the root made none. */
static void check_group_outputs(const gdr_mesh_clusters *mc, uint32_t g, uint32_t root)
{
    const gdr_cluster_group *gr = &mc->groups[g];
    uint32_t next = gr->first_cluster + gr->cluster_count;
    uint64_t in = triangles_of(mc, gr->first_cluster, gr->cluster_count), out = 0;
    uint32_t outputs = 0, passthrough = 0;
    for (uint32_t i = mc->level0_cluster_count; i < mc->cluster_count; i++)
        if (mc->clusters[i].refined_group == g) {
            out += mc->clusters[i].triangle_count;
            outputs++;
            for (uint32_t j = gr->first_cluster; j < next; j++)
                passthrough += mc->clusters[j].triangle_offset == mc->clusters[i].triangle_offset &&
                               mc->clusters[j].vertex_offset == mc->clusters[i].vertex_offset;
        }
    if (g == root) {
        CHECK(outputs == 0);
    } else if (passthrough) {
        CHECK(gr->depth == 0 && passthrough == outputs && outputs == gr->cluster_count && out == in);
    } else {
        CHECK(outputs >= 1 && (double)out <= 0.85 * (double)in);
    }
}

/* Groups: contiguous clusters, finite positive errors below the root, depths in order, triangles
 * reduced, and each step reducing what it formed groups over. Returns 0 where a group's clusters
 * run past the array. */
static int check_groups(const gdr_mesh_clusters *mc, uint32_t root)
{
    uint32_t next = 0;
    for (uint32_t g = 0; g < mc->group_count; g++) {
        const gdr_cluster_group *gr = &mc->groups[g];
        CHECK(gr->first_cluster == next && gr->cluster_count >= 1);
        next = gr->first_cluster + gr->cluster_count;
        if (next > mc->cluster_count)
            return 0;
        for (uint32_t i = gr->first_cluster; i < next; i++)
            CHECK(mc->clusters[i].group == g);
        if (g != root)
            CHECK(isfinite(gr->error) && gr->error > 0.0f);
        if (g > 0)
            CHECK(gr->depth >= mc->groups[g - 1].depth);
        check_group_outputs(mc, g, root);
    }
    CHECK(next == mc->cluster_count);
    for (uint32_t d = 0; d < mc->dag_depth; d++) {
        uint64_t in = 0, out = 0;
        for (uint32_t g = 0; g < root; g++)
            if (mc->groups[g].depth == d) {
                in += triangles_of(mc, mc->groups[g].first_cluster, mc->groups[g].cluster_count);
                for (uint32_t i = mc->level0_cluster_count; i < mc->cluster_count; i++)
                    out += mc->clusters[i].refined_group == g ? mc->clusters[i].triangle_count : 0;
            }
        CHECK(in > 0 && out < in);
    }
    return 1;
}

/* The stats agree with the data. */
static void check_stats(const gdr_mesh *mesh, const gdr_lod_stats *st, uint32_t root)
{
    const gdr_mesh_clusters *mc = &mesh->clusters;
    uint64_t total = triangles_of(mc, 0, mc->cluster_count);
    uint32_t stops = 0;
    for (int i = 0; i < GDR_LOD_STOP_COUNT; i++)
        stops += st->stop_counts[i];
    CHECK(st->mesh_count == 1 && stops == 1 && st->stop_counts[GDR_LOD_STOP_NONE] == 0);
    CHECK(st->group_count == mc->group_count && st->cluster_count == mc->cluster_count);
    CHECK(st->input_triangles == mesh->index_count / 3 && st->dag_triangles == total);
    CHECK(st->root_clusters == mc->groups[root].cluster_count);
    CHECK(st->root_triangles == triangles_of(mc, mc->groups[root].first_cluster, mc->groups[root].cluster_count));
    CHECK(st->max_depth == mc->dag_depth);
    if (st->stop_counts[GDR_LOD_STOP_SINGLE_CLUSTER])
        CHECK(mc->groups[root].cluster_count == 1);
}

/* Everything gdr/geometry.h promises about a built DAG; returns 1 when it all holds. */
static int check_dag(const gdr_mesh *mesh, const gdr_lod_stats *st)
{
    const gdr_mesh_clusters *mc = &mesh->clusters;
    int failures = test_failure_count;
    CHECK(mc->group_count >= 1 && mc->groups && mc->cluster_count >= mc->level0_cluster_count);
    if (test_failure_count != failures)
        return 0;
    CHECK(level0_covers_input(mesh));
    uint32_t root = mc->group_count - 1;
    CHECK(isinf(mc->groups[root].error) && mc->groups[root].error > 0);
    CHECK(mc->groups[root].depth == mc->dag_depth);
    if (!check_clusters(mesh, root))
        return 0;
    CHECK(check_cluster_spheres(mesh, mc)); /* every vertex inside its cluster's sphere */
    if (!check_groups(mc, root))
        return 0;
    check_stats(mesh, st, root);
    return test_failure_count == failures;
}

/* --- the cut ------------------------------------------------------------------------------------- */

/* Every path from a level-0 cluster to a root cluster (cluster -> the clusters made from its group)
 * holds exactly one selected cluster: the selection is an antichain that covers the DAG. Clusters
 * are ordered by group and groups by depth, so successors come later in the array. */
static int cut_is_exact(const gdr_mesh_clusters *mc, const uint8_t *selected)
{
    uint32_t n = mc->cluster_count;
    uint32_t *lo = malloc(sizeof *lo * n), *hi = malloc(sizeof *hi * n);
    uint32_t *succ_lo = malloc(sizeof *succ_lo * mc->group_count), *succ_hi = malloc(sizeof *succ_hi * mc->group_count);
    for (uint32_t g = 0; g < mc->group_count; g++)
        succ_lo[g] = UINT32_MAX, succ_hi[g] = 0;
    int ok = 1;
    for (uint32_t i = n; i-- > 0;) {
        const gdr_cluster *c = &mc->clusters[i];
        uint32_t g = c->group;
        uint32_t min = succ_lo[g] == UINT32_MAX ? 0 : succ_lo[g], max = succ_lo[g] == UINT32_MAX ? 0 : succ_hi[g];
        lo[i] = min + selected[i];
        hi[i] = max + selected[i];
        if (c->refined_group != GDR_NO_INDEX) {
            uint32_t r = c->refined_group;
            ok = ok && r < g;
            succ_lo[r] = lo[i] < succ_lo[r] ? lo[i] : succ_lo[r];
            succ_hi[r] = hi[i] > succ_hi[r] ? hi[i] : succ_hi[r];
        }
    }
    for (uint32_t i = 0; i < mc->level0_cluster_count && ok; i++)
        ok = lo[i] == 1 && hi[i] == 1;
    free(lo);
    free(hi);
    free(succ_lo);
    free(succ_hi);
    return ok;
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Position ids: vertices with equal coordinates share one (so seams count as connected). */
static uint32_t *position_ids(const gdr_mesh *mesh)
{
    uint32_t *id = malloc(sizeof *id * mesh->vertex_count);
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        id[v] = v;
        for (uint32_t w = 0; w < v; w++)
            if (memcmp(&mesh->positions[w], &mesh->positions[v], sizeof(gdr_vec3)) == 0) {
                id[v] = id[w];
                break;
            }
    }
    return id;
}

/* Directed edges (by position) of the selected clusters' triangles that no selected triangle runs
 * the other way: 0 for a closed mesh means the cut has no crack. */
static uint64_t open_edges(const gdr_mesh_clusters *mc, const uint8_t *selected, const uint32_t *pos)
{
    size_t n = 0;
    for (uint32_t i = 0; i < mc->cluster_count; i++)
        n += selected[i] ? 3u * mc->clusters[i].triangle_count : 0;
    uint64_t *e = malloc(sizeof *e * (n ? n : 1));
    size_t k = 0;
    for (uint32_t i = 0; i < mc->cluster_count; i++) {
        if (!selected[i])
            continue;
        const gdr_cluster *c = &mc->clusters[i];
        for (uint32_t t = 0; t < c->triangle_count; t++)
            for (uint32_t j = 0; j < 3; j++) {
                uint32_t a = pos[cluster_corner(mc, c, t, j)], b = pos[cluster_corner(mc, c, t, (j + 1) % 3)];
                if (a != b)
                    e[k++] = (uint64_t)a << 32 | b;
            }
    }
    qsort(e, k, sizeof *e, compare_u64);
    uint64_t open = 0;
    for (size_t i = 0; i < k;) {
        size_t j = i;
        while (j < k && e[j] == e[i])
            j++;
        uint64_t reverse = e[i] << 32 | e[i] >> 32;
        size_t lo = 0, hi = k;
        while (lo < hi) {
            size_t mid = (lo + hi) / 2;
            if (e[mid] < reverse)
                lo = mid + 1;
            else
                hi = mid;
        }
        size_t r = lo;
        while (r < k && e[r] == reverse)
            r++;
        open += (j - i) > (r - lo) ? (j - i) - (r - lo) : 0;
        i = j;
    }
    free(e);
    return open;
}

static gdr_lod_view random_view(const gdr_mesh *mesh, unsigned *rng)
{
    gdr_vec3 axis = gdr_vec3_normalize((gdr_vec3){test_random_range(rng, -1, 1), test_random_range(rng, -1, 1),
                                                  test_random_range(rng, -1, 1) + 0.01f});
    float s = test_random_range(rng, 0.2f, 5.0f);
    gdr_vec3 scale = {s, s * test_random_range(rng, 0.5f, 1.5f), s};
    gdr_vec3 t = {test_random_range(rng, -10, 10), test_random_range(rng, -10, 10), test_random_range(rng, -10, 10)};
    gdr_lod_view v = {.transform = gdr_mat4_from_trs(t, gdr_quat_from_axis_angle(axis, test_random(rng) * 6.28f), scale),
                      .projection_y = 1.0f / tanf(0.5f * test_random_range(rng, 0.3f, 1.6f)),
                      .viewport_height = test_random_range(rng, 240.0f, 2160.0f),
                      .znear = test_random_range(rng, 0.01f, 0.5f),
                      .threshold = test_random_range(rng, 0.05f, 40.0f)};
    /* A camera from inside the mesh to far away from it. */
    gdr_vec3 dir = gdr_vec3_normalize((gdr_vec3){test_random_range(rng, -1, 1), test_random_range(rng, -1, 1),
                                                 test_random_range(rng, -1, 1) + 0.01f});
    float distance = mesh->bounds.w * s * powf(10.0f, test_random_range(rng, -1.0f, 2.5f));
    gdr_vec3 centre = gdr_mat4_transform_point(v.transform, (gdr_vec3){mesh->bounds.x, mesh->bounds.y, mesh->bounds.z});
    v.camera_position = gdr_vec3_add(centre, gdr_vec3_scale(dir, distance));
    return v;
}

/* The CPU cut at the extremes and for random views. No cut may have more open edges than level 0
 * (a crack adds some; simplifying the mesh's own open border only removes some); `closed`: level
 * 0 has none. Returns how many different cut sizes the random views gave. */
static uint32_t check_cuts(const gdr_mesh *mesh, int closed, unsigned seed, uint32_t views)
{
    const gdr_mesh_clusters *mc = &mesh->clusters;
    uint8_t *sel = malloc(mc->cluster_count);
    uint32_t *pos = position_ids(mesh);
    uint64_t level0_open = 0;
    unsigned rng = seed;
    gdr_lod_view v = random_view(mesh, &rng);
    /* Threshold 0: exactly level 0. */
    v.threshold = 0.0f;
    uint32_t count = gdr_lod_cut_select(mc, &v, sel);
    level0_open = open_edges(mc, sel, pos);
    CHECK(!closed || level0_open == 0);
    CHECK(count == mc->level0_cluster_count);
    for (uint32_t i = 0; i < mc->cluster_count; i++)
        CHECK(sel[i] == (i < mc->level0_cluster_count));
    /* A huge threshold: exactly the root group's clusters. */
    const gdr_cluster_group *root = &mc->groups[mc->group_count - 1];
    v.threshold = 1e30f;
    count = gdr_lod_cut_select(mc, &v, sel);
    CHECK(count == root->cluster_count);
    for (uint32_t i = 0; i < mc->cluster_count; i++)
        CHECK(sel[i] == (i >= root->first_cluster && i < root->first_cluster + root->cluster_count));
    /* Random views: an exact cover of the DAG, without cracks. */
    uint32_t sizes[64], distinct = 0;
    for (uint32_t k = 0; k < views; k++) {
        v = random_view(mesh, &rng);
        count = gdr_lod_cut_select(mc, &v, sel);
        CHECK(count > 0);
        CHECK(cut_is_exact(mc, sel));
        uint64_t open = open_edges(mc, sel, pos);
        CHECK(open <= level0_open);
        if (open > level0_open)
            fprintf(stderr, "mesh '%s': %llu open edges (level 0: %llu) in a cut of %u clusters\n", mesh->name,
                    (unsigned long long)open, (unsigned long long)level0_open, count);
        int seen = 0;
        for (uint32_t j = 0; j < distinct; j++)
            seen |= sizes[j] == count;
        if (!seen && distinct < 64)
            sizes[distinct++] = count;
    }
    /* The discrete depth cut: level 0 at depth 0, the root past the last depth, exact between. */
    for (uint32_t d = 0; d <= mc->dag_depth + 1; d++) {
        count = gdr_lod_cut_select_depth(mc, d, sel);
        CHECK(cut_is_exact(mc, sel));
        CHECK(open_edges(mc, sel, pos) <= level0_open);
        if (d == 0)
            CHECK(count == mc->level0_cluster_count);
        if (d > mc->dag_depth)
            CHECK(count == root->cluster_count);
    }
    free(pos);
    free(sel);
    return distinct;
}

/* --- tests ----------------------------------------------------------------------------------- */

static void report(const gdr_mesh *m, const gdr_lod_stats *st)
{
    const char *stop = st->stop_counts[GDR_LOD_STOP_SINGLE_CLUSTER] ? "single cluster"
                       : st->stop_counts[GDR_LOD_STOP_NO_PROGRESS] ? "no progress"
                                                                    : "level limit";
    printf("%-9s %7llu tris -> DAG %7llu (%.2fx), %5u clusters, %4u groups, depth %2u, root %llu clusters / %llu tris "
           "(%s), stuck %llu (border %llu), pass-through %llu, sloppy %llu\n",
           m->name, (unsigned long long)st->input_triangles, (unsigned long long)st->dag_triangles,
           (double)st->dag_triangles / (double)st->input_triangles, m->clusters.cluster_count,
           m->clusters.group_count, m->clusters.dag_depth, (unsigned long long)st->root_clusters,
           (unsigned long long)st->root_triangles, stop, (unsigned long long)st->stuck_groups,
           (unsigned long long)st->border_rejects, (unsigned long long)st->passthrough_clusters,
           (unsigned long long)st->sloppy_groups);
}

static void test_meshes(void)
{
    gdr_scene *s = new_scene();
    gdr_error err = {0};
    uint32_t blob, sphere, ground, torus, box, tri, pieces, seamed, boxes;
    check_ok(gdr_procedural_blob(s, 4, &blob, &err), &err, "blob");         /* closed, welded */
    /* UV sphere and torus: their seams are not bit-equal (sinf(2 pi) != 0), so they are open. */
    check_ok(gdr_procedural_sphere(s, 96, 48, &sphere, &err), &err, "sphere"); /* degenerate poles */
    check_ok(gdr_procedural_ground(s, 10.0f, 48, &ground, &err), &err, "ground"); /* flat, open border */
    check_ok(gdr_procedural_torus(s, 1.0f, 0.3f, 64, 24, &torus, &err), &err, "torus"); /* seams, genus 1 */
    check_ok(gdr_procedural_box(s, (gdr_vec3){1, 2, 3}, &box, &err), &err, "box"); /* hard edges, 12 tris */
    tri = add_single_triangle(s);
    pieces = add_pieces(s, 150);
    seamed = add_seamed_blob(s);
    boxes = add_blob_and_boxes(s, 300);
    struct {
        uint32_t mesh;
        int closed, curved;
    } cases[] = {{blob, 1, 1},   {seamed, 1, 1}, {sphere, 0, 1}, {ground, 0, 0},
                 {torus, 0, 1},  {box, 1, 0},    {tri, 0, 0},    {pieces, 0, 1}, {boxes, 1, 1}};
    gdr_lod_stats stats[sizeof cases / sizeof cases[0]];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        gdr_mesh *m = &s->meshes[cases[i].mesh];
        build_level0(m);
        gdr_lod_stats st = stats[i] = build_dag(m, 2);
        report(m, &st);
        if (!check_dag(m, &st)) {
            fprintf(stderr, "mesh '%s': DAG invariants broken\n", m->name);
            continue;
        }
        uint32_t distinct = check_cuts(m, cases[i].closed, 1234u + (unsigned)i, 40);
        /* Curved meshes with a real DAG must give different cuts for different views (a flat
         * grid simplifies without error: its root is always enough). */
        if (cases[i].curved && m->clusters.dag_depth >= 2 && distinct < 4) {
            CHECK(distinct >= 4);
            fprintf(stderr, "mesh '%s': only %u different cuts\n", m->name, distinct);
        }
    }
    /* What the shapes must come to. */
    const gdr_mesh *m = &s->meshes[blob];
    CHECK(m->clusters.dag_depth >= 3);
    CHECK(m->clusters.groups[m->clusters.group_count - 1].cluster_count <= 2);
    m = &s->meshes[ground];
    /* Its open border is not locked (only what groups share is): the grid simplifies away. */
    CHECK(m->clusters.dag_depth >= 3 && m->clusters.groups[m->clusters.group_count - 1].cluster_count == 1);
    /* The tetrahedra cannot simplify while groups of them meet neighbours: passed through at step 0,
     * stuck; once one group holds them all, the fallback simplifier removes pieces (its error measured). */
    CHECK(stats[8].passthrough_clusters > 0 && stats[8].stuck_groups > 0);
    /* ... and where it cannot either, the whole frontier is clustered by vertices: the small root. */
    CHECK(stats[8].stop_counts[GDR_LOD_STOP_SINGLE_CLUSTER] == 1 && stats[8].root_triangles <= GDR_LOD_DEFAULT_ROOT_TRIANGLES);
    m = &s->meshes[tri];
    CHECK(m->clusters.cluster_count == 1 && m->clusters.group_count == 1 && m->clusters.dag_depth == 0);
    gdr_scene_destroy(s);
}

/* Same bytes whatever the thread count, and a rebuild replaces the DAG with the same bytes. */
static void test_determinism(void)
{
    gdr_scene *s = new_scene();
    gdr_error err = {0};
    uint32_t a, b;
    check_ok(gdr_procedural_blob(s, 5, &a, &err), &err, "blob");
    check_ok(gdr_procedural_blob(s, 5, &b, &err), &err, "blob");
    build_level0(&s->meshes[a]);
    build_level0(&s->meshes[b]);
    gdr_lod_stats sa = build_dag(&s->meshes[a], 1);
    gdr_lod_stats sb = build_dag(&s->meshes[b], 2);
    CHECK(same_clusters(&s->meshes[a].clusters, &s->meshes[b].clusters));
    CHECK(memcmp(&sa, &sb, sizeof sa) == 0);
    build_dag(&s->meshes[b], 3);
    CHECK(same_clusters(&s->meshes[a].clusters, &s->meshes[b].clusters));
    gdr_scene_destroy(s);
}

/* The whole demo scene through gdr_scene_build_lod (clusters first), 1 vs 2 threads. */
static void test_scene(void)
{
    gdr_scene *one = NULL, *two = NULL;
    gdr_error err = {0};
    gdr_demo_desc desc = {.instances = 16};
    check_ok(gdr_scene_create_demo(&desc, &one, &err), &err, "demo");
    check_ok(gdr_scene_create_demo(&desc, &two, &err), &err, "demo");
    gdr_lod_stats s1, s2;
    check_ok(gdr_scene_build_lod(one, &(gdr_lod_options){.thread_count = 1, .no_progress = 1}, &s1, &err), &err,
             "scene 1");
    check_ok(gdr_scene_build_lod(two, &(gdr_lod_options){.thread_count = 2, .no_progress = 1}, &s2, &err), &err,
             "scene 2");
    CHECK(memcmp(&s1, &s2, sizeof s1) == 0);
    CHECK(s1.mesh_count == one->mesh_count);
    uint64_t input = 0;
    for (uint32_t m = 0; m < one->mesh_count; m++) {
        CHECK(same_clusters(&one->meshes[m].clusters, &two->meshes[m].clusters));
        CHECK(one->meshes[m].clusters.group_count > 0);
        input += one->meshes[m].index_count / 3;
    }
    CHECK(s1.input_triangles == input);
    /* Meshes that already have a DAG are left alone. */
    gdr_lod_stats again;
    check_ok(gdr_scene_build_lod(one, NULL, &again, &err), &err, "scene again");
    CHECK(again.mesh_count == 0);
    for (uint32_t m = 0; m < one->mesh_count; m++)
        CHECK(same_clusters(&one->meshes[m].clusters, &two->meshes[m].clusters));
    gdr_scene_destroy(one);
    gdr_scene_destroy(two);
}

static void test_bad_input(void)
{
    gdr_scene *s = new_scene();
    gdr_error err = {0};
    uint32_t blob;
    check_ok(gdr_procedural_blob(s, 2, &blob, &err), &err, "blob");
    gdr_mesh *m = &s->meshes[blob];
    /* No level 0 yet. */
    CHECK_FAILS(gdr_mesh_build_lod_dag(m, NULL, NULL, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    build_level0(m);
    const gdr_lod_options bad[] = {{.group_size = 1}, {.group_size = 33}, {.target_ratio = 0.9f},
                                   {.target_ratio = -0.5f}, {.thread_count = 1000}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        CHECK(gdr_mesh_build_lod_dag(m, &bad[i], NULL, &err) == GDR_ERROR_INVALID_ARGUMENT);
        CHECK(m->clusters.group_count == 0 && m->clusters.cluster_count == m->clusters.level0_cluster_count);
    }
    /* A corner out of range is refused before anything reads it, and level 0 is left as it was. */
    gdr_mesh_clusters before = m->clusters;
    uint8_t saved = m->clusters.triangles[4];
    m->clusters.triangles[4] = 200;
    CHECK_FAILS(gdr_mesh_build_lod_dag(m, NULL, NULL, &err), err, GDR_ERROR_INVALID_ARGUMENT);
    CHECK_NAMES(err, "clusters[0]");
    m->clusters.triangles[4] = saved;
    CHECK(m->clusters.cluster_count == before.cluster_count && m->clusters.group_count == 0);
    /* Other options still give a valid DAG. */
    gdr_lod_stats st;
    gdr_lod_options o = {.group_size = 8, .target_ratio = 0.3f, .thread_count = 2, .no_progress = 1};
    CHECK(gdr_mesh_build_lod_dag(m, &o, &st, &err) == GDR_OK);
    CHECK(check_dag(m, &st));
    gdr_scene_destroy(s);
}

/* --- the error bounds the deviation from full detail ------------------------------------------- */

/* Distance from p to the nearest triangle of a list of mesh-vertex corners. */
static double point_surface(const gdr_mesh *m, dvec3 p, const uint32_t *corners, size_t triangles)
{
    double best = INFINITY;
    for (size_t t = 0; t < triangles; t++)
        best = fmin(best, point_triangle(p, d3(m->positions[corners[3 * t]]), d3(m->positions[corners[3 * t + 1]]),
                                         d3(m->positions[corners[3 * t + 2]])));
    return best;
}

/* The largest distance from the vertices and centroids of `from` to `to`. */
static double one_sided(const gdr_mesh *m, const uint32_t *from, size_t from_count, const uint32_t *to,
                        size_t to_count)
{
    double worst = 0;
    for (size_t t = 0; t < from_count; t++) {
        dvec3 c[3] = {d3(m->positions[from[3 * t]]), d3(m->positions[from[3 * t + 1]]), d3(m->positions[from[3 * t + 2]])};
        dvec3 probes[4] = {c[0], c[1], c[2], {(c[0].x + c[1].x + c[2].x) / 3, (c[0].y + c[1].y + c[2].y) / 3,
                                              (c[0].z + c[1].z + c[2].z) / 3}};
        for (int k = 0; k < 4; k++)
            worst = fmax(worst, point_surface(m, probes[k], to, to_count));
    }
    return worst;
}

/* The cut at threshold t as mesh-vertex corners into `cut`; returns the corner count and the largest
 * error of the groups its clusters were made from in *stated. */
static size_t gather_cut(const gdr_mesh_clusters *mc, float t, uint32_t *cut, double *stated)
{
    size_t n = 0;
    *stated = 0;
    for (uint32_t i = 0; i < mc->cluster_count; i++) {
        const gdr_cluster *c = &mc->clusters[i];
        float refined = c->refined_group == GDR_NO_INDEX ? 0.0f : mc->groups[c->refined_group].error;
        float own = c->group == GDR_NO_INDEX ? INFINITY : mc->groups[c->group].error;
        if (!(refined <= t && !(own <= t)))
            continue;
        *stated = fmax(*stated, refined);
        for (uint32_t j = 0; j < c->triangle_count * 3; j++)
            cut[n++] = mc->vertices[c->vertex_offset + mc->triangles[c->triangle_offset + j]];
    }
    return n;
}

/* Every cut at a range of thresholds deviates from full detail (both ways) by at most the largest
 * error of the groups its clusters were made from. */
static void check_error_bounds_cuts(const gdr_mesh *m)
{
    const gdr_mesh_clusters *mc = &m->clusters;
    uint32_t *cut = malloc((size_t)m->index_count * 4 * sizeof *cut);
    uint8_t *sel = malloc(mc->cluster_count);
    double worst_ratio = 0;
    for (int step = 0; step < 7; step++) {
        float t = m->bounds.w * 1e-4f * powf(4.0f, (float)step);
        double stated = 0;
        size_t n = gather_cut(mc, t, cut, &stated);
        double a = one_sided(m, cut, n / 3, m->indices, m->index_count / 3);
        double b = one_sided(m, m->indices, m->index_count / 3, cut, n / 3);
        double deviation = fmax(a, b), slack = 1e-5 * m->bounds.w;
        if (deviation > stated + slack)
            fprintf(stderr, "mesh '%s': cut at %g deviates %g (to full %g, from full %g), states %g\n", m->name,
                    (double)t, deviation, a, b, stated);
        CHECK(deviation <= stated + slack);
        if (stated > 0)
            worst_ratio = fmax(worst_ratio, deviation / stated);
    }
    /* The coarse end: a cut at the error of every group that is the only one of its depth (it
     * holds the whole mesh: the steps below one cluster, a few triangles each). */
    uint32_t coarse = 0;
    double worst_coarse = 0, worst_centroid = 0;
    for (uint32_t g = 0; g + 1 < mc->group_count; g++) {
        float t = mc->groups[g].error;
        uint32_t at_depth = 0;
        for (uint32_t h = 0; h < mc->group_count; h++)
            at_depth += mc->groups[h].depth == mc->groups[g].depth;
        if (at_depth != 1)
            continue;
        double stated = 0;
        size_t n = gather_cut(mc, t, cut, &stated);
        /* What the error promises: from the cut's probes (corners, centroids) to full detail, and
         * from every level-0 vertex (the samples) to the cut. Between the samples (a level-0
         * centroid) the distance may exceed it by up to half a level-0 edge: reported. */
        double a = one_sided(m, cut, n / 3, m->indices, m->index_count / 3);
        double b = 0, centroids = one_sided(m, m->indices, m->index_count / 3, cut, n / 3);
        for (uint32_t v = 0; v < m->index_count; v++)
            b = fmax(b, point_surface(m, d3(m->positions[m->indices[v]]), cut, n / 3));
        double deviation = fmax(a, b);
        if (deviation > stated + 1e-5 * m->bounds.w)
            fprintf(stderr, "mesh '%s': cut of %zu triangles at %g deviates %g (to full %g, from full %g), states %g\n",
                    m->name, n / 3, (double)t, deviation, a, b, stated);
        CHECK(deviation <= stated + 1e-5 * m->bounds.w);
        worst_coarse = fmax(worst_coarse, deviation / stated);
        worst_centroid = fmax(worst_centroid, centroids / stated);
        coarse++;
    }
    CHECK(coarse >= 2);
    printf("%-8s cuts at 1e-4 .. 0.4 of the radius: true deviation / stated error at most %.3f; at the errors of %u "
           "whole-mesh groups %.3f (%.3f with level-0 centroids)\n", m->name, worst_ratio, coarse, worst_coarse,
           worst_centroid);
    free(cut);
    free(sel);
}

static void test_error_bounds_deviation(void)
{
    gdr_scene *s = new_scene();
    gdr_error err = {0};
    uint32_t blob, torus;
    check_ok(gdr_procedural_blob(s, 3, &blob, &err), &err, "blob");
    check_ok(gdr_procedural_torus(s, 1.0f, 0.3f, 32, 16, &torus, &err), &err, "torus");
    const uint32_t meshes[] = {blob, torus};
    for (int i = 0; i < 2; i++) {
        gdr_mesh *m = &s->meshes[meshes[i]];
        build_level0(m);
        gdr_lod_options o = {.group_size = 4, .thread_count = 1, .no_progress = 1};
        check_ok(gdr_mesh_build_lod_dag(m, &o, NULL, &err), &err, m->name);
        CHECK(m->clusters.dag_depth >= 2);
        check_error_bounds_cuts(m);
    }
    gdr_scene_destroy(s);
}

/* A mesh of many separate pieces that edge collapses cannot take below a tetrahedron each
 * (hard-edged boxes and tetrahedra): the steps form no group, where the build used to stop with a
 * root of every piece. Vertex clustering of the
 * whole frontier merges them, one ordinary group a step, down to one cluster and a root of at most
 * GDR_LOD_DEFAULT_ROOT_TRIANGLES triangles; every cut still deviates from full detail by at most
 * what it states (measured by brute force), is an exact cover and opens no edge. */
static void test_separate_pieces(void)
{
    gdr_scene *s = new_scene();
    uint32_t separate = add_separate_pieces(s, 60);
    gdr_mesh *m = &s->meshes[separate];
    build_level0(m);
    gdr_lod_options o = {.thread_count = 2, .no_progress = 1};
    gdr_lod_stats st;
    gdr_error err = {0};
    check_ok(gdr_mesh_build_lod_dag(m, &o, &st, &err), &err, m->name);
    report(m, &st);
    CHECK(check_dag(m, &st));
    check_cuts(m, 1, 4321u, 40);
    const gdr_mesh_clusters *mc = &m->clusters;
    CHECK(st.stop_counts[GDR_LOD_STOP_SINGLE_CLUSTER] == 1 && mc->groups[mc->group_count - 1].cluster_count == 1);
    CHECK(st.root_triangles <= GDR_LOD_DEFAULT_ROOT_TRIANGLES);
    CHECK(st.sloppy_groups >= 1);
    check_error_bounds_cuts(m);
    gdr_scene_destroy(s);
}

/* The coarse end: below one cluster the build goes on, one lone cluster simplified step by step,
 * until the root holds at most root_triangles triangles (GDR_LOD_DEFAULT_ROOT_TRIANGLES by default)
 * or stops simplifying; root_triangles = GDR_CLUSTER_MAX_TRIANGLES stops at one cluster. */
static void test_coarse_end(void)
{
    gdr_scene *s = new_scene();
    gdr_error err = {0};
    uint32_t blob, knot, early;
    check_ok(gdr_procedural_blob(s, 5, &blob, &err), &err, "blob");            /* closed, genus 0 */
    check_ok(gdr_procedural_torus_knot(s, 240, 24, &knot, &err), &err, "knot"); /* closed, genus 1 */
    check_ok(gdr_procedural_blob(s, 5, &early, &err), &err, "blob");
    const struct {
        uint32_t mesh, root_triangles, most; /* most: the root's largest triangle count */
    } cases[] = {{blob, 0, GDR_LOD_DEFAULT_ROOT_TRIANGLES}, {knot, 0, 16}, {early, GDR_CLUSTER_MAX_TRIANGLES, 124}};
    for (int i = 0; i < 3; i++) {
        gdr_mesh *m = &s->meshes[cases[i].mesh];
        build_level0(m);
        gdr_lod_options o = {.thread_count = 2, .no_progress = 1, .root_triangles = cases[i].root_triangles};
        gdr_lod_stats st;
        check_ok(gdr_mesh_build_lod_dag(m, &o, &st, &err), &err, m->name);
        report(m, &st);
        CHECK(check_dag(m, &st));
        const gdr_mesh_clusters *mc = &m->clusters;
        const gdr_cluster_group *root = &mc->groups[mc->group_count - 1];
        CHECK(st.stop_counts[GDR_LOD_STOP_SINGLE_CLUSTER] == 1 && root->cluster_count == 1);
        CHECK(st.root_triangles <= cases[i].most);
        /* Below one cluster, every step is one group of one cluster that made one smaller cluster. */
        uint32_t lone = 0;
        for (uint32_t at = root->first_cluster; mc->clusters[at].refined_group != GDR_NO_INDEX; lone++) {
            const gdr_cluster_group *from = &mc->groups[mc->clusters[at].refined_group];
            if (from->cluster_count != 1)
                break;
            CHECK(mc->clusters[at].triangle_count < mc->clusters[from->first_cluster].triangle_count);
            at = from->first_cluster;
        }
        printf("%-8s root of %llu triangles after %u steps below one cluster\n", m->name,
               (unsigned long long)st.root_triangles, lone);
        CHECK(cases[i].root_triangles == GDR_CLUSTER_MAX_TRIANGLES ? lone == 0 : lone >= 3);
        if (cases[i].root_triangles == GDR_CLUSTER_MAX_TRIANGLES)
            CHECK(st.root_triangles > 4 * GDR_LOD_DEFAULT_ROOT_TRIANGLES);
    }
    /* root_triangles outside [1, GDR_CLUSTER_MAX_TRIANGLES] is refused, naming the option. */
    gdr_lod_options bad = {.no_progress = 1, .root_triangles = GDR_CLUSTER_MAX_TRIANGLES + 1};
    CHECK(gdr_mesh_build_lod_dag(&s->meshes[blob], &bad, NULL, &err) == GDR_ERROR_INVALID_ARGUMENT &&
          strstr(err.message, "root_triangles") != NULL);
    gdr_scene_destroy(s);
}

/* The coarsest cut (the root's members) of a torus of 512 x 8 quads: each coarse triangle spans more
 * level-0 positions along the ring than a walk over them takes steps, and bounds from where such walks
 * were cut off made the coarse groups state 3-4x their true deviation. The stated error must stay
 * within 2x the true one (and never below it). */
static void test_coarse_error_tight(void)
{
    gdr_scene *s = new_scene();
    gdr_error err = {0};
    uint32_t torus;
    check_ok(gdr_procedural_torus(s, 1.0f, 0.3f, 512, 8, &torus, &err), &err, "torus");
    gdr_mesh *m = &s->meshes[torus];
    build_level0(m);
    gdr_lod_options o = {.thread_count = 1, .no_progress = 1};
    check_ok(gdr_mesh_build_lod_dag(m, &o, NULL, &err), &err, m->name);
    const gdr_mesh_clusters *mc = &m->clusters;
    float coarsest = 0.0f;
    for (uint32_t g = 0; g < mc->group_count; g++)
        if (mc->groups[g].error < INFINITY && mc->groups[g].error > coarsest)
            coarsest = mc->groups[g].error;
    uint32_t *cut = malloc((size_t)m->index_count * 4 * sizeof *cut);
    double stated = 0;
    size_t n = gather_cut(mc, coarsest, cut, &stated);
    double a = one_sided(m, cut, n / 3, m->indices, m->index_count / 3);
    double b = one_sided(m, m->indices, m->index_count / 3, cut, n / 3);
    double deviation = fmax(a, b);
    printf("torus 512x8: coarsest cut of %zu triangles states %g, deviates %g (%.2fx)\n", n / 3, stated, deviation,
           stated / deviation);
    CHECK(n > 0 && deviation <= stated + 1e-5 * m->bounds.w);
    CHECK(stated <= 2.0 * deviation);
    free(cut);
    gdr_scene_destroy(s);
}

/* Distance from p to the ideal torus around the y axis. */
static double torus_distance(dvec3 p, double major, double minor)
{
    double q = sqrt(p.x * p.x + p.z * p.z) - major;
    return fabs(sqrt(q * q + p.y * p.y) - minor);
}

/* Per group: the largest distance from points of its new clusters (a grid of 4 steps an edge) to
 * the ideal torus, into own[]. */
static void clusters_to_torus(const gdr_mesh *m, double *own)
{
    const gdr_mesh_clusters *mc = &m->clusters;
    for (uint32_t i = 0; i < mc->cluster_count; i++) {
        const gdr_cluster *k = &mc->clusters[i];
        for (uint32_t t = 0; k->refined_group != GDR_NO_INDEX && t < k->triangle_count; t++) {
            dvec3 v[3];
            for (int j = 0; j < 3; j++)
                v[j] = d3(m->positions[mc->vertices[k->vertex_offset + mc->triangles[k->triangle_offset + 3 * t + j]]]);
            for (int u = 0; u <= 4; u++)
                for (int w = 0; u + w <= 4; w++) {
                    double x = u / 4.0, y = w / 4.0, z = 1 - x - y;
                    dvec3 p = {z * v[0].x + x * v[1].x + y * v[2].x, z * v[0].y + x * v[1].y + y * v[2].y,
                               z * v[0].z + x * v[1].z + y * v[2].z};
                    own[k->refined_group] = fmax(own[k->refined_group], torus_distance(p, 1.0, 0.35));
                }
        }
    }
}

/* Per group that is the only one of its depth and made one cluster (it holds the whole mesh: the
 * steps below one cluster), the largest distance from a vertex of the mesh to its new cluster's
 * triangles, into own[] where larger. Such a cluster's few triangles lie close to the torus but
 * leave most of it far away: the distance from its clusters to the torus alone misses that. */
static void mesh_to_lone_groups(const gdr_mesh *m, double *own)
{
    const gdr_mesh_clusters *mc = &m->clusters;
    for (uint32_t g = 0; g + 1 < mc->group_count; g++) {
        uint32_t at_depth = 0;
        for (uint32_t h = 0; h < mc->group_count; h++)
            at_depth += mc->groups[h].depth == mc->groups[g].depth;
        if (at_depth != 1)
            continue;
        size_t n = 0, made = 0;
        for (uint32_t i = 0; i < mc->cluster_count; i++) {
            n += mc->clusters[i].refined_group == g ? mc->clusters[i].triangle_count : 0;
            made += mc->clusters[i].refined_group == g;
        }
        if (made != 1)
            continue;
        uint32_t *corners = malloc(3 * n * sizeof *corners);
        n = 0;
        for (uint32_t i = 0; corners && i < mc->cluster_count; i++) {
            const gdr_cluster *k = &mc->clusters[i];
            for (uint32_t j = 0; k->refined_group == g && j < k->triangle_count * 3; j++)
                corners[n++] = mc->vertices[k->vertex_offset + mc->triangles[k->triangle_offset + j]];
        }
        CHECK(corners != NULL);
        for (uint32_t v = 0; corners && v < m->vertex_count; v++)
            own[g] = fmax(own[g], point_surface(m, d3(m->positions[v]), corners, n / 3));
        free(corners);
    }
}

/* A torus of 360 x 180 quads has open seams (positions not bit-equal) and groups that drop a
 * border sliver their neighbour keeps: samples there lie far from their own group's new clusters
 * but on a neighbour's. Without passing them to the neighbour a group stated 5.2x the larger of
 * its children's errors and its clusters' distance to the torus (the deviation the rest of it
 * shows); every group must now state at most 2x that. Since near-equal positions are welded no
 * group of it passes a sample (1.21x either way): it fails only with neither the weld nor the
 * passing; test_lod_samples's flat grid fails without the passing alone. Its uvs are cleared: the
 * texture slide that also enters a group's error (lod_simplify.c) is not a distance to the torus
 * (with them, 2.42x). */
static void test_samples_pass_to_neighbours(void)
{
    gdr_scene *s = new_scene();
    gdr_error err = {0};
    uint32_t torus;
    check_ok(gdr_procedural_torus(s, 1.0f, 0.35f, 360, 180, &torus, &err), &err, "torus");
    gdr_mesh *m = &s->meshes[torus];
    /* The geometric error alone: without uvs no texture slide enters the stated error. */
    memset(m->uvs, 0, sizeof *m->uvs * m->vertex_count);
    build_level0(m);
    gdr_lod_options o = {.thread_count = 1, .no_progress = 1};
    check_ok(gdr_mesh_build_lod_dag(m, &o, NULL, &err), &err, m->name);
    const gdr_mesh_clusters *mc = &m->clusters;
    double *own = calloc(mc->group_count, sizeof *own), *child = calloc(mc->group_count, sizeof *child);
    clusters_to_torus(m, own);
    mesh_to_lone_groups(m, own);
    for (uint32_t i = 0; i < mc->cluster_count; i++) {
        const gdr_cluster *k = &mc->clusters[i];
        if (k->group != GDR_NO_INDEX && k->refined_group != GDR_NO_INDEX)
            child[k->group] = fmax(child[k->group], mc->groups[k->refined_group].error);
    }
    double worst = 0;
    for (uint32_t g = 0; g < mc->group_count; g++)
        if (mc->groups[g].error < INFINITY)
            worst = fmax(worst, mc->groups[g].error / fmax(fmax(own[g], child[g]), 1e-6 * m->bounds.w));
    printf("torus 360x180: a group states at most %.2fx its children's errors and its clusters' distance\n", worst);
    CHECK(worst <= 2.0);
    free(own);
    free(child);
    gdr_scene_destroy(s);
}

/* The largest finite group error at each DAG depth of a torus of 120 x 60 quads, its seams'
 * positions as generated (sinf(2 pi) != 0: not bit-equal) or copied from the other side. */
static uint32_t torus_errors_by_depth(int weld, double *worst, uint32_t max_depth)
{
    gdr_scene *s = new_scene();
    gdr_error err = {0};
    uint32_t torus, su = 120, sv = 60;
    check_ok(gdr_procedural_torus(s, 1.0f, 0.35f, su, sv, &torus, &err), &err, "torus");
    gdr_mesh *m = &s->meshes[torus];
    for (uint32_t r = 0; weld && r <= sv; r++)
        for (uint32_t c = 0; c <= su; c++)
            m->positions[r * (su + 1) + c] = m->positions[(r % sv) * (su + 1) + c % su];
    build_level0(m);
    gdr_lod_options o = {.thread_count = 1, .no_progress = 1};
    check_ok(gdr_mesh_build_lod_dag(m, &o, NULL, &err), &err, m->name);
    const gdr_mesh_clusters *mc = &m->clusters;
    for (uint32_t g = 0; g < mc->group_count; g++)
        if (mc->groups[g].error < INFINITY && mc->groups[g].depth < max_depth)
            worst[mc->groups[g].depth] = fmax(worst[mc->groups[g].depth], mc->groups[g].error);
    uint32_t depth = mc->dag_depth;
    gdr_scene_destroy(s);
    return depth;
}

/* Seams whose two sides differ by rounding are welded for grouping and simplification: the torus
 * with its seams as generated must simplify about as well as with them bit-equal (the position
 * ids differ, so METIS groups it differently: 1.16x at one depth). Left open (borders that slide
 * apart), its groups stated up to 2.8x the bit-equal torus's error at a depth. */
static void test_seams_welded(void)
{
    double open[GDR_LOD_MAX_LEVELS] = {0}, closed[GDR_LOD_MAX_LEVELS] = {0};
    uint32_t depth = torus_errors_by_depth(0, open, GDR_LOD_MAX_LEVELS);
    uint32_t depth_closed = torus_errors_by_depth(1, closed, GDR_LOD_MAX_LEVELS);
    double worst = 0;
    for (uint32_t d = 0; d < depth && d < depth_closed; d++)
        if (closed[d] > 0)
            worst = fmax(worst, open[d] / closed[d]);
    printf("torus 120x60, seams as generated: at most %.2fx the error of bit-equal seams at a depth\n", worst);
    CHECK(depth >= 4 && worst <= 1.3);
}

/* --- the error bounds the distance between the build's probes ---------------------------------- */

static float point_triangle_d2_float(gdr_vec3 p, gdr_vec3 a, gdr_vec3 b, gdr_vec3 c)
{
    double d = point_triangle(d3(p), d3(a), d3(b), d3(c));
    return (float)(d * d);
}

/* The largest distance (exact, a grid without a cell limit) from the points of a barycentric grid of
 * n steps on triangle v to the full-detail surface. */
static double grid_distance(const lod_triangle_grid *full, const gdr_vec3 v[3], int n)
{
    double worst = 0;
    for (int a = 0; a <= n; a++)
        for (int b = 0; a + b <= n; b++) {
            float u = (float)a / (float)n, w = (float)b / (float)n, z = 1.0f - u - w;
            gdr_vec3 p = {z * v[0].x + u * v[1].x + w * v[2].x, z * v[0].y + u * v[1].y + w * v[2].y,
                          z * v[0].z + u * v[1].z + w * v[2].z};
            float d2;
            lod_triangle_grid_nearest(full, p, point_triangle_d2_float, &d2);
            worst = fmax(worst, sqrt(d2));
        }
    return worst;
}

/* The largest ratio, over the triangles of the clusters groups made, of the distance to the
 * full-detail surface at a grid of 16 steps an edge to the error of the group that made them; only
 * triangles whose grid of 4 steps comes within half the error are measured densely (the others are
 * far below it: on the knot below, none of them reaches 0.7 of it). */
static double densest_ratio(const gdr_mesh *m)
{
    const gdr_mesh_clusters *mc = &m->clusters;
    lod_triangle_grid full = {0};
    CHECK(lod_triangle_grid_build(&full, &m->positions[0].x, m->indices, m->index_count / 3));
    full.cell_limit = UINT32_MAX; /* exact */
    double worst = 0;
    for (uint32_t i = 0; i < mc->cluster_count; i++) {
        const gdr_cluster *c = &mc->clusters[i];
        if (c->refined_group == GDR_NO_INDEX)
            continue;
        double error = fmax(mc->groups[c->refined_group].error, 1e-7 * m->bounds.w);
        for (uint32_t t = 0; t < c->triangle_count; t++) {
            gdr_vec3 v[3];
            for (int k = 0; k < 3; k++)
                v[k] = m->positions[mc->vertices[c->vertex_offset + mc->triangles[c->triangle_offset + 3 * t + k]]];
            if (grid_distance(&full, v, 4) >= 0.5 * error)
                worst = fmax(worst, grid_distance(&full, v, 16) / error);
        }
    }
    lod_triangle_grid_free(&full);
    return worst;
}

/* A torus knot's tube is folded tighter than its simplified triangles: the distance from one of
 * them to S0 peaks on ridges between the build's probe points (where two level-0 facets seen from
 * inside the fold are equally near), which the build predicts from the facets' planes and probes.
 * Measured on a grid of 16 steps an edge (points between the build's grids of 3 and 8), every
 * cluster lies within 1.007x its group's error; 1.036x without probing the ridges. */
static void test_error_between_probes(void)
{
    gdr_scene *s = new_scene();
    gdr_error err = {0};
    uint32_t knot;
    check_ok(gdr_procedural_torus_knot(s, 200, 40, &knot, &err), &err, "knot");
    gdr_mesh *m = &s->meshes[knot];
    build_level0(m);
    gdr_lod_options o = {.thread_count = 1, .no_progress = 1};
    check_ok(gdr_mesh_build_lod_dag(m, &o, NULL, &err), &err, m->name);
    double ratio = densest_ratio(m);
    printf("knot 200 x 40: distance to full detail at a grid of 16 steps at most %.4fx the error\n", ratio);
    CHECK(ratio <= 1.02);
    gdr_scene_destroy(s);
}

/* The uvs steer simplification only where a texture reads them: a scene's mesh whose instance has an
 * untextured material builds the DAG of the mesh built alone with ignore_uvs, bit for bit in its
 * groups' errors; with a textured material, the DAG with its uvs. The blob's spherical uv map is far
 * from affine, so the two differ. */
static uint32_t add_blob_instance(gdr_scene *s, int textured)
{
    gdr_error err = {0};
    uint32_t blob, material, texture = GDR_NO_INDEX;
    check_ok(gdr_procedural_blob(s, 4, &blob, &err), &err, "blob");
    gdr_material m = gdr_material_default();
    if (textured) {
        const uint8_t texels[4 * 4] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
        check_ok(gdr_scene_add_texture(s, "checker", 2, 2, texels, 1, &texture, &err), &err, "texture");
        m.base_color_texture.texture = texture;
    }
    check_ok(gdr_scene_add_material(s, &m, &material, &err), &err, "material");
    gdr_instance in = {.transform = gdr_mat4_identity(), .mesh = blob, .material = material,
                       .color = {1, 1, 1, 1}};
    check_ok(gdr_scene_add_instance(s, &in, &err), &err, "instance");
    return blob;
}

static int same_errors(const gdr_mesh_clusters *a, const gdr_mesh_clusters *b)
{
    if (a->group_count != b->group_count || a->cluster_count != b->cluster_count)
        return 0;
    for (uint32_t g = 0; g < a->group_count; g++)
        if (memcmp(&a->groups[g].error, &b->groups[g].error, sizeof a->groups[g].error) != 0)
            return 0;
    return 1;
}

static void test_uvs_where_textured(void)
{
    gdr_error err = {0};
    gdr_scene *plain = new_scene(), *textured = new_scene(), *alone = new_scene();
    uint32_t p = add_blob_instance(plain, 0), t = add_blob_instance(textured, 1);
    gdr_lod_options o = {.thread_count = 2, .no_progress = 1};
    check_ok(gdr_scene_build_lod(plain, &o, NULL, &err), &err, "untextured scene");
    check_ok(gdr_scene_build_lod(textured, &o, NULL, &err), &err, "textured scene");
    uint32_t with, without;
    check_ok(gdr_procedural_blob(alone, 4, &with, &err), &err, "blob");
    check_ok(gdr_procedural_blob(alone, 4, &without, &err), &err, "blob");
    build_level0(&alone->meshes[with]);
    build_level0(&alone->meshes[without]);
    check_ok(gdr_mesh_build_lod_dag(&alone->meshes[with], &o, NULL, &err), &err, "with uvs");
    gdr_lod_options no_uvs = o;
    no_uvs.ignore_uvs = 1;
    check_ok(gdr_mesh_build_lod_dag(&alone->meshes[without], &no_uvs, NULL, &err), &err, "without uvs");
    const gdr_mesh_clusters *cp = &plain->meshes[p].clusters, *ct = &textured->meshes[t].clusters;
    const gdr_mesh_clusters *cw = &alone->meshes[with].clusters, *cn = &alone->meshes[without].clusters;
    printf("blob: %u / %u groups with / without uvs\n", cw->group_count, cn->group_count);
    CHECK(!same_errors(cw, cn));
    CHECK(same_errors(cp, cn)); /* untextured: the uvs ignored */
    CHECK(same_errors(ct, cw)); /* textured: the uvs steer */
    gdr_scene_destroy(plain);
    gdr_scene_destroy(textured);
    gdr_scene_destroy(alone);
}

int main(void)
{
    test_meshes();
    test_determinism();
    test_error_bounds_deviation();
    test_coarse_end();
    test_separate_pieces();
    test_coarse_error_tight();
    test_samples_pass_to_neighbours();
    test_seams_welded();
    test_error_between_probes();
    test_scene();
    test_uvs_where_textured();
    test_bad_input();
    return test_finish("test_lod_dag");
}
