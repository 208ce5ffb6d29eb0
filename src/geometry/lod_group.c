/* Simplifying one group of a DAG step: merge its clusters' triangles over a compact local vertex
 * list, simplify to about half with the shared border locked (lod_simplify.c, across attribute
 * seams), check the border, split into new clusters with their bounds (meshoptimizer). Runs as a thread-pool task; it writes only its own
 * group_result and its worker's scratch. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geometry/cluster_bounds.h"
#include "geometry/lod_internal.h"

/* The normals weigh as little as they did before they were raised for the scans' shading in two
 * places (docs/GEOMETRY.md, "Shading at equal triangles"): below one cluster (the lone cluster of the
 * whole mesh simplified further), drawn for an instance a few pixels across, where its geometric
 * error decides how coarse it may be and no shading is seen; and on a textured mesh, whose
 * appearance the texture slide guards and whose coarse steps, simplified to keep their normals,
 * crossed charts with larger slides (100,000 DamagedHelmets 1-3 px across drew 7.5 times the
 * triangles). */
#define LOD_LOW_NORMAL_WEIGHT 0.1

/* The smallest float >= x. */
static float round_up_to_float(double x)
{
    float f = (float)x;
    return (double)f < x ? nextafterf(f, INFINITY) : f;
}

/* The distance from `c` to the far side of the farthest sphere of the list: the radius a sphere
 * centred at `c` needs to contain them all. */
static double enclosing_radius(const gdr_vec4 *s, size_t n, const double c[3], size_t *farthest)
{
    double radius = 0.0;
    for (size_t i = 0; i < n; i++) {
        double dx = (double)s[i].x - c[0], dy = (double)s[i].y - c[1], dz = (double)s[i].z - c[2];
        double d = sqrt(dx * dx + dy * dy + dz * dz) + s[i].w;
        if (d > radius || i == 0) {
            radius = d;
            *farthest = i;
        }
    }
    return radius;
}

/* Moves `c` towards the point of the list's spheres farthest from it by 1/(k + 2) of the way, for
 * k = 0, 1, ... (Badoiu and Clarkson's iteration for the smallest enclosing ball, taken over the
 * spheres' far points), and keeps the centre that needed the smallest radius. The box centre it
 * starts from can need up to sqrt(3) times the smallest radius, and a group's sphere encloses those
 * of the groups below it, so the slack compounded over the DAG's depths. */
#define LOD_SPHERE_ITERATIONS 48

static void shrink_enclosing_centre(const gdr_vec4 *s, size_t n, double best[3])
{
    size_t far = 0;
    double c[3] = {best[0], best[1], best[2]};
    double best_radius = enclosing_radius(s, n, c, &far);
    for (int k = 0; k < LOD_SPHERE_ITERATIONS; k++) {
        const double centre[3] = {s[far].x, s[far].y, s[far].z}, radius = s[far].w;
        double d[3] = {centre[0] - c[0], centre[1] - c[1], centre[2] - c[2]};
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (len == 0.0) /* c is that sphere's centre: any point of its surface is as far */
            d[0] = len = 1.0;
        double step = 1.0 / (k + 2);
        for (int a = 0; a < 3; a++)
            c[a] += (centre[a] + radius * d[a] / len - c[a]) * step;
        double r = enclosing_radius(s, n, c, &far);
        if (r < best_radius) {
            best_radius = r;
            memcpy(best, c, sizeof c);
        }
    }
}

/* A sphere containing every sphere of the list, in double, rounded up, with a relative slack of
 * 1e-6 so that containment survives float evaluation of the distances. Its centre is the best
 * found from the box centre (above); whatever the centre, the radius is the exact one it needs. */
gdr_vec4 gdr_lod_enclosing_sphere(const gdr_vec4 *s, size_t n)
{
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (size_t i = 0; i < n; i++) {
        const double c[3] = {s[i].x, s[i].y, s[i].z}, r = s[i].w;
        for (int k = 0; k < 3; k++) {
            lo[k] = c[k] - r < lo[k] ? c[k] - r : lo[k];
            hi[k] = c[k] + r > hi[k] ? c[k] + r : hi[k];
        }
    }
    double box[3] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
    if (n > 1)
        shrink_enclosing_centre(s, n, box);
    double centre[3] = {(float)box[0], (float)box[1], (float)box[2]};
    size_t far = 0;
    double radius = n ? enclosing_radius(s, n, centre, &far) : 0.0;
    return (gdr_vec4){(float)centre[0], (float)centre[1], (float)centre[2], round_up_to_float(radius * (1.0 + 1e-6))};
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static int contains_u64(const uint64_t *sorted, size_t n, uint64_t key)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (sorted[mid] < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < n && sorted[lo] == key;
}

/* The sphere of a group over `members` (count clusters) and the spheres of the groups they came
 * from, into r. Read once the spheres of the earlier steps are set. */
void gdr_lod_group_sphere(lod_build *b, lod_scratch *s, const uint32_t *members, uint32_t count, group_result *r)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < count; i++) {
        const gdr_cluster *c = &b->clusters[members[i]];
        s->spheres[n++] = c->sphere;
        if (c->refined_group != GDR_NO_INDEX)
            s->spheres[n++] = b->groups[c->refined_group].sphere;
    }
    r->sphere = gdr_lod_enclosing_sphere(s->spheres, n);
}

/* Every border edge of the input (an edge between two locked positions that no other input
 * triangle runs the other way) must still be there: else the group would no longer meet its
 * neighbours exactly. (A locked vertex may lose all its triangles, when they only touched other
 * groups at that point: that leaves no gap.) */
static int border_kept(lod_build *b, lod_scratch *s, size_t in_count, size_t out_count)
{
    size_t na = 0, nb = 0;
    for (int pass = 0; pass < 2; pass++) {
        const unsigned int *idx = pass ? s->simplified : s->indices;
        size_t count = pass ? out_count : in_count;
        uint64_t *keys = pass ? s->edges_out : s->edges_in;
        size_t k = 0;
        for (size_t i = 0; i < count; i++) {
            unsigned int a = idx[i], e = idx[i - i % 3 + (i % 3 + 1) % 3];
            if (s->locked[a] && s->locked[e])
                keys[k++] = (uint64_t)b->position_id[s->local_to_mesh[a]] << 32 |
                            b->position_id[s->local_to_mesh[e]];
        }
        qsort(keys, k, sizeof *keys, compare_u64);
        *(pass ? &nb : &na) = k;
    }
    for (size_t i = 0; i < na; i++) {
        uint64_t reverse = s->edges_in[i] << 32 | s->edges_in[i] >> 32;
        if ((uint32_t)s->edges_in[i] == (uint32_t)(s->edges_in[i] >> 32))
            continue;
        if (!contains_u64(s->edges_in, na, reverse) && !contains_u64(s->edges_out, nb, s->edges_in[i]))
            return 0;
    }
    return 1;
}

/* Splits the simplified triangles into clusters (meshoptimizer), written to r. */
static int split_into_clusters(lod_build *b, lod_scratch *s, size_t index_count, uint32_t local_count,
                               group_result *r)
{
    const uint32_t max_v = GDR_CLUSTER_MAX_VERTICES, max_t = GDR_CLUSTER_MAX_TRIANGLES;
    size_t bound = meshopt_buildMeshletsBound(index_count, max_v, max_t);
    if (!LOD_RESERVE(s, meshlets, bound) || !LOD_RESERVE(s, meshlet_vertices, bound * max_v) ||
        !LOD_RESERVE(s, meshlet_triangles, bound * max_t * 3))
        return 0;
    size_t count = meshopt_buildMeshlets(s->meshlets, s->meshlet_vertices, s->meshlet_triangles, s->simplified,
                                         index_count, s->positions, local_count, sizeof(float) * 3, max_v, max_t,
                                         LOD_CONE_WEIGHT);
    size_t vertex_total = 0, triangle_bytes = 0;
    for (size_t i = 0; i < count; i++) {
        vertex_total += s->meshlets[i].vertex_count;
        triangle_bytes += gdr_lod_align4((size_t)s->meshlets[i].triangle_count * 3);
    }
    r->clusters = malloc(count * sizeof *r->clusters);
    r->vertices = malloc(vertex_total * sizeof *r->vertices);
    r->triangles = calloc(triangle_bytes, 1);
    if (!r->clusters || !r->vertices || !r->triangles)
        return 0;
    size_t vo = 0, to = 0;
    for (size_t i = 0; i < count; i++) {
        const struct meshopt_Meshlet *m = &s->meshlets[i];
        gdr_cluster *c = &r->clusters[i];
        *c = (gdr_cluster){.vertex_offset = (uint32_t)vo, .triangle_offset = (uint32_t)to,
                           .vertex_count = m->vertex_count, .triangle_count = m->triangle_count,
                           .group = GDR_NO_INDEX, .refined_group = GDR_NO_INDEX};
        for (uint32_t k = 0; k < m->vertex_count; k++)
            r->vertices[vo + k] = s->local_to_mesh[s->meshlet_vertices[m->vertex_offset + k]];
        memcpy(r->triangles + to, s->meshlet_triangles + m->triangle_offset, (size_t)m->triangle_count * 3);
        gdr_cluster_compute_bounds(c, r->vertices + vo, r->triangles + to, b->mesh);
        vo += m->vertex_count;
        to += gdr_lod_align4((size_t)m->triangle_count * 3);
    }
    r->cluster_count = (uint32_t)count;
    r->vertex_count = (uint32_t)vo;
    r->triangle_bytes = (uint32_t)to;
    return 1;
}

/* The members' triangles over a compact local vertex list, numbered in the order the members'
 * triangles first use them: fills s->local_to_mesh and s->map (mesh vertex -> local; the caller
 * clears it), and s->indices when `indices` is set. Returns the local vertex count. */
static uint32_t merge_members(lod_build *b, lod_scratch *s, const uint32_t *members, uint32_t count, int indices)
{
    uint32_t local_count = 0;
    size_t k = 0;
    for (uint32_t i = 0; i < count; i++) {
        const gdr_cluster *c = &b->clusters[members[i]];
        const uint8_t *t = gdr_lod_cluster_triangles(b, c);
        const uint32_t *v = gdr_lod_cluster_vertices(b, c);
        for (uint32_t j = 0; j < c->triangle_count * 3; j++) {
            uint32_t mv = v[t[j]];
            if (s->map[mv] == UINT32_MAX) {
                s->map[mv] = local_count;
                s->local_to_mesh[local_count++] = mv;
            }
            if (indices)
                s->indices[k++] = s->map[mv];
        }
    }
    return local_count;
}

/* Reserves the scratch for a group of `triangles` input triangles and `count` members. */
static int reserve_group(lod_scratch *s, size_t triangles, uint32_t count)
{
    size_t index_count = triangles * 3;
    return LOD_RESERVE(s, spheres, (size_t)count * 2) && LOD_RESERVE(s, indices, index_count) &&
           LOD_RESERVE(s, simplified, index_count) && LOD_RESERVE(s, local_to_mesh, index_count) &&
           LOD_RESERVE(s, locked, index_count) && LOD_RESERVE(s, edges_in, index_count) &&
           LOD_RESERVE(s, edges_out, index_count) && LOD_RESERVE(s, positions, index_count * 9) &&
           LOD_RESERVE(s, vertex_position, index_count) && LOD_RESERVE(s, local_positions, index_count * 3) &&
           LOD_RESERVE(s, position_locked, index_count);
}

/* Local positions of the merged group: each local vertex's position (its welded position id's
 * representative coordinates: near-equal positions are one) and which are shared with another group
 * of the step (locked); fills s->positions per local vertex for the meshlet builder. Returns the
 * local position count. */
static uint32_t local_positions(lod_build *b, lod_scratch *s, uint32_t local_count)
{
    const gdr_vec3 *mesh_positions = b->mesh->positions;
    uint32_t count = 0;
    for (uint32_t l = 0; l < local_count; l++) {
        uint32_t mv = s->local_to_mesh[l], id = b->position_id[mv];
        s->map[mv] = UINT32_MAX;
        const gdr_vec3 p = mesh_positions[b->sample_vertex[id]];
        memcpy(s->positions + (size_t)l * 3, &p, sizeof p);
        s->locked[l] = b->owner[id] == OWNER_SHARED;
        if (s->position_map[id] == UINT32_MAX) {
            s->position_map[id] = count;
            memcpy(s->local_positions + (size_t)count * 3, &p, sizeof p);
            s->position_locked[count++] = s->locked[l];
        }
        s->vertex_position[l] = s->position_map[id];
    }
    for (uint32_t l = 0; l < local_count; l++)
        s->position_map[b->position_id[s->local_to_mesh[l]]] = UINT32_MAX;
    return count;
}

/* meshoptimizer 0.18's simplifier over the local vertices' positions, each shared position locked by
 * two unused copies of it appended (0.18 never moves a position held by three or more vertices):
 * the fallback where the collapses over positions stop short of the 85% a group needs and the group
 * is the whole frontier (a lone cluster of a genus-1 mesh, where the flip and turn checks refuse what
 * 0.18 does). Seam vertices then slide only along their seams, as before the seam-crossing
 * simplifier. Returns the index
 * count, 0 where it failed. */
static size_t simplify_by_meshoptimizer(lod_scratch *s, size_t index_count, uint32_t local_count, size_t target)
{
    uint32_t padded = local_count;
    for (uint32_t l = 0; l < local_count; l++)
        if (s->locked[l])
            for (int copy = 0; copy < 2; copy++, padded++)
                memcpy(s->positions + (size_t)padded * 3, s->positions + (size_t)l * 3, sizeof(float) * 3);
    float relative_error = 0.0f;
    size_t count = meshopt_simplify(s->simplified, s->indices, index_count, s->positions, padded, sizeof(float) * 3,
                                    target, FLT_MAX, 0, &relative_error);
    for (size_t i = 0; i < count; i++)
        if (s->simplified[i] >= local_count)
            return 0;
    return count;
}

void gdr_lod_simplify_group_task(void *user, uint32_t g, uint32_t worker)
{
    lod_build *b = user;
    lod_scratch *s = &b->scratch[worker];
    group_result *r = &b->results[g];
    uint32_t first = b->member_start[g], count = b->member_start[g + 1] - first;

    size_t triangles = 0;
    for (uint32_t i = 0; i < count; i++)
        triangles += b->clusters[b->members[first + i]].triangle_count;
    r->input_triangles = (uint32_t)triangles;
    size_t index_count = triangles * 3;
    if (!reserve_group(s, triangles, count)) {
        r->out_of_memory = 1;
        return;
    }
    uint32_t local_count = merge_members(b, s, b->members + first, count, 1);
    uint32_t position_count = local_positions(b, s, local_count);

    size_t target = (size_t)((double)triangles * b->opt.target_ratio) * 3;
    target = target < 3 ? 3 : target;
    lod_simplify_input in = {.indices = s->indices, .index_count = index_count, .vertex_count = local_count,
                             .vertex_position = s->vertex_position, .vertex_source = s->local_to_mesh,
                             .uvs = b->opt.ignore_uvs ? NULL : b->mesh->uvs, .normals = b->mesh->normals, .position_count = position_count,
                             .positions = s->local_positions, .locked = s->position_locked,
                             .target_index_count = target, .texture = b->texture,
                             .normal_weight = (count == 1 && b->frontier_count == 1) || !b->opt.ignore_uvs
                                                ? LOD_LOW_NORMAL_WEIGHT : 0.0};
    lod_simplify_result out = {0};
    if (b->sloppy) /* a step that formed no group, again as one whole-frontier group (lod_sloppy.c) */
        out.index_count = gdr_lod_simplify_sloppy(s, index_count, local_count);
    else if (!lod_simplify(&s->simplify, &in, s->simplified, &out)) {
        r->out_of_memory = 1;
        return;
    }
    size_t out_count = out.index_count;
    r->slide = out.slide;
    int enough = out_count > 0 && (double)out_count <= (double)index_count * LOD_MAX_KEPT_SHARE;
    if (!enough && count == b->frontier_count) { /* the whole frontier: no neighbour to meet */
        out_count = simplify_by_meshoptimizer(s, index_count, local_count, target);
        r->slide = 0.0f;
        enough = out_count > 0 && (double)out_count <= (double)index_count * LOD_MAX_KEPT_SHARE;
    }
    if (enough && !border_kept(b, s, index_count, out_count)) {
        r->border_reject = 1;
        enough = 0;
    }
    gdr_lod_progress_add(b, triangles / 2, worker);
    if (!enough)
        return;
    if (!split_into_clusters(b, s, out_count, local_count, r)) {
        r->out_of_memory = 1;
        return;
    }
    r->formed = 1;
}

/* Puts back into the scratch what simplifying group g left there and measuring its deviation
 * reads: the local vertex numbering and positions, and its new clusters (taken into b by now, from
 * r->first_cluster on) as meshlets over local vertices. Returns the local vertex count, 0 when out
 * of memory. */
static uint32_t restore_group(lod_build *b, lod_scratch *s, const uint32_t *members, uint32_t count,
                              const group_result *r)
{
    size_t vertices = 0, bytes = 0;
    for (uint32_t i = 0; i < r->cluster_count; i++) {
        vertices += b->clusters[r->first_cluster + i].vertex_count;
        bytes += (size_t)b->clusters[r->first_cluster + i].triangle_count * 3;
    }
    size_t index_count = (size_t)r->input_triangles * 3; /* bounds the local vertex count */
    if (!LOD_RESERVE(s, local_to_mesh, index_count) || !LOD_RESERVE(s, positions, index_count * 3) ||
        !LOD_RESERVE(s, meshlets, r->cluster_count) || !LOD_RESERVE(s, meshlet_vertices, vertices) ||
        !LOD_RESERVE(s, meshlet_triangles, bytes))
        return 0;
    uint32_t local_count = merge_members(b, s, members, count, 0);
    size_t vo = 0, to = 0;
    for (uint32_t i = 0; i < r->cluster_count; i++) {
        const gdr_cluster *c = &b->clusters[r->first_cluster + i];
        const uint32_t *v = gdr_lod_cluster_vertices(b, c);
        s->meshlets[i] = (struct meshopt_Meshlet){.vertex_offset = (unsigned int)vo,
                                                  .triangle_offset = (unsigned int)to,
                                                  .vertex_count = c->vertex_count,
                                                  .triangle_count = c->triangle_count};
        for (uint32_t k = 0; k < c->vertex_count; k++)
            s->meshlet_vertices[vo + k] = s->map[v[k]];
        memcpy(s->meshlet_triangles + to, gdr_lod_cluster_triangles(b, c), (size_t)c->triangle_count * 3);
        vo += c->vertex_count;
        to += (size_t)c->triangle_count * 3;
    }
    for (uint32_t l = 0; l < local_count; l++) {
        uint32_t mv = s->local_to_mesh[l];
        s->map[mv] = UINT32_MAX;
        memcpy(s->positions + (size_t)l * 3, &b->mesh->positions[mv], sizeof(gdr_vec3));
    }
    return local_count;
}

/* The largest error of the groups the members came from (set once the steps before had all their
 * deviations measured, before this job). */
static float members_error(const lod_build *b, const uint32_t *members, uint32_t count)
{
    float error = 0.0f;
    for (uint32_t i = 0; i < count; i++) {
        uint32_t from = b->clusters[members[i]].refined_group;
        if (from != GDR_NO_INDEX && b->groups[from].error > error)
            error = b->groups[from].error;
    }
    return error;
}

void gdr_lod_measure_group_task(void *user, uint32_t i, uint32_t worker)
{
    lod_build *b = user;
    lod_scratch *s = &b->scratch[worker];
    uint32_t g = b->measured[i];
    group_result *r = &b->measured_results[g];
    const uint32_t *members = b->measured_members + b->measured_member_start[g];
    uint32_t count = b->measured_member_start[g + 1] - b->measured_member_start[g];
    uint32_t local_count = restore_group(b, s, members, count, r);
    r->error = members_error(b, members, count); /* the deviation's floor starts from it */
    if (!local_count || !gdr_lod_group_deviation(b, s, members, count, local_count, r))
        r->out_of_memory = 1;
}

void gdr_lod_result_free(group_result *r)
{
    free(r->clusters);
    free(r->vertices);
    free(r->triangles);
    free(r->samples);
    free(r->cluster_sample_first);
    free(r->excess);
    free(r->excess_distance);
    free(r->kept);
    memset(r, 0, sizeof *r);
}

void gdr_lod_scratch_free(lod_scratch *s)
{
    free(s->map);
    free(s->local_to_mesh);
    free(s->locked);
    free(s->positions);
    free(s->vertex_position);
    free(s->position_map);
    free(s->local_positions);
    free(s->position_locked);
    lod_simplify_scratch_free(&s->simplify);
    free(s->indices);
    free(s->simplified);
    free(s->edges_in);
    free(s->edges_out);
    free(s->spheres);
    free(s->meshlets);
    free(s->meshlet_vertices);
    free(s->meshlet_triangles);
    free(s->out_corners);
    free(s->out_cluster);
    free(s->ring_start);
    free(s->ring);
    free(s->sample_ids);
    free(s->sample_cluster);
    free(s->vertex_local);
    free(s->sample_points);
    free(s->vertex_points);
    lod_grid_free(&s->grid);
    lod_triangle_grid_free(&s->triangle_grid);
    lod_triangle_grid_free(&s->region_grid);
    free(s->region_refs);
    free(s->region_corners);
    lod_triangle_grid_free(&s->span_grid);
    free(s->span_refs);
    free(s->span_positions);
    free(s->span_corners);
    free(s->coarse_d2);
    free(s->edge_d2);
    free(s->range_kept);
}
