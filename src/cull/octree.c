/* The loose octree over object bounds, and its per-view classification (two bits per node).
 *
 * An object lives in the deepest node whose cell holds its centre and whose cell half-size h is
 * at least the object's largest half-extent, so its box lies inside the node's loose cube (the
 * cell grown to half-size 2h). The root's cube holds every box. Each node cube is also grown by
 * a margin much larger than float rounding, so "node fully inside / fully outside a plane"
 * implies the same for each object box in it: culling with the tree gives exactly the result of
 * testing every object. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/thread_pool.h"
#include "cull/cull_internal.h"

typedef struct octree_builder {
    gdr_cull_scene *scene;
    uint32_t *scratch; /* object indices while partitioning */
    float margin;
    gdr_error *err;
} octree_builder;

static void cull_octree_plan_tasks(gdr_cull_scene *s);

static float max3f(float a, float b, float c) { return fmaxf(a, fmaxf(b, c)); }

static uint32_t octant_of(gdr_vec3 node_center, gdr_vec3 p)
{
    return (uint32_t)(p.x >= node_center.x) | (uint32_t)(p.y >= node_center.y) << 1 |
           (uint32_t)(p.z >= node_center.z) << 2;
}

static gdr_vec3 child_center(gdr_vec3 c, float child_half, uint32_t octant)
{
    return (gdr_vec3){c.x + ((octant & 1) ? child_half : -child_half),
                      c.y + ((octant & 2) ? child_half : -child_half),
                      c.z + ((octant & 4) ? child_half : -child_half)};
}

static gdr_status add_node(octree_builder *b, gdr_vec3 center, float cell_half, float fit_extent, uint32_t depth,
                           uint32_t *out_index)
{
    gdr_cull_scene *s = b->scene;
    if (s->node_count == s->node_capacity) {
        uint32_t capacity = s->node_capacity ? s->node_capacity * 2 : 64;
        cull_node *nodes = realloc(s->nodes, (size_t)capacity * sizeof(*nodes));
        if (!nodes)
            return gdr_error_set(b->err, GDR_ERROR_OUT_OF_MEMORY, "cull scene: out of memory for octree nodes");
        s->nodes = nodes;
        s->node_capacity = capacity;
    }
    cull_node *n = &s->nodes[s->node_count];
    memset(n, 0, sizeof(*n));
    n->center = center;
    n->cell_half = cell_half;
    n->fit_extent = fit_extent;
    /* The margin: relative to the node and to the whole tree (coordinates' rounding scale). */
    n->extent = fit_extent * (1.0f + 1.0f / 4096.0f) + b->margin;
    n->depth = depth;
    for (int i = 0; i < 8; i++)
        n->children[i] = UINT32_MAX;
    *out_index = s->node_count++;
    return GDR_OK;
}

/* Builds the subtree of node `index` over objects[0, count) (indices into the scene). */
static gdr_status build_node(octree_builder *b, uint32_t index, uint32_t *objects, uint32_t count)
{
    gdr_cull_scene *s = b->scene;
    cull_node node = s->nodes[index];
    float child_half = node.cell_half * 0.5f;
    uint32_t counts[9] = {0}; /* bucket 8: stays in this node */
    uint32_t *bucket_of = b->scratch;

    bool split = count > s->leaf_objects && node.depth < s->max_depth;
    for (uint32_t i = 0; i < count; i++) {
        const gdr_cull_object *o = &s->objects[objects[i]];
        uint32_t bucket = 8;
        if (split && max3f(o->extent.x, o->extent.y, o->extent.z) <= child_half)
            bucket = octant_of(node.center, o->center);
        bucket_of[i] = bucket;
        counts[bucket]++;
    }
    if (!split || counts[8] == count) {
        for (uint32_t i = 0; i < count; i++)
            s->object_node[objects[i]] = index;
        s->nodes[index].skip = s->node_count;
        return GDR_OK;
    }
    /* Sort the indices by bucket (stable) through the second half of the scratch space. */
    uint32_t offsets[9], start = 0;
    for (int k = 0; k < 9; k++) {
        offsets[k] = start;
        start += counts[k];
    }
    uint32_t *sorted = b->scratch + s->object_count;
    for (uint32_t i = 0; i < count; i++)
        sorted[offsets[bucket_of[i]]++] = objects[i];
    memcpy(objects, sorted, (size_t)count * sizeof(uint32_t));

    uint32_t first = 0;
    for (uint32_t k = 0; k < 8; first += counts[k], k++) {
        if (!counts[k])
            continue;
        uint32_t child;
        gdr_status st = add_node(b, child_center(node.center, child_half, k), child_half, 2.0f * child_half,
                                 node.depth + 1, &child);
        if (st != GDR_OK)
            return st;
        s->nodes[index].children[k] = child;
        st = build_node(b, child, objects + first, counts[k]);
        if (st != GDR_OK)
            return st;
    }
    for (uint32_t i = first; i < count; i++)
        s->object_node[objects[i]] = index;
    s->nodes[index].skip = s->node_count;
    return GDR_OK;
}

gdr_status cull_octree_build(gdr_cull_scene *s, gdr_error *err)
{
    s->node_count = 0;
    gdr_vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
    uint32_t valid = 0;
    for (uint32_t i = 0; i < s->object_count; i++) {
        const gdr_cull_object *o = &s->objects[i];
        if (s->object_node[i] == CULL_NODE_INVALID)
            continue;
        valid++;
        lo.x = fminf(lo.x, o->center.x - o->extent.x);
        lo.y = fminf(lo.y, o->center.y - o->extent.y);
        lo.z = fminf(lo.z, o->center.z - o->extent.z);
        hi.x = fmaxf(hi.x, o->center.x + o->extent.x);
        hi.y = fmaxf(hi.y, o->center.y + o->extent.y);
        hi.z = fmaxf(hi.z, o->center.z + o->extent.z);
    }
    if (valid == 0)
        return GDR_OK;

    uint32_t *objects = malloc((size_t)valid * sizeof(uint32_t));
    uint32_t *scratch = malloc((size_t)s->object_count * 2 * sizeof(uint32_t));
    if (!objects || !scratch) {
        free(objects);
        free(scratch);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "cull scene: out of memory for the octree");
    }
    valid = 0;
    for (uint32_t i = 0; i < s->object_count; i++)
        if (s->object_node[i] != CULL_NODE_INVALID)
            objects[valid++] = i;

    gdr_vec3 center = {0.5f * (lo.x + hi.x), 0.5f * (lo.y + hi.y), 0.5f * (lo.z + hi.z)};
    float half = 0.5f * max3f(hi.x - lo.x, hi.y - lo.y, hi.z - lo.z);
    float scale = max3f(fabsf(center.x), fabsf(center.y), fabsf(center.z)) + half;
    if (!(half > 0.0f))
        half = fmaxf(scale, 1.0f) * 1e-6f; /* every box is a point: any small cube will do */
    octree_builder b = {s, scratch, scale * (1.0f / 65536.0f) + 1e-30f, err};
    uint32_t root;
    gdr_status st = add_node(&b, center, half, half, 0, &root);
    if (st == GDR_OK)
        st = build_node(&b, root, objects, valid);
    free(objects);
    free(scratch);
    if (st == GDR_OK)
        cull_octree_plan_tasks(s);
    return st;
}

static bool box_fits(const cull_node *n, gdr_vec3 c, gdr_vec3 e)
{
    return fabsf(c.x - n->center.x) + e.x <= n->fit_extent && fabsf(c.y - n->center.y) + e.y <= n->fit_extent &&
           fabsf(c.z - n->center.z) + e.z <= n->fit_extent;
}

uint32_t cull_octree_place(const gdr_cull_scene *s, gdr_vec3 center, gdr_vec3 extent)
{
    if (s->node_count == 0 || !box_fits(&s->nodes[0], center, extent))
        return CULL_NODE_NONE;
    uint32_t index = 0;
    for (;;) {
        const cull_node *n = &s->nodes[index];
        uint32_t child = n->children[octant_of(n->center, center)];
        if (child == UINT32_MAX || !box_fits(&s->nodes[child], center, extent))
            return index;
        index = child;
    }
}

static gdr_cull_outcome node_classify(const gdr_frustum *f, const float slack[8], gdr_vec3 c, float extent)
{
    int outside = 0, partly = 0;
    for (int i = 0; i < 8; i++) {
        float dist = f->px[i] * c.x + f->py[i] * c.y + f->pz[i] * c.z + f->pd[i];
        float push = (fabsf(f->px[i]) + fabsf(f->py[i]) + fabsf(f->pz[i])) * extent + slack[i];
        outside |= dist < -push;
        partly |= dist < push;
    }
    return outside ? GDR_CULL_OUTSIDE : partly ? GDR_CULL_INTERSECTS : GDR_CULL_INSIDE;
}

/* The tree's top: nodes whose subtree has more than task_nodes nodes. The view pass walks them on
 * one thread and hands every subtree it reaches below them to a task; a subtree of at most
 * 1/64 of the tree keeps the tasks many and even. */
static void cull_octree_plan_tasks(gdr_cull_scene *s)
{
    s->task_nodes = s->node_count / 64 > 256 ? s->node_count / 64 : 256;
    s->task_capacity = 0;
    for (uint32_t i = 0; i < s->node_count; i++) {
        const cull_node *n = &s->nodes[i];
        if (n->skip - i <= s->task_nodes)
            continue; /* counted from its parent */
        for (int k = 0; k < 8; k++)
            if (n->children[k] != UINT32_MAX) {
                const cull_node *c = &s->nodes[n->children[k]];
                s->task_capacity += c->skip - n->children[k] <= s->task_nodes;
            }
    }
    if (s->node_count && s->nodes[0].skip <= s->task_nodes)
        s->task_capacity = 1; /* the whole tree is one task */
}

typedef struct octree_pass {
    const gdr_cull_scene *scene;
    const gdr_frustum *frustum;
    float slack[8];
    uint32_t *node_bits;
    const uint32_t *roots;
    uint32_t (*counts)[2]; /* per task: nodes tested, nodes found inside */
} octree_pass;

/* ORs value into word w of node_bits. A task owns the words wholly inside its node range; the
 * two end words may hold bits of other tasks' nodes and are written atomically. */
static void or_word(uint32_t *bits, uint32_t w, uint32_t value, uint32_t shared_lo, uint32_t shared_hi)
{
    if (w == shared_lo || w == shared_hi)
        __atomic_fetch_or(&bits[w], value, __ATOMIC_RELAXED);
    else
        bits[w] |= value;
}

/* Bits "intersects, not partly outside" (01) for nodes [first, last). */
static void mark_inside(uint32_t *bits, uint32_t first, uint32_t last, uint32_t shared_lo, uint32_t shared_hi)
{
    while (first < last) {
        uint32_t w = first >> 4, end = (w + 1) * 16 < last ? (w + 1) * 16 : last;
        uint32_t lo = (first & 15u) * 2, hi = end - w * 16 == 16 ? 32 : (end & 15u) * 2;
        uint32_t mask = (hi == 32 ? 0xFFFFFFFFu : (1u << hi) - 1u) & ~((1u << lo) - 1u);
        or_word(bits, w, 0x55555555u & mask, shared_lo, shared_hi);
        first = end;
    }
}

/* Tests node i and writes its bits (and its subtree's when fully inside). */
static gdr_cull_outcome classify_node(const octree_pass *pass, uint32_t i, uint32_t counts[2], uint32_t shared_lo,
                                      uint32_t shared_hi)
{
    const cull_node *n = &pass->scene->nodes[i];
    counts[0]++;
    gdr_cull_outcome outcome = node_classify(pass->frustum, pass->slack, n->center, n->extent);
    if (outcome == GDR_CULL_INSIDE) {
        /* Fully inside: every node below is inside too and skips its own test. */
        counts[1]++;
        mark_inside(pass->node_bits, i, n->skip, shared_lo, shared_hi);
    } else if (outcome == GDR_CULL_INTERSECTS) {
        or_word(pass->node_bits, i >> 4, 3u << ((i & 15u) * 2u), shared_lo, shared_hi);
    }
    return outcome; /* outside: the bits stay 00 for the whole subtree */
}

/* Walks nodes [first, last) in pre-order, jumping over subtrees found outside or inside. */
static void classify_range(const octree_pass *pass, uint32_t first, uint32_t last, uint32_t counts[2],
                           uint32_t shared_lo, uint32_t shared_hi)
{
    uint32_t i = first;
    while (i < last)
        i = classify_node(pass, i, counts, shared_lo, shared_hi) == GDR_CULL_INTERSECTS ? i + 1
                                                                                       : pass->scene->nodes[i].skip;
}

static void classify_task(void *user, uint32_t task, uint32_t worker)
{
    (void)worker;
    const octree_pass *pass = user;
    uint32_t root = pass->roots[task], last = pass->scene->nodes[root].skip;
    classify_range(pass, root, last, pass->counts[task], root >> 4, (last - 1) >> 4);
}

gdr_status cull_octree_classify(const gdr_cull_scene *s, const gdr_frustum *frustum, gdr_thread_pool *pool,
                                uint32_t *node_bits, uint32_t *nodes_tested, uint32_t *nodes_inside,
                                gdr_error *err)
{
    *nodes_tested = *nodes_inside = 0;
    if (s->node_count == 0)
        return GDR_OK;
    octree_pass pass = {s, frustum, {0}, node_bits, NULL, NULL};
    /* Slack for the rounding of the plane offset itself (a far-away camera has a large d): a
     * node counts as inside or outside only with that much room to spare. */
    for (int k = 0; k < 8; k++)
        pass.slack[k] = isfinite(frustum->pd[k]) ? fabsf(frustum->pd[k]) * (1.0f / 65536.0f) : 0.0f;
    uint32_t *roots = malloc((size_t)s->task_capacity * sizeof(uint32_t));
    uint32_t (*counts)[2] = calloc(s->task_capacity, sizeof(*counts));
    if (!roots || !counts) {
        free(roots);
        free(counts);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "cull: out of memory for %u octree tasks",
                             s->task_capacity);
    }
    /* The top, on this thread (before any task runs, so plain writes are safe). */
    uint32_t top[2] = {0, 0}, task_count = 0;
    uint32_t i = 0;
    while (i < s->node_count) {
        const cull_node *n = &s->nodes[i];
        if (n->skip - i <= s->task_nodes) {
            roots[task_count++] = i;
            i = n->skip;
            continue;
        }
        i = classify_node(&pass, i, top, UINT32_MAX, UINT32_MAX) == GDR_CULL_INTERSECTS ? i + 1 : n->skip;
    }
    pass.roots = roots;
    pass.counts = counts;
    gdr_thread_pool_run(pool, task_count, classify_task, &pass);
    *nodes_tested = top[0];
    *nodes_inside = top[1];
    for (uint32_t t = 0; t < task_count; t++) {
        *nodes_tested += counts[t][0];
        *nodes_inside += counts[t][1];
    }
    free(roots);
    free(counts);
    return GDR_OK;
}
