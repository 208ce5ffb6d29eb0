/* Level-0 clusters (meshlets) of a mesh, built with meshoptimizer, and the scene-level build that
 * runs it over every mesh in parallel. See docs/GEOMETRY.md for the format and the limits. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>

#include "gdr/thread_pool.h"
#include "geometry/cluster_bounds.h"
#include "geometry/meshlet_chunks.h"
#include "geometry/meshlet_split.h"
#include "geometry/vertex_weld.h"
#include "gdr/geometry.h"
#include "gdr/scene.h"

#define DEFAULT_CONE_WEIGHT 0.25f

_Static_assert(sizeof(gdr_cluster) == 72, "gdr_cluster is serialised field by field; keep it packed");
_Static_assert(GDR_CLUSTER_MAX_VERTICES <= 255 && GDR_CLUSTER_MAX_TRIANGLES <= 512,
               "meshoptimizer's meshlet limits (and uint8 local indices)");
_Static_assert(GDR_CLUSTER_MAX_TRIANGLES % 4 == 0, "meshoptimizer needs a multiple of 4");

/* --- options and input checks ------------------------------------------------------------- */

/* The options with every default applied, or an error naming the bad field. */
static gdr_status resolve_options(const gdr_meshlet_options *in, gdr_meshlet_options *out, gdr_error *err)
{
    gdr_meshlet_options o = in ? *in : (gdr_meshlet_options){0};
    if (o.max_vertices == 0)
        o.max_vertices = GDR_CLUSTER_MAX_VERTICES;
    if (o.max_triangles == 0)
        o.max_triangles = GDR_CLUSTER_MAX_TRIANGLES;
    if (o.cone_weight == 0.0f)
        o.cone_weight = DEFAULT_CONE_WEIGHT;
    if (o.max_vertices < 3 || o.max_vertices > GDR_CLUSTER_MAX_VERTICES)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "meshlet options: max_vertices %u is outside [3, %u]", o.max_vertices, GDR_CLUSTER_MAX_VERTICES);
    if (o.max_triangles < 4 || o.max_triangles > GDR_CLUSTER_MAX_TRIANGLES || o.max_triangles % 4 != 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "meshlet options: max_triangles %u is not a multiple of 4 in [4, %u]", o.max_triangles, GDR_CLUSTER_MAX_TRIANGLES);
    if (!(o.cone_weight > 0.0f && o.cone_weight <= 1.0f))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "meshlet options: cone_weight %g is outside (0, 1]", (double)o.cone_weight);
    if (o.thread_count > GDR_THREAD_POOL_MAX_THREADS)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "meshlet options: thread_count %u exceeds %u", o.thread_count,
                             GDR_THREAD_POOL_MAX_THREADS);
    *out = o;
    return GDR_OK;
}

/* meshoptimizer asserts its contract (or reads out of bounds without asserts): check it first. */
static gdr_status check_mesh(const gdr_mesh *mesh, gdr_error *err)
{
    if (mesh->index_count == 0 || mesh->index_count % 3 != 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "mesh '%s': %u indices: meshlets need a non-empty triangle list", mesh->name,
                             mesh->index_count);
    if (mesh->vertex_count == 0 || !mesh->positions || !mesh->indices)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': no vertex positions or indices",
                             mesh->name);
    for (uint32_t i = 0; i < mesh->index_count; i++)
        if (mesh->indices[i] >= mesh->vertex_count)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                 "mesh '%s': index %u (at %u) is out of range (vertex count %u)", mesh->name,
                                 mesh->indices[i], i, mesh->vertex_count);
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const gdr_vec3 p = mesh->positions[v];
        /* meshoptimizer's own asserts fire on coordinates near sqrt(FLT_MAX) */
        if (!(fabsf(p.x) <= GDR_MAX_COORDINATE) || !(fabsf(p.y) <= GDR_MAX_COORDINATE) ||
            !(fabsf(p.z) <= GDR_MAX_COORDINATE))
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                 "mesh '%s': position %u is not finite or beyond the %g limit on coordinates",
                                 mesh->name, v, GDR_MAX_COORDINATE);
    }
    return GDR_OK;
}

/* --- bounds ------------------------------------------------------------------------------- */

/* The smallest float >= x. */
static float round_up_to_float(double x)
{
    float f = (float)x;
    return (double)f < x ? nextafterf(f, INFINITY) : f;
}

static void set_no_cone(gdr_cluster *c)
{
    c->cone_apex = (gdr_vec3){c->sphere.x, c->sphere.y, c->sphere.z};
    c->cone_axis = (gdr_vec3){0.0f, 0.0f, 0.0f};
    c->cone_cutoff = 1.0f;
}

/* meshoptimizer fits the cone in float, from float edge vectors: for a sliver (the triangles at
 * the pole of a UV sphere, whose corners differ by 1e-8) the rounding of the edges is as large
 * as the triangle and its normal comes out wrong; far from the origin (positions of 1e4) the
 * apex is rounded by 1e-3, which a camera near the surface sees as a wrong cull. The cone is
 * checked in double, from the exact float positions, and made conservative: the cutoff from the
 * widest triangle normal, the apex pushed back along the axis until, rounded to float, it lies
 * behind every triangle's plane. Then, for any p with dot(normalize(apex - p), axis) >= cutoff,
 * every triangle is back-facing or edge-on from p in exact arithmetic on the stored floats. */
static void make_cone_conservative(gdr_cluster *c, const uint32_t *vertices, const uint8_t *triangles,
                                   const gdr_mesh *mesh)
{
    double axis[3] = {c->cone_axis.x, c->cone_axis.y, c->cone_axis.z};
    double axis_length = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    double normals[GDR_CLUSTER_MAX_TRIANGLES][3], corners[GDR_CLUSTER_MAX_TRIANGLES][3];
    uint32_t count = 0;
    double min_dot = 1.0;
    for (uint32_t t = 0; t < c->triangle_count; t++) {
        double v[3][3];
        for (int k = 0; k < 3; k++) {
            const gdr_vec3 q = mesh->positions[vertices[triangles[3 * t + k]]];
            v[k][0] = q.x, v[k][1] = q.y, v[k][2] = q.z;
        }
        double e1[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
        double e2[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        double length = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (length == 0.0)
            continue; /* exactly degenerate: never drawn */
        double dot = 0.0;
        for (int k = 0; k < 3; k++) {
            normals[count][k] = n[k] / length;
            corners[count][k] = v[0][k];
            dot += normals[count][k] * axis[k] / axis_length;
        }
        min_dot = dot < min_dot ? dot : min_dot;
        count++;
    }
    /* meshoptimizer's limit: a cone wider than ~168 degrees culls too little to be worth it. */
    if (count == 0 || !(min_dot > 0.1)) {
        set_no_cone(c);
        return;
    }
    double apex[3] = {c->cone_apex.x, c->cone_apex.y, c->cone_apex.z}, back = 0.0;
    for (uint32_t i = 0; i < count; i++) {
        double ahead = 0.0, along = 0.0;
        for (int k = 0; k < 3; k++) {
            ahead += (apex[k] - corners[i][k]) * normals[i][k];
            along += axis[k] * normals[i][k];
        }
        if (ahead > 0.0 && ahead / along > back)
            back = ahead / along;
    }
    double extra = 0.0;
    for (int attempt = 0; attempt < 16; attempt++) {
        float rounded[3];
        double magnitude = 0.0;
        for (int k = 0; k < 3; k++) {
            rounded[k] = (float)(apex[k] - axis[k] * (back + extra));
            magnitude = fabs(rounded[k]) > magnitude ? fabs(rounded[k]) : magnitude;
        }
        int behind = 1;
        for (uint32_t i = 0; i < count && behind; i++) {
            double ahead = 0.0;
            for (int k = 0; k < 3; k++)
                ahead += ((double)rounded[k] - corners[i][k]) * normals[i][k];
            behind = ahead <= 0.0;
        }
        if (behind) {
            c->cone_apex = (gdr_vec3){rounded[0], rounded[1], rounded[2]};
            /* The test compares with the stored (not quite unit) axis: scale the cutoff by its length. */
            c->cone_cutoff = round_up_to_float(sqrt(1.0 - min_dot * min_dot) * axis_length);
            return;
        }
        /* Rounding moved it in front of a plane: step back a few float spacings more. */
        extra = 2.0 * extra + 4.0 * (magnitude + 1e-30) * FLT_EPSILON / min_dot;
    }
    set_no_cone(c);
}

/* meshopt_computeMeshletBounds, made to hold its contract for every cluster:
 *  - its sphere is fitted to the corners of triangles of non-zero area only and can miss the
 *    others' corners, or by rounding any corner by an ulp: the radius is grown to reach every
 *    vertex of the cluster, computed in double and rounded up;
 *  - a cluster without a triangle of non-zero area comes back with a zero sphere and a zero
 *    cone (cutoff 0: "always culled" in the apex test); such a cluster draws nothing, but we
 *    give it a real sphere and no cone rather than rely on that;
 *  - "no useful cone" (a normal cone wider than ~168 degrees) is cutoff 1 with a zero axis: the
 *    dot product in the test is then exactly 0, so no rounding can ever cull it;
 *  - the cone is made conservative in double (make_cone_conservative). */
static void cluster_bounds(gdr_cluster *c, const uint32_t *vertices, const uint8_t *triangles, const gdr_mesh *mesh)
{
    struct meshopt_Bounds b = meshopt_computeMeshletBounds(vertices, triangles, c->triangle_count,
                                                           &mesh->positions[0].x, mesh->vertex_count,
                                                           sizeof(gdr_vec3));
    int has_area = b.radius > 0.0f || b.cone_cutoff != 0.0f || b.cone_axis[0] != 0.0f ||
                   b.cone_axis[1] != 0.0f || b.cone_axis[2] != 0.0f;
    /* The centre as stored (float), so that the radius is measured from exactly the stored point.
     * (Kept in doubles rounded through float, gcc 12 -O3's basic-block vectorizer measured from the
     * unrounded x and y and stored the rounded ones: radii short by an ulp or two.) */
    float center[3] = {b.center[0], b.center[1], b.center[2]};
    if (!has_area) {
        /* The middle of the vertices' bounding box. */
        double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
        for (uint32_t i = 0; i < c->vertex_count; i++) {
            const float *p = &mesh->positions[vertices[i]].x;
            for (int k = 0; k < 3; k++) {
                lo[k] = p[k] < lo[k] ? p[k] : lo[k];
                hi[k] = p[k] > hi[k] ? p[k] : hi[k];
            }
        }
        for (int k = 0; k < 3; k++)
            center[k] = (float)(0.5 * (lo[k] + hi[k]));
    }
    double radius = has_area ? b.radius : 0.0;
    for (uint32_t i = 0; i < c->vertex_count; i++) {
        const gdr_vec3 p = mesh->positions[vertices[i]];
        double dx = (double)p.x - center[0], dy = (double)p.y - center[1], dz = (double)p.z - center[2];
        double d = sqrt(dx * dx + dy * dy + dz * dz);
        radius = d > radius ? d : radius;
    }
    c->sphere = (gdr_vec4){center[0], center[1], center[2], round_up_to_float(radius)};
    if (has_area && b.cone_cutoff < 1.0f) {
        c->cone_apex = (gdr_vec3){b.cone_apex[0], b.cone_apex[1], b.cone_apex[2]};
        c->cone_axis = (gdr_vec3){b.cone_axis[0], b.cone_axis[1], b.cone_axis[2]};
        c->cone_cutoff = b.cone_cutoff;
        make_cone_conservative(c, vertices, triangles, mesh);
    } else {
        set_no_cone(c);
    }
}

/* The same bounds for the clusters of the LOD DAG (lod_group.c). */
void gdr_cluster_compute_bounds(gdr_cluster *c, const uint32_t *vertices, const uint8_t *triangles,
                                const gdr_mesh *mesh)
{
    cluster_bounds(c, vertices, triangles, mesh);
}

/* --- one mesh ----------------------------------------------------------------------------- */

/* Meshes are split into chunks of this many triangles, built independently (in parallel when
 * asked) and concatenated in order: a fixed size, so the clusters do not depend on the thread
 * count. Each chunk ends with at most one partly filled cluster. */
#define MESHLET_CHUNK_TRIANGLES 32768u

/* The clusters of one chunk: offsets relative to its own arrays, vertices as mesh indices. */
typedef struct chunk_result {
    gdr_cluster *clusters;
    uint32_t cluster_count;
    uint32_t *vertices;
    uint32_t vertex_count;
    uint8_t *triangles;
    uint32_t triangle_bytes;
    gdr_status status;
} chunk_result;

typedef struct chunk_job {
    const gdr_mesh *mesh;
    const gdr_meshlet_options *o;
    uint32_t chunk_triangles; /* MESHLET_CHUNK_TRIANGLES, or fewer for a hostile mesh */
    chunk_result *results;
    uint32_t **maps; /* per worker: mesh vertex -> chunk-local vertex (UINT32_MAX: unused) */
} chunk_job;

/* meshoptimizer's meshlets of indices[0 .. index_count) over `positions` (vertex_count), into r;
 * local_to_mesh (NULL: the identity) turns their vertices into mesh indices. */
static gdr_status meshlets_of(const gdr_mesh *mesh, const gdr_meshlet_options *o, const uint32_t *indices,
                              size_t index_count, const float *positions, size_t vertex_count,
                              const uint32_t *local_to_mesh, chunk_result *r)
{
    size_t bound = meshopt_buildMeshletsBound(index_count, o->max_vertices, o->max_triangles);
    struct meshopt_Meshlet *meshlets = malloc(bound * sizeof *meshlets);
    r->vertices = malloc(bound * o->max_vertices * sizeof *r->vertices);
    r->triangles = malloc(bound * o->max_triangles * 3);
    size_t count = 0;
    if (meshlets && r->vertices && r->triangles)
        count = meshopt_buildMeshlets(meshlets, r->vertices, r->triangles, indices, index_count, positions,
                                      vertex_count, sizeof(float) * 3, o->max_vertices, o->max_triangles,
                                      o->cone_weight);
    /* Meshlets that jumped to a far triangle are cut at the jump (meshlet_split.c). */
    meshlet_arrays split = {meshlets, count, r->vertices, r->triangles};
    int split_failed = count > 0 && gdr_meshlets_split_far_parts(&split, positions) != 0;
    meshlets = split.meshlets, count = split.count, r->vertices = split.vertices, r->triangles = split.triangles;
    r->clusters = count > 0 && !split_failed ? malloc(count * sizeof *r->clusters) : NULL;
    if (!r->clusters) {
        free(meshlets);
        return meshlets && r->vertices && r->triangles && count == 0 ? GDR_ERROR_INVALID_ARGUMENT
                                                                     : GDR_ERROR_OUT_OF_MEMORY;
    }
    const struct meshopt_Meshlet *last = &meshlets[count - 1];
    r->vertex_count = last->vertex_offset + last->vertex_count;
    r->triangle_bytes = last->triangle_offset + (last->triangle_count * 3 + 3) / 4 * 4;
    r->cluster_count = (uint32_t)count;
    /* meshoptimizer wanted room for the worst case: keep only what was used. */
    uint32_t *vertices = realloc(r->vertices, (size_t)r->vertex_count * sizeof *vertices);
    uint8_t *triangles = realloc(r->triangles, r->triangle_bytes);
    r->vertices = vertices ? vertices : r->vertices;
    r->triangles = triangles ? triangles : r->triangles;
    if (local_to_mesh)
        for (uint32_t i = 0; i < r->vertex_count; i++)
            r->vertices[i] = local_to_mesh[r->vertices[i]];
    for (size_t i = 0; i < count; i++) {
        const struct meshopt_Meshlet *m = &meshlets[i];
        gdr_cluster *cl = &r->clusters[i];
        *cl = (gdr_cluster){.vertex_offset = m->vertex_offset, .triangle_offset = m->triangle_offset,
                            .vertex_count = m->vertex_count, .triangle_count = m->triangle_count,
                            .group = GDR_NO_INDEX, .refined_group = GDR_NO_INDEX};
        /* Zero the padding: the output must not depend on what malloc returned. */
        size_t used = (size_t)m->triangle_offset + (size_t)m->triangle_count * 3;
        size_t end = i + 1 < count ? meshlets[i + 1].triangle_offset : r->triangle_bytes;
        memset(r->triangles + used, 0, end - used);
        cluster_bounds(cl, r->vertices + m->vertex_offset, r->triangles + m->triangle_offset, mesh);
    }
    free(meshlets);
    return GDR_OK;
}

/* Chunk c over a compact local vertex list (meshoptimizer's cost grows with the vertex count it
 * is given, so a chunk must not pass the whole mesh's). */
static void chunk_task(void *user, uint32_t c, uint32_t worker)
{
    chunk_job *job = user;
    const gdr_mesh *mesh = job->mesh;
    size_t first = (size_t)c * job->chunk_triangles * 3, n = mesh->index_count - first;
    n = n > (size_t)job->chunk_triangles * 3 ? (size_t)job->chunk_triangles * 3 : n;
    uint32_t *map = job->maps[worker], count = 0;
    uint32_t *local = malloc(n * sizeof *local), *local_to_mesh = NULL;
    float *positions = NULL;
    job->results[c].status = GDR_ERROR_OUT_OF_MEMORY;
    if (!local)
        return;
    for (size_t i = 0; i < n; i++) {
        uint32_t v = mesh->indices[first + i];
        if (map[v] == UINT32_MAX)
            map[v] = count++;
        local[i] = map[v];
    }
    local_to_mesh = malloc((size_t)count * sizeof *local_to_mesh);
    positions = malloc((size_t)count * 3 * sizeof *positions);
    for (size_t i = 0; i < n; i++) {
        uint32_t v = mesh->indices[first + i];
        map[v] = UINT32_MAX;
        if (local_to_mesh && positions) {
            local_to_mesh[local[i]] = v;
            memcpy(positions + (size_t)local[i] * 3, &mesh->positions[v], sizeof(float) * 3);
        }
    }
    if (local_to_mesh && positions)
        job->results[c].status = meshlets_of(mesh, job->o, local, n, positions, count, local_to_mesh,
                                             &job->results[c]);
    free(local);
    free(local_to_mesh);
    free(positions);
}

/* The chunks' clusters, concatenated in order, into out. */
static gdr_status concatenate(const chunk_result *r, uint32_t chunks, gdr_mesh_clusters *out)
{
    size_t clusters = 0, vertices = 0, bytes = 0;
    for (uint32_t c = 0; c < chunks; c++) {
        clusters += r[c].cluster_count;
        vertices += r[c].vertex_count;
        bytes += r[c].triangle_bytes;
    }
    if (clusters > UINT32_MAX || vertices > UINT32_MAX || bytes > UINT32_MAX)
        return GDR_ERROR_OUT_OF_MEMORY;
    gdr_mesh_clusters m = {.cluster_count = (uint32_t)clusters, .level0_cluster_count = (uint32_t)clusters,
                           .vertex_count = (uint32_t)vertices, .triangle_byte_count = (uint32_t)bytes};
    m.clusters = malloc(clusters * sizeof *m.clusters);
    m.vertices = malloc(vertices * sizeof *m.vertices);
    m.triangles = malloc(bytes);
    if (!m.clusters || !m.vertices || !m.triangles) {
        gdr_mesh_clusters_free(&m);
        return GDR_ERROR_OUT_OF_MEMORY;
    }
    size_t k = 0, vo = 0, to = 0;
    for (uint32_t c = 0; c < chunks; c++) {
        for (uint32_t i = 0; i < r[c].cluster_count; i++, k++) {
            m.clusters[k] = r[c].clusters[i];
            m.clusters[k].vertex_offset += (uint32_t)vo;
            m.clusters[k].triangle_offset += (uint32_t)to;
        }
        memcpy(m.vertices + vo, r[c].vertices, (size_t)r[c].vertex_count * sizeof *m.vertices);
        memcpy(m.triangles + to, r[c].triangles, r[c].triangle_bytes);
        vo += r[c].vertex_count;
        to += r[c].triangle_bytes;
    }
    *out = m;
    return GDR_OK;
}

/* Builds the chunks (with a pool when thread_count asks for one) and concatenates them. */
static gdr_status build_chunks(const gdr_mesh *mesh, const gdr_meshlet_options *o, uint32_t chunk_triangles,
                               gdr_mesh_clusters *out)
{
    uint32_t chunks = (uint32_t)(((size_t)mesh->index_count / 3 + chunk_triangles - 1) / chunk_triangles);
    gdr_thread_pool *pool = NULL;
    gdr_error ignored;
    if (o->thread_count != 1 && gdr_thread_pool_create(o->thread_count, &pool, &ignored) != GDR_OK)
        pool = NULL; /* one thread then: the result is the same */
    uint32_t workers = gdr_thread_pool_thread_count(pool);
    chunk_job job = {mesh, o, chunk_triangles, calloc(chunks, sizeof(chunk_result)),
                     calloc(workers, sizeof(uint32_t *))};
    gdr_status status = job.results && job.maps ? GDR_OK : GDR_ERROR_OUT_OF_MEMORY;
    for (uint32_t w = 0; w < workers && status == GDR_OK; w++) {
        job.maps[w] = malloc((size_t)mesh->vertex_count * sizeof *job.maps[w]);
        if (!job.maps[w])
            status = GDR_ERROR_OUT_OF_MEMORY;
        else
            memset(job.maps[w], 0xff, (size_t)mesh->vertex_count * sizeof *job.maps[w]);
    }
    if (status == GDR_OK)
        gdr_thread_pool_run(pool, chunks, chunk_task, &job);
    for (uint32_t c = 0; c < chunks && status == GDR_OK; c++)
        status = job.results[c].status;
    if (status == GDR_OK)
        status = concatenate(job.results, chunks, out);
    for (uint32_t c = 0; job.results && c < chunks; c++) {
        free(job.results[c].clusters);
        free(job.results[c].vertices);
        free(job.results[c].triangles);
    }
    for (uint32_t w = 0; job.maps && w < workers; w++)
        free(job.maps[w]);
    free(job.results);
    free(job.maps);
    gdr_thread_pool_destroy(pool);
    return status;
}

gdr_status gdr_meshlets_build(const gdr_mesh *mesh, const gdr_meshlet_options *options, gdr_mesh_clusters *out,
                              gdr_error *err)
{
    /* Programmer errors: a NULL mesh or output, or an output that already holds data. */
    if (!mesh || !out)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "gdr_meshlets_build: mesh and out must not be NULL");
    if (out->clusters || out->vertices || out->triangles || out->groups || out->cluster_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "mesh '%s': gdr_meshlets_build: the output must be zeroed (free it first)", mesh->name);
    gdr_meshlet_options o;
    gdr_status status = resolve_options(options, &o, err);
    if (status == GDR_OK)
        status = check_mesh(mesh, err);
    if (status != GDR_OK)
        return status;
    /* A mesh whose kd-tree of centroids meshoptimizer could not split (meshlet_chunks.h) goes in
     * small chunks, so that no leaf it scans holds more than one chunk; sound meshes as before. */
    uint32_t chunk = gdr_meshlet_needs_chunks(mesh) ? GDR_MESHLET_HOSTILE_CHUNK : MESHLET_CHUNK_TRIANGLES;
    if (mesh->index_count / 3 <= chunk) {
        /* One chunk: straight over the mesh's own vertices. */
        chunk_result r = {0};
        status = meshlets_of(mesh, &o, mesh->indices, mesh->index_count, &mesh->positions[0].x, mesh->vertex_count,
                             NULL, &r);
        if (status == GDR_OK)
            status = concatenate(&r, 1, out);
        free(r.clusters);
        free(r.vertices);
        free(r.triangles);
    } else {
        status = build_chunks(mesh, &o, chunk, out);
    }
    if (status == GDR_ERROR_INVALID_ARGUMENT)
        return gdr_error_set(err, status, "mesh '%s': meshoptimizer made no meshlets", mesh->name);
    if (status != GDR_OK)
        return gdr_error_set(err, status, "mesh '%s': out of memory for meshlets", mesh->name);
    status = gdr_mesh_clusters_build_hierarchy(out, err);
    if (status != GDR_OK) {
        gdr_mesh_clusters_free(out);
        return status;
    }
    return GDR_OK;
}

/* --- vertex order ------------------------------------------------------------------------- */

/* Renumbers the mesh's vertices in the order its clusters first use them (the unused ones last,
 * in their old order), so that a cluster's vertices lie together in memory and a mesh shader
 * fetching them touches few cache lines. Triangles, their order and winding are unchanged.
 * Inside a cluster, meshoptimizer already lists the vertices in the order its triangles first use
 * them; reordering the triangles within a meshlet (meshopt_optimizeMeshlet) came after 0.18.
 * Vertex colours, where the mesh has them, move with their vertices. */
static gdr_status reorder_vertices(gdr_mesh *mesh, gdr_error *err)
{
    gdr_mesh_clusters *c = &mesh->clusters;
    size_t n = mesh->vertex_count, corner_count = 0;
    for (uint32_t i = 0; i < c->level0_cluster_count; i++)
        corner_count += (size_t)c->clusters[i].triangle_count * 3;
    uint32_t *corners = malloc(corner_count * sizeof *corners), *remap = malloc(n * sizeof *remap);
    gdr_vec3 *positions = malloc(n * sizeof *positions), *normals = malloc(n * sizeof *normals);
    gdr_vec2 *uvs = malloc(n * sizeof *uvs);
    gdr_vec4 *colors = mesh->colors ? malloc(n * sizeof *colors) : NULL;
    if (!corners || !remap || !positions || !normals || !uvs || (mesh->colors && !colors)) {
        free(corners);
        free(remap);
        free(positions);
        free(normals);
        free(uvs);
        free(colors);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory reordering vertices",
                             mesh->name);
    }
    /* The index buffer in cluster order: its first-use order is the clusters' vertex order. */
    size_t at = 0;
    for (uint32_t i = 0; i < c->level0_cluster_count; i++) {
        const gdr_cluster *cl = &c->clusters[i];
        for (uint32_t k = 0; k < cl->triangle_count * 3; k++)
            corners[at++] = c->vertices[cl->vertex_offset + c->triangles[cl->triangle_offset + k]];
    }
    size_t next = meshopt_optimizeVertexFetchRemap(remap, corners, corner_count, n);
    for (size_t v = 0; v < n; v++)
        if (remap[v] == UINT32_MAX)
            remap[v] = (uint32_t)next++;
    meshopt_remapVertexBuffer(positions, mesh->positions, n, sizeof *positions, remap);
    meshopt_remapVertexBuffer(normals, mesh->normals, n, sizeof *normals, remap);
    meshopt_remapVertexBuffer(uvs, mesh->uvs, n, sizeof *uvs, remap);
    if (colors)
        meshopt_remapVertexBuffer(colors, mesh->colors, n, sizeof *colors, remap);
    meshopt_remapIndexBuffer(mesh->indices, mesh->indices, mesh->index_count, remap);
    for (uint32_t i = 0; i < c->vertex_count; i++)
        c->vertices[i] = remap[c->vertices[i]];
    free(mesh->positions);
    free(mesh->normals);
    free(mesh->uvs);
    mesh->positions = positions;
    mesh->normals = normals;
    mesh->uvs = uvs;
    if (colors) {
        free(mesh->colors);
        mesh->colors = colors;
    }
    free(corners);
    free(remap);
    return GDR_OK;
}

/* --- every mesh of a scene ---------------------------------------------------------------- */

typedef struct scene_build {
    gdr_scene *scene;
    const gdr_meshlet_options *options;
    const uint32_t *todo;   /* meshes to build, largest first (the longest tasks start first) */
    uint32_t mesh_threads;  /* gdr_meshlets_build's thread_count for one mesh */
    uint32_t *failed_mesh;  /* per worker: the lowest mesh index that failed, or GDR_NO_INDEX */
    gdr_error *errors;      /* per worker: that mesh's error */
} scene_build;

static void build_task(void *user, uint32_t task_index, uint32_t worker_index)
{
    scene_build *b = user;
    uint32_t m = b->todo[task_index];
    gdr_mesh *mesh = &b->scene->meshes[m];
    gdr_error err;
    /* Meshes side by side, one thread each; a single mesh gets every thread. */
    gdr_meshlet_options o = *b->options;
    o.thread_count = b->mesh_threads;
    /* Bit-equal vertices first, so that clusters fill and the DAG sees the shared edges. */
    gdr_status status = gdr_mesh_weld_vertices(mesh, NULL, &err);
    if (status == GDR_OK)
        status = gdr_meshlets_build(mesh, &o, &mesh->clusters, &err);
    if (status == GDR_OK)
        status = reorder_vertices(mesh, &err);
    /* Keeping the lowest failing index per worker makes the reported error independent of the
     * thread count and of which worker ran what. */
    if (status != GDR_OK && m < b->failed_mesh[worker_index]) {
        b->failed_mesh[worker_index] = m;
        b->errors[worker_index] = err;
    }
}

typedef struct mesh_size {
    uint32_t index_count, mesh;
} mesh_size;

static int larger_mesh_first(const void *a, const void *b)
{
    const mesh_size *x = a, *y = b;
    if (x->index_count != y->index_count)
        return x->index_count > y->index_count ? -1 : 1;
    return x->mesh < y->mesh ? -1 : x->mesh > y->mesh;
}

gdr_status gdr_scene_build_clusters(gdr_scene *scene, const gdr_meshlet_options *options, gdr_error *err)
{
    if (scene->geometry_in_pages)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "clusters: the scene was read for streaming and holds "
                             "no geometry to build them from");
    gdr_meshlet_options o;
    gdr_status status = resolve_options(options, &o, err);
    if (status != GDR_OK)
        return status;
    size_t slots = (size_t)scene->mesh_count + 1;
    mesh_size *sizes = malloc(slots * sizeof *sizes);
    uint32_t *todo = malloc(slots * sizeof *todo), todo_count = 0;
    if (!sizes || !todo) {
        free(sizes);
        free(todo);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    /* A mesh without triangles has no clusters: nothing to build. */
    for (uint32_t i = 0; i < scene->mesh_count; i++)
        if (scene->meshes[i].clusters.cluster_count == 0 && scene->meshes[i].index_count > 0)
            sizes[todo_count++] = (mesh_size){scene->meshes[i].index_count, i};
    qsort(sizes, todo_count, sizeof *sizes, larger_mesh_first);
    for (uint32_t i = 0; i < todo_count; i++)
        todo[i] = sizes[i].mesh;
    free(sizes);
    if (todo_count == 0) {
        free(todo);
        return GDR_OK;
    }

    gdr_thread_pool *pool = NULL;
    if (todo_count > 1 && o.thread_count != 1) {
        status = gdr_thread_pool_create(o.thread_count, &pool, err);
        if (status != GDR_OK) {
            free(todo);
            return status;
        }
    }
    uint32_t workers = gdr_thread_pool_thread_count(pool);
    scene_build b = {scene, &o, todo, todo_count == 1 ? o.thread_count : 1, malloc(workers * sizeof(uint32_t)),
                     malloc(workers * sizeof(gdr_error))};
    if (!b.failed_mesh || !b.errors) {
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
    } else {
        for (uint32_t w = 0; w < workers; w++)
            b.failed_mesh[w] = GDR_NO_INDEX;
        gdr_thread_pool_run(pool, todo_count, build_task, &b);
        uint32_t first = 0;
        for (uint32_t w = 1; w < workers; w++)
            if (b.failed_mesh[w] < b.failed_mesh[first])
                first = w;
        if (b.failed_mesh[first] != GDR_NO_INDEX) {
            status = gdr_error_set(err, b.errors[first].status, "meshes[%u]: %s", b.failed_mesh[first],
                                   b.errors[first].message);
            /* All or nothing: no mesh keeps clusters from a failed call. */
            for (uint32_t i = 0; i < todo_count; i++)
                gdr_mesh_clusters_free(&scene->meshes[todo[i]].clusters);
        }
    }
    gdr_thread_pool_destroy(pool);
    free(b.failed_mesh);
    free(b.errors);
    free(todo);
    return status;
}
