/* Vertices onto a per-mesh grid (gdr_scene_quantize_vertices, gdr/geometry.h): positions and uvs
 * on power-of-two steps, normals as 10-bit octahedral pairs, and every bound that depends on the
 * positions made honest again for the moved vertices; one mesh per task on a thread pool (the result
 * does not depend on it). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/thread_pool.h"
#include "geometry/cluster_bounds.h"
#include "geometry/vertex_quantize.h"
#include "gdr/scene.h"

#define POSITION_MAX ((1u << GDR_QUANTIZED_POSITION_BITS) - 1u)
#define UV_MAX ((1u << GDR_QUANTIZED_UV_BITS) - 1u)
#define NORMAL_MAX 511.0f /* 10-bit octahedral components: within 0.24 degrees */

/* --- the codec ----------------------------------------------------------------------------------- */

static float sign_of(float v) { return v < 0.0f ? -1.0f : 1.0f; }

/* The octahedral map folds the lower hemisphere over the upper one. */
static void oct_fold(float *x, float *y)
{
    float fx = (1.0f - fabsf(*y)) * sign_of(*x), fy = (1.0f - fabsf(*x)) * sign_of(*y);
    *x = fx, *y = fy;
}

static void oct_encode(gdr_vec3 n, int16_t out[2])
{
    float l1 = fabsf(n.x) + fabsf(n.y) + fabsf(n.z);
    float x = l1 > 0.0f ? n.x / l1 : 0.0f, y = l1 > 0.0f ? n.y / l1 : 0.0f;
    if (n.z < 0.0f)
        oct_fold(&x, &y);
    out[0] = (int16_t)lrintf(fminf(fmaxf(x, -1.0f), 1.0f) * NORMAL_MAX);
    out[1] = (int16_t)lrintf(fminf(fmaxf(y, -1.0f), 1.0f) * NORMAL_MAX);
}

/* The octahedral pair back to a unit vector; inline arithmetic only (no libm calls: it runs once
 * per vertex of every page read). v < -1 ? -1 : v is fmaxf(v, -1) for the quotients here, which are
 * never NaN. */
static gdr_vec3 oct_decode(const int16_t in[2])
{
    float x = (float)in[0] / NORMAL_MAX, y = (float)in[1] / NORMAL_MAX;
    x = x < -1.0f ? -1.0f : x;
    y = y < -1.0f ? -1.0f : y;
    float z = 1.0f - fabsf(x) - fabsf(y);
    if (z < 0.0f)
        oct_fold(&x, &y);
    float length = sqrtf(x * x + y * y + z * z);
    /* + 0.0f turns -0 into +0, so that every decoded normal encodes to the same pair again. */
    return (gdr_vec3){x / length + 0.0f, y / length + 0.0f, z / length + 0.0f};
}

/* One coordinate onto the grid origin + q * 2^exponent, q in [0, max]; -1 when outside. */
static int64_t grid_index(float v, float origin, int exponent, uint32_t max)
{
    double q = nearbyint(ldexp((double)v - (double)origin, -exponent));
    return q >= 0.0 && q <= (double)max ? (int64_t)q : -1;
}

/* 2^exponent where a float holds it exactly, else 0. Then (float)q * step is ldexpf((float)q,
 * exponent) bit for bit: both are the one correctly rounded product of the same two values (an
 * overflow to infinity included). One per grid, not an ldexpf per coordinate. */
static float grid_step(int exponent) { return exponent >= -149 && exponent <= 127 ? ldexpf(1.0f, exponent) : 0.0f; }

/* origin + q * 2^exponent. The product is a statement of its own so that a compiler contracting
 * within an expression cannot fuse it with the sum (the result must not depend on the build). */
static float grid_value(float origin, float step, int exponent, uint32_t q)
{
    float offset = step != 0.0f ? (float)q * step : ldexpf((float)q, exponent);
    return origin + offset;
}

/* A grid's steps, computed once for many vertices. */
typedef struct grid_steps {
    float position, uv;
} grid_steps;

static grid_steps steps_of(const gdr_vertex_quantization *q)
{
    return (grid_steps){grid_step(q->position_exponent), grid_step(q->uv_exponent)};
}

static void decode_grid(const gdr_vertex_quantization *q, grid_steps s, const gdr_quantized_vertex *v,
                        gdr_vec3 *position, gdr_vec2 *uv)
{
    int pe = q->position_exponent, te = q->uv_exponent;
    *position = (gdr_vec3){grid_value(q->position_origin.x, s.position, pe, v->position[0]),
                           grid_value(q->position_origin.y, s.position, pe, v->position[1]),
                           grid_value(q->position_origin.z, s.position, pe, v->position[2])};
    *uv = (gdr_vec2){grid_value(q->uv_origin.x, s.uv, te, v->uv[0]), grid_value(q->uv_origin.y, s.uv, te, v->uv[1])};
}

/* The nearest grid point of each value; 0 when one lies outside the grid's range. */
static int encode_nearest(const gdr_vertex_quantization *q, gdr_vec3 position, gdr_vec3 normal, gdr_vec2 uv,
                          gdr_quantized_vertex *out)
{
    const float *p = &position.x, *po = &q->position_origin.x, *t = &uv.x, *to = &q->uv_origin.x;
    *out = (gdr_quantized_vertex){0};
    for (int i = 0; i < 3; i++) {
        int64_t k = grid_index(p[i], po[i], q->position_exponent, POSITION_MAX);
        if (k < 0)
            return 0;
        out->position[i] = (uint16_t)k;
    }
    for (int i = 0; i < 2; i++) {
        int64_t k = grid_index(t[i], to[i], q->uv_exponent, UV_MAX);
        if (k < 0)
            return 0;
        out->uv[i] = (uint32_t)k;
    }
    oct_encode(normal, out->normal);
    return 1;
}

int gdr_vertex_encode(const gdr_vertex_quantization *q, gdr_vec3 position, gdr_vec3 normal, gdr_vec2 uv,
                      gdr_quantized_vertex *out)
{
    if (!encode_nearest(q, position, normal, uv, out))
        return 0;
    gdr_vec3 p2, n2;
    gdr_vec2 t2;
    gdr_vertex_decode(q, out, &p2, &n2, &t2);
    return memcmp(&p2, &position, sizeof p2) == 0 && memcmp(&n2, &normal, sizeof n2) == 0 &&
           memcmp(&t2, &uv, sizeof t2) == 0;
}

void gdr_vertex_decode(const gdr_vertex_quantization *q, const gdr_quantized_vertex *v, gdr_vec3 *position,
                       gdr_vec3 *normal, gdr_vec2 *uv)
{
    decode_grid(q, steps_of(q), v, position, uv);
    *normal = oct_decode(v->normal);
}

/* yes ? a : b on the bits, without a branch (whether a normal is folded is a coin toss). */
static float select_float(int yes, float a, float b)
{
    uint32_t ua, ub, mask = 0u - (uint32_t)(yes != 0);
    memcpy(&ua, &a, sizeof ua);
    memcpy(&ub, &b, sizeof ub);
    ua = (ua & mask) | (ub & ~mask);
    memcpy(&a, &ua, sizeof a);
    return a;
}

/* Vertices decoded together: each step of oct_decode as a loop over a block of them, of the same
 * operations in the same order (so the same bits), which compilers turn into vector instructions
 * (the divisions and the square root dominate a vertex). */
#define DECODE_BLOCK 8

static void decode_normals(const gdr_quantized_vertex *in, gdr_vertex_bytes *out)
{
    float x[DECODE_BLOCK], y[DECODE_BLOCK], z[DECODE_BLOCK], length[DECODE_BLOCK];
    for (int i = 0; i < DECODE_BLOCK; i++) {
        x[i] = (float)in[i].normal[0];
        y[i] = (float)in[i].normal[1];
    }
    for (int i = 0; i < DECODE_BLOCK; i++) {
        x[i] /= NORMAL_MAX;
        y[i] /= NORMAL_MAX;
    }
    for (int i = 0; i < DECODE_BLOCK; i++) {
        /* oct_decode's steps without a branch: x is never -0 (it is an integer's quotient, or -1),
         * so sign_of(x) is copysignf(1, x); the fold is a select on the bits. */
        float cx = select_float(x[i] < -1.0f, -1.0f, x[i]), cy = select_float(y[i] < -1.0f, -1.0f, y[i]);
        float cz = 1.0f - fabsf(cx) - fabsf(cy);
        float fx = (1.0f - fabsf(cy)) * copysignf(1.0f, cx), fy = (1.0f - fabsf(cx)) * copysignf(1.0f, cy);
        x[i] = select_float(cz < 0.0f, fx, cx);
        y[i] = select_float(cz < 0.0f, fy, cy);
        z[i] = cz;
    }
    for (int i = 0; i < DECODE_BLOCK; i++)
        length[i] = sqrtf(x[i] * x[i] + y[i] * y[i] + z[i] * z[i]);
    for (int i = 0; i < DECODE_BLOCK; i++)
        out[i].normal = (gdr_vec3){x[i] / length[i] + 0.0f, y[i] / length[i] + 0.0f, z[i] / length[i] + 0.0f};
}

/* Positions and uvs of a block of vertices whose grid has exact steps (no ldexpf fallback): the
 * products are computed apart from the sums, as grid_value does. */
static void decode_grid_block(const gdr_vertex_quantization *q, grid_steps s, const gdr_quantized_vertex *in,
                              gdr_vertex_bytes *out)
{
    for (int i = 0; i < DECODE_BLOCK; i++) {
        float p[3], t[2];
        for (int k = 0; k < 3; k++)
            p[k] = (float)in[i].position[k] * s.position;
        for (int k = 0; k < 2; k++)
            t[k] = (float)in[i].uv[k] * s.uv;
        out[i].position = (gdr_vec3){q->position_origin.x + p[0], q->position_origin.y + p[1],
                                     q->position_origin.z + p[2]};
        out[i].uv = (gdr_vec2){q->uv_origin.x + t[0], q->uv_origin.y + t[1]};
    }
}

void gdr_vertex_decode_many(const gdr_vertex_quantization *q, const gdr_quantized_vertex *in, size_t count,
                            gdr_vertex_bytes *out)
{
    grid_steps s = steps_of(q);
    size_t blocks = s.position != 0.0f && s.uv != 0.0f ? count / DECODE_BLOCK * DECODE_BLOCK : 0;
    for (size_t i = 0; i < blocks; i += DECODE_BLOCK) {
        decode_grid_block(q, s, in + i, out + i);
        decode_normals(in + i, out + i);
    }
    for (size_t i = blocks; i < count; i++) {
        decode_grid(q, s, &in[i], &out[i].position, &out[i].uv);
        out[i].normal = oct_decode(in[i].normal);
    }
}

int gdr_vertex_grid_finite(const gdr_vertex_quantization *q)
{
    /* The stored integers' largest values: uint16 positions, uint32 uvs. */
    gdr_quantized_vertex largest = {.position = {UINT16_MAX, UINT16_MAX, UINT16_MAX}, .uv = {UINT32_MAX, UINT32_MAX}};
    gdr_vertex_bytes low, high;
    gdr_vertex_decode(q, &(gdr_quantized_vertex){0}, &low.position, &low.normal, &low.uv);
    gdr_vertex_decode(q, &largest, &high.position, &high.normal, &high.uv);
    const float *l = &low.position.x, *h = &high.position.x;
    for (int i = 0; i < 8; i++)
        if (!isfinite(l[i]) || !isfinite(h[i]))
            return 0;
    return 1;
}

/* --- choosing a mesh's grid ------------------------------------------------------------------------ */

/* The smallest power-of-two step over which `extent` spans at most max - 1 steps, and the origin:
 * the grid point at or below `lo`. */
static void choose_grid(const float *lo, const float *hi, int axes, uint32_t max, int *exponent, float *origin)
{
    double extent = 0.0;
    for (int i = 0; i < axes; i++)
        extent = fmax(extent, (double)hi[i] - (double)lo[i]);
    int e = -126;
    if (extent > 0.0) {
        (void)frexp(extent / (double)(max - 1u), &e); /* extent / (max - 1) < 2^e */
    }
    e = e < -126 ? -126 : e > 100 ? 100 : e;
    *exponent = e;
    for (int i = 0; i < axes; i++)
        origin[i] = (float)ldexp(floor(ldexp((double)lo[i], -e)), e);
}

static gdr_vertex_quantization mesh_grid(const gdr_mesh *mesh)
{
    float plo[3] = {INFINITY, INFINITY, INFINITY}, phi[3] = {-INFINITY, -INFINITY, -INFINITY};
    float tlo[2] = {INFINITY, INFINITY}, thi[2] = {-INFINITY, -INFINITY};
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const float *p = &mesh->positions[v].x, *t = &mesh->uvs[v].x;
        for (int i = 0; i < 3; i++)
            plo[i] = fminf(plo[i], p[i]), phi[i] = fmaxf(phi[i], p[i]);
        for (int i = 0; i < 2; i++)
            tlo[i] = fminf(tlo[i], t[i]), thi[i] = fmaxf(thi[i], t[i]);
    }
    gdr_vertex_quantization q = {.enabled = 1};
    if (mesh->vertex_count == 0)
        return q;
    choose_grid(plo, phi, 3, POSITION_MAX, &q.position_exponent, &q.position_origin.x);
    choose_grid(tlo, thi, 2, UV_MAX, &q.uv_exponent, &q.uv_origin.x);
    return q;
}

/* --- moving a mesh and its bounds ------------------------------------------------------------------ */

static double distance3(gdr_vec3 a, gdr_vec3 b)
{
    double dx = (double)a.x - b.x, dy = (double)a.y - b.y, dz = (double)a.z - b.z;
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* Every vertex onto the grid (through the codec, so that the page reproduces it); the largest
 * position displacement, rounded up. 0 when some vertex falls outside the grid's range. */
static int snap_vertices(gdr_mesh *mesh, const gdr_vertex_quantization *q, float *displacement)
{
    double largest = 0.0;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        gdr_quantized_vertex code;
        gdr_vec3 p, n;
        gdr_vec2 t;
        if (!encode_nearest(q, mesh->positions[v], mesh->normals[v], mesh->uvs[v], &code))
            return 0;
        gdr_vertex_decode(q, &code, &p, &n, &t);
        largest = fmax(largest, distance3(p, mesh->positions[v]));
        mesh->positions[v] = p, mesh->normals[v] = n, mesh->uvs[v] = t;
    }
    *displacement = (float)(largest * (1.0 + 1e-6)) + FLT_MIN;
    return 1;
}

static gdr_vertex_bytes vertex_bytes(const gdr_mesh *mesh, uint32_t v)
{
    return (gdr_vertex_bytes){mesh->positions[v], mesh->normals[v], mesh->uvs[v]};
}

/* Every triangle of cluster k into its canonical rotation (gdr_triangle_first_corner), then the
 * cluster's vertex list renumbered in the order its triangles first use them, as every cluster
 * builder lists them. */
static void canonical_cluster(gdr_mesh *mesh, uint32_t k)
{
    gdr_mesh_clusters *c = &mesh->clusters;
    const gdr_cluster *cl = &c->clusters[k];
    uint32_t *list = c->vertices + cl->vertex_offset, old[GDR_CLUSTER_MAX_VERTICES];
    uint8_t *tri = c->triangles + cl->triangle_offset, local_of[GDR_CLUSTER_MAX_VERTICES], seen = 0;
    memcpy(old, list, sizeof *old * cl->vertex_count);
    memset(local_of, 0xff, sizeof local_of);
    for (uint32_t t = 0; t < cl->triangle_count; t++) {
        uint8_t *corners = tri + 3 * t, was[3] = {corners[0], corners[1], corners[2]};
        gdr_vertex_bytes v[3] = {vertex_bytes(mesh, old[was[0]]), vertex_bytes(mesh, old[was[1]]),
                                 vertex_bytes(mesh, old[was[2]])};
        uint32_t first = gdr_triangle_first_corner(&v[0], &v[1], &v[2]);
        for (uint32_t i = 0; i < 3; i++) {
            uint8_t local = was[(first + i) % 3];
            if (local_of[local] == 0xff) {
                local_of[local] = seen;
                list[seen++] = old[local];
            }
            corners[i] = local_of[local];
        }
    }
}

/* Spheres grow by d, cones are measured on the moved triangles, errors above level 0 grow by 2d, the
 * hierarchy is built again over the new bounds. */
static gdr_status fix_bounds(gdr_mesh *mesh, float d, gdr_error *err)
{
    gdr_mesh_clusters *c = &mesh->clusters;
    mesh->bounds.w += d;
    for (uint32_t k = 0; k < c->cluster_count; k++) {
        canonical_cluster(mesh, k);
        gdr_cluster *cl = &c->clusters[k], moved = *cl;
        gdr_cluster_compute_bounds(&moved, c->vertices + cl->vertex_offset, c->triangles + cl->triangle_offset, mesh);
        cl->sphere.w += d;
        cl->cone_apex = moved.cone_apex, cl->cone_axis = moved.cone_axis, cl->cone_cutoff = moved.cone_cutoff;
    }
    for (uint32_t g = 0; g < c->group_count; g++) {
        c->groups[g].sphere.w += d;
        if (c->groups[g].depth > 0 && isfinite(c->groups[g].error))
            c->groups[g].error += 2.0f * d;
    }
    return c->cluster_count ? gdr_mesh_clusters_build_hierarchy(c, err) : GDR_OK;
}

/* One mesh per task; each task's outcome in its own slot, the first failure reported after. */
typedef struct quantize_job {
    gdr_scene *scene;
    gdr_status *status;
    gdr_error *errors;
} quantize_job;

static void quantize_mesh_task(void *user, uint32_t m, uint32_t worker)
{
    (void)worker;
    quantize_job *job = user;
    gdr_mesh *mesh = &job->scene->meshes[m];
    if (mesh->quantization.enabled)
        return;
    gdr_vertex_quantization q = mesh_grid(mesh);
    if (!snap_vertices(mesh, &q, &q.max_displacement)) {
        job->status[m] = gdr_error_set(&job->errors[m], GDR_ERROR_INVALID_ARGUMENT, "quantize: mesh %u ('%s'): a "
                                       "position lies outside its grid", m, mesh->name);
        return;
    }
    job->status[m] = fix_bounds(mesh, q.max_displacement, &job->errors[m]);
    if (job->status[m] == GDR_OK)
        mesh->quantization = q;
}

gdr_status gdr_scene_quantize_vertices(gdr_scene *scene, gdr_error *err)
{
    if (scene->geometry_in_pages)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "quantize: the scene was read for streaming and holds "
                             "no vertices");
    uint32_t n = scene->mesh_count ? scene->mesh_count : 1;
    quantize_job job = {scene, calloc(n, sizeof *job.status), calloc(n, sizeof *job.errors)};
    gdr_thread_pool *pool = NULL;
    gdr_status status = job.status && job.errors ? gdr_thread_pool_create(0, &pool, err)
                                                 : gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "quantize: out of memory");
    if (status == GDR_OK)
        gdr_thread_pool_run(pool, scene->mesh_count, quantize_mesh_task, &job);
    for (uint32_t m = 0; status == GDR_OK && m < scene->mesh_count; m++)
        if (job.status[m] != GDR_OK) {
            if (err)
                *err = job.errors[m];
            status = job.status[m];
        }
    gdr_thread_pool_destroy(pool);
    free(job.status);
    free(job.errors);
    return status;
}
