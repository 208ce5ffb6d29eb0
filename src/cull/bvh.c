/* A bounding volume hierarchy over triangles (binned SAH), for ray casts and box overlap tests.
 * Used by the precomputed-visibility bake; useful on its own for picking and game queries. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cull/cull_internal.h"

#define BVH_BINS 12
#define BVH_LEAF_TRIANGLES 4
#define BVH_STACK 64

typedef struct bvh_node {
    gdr_vec3 lo, hi;
    uint32_t first; /* leaf: first entry of order[]; interior: left child (right = first + 1) */
    uint32_t count; /* triangles in a leaf; 0 for an interior node */
} bvh_node;

struct gdr_bvh {
    uint32_t triangle_count;
    gdr_vec3 *corners;  /* 3 per triangle, in the caller's order */
    uint32_t *objects;  /* per triangle */
    uint32_t *order;    /* leaf entries -> triangle index */
    bvh_node *nodes;
    uint32_t node_count;
};

typedef struct bvh_builder {
    gdr_bvh *bvh;
    gdr_vec3 *centroids;
    gdr_vec3 *tri_lo, *tri_hi;
} bvh_builder;

static gdr_vec3 vmin(gdr_vec3 a, gdr_vec3 b) { return (gdr_vec3){fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)}; }
static gdr_vec3 vmax(gdr_vec3 a, gdr_vec3 b) { return (gdr_vec3){fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)}; }
static float axis_of(gdr_vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }
static float half_area(gdr_vec3 lo, gdr_vec3 hi)
{
    gdr_vec3 d = gdr_vec3_sub(hi, lo);
    if (d.x < 0.0f)
        return 0.0f;
    return d.x * d.y + d.y * d.z + d.z * d.x;
}

/* Splits order[first, first + count) of node `index`; nodes are allocated two at a time. */
static void build(bvh_builder *b, uint32_t index, uint32_t first, uint32_t count, uint32_t depth)
{
    gdr_bvh *bvh = b->bvh;
    gdr_vec3 lo = {FLT_MAX, FLT_MAX, FLT_MAX}, hi = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    gdr_vec3 clo = lo, chi = hi;
    for (uint32_t i = first; i < first + count; i++) {
        uint32_t t = bvh->order[i];
        lo = vmin(lo, b->tri_lo[t]);
        hi = vmax(hi, b->tri_hi[t]);
        clo = vmin(clo, b->centroids[t]);
        chi = vmax(chi, b->centroids[t]);
    }
    bvh_node *node = &bvh->nodes[index];
    node->lo = lo;
    node->hi = hi;
    node->first = first;
    node->count = count;
    if (count <= BVH_LEAF_TRIANGLES || depth >= BVH_STACK - 2)
        return;

    /* Binned SAH over the longest axis of the centroids' box. */
    gdr_vec3 ext = gdr_vec3_sub(chi, clo);
    int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    float amin = axis_of(clo, axis), aext = axis_of(ext, axis);
    if (!(aext > 0.0f))
        return; /* all centroids coincide: keep a (large) leaf */
    uint32_t bin_count[BVH_BINS] = {0};
    gdr_vec3 bin_lo[BVH_BINS], bin_hi[BVH_BINS];
    for (int k = 0; k < BVH_BINS; k++) {
        bin_lo[k] = (gdr_vec3){FLT_MAX, FLT_MAX, FLT_MAX};
        bin_hi[k] = (gdr_vec3){-FLT_MAX, -FLT_MAX, -FLT_MAX};
    }
    float scale = (float)BVH_BINS / aext;
    for (uint32_t i = first; i < first + count; i++) {
        uint32_t t = bvh->order[i];
        int k = (int)((axis_of(b->centroids[t], axis) - amin) * scale);
        k = k < 0 ? 0 : k >= BVH_BINS ? BVH_BINS - 1 : k;
        bin_count[k]++;
        bin_lo[k] = vmin(bin_lo[k], b->tri_lo[t]);
        bin_hi[k] = vmax(bin_hi[k], b->tri_hi[t]);
    }
    float right_cost[BVH_BINS];
    gdr_vec3 rlo = {FLT_MAX, FLT_MAX, FLT_MAX}, rhi = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    uint32_t rcount = 0;
    for (int k = BVH_BINS - 1; k > 0; k--) {
        rlo = vmin(rlo, bin_lo[k]);
        rhi = vmax(rhi, bin_hi[k]);
        rcount += bin_count[k];
        right_cost[k] = half_area(rlo, rhi) * (float)rcount;
    }
    gdr_vec3 llo = {FLT_MAX, FLT_MAX, FLT_MAX}, lhi = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    uint32_t lcount = 0;
    float best_cost = FLT_MAX;
    int best_split = -1;
    for (int k = 1; k < BVH_BINS; k++) {
        llo = vmin(llo, bin_lo[k - 1]);
        lhi = vmax(lhi, bin_hi[k - 1]);
        lcount += bin_count[k - 1];
        if (lcount == 0 || lcount == count)
            continue;
        float cost = half_area(llo, lhi) * (float)lcount + right_cost[k];
        if (cost < best_cost) {
            best_cost = cost;
            best_split = k;
        }
    }
    if (best_split < 0)
        return;
    /* Partition in place by bin. */
    uint32_t i = first, j = first + count;
    while (i < j) {
        uint32_t t = bvh->order[i];
        int k = (int)((axis_of(b->centroids[t], axis) - amin) * scale);
        k = k < 0 ? 0 : k >= BVH_BINS ? BVH_BINS - 1 : k;
        if (k < best_split) {
            i++;
        } else {
            j--;
            bvh->order[i] = bvh->order[j];
            bvh->order[j] = t;
        }
    }
    uint32_t left_count = i - first;
    if (left_count == 0 || left_count == count)
        return;
    uint32_t left = bvh->node_count;
    bvh->node_count += 2;
    node->first = left;
    node->count = 0;
    build(b, left, first, left_count, depth + 1);
    build(b, left + 1, i, count - left_count, depth + 1);
}

gdr_status gdr_bvh_create(const gdr_vec3 *positions, const uint32_t *objects, uint32_t triangle_count, gdr_bvh **out,
                          gdr_error *err)
{
    *out = NULL;
    if (triangle_count && !positions)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "bvh: positions is NULL");
    if (triangle_count > UINT32_MAX / 4)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "bvh: %u triangles is too many", triangle_count);
    gdr_bvh *bvh = calloc(1, sizeof(*bvh));
    size_t n = triangle_count ? triangle_count : 1;
    bvh_builder b = {bvh, malloc(n * sizeof(gdr_vec3)), malloc(n * sizeof(gdr_vec3)), malloc(n * sizeof(gdr_vec3))};
    if (bvh) {
        bvh->triangle_count = triangle_count;
        bvh->corners = malloc(3 * n * sizeof(gdr_vec3));
        bvh->objects = calloc(n, sizeof(uint32_t));
        bvh->order = malloc(n * sizeof(uint32_t));
        bvh->nodes = malloc(2 * n * sizeof(bvh_node));
    }
    if (!bvh || !b.centroids || !b.tri_lo || !b.tri_hi || !bvh->corners || !bvh->objects || !bvh->order ||
        !bvh->nodes) {
        free(b.centroids);
        free(b.tri_lo);
        free(b.tri_hi);
        gdr_bvh_destroy(bvh);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "bvh: out of memory for %u triangles", triangle_count);
    }
    if (triangle_count)
        memcpy(bvh->corners, positions, 3 * (size_t)triangle_count * sizeof(gdr_vec3));
    if (objects && triangle_count)
        memcpy(bvh->objects, objects, (size_t)triangle_count * sizeof(uint32_t));
    for (uint32_t t = 0; t < triangle_count; t++) {
        const gdr_vec3 *c = &bvh->corners[3 * t];
        b.tri_lo[t] = vmin(c[0], vmin(c[1], c[2]));
        b.tri_hi[t] = vmax(c[0], vmax(c[1], c[2]));
        b.centroids[t] = gdr_vec3_scale(gdr_vec3_add(c[0], gdr_vec3_add(c[1], c[2])), 1.0f / 3.0f);
        bvh->order[t] = t;
    }
    bvh->node_count = 1;
    build(&b, 0, 0, triangle_count, 0);
    free(b.centroids);
    free(b.tri_lo);
    free(b.tri_hi);
    *out = bvh;
    return GDR_OK;
}

gdr_status gdr_bvh_create_from_scene(const gdr_scene *scene, gdr_bvh **out, gdr_error *err)
{
    *out = NULL;
    uint64_t total = 0;
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        uint32_t mesh = scene->instances[i].mesh;
        if (mesh >= scene->mesh_count)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "bvh: instances[%u].mesh %u out of range", i, mesh);
        total += scene->meshes[mesh].index_count / 3;
    }
    if (total > UINT32_MAX / 4)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "bvh: %llu triangles is too many", (unsigned long long)total);
    gdr_vec3 *positions = malloc((size_t)(total ? total : 1) * 3 * sizeof(gdr_vec3));
    uint32_t *objects = malloc((size_t)(total ? total : 1) * sizeof(uint32_t));
    if (!positions || !objects) {
        free(positions);
        free(objects);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "bvh: out of memory for %llu triangles",
                             (unsigned long long)total);
    }
    size_t t = 0;
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        const gdr_instance *inst = &scene->instances[i];
        const gdr_mesh *mesh = &scene->meshes[inst->mesh];
        for (uint32_t k = 0; k + 2 < mesh->index_count; k += 3, t++) {
            for (int c = 0; c < 3; c++)
                positions[3 * t + (size_t)c] =
                    gdr_mat4_transform_point(inst->transform, mesh->positions[mesh->indices[k + (uint32_t)c]]);
            objects[t] = i;
        }
    }
    gdr_status st = gdr_bvh_create(positions, objects, (uint32_t)t, out, err);
    free(positions);
    free(objects);
    return st;
}

void gdr_bvh_destroy(gdr_bvh *bvh)
{
    if (!bvh)
        return;
    free(bvh->corners);
    free(bvh->objects);
    free(bvh->order);
    free(bvh->nodes);
    free(bvh);
}

uint32_t gdr_bvh_triangle_count(const gdr_bvh *bvh) { return bvh->triangle_count; }

void gdr_bvh_triangle(const gdr_bvh *bvh, uint32_t triangle, gdr_vec3 corners[3], uint32_t *object)
{
    memcpy(corners, &bvh->corners[3 * (size_t)triangle], 3 * sizeof(gdr_vec3));
    if (object)
        *object = bvh->objects[triangle];
}

bool gdr_ray_triangle(gdr_vec3 o, gdr_vec3 d, const gdr_vec3 c[3], float *t_out, float *u_out, float *v_out)
{
    gdr_vec3 e1 = gdr_vec3_sub(c[1], c[0]), e2 = gdr_vec3_sub(c[2], c[0]);
    gdr_vec3 p = gdr_vec3_cross(d, e2);
    float det = gdr_vec3_dot(e1, p);
    if (det == 0.0f || !isfinite(det))
        return false;
    float inv = 1.0f / det;
    gdr_vec3 s = gdr_vec3_sub(o, c[0]);
    float u = gdr_vec3_dot(s, p) * inv;
    if (!(u >= 0.0f && u <= 1.0f))
        return false;
    gdr_vec3 q = gdr_vec3_cross(s, e1);
    float v = gdr_vec3_dot(d, q) * inv;
    if (!(v >= 0.0f && u + v <= 1.0f))
        return false;
    *t_out = gdr_vec3_dot(e2, q) * inv;
    *u_out = u;
    *v_out = v;
    return true;
}

/* Slab test: the entry distance, or INFINITY when the box is missed within (0, t_max]. */
static float ray_box(gdr_vec3 o, gdr_vec3 inv_d, gdr_vec3 lo, gdr_vec3 hi, float t_max)
{
    float tx1 = (lo.x - o.x) * inv_d.x, tx2 = (hi.x - o.x) * inv_d.x;
    float ty1 = (lo.y - o.y) * inv_d.y, ty2 = (hi.y - o.y) * inv_d.y;
    float tz1 = (lo.z - o.z) * inv_d.z, tz2 = (hi.z - o.z) * inv_d.z;
    /* fminf/fmaxf drop the NaN of 0 * inf (a ray in the box's face plane) */
    float t_near = fmaxf(fmaxf(fminf(tx1, tx2), fminf(ty1, ty2)), fmaxf(fminf(tz1, tz2), 0.0f));
    float t_far = fminf(fminf(fmaxf(tx1, tx2), fmaxf(ty1, ty2)), fminf(fmaxf(tz1, tz2), t_max));
    return t_near <= t_far ? t_near : INFINITY;
}

bool gdr_bvh_raycast(const gdr_bvh *bvh, gdr_vec3 origin, gdr_vec3 direction, float t_max, gdr_ray_hit *hit)
{
    if (bvh->triangle_count == 0)
        return false;
    gdr_vec3 inv_d = {1.0f / direction.x, 1.0f / direction.y, 1.0f / direction.z};
    float best = t_max;
    bool found = false;
    uint32_t stack[BVH_STACK];
    uint32_t top = 0;
    if (ray_box(origin, inv_d, bvh->nodes[0].lo, bvh->nodes[0].hi, best) == INFINITY)
        return false;
    stack[top++] = 0;
    while (top) {
        const bvh_node *n = &bvh->nodes[stack[--top]];
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                uint32_t tri = bvh->order[i];
                float t, u, v;
                if (gdr_ray_triangle(origin, direction, &bvh->corners[3 * (size_t)tri], &t, &u, &v) && t > 0.0f &&
                    t <= best) {
                    /* ties go to the lower triangle index, so the answer does not depend on the tree */
                    if (t == best && found && tri > hit->triangle)
                        continue;
                    best = t;
                    found = true;
                    *hit = (gdr_ray_hit){t, u, v, tri, bvh->objects[tri]};
                }
            }
            continue;
        }
        const bvh_node *a = &bvh->nodes[n->first], *b = &bvh->nodes[n->first + 1];
        float ta = ray_box(origin, inv_d, a->lo, a->hi, best), tb = ray_box(origin, inv_d, b->lo, b->hi, best);
        uint32_t ia = n->first, ib = n->first + 1;
        if (ta > tb) { /* push the farther first so the nearer is popped first */
            float tt = ta;
            ta = tb;
            tb = tt;
            uint32_t it = ia;
            ia = ib;
            ib = it;
        }
        if (tb != INFINITY)
            stack[top++] = ib;
        if (ta != INFINITY)
            stack[top++] = ia;
    }
    return found;
}

/* Separating axis test of a triangle against a box (Akenine-Möller): the box's three axes, the
 * triangle's normal and the nine edge cross products. Touching counts as overlapping. */
bool gdr_triangle_overlaps_box(const gdr_vec3 corners[3], gdr_vec3 center, gdr_vec3 e)
{
    gdr_vec3 v[3];
    for (int i = 0; i < 3; i++)
        v[i] = gdr_vec3_sub(corners[i], center);
    /* box axes */
    if (fminf(v[0].x, fminf(v[1].x, v[2].x)) > e.x || fmaxf(v[0].x, fmaxf(v[1].x, v[2].x)) < -e.x)
        return false;
    if (fminf(v[0].y, fminf(v[1].y, v[2].y)) > e.y || fmaxf(v[0].y, fmaxf(v[1].y, v[2].y)) < -e.y)
        return false;
    if (fminf(v[0].z, fminf(v[1].z, v[2].z)) > e.z || fmaxf(v[0].z, fmaxf(v[1].z, v[2].z)) < -e.z)
        return false;
    gdr_vec3 edges[3] = {gdr_vec3_sub(v[1], v[0]), gdr_vec3_sub(v[2], v[1]), gdr_vec3_sub(v[0], v[2])};
    /* triangle normal */
    gdr_vec3 n = gdr_vec3_cross(edges[0], edges[1]);
    float r = e.x * fabsf(n.x) + e.y * fabsf(n.y) + e.z * fabsf(n.z);
    if (fabsf(gdr_vec3_dot(n, v[0])) > r)
        return false;
    /* edges x box axes */
    for (int i = 0; i < 3; i++) {
        gdr_vec3 f = edges[i];
        gdr_vec3 axes[3] = {{0.0f, -f.z, f.y}, {f.z, 0.0f, -f.x}, {-f.y, f.x, 0.0f}};
        for (int a = 0; a < 3; a++) {
            gdr_vec3 ax = axes[a];
            float p0 = gdr_vec3_dot(v[0], ax), p1 = gdr_vec3_dot(v[1], ax), p2 = gdr_vec3_dot(v[2], ax);
            float rad = e.x * fabsf(ax.x) + e.y * fabsf(ax.y) + e.z * fabsf(ax.z);
            if (fminf(p0, fminf(p1, p2)) > rad || fmaxf(p0, fmaxf(p1, p2)) < -rad)
                return false;
        }
    }
    return true;
}

bool gdr_bvh_overlaps_box(const gdr_bvh *bvh, gdr_vec3 center, gdr_vec3 extent)
{
    if (bvh->triangle_count == 0)
        return false;
    gdr_vec3 lo = gdr_vec3_sub(center, extent), hi = gdr_vec3_add(center, extent);
    uint32_t stack[BVH_STACK];
    uint32_t top = 0;
    stack[top++] = 0;
    while (top) {
        const bvh_node *n = &bvh->nodes[stack[--top]];
        if (n->lo.x > hi.x || n->hi.x < lo.x || n->lo.y > hi.y || n->hi.y < lo.y || n->lo.z > hi.z || n->hi.z < lo.z)
            continue;
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++)
                if (gdr_triangle_overlaps_box(&bvh->corners[3 * (size_t)bvh->order[i]], center, extent))
                    return true;
            continue;
        }
        stack[top++] = n->first;
        stack[top++] = n->first + 1;
    }
    return false;
}

/* For the bake: the bounds of all triangles. */
void cull_bvh_bounds(const gdr_bvh *bvh, gdr_vec3 *lo, gdr_vec3 *hi)
{
    *lo = bvh->nodes[0].lo;
    *hi = bvh->nodes[0].hi;
}
