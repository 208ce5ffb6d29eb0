/* The LOD hierarchy over a mesh's DAG groups (gdr/geometry.h "LOD hierarchy", docs/GEOMETRY.md):
 * leaves made from the groups, one subtree per DAG depth built by median splits, a top tree over
 * the subtrees, stored breadth first. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "geometry/lod_internal.h"
#include "gpu_shared/gpu_types.h"

_Static_assert(sizeof(gdr_lod_node) == offsetof(GdrGpuLodNode, bounds) &&
                   offsetof(gdr_lod_node, max_error) == offsetof(GdrGpuLodNode, max_error) &&
                   offsetof(gdr_lod_node, min_refined_error) == offsetof(GdrGpuLodNode, min_refined_error) &&
                   offsetof(gdr_lod_node, first) == offsetof(GdrGpuLodNode, first) &&
                   offsetof(gdr_lod_node, count) == offsetof(GdrGpuLodNode, count) &&
                   offsetof(gdr_lod_node, group) == offsetof(GdrGpuLodNode, group) &&
                   offsetof(gdr_lod_node, flags) == offsetof(GdrGpuLodNode, flags),
               "gdr_lod_node is uploaded as the first fields of GdrGpuLodNode");
_Static_assert(GDR_LOD_NODE_LEAF == GDR_GPU_LOD_NODE_LEAF &&
                   GDR_LOD_NODE_MAX_CHILDREN == GDR_GPU_LOD_NODE_MAX_CHILDREN &&
                   GDR_NO_INDEX == GDR_GPU_NO_GROUP,
               "the hierarchy's constants are the GPU's");

/* The tree before it is stored breadth first: nodes in build order, each inner node's children
 * listed in `children`. */
typedef struct tree {
    gdr_lod_node *nodes; /* first/count of inner nodes index `children` until stored */
    uint32_t count, capacity;
    uint32_t *children;
    uint32_t child_count, child_capacity;
    int out_of_memory;
} tree;

typedef struct sort_key {
    float key;
    uint32_t item;
} sort_key;

static int compare_keys(const void *a, const void *b)
{
    const sort_key *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->item < y->item ? -1 : x->item > y->item;
}

static uint32_t add_node(tree *t, gdr_lod_node node)
{
    if (t->count == t->capacity) {
        uint32_t capacity = t->capacity ? 2 * t->capacity : 64;
        gdr_lod_node *grown = realloc(t->nodes, sizeof *grown * capacity);
        if (!grown) {
            t->out_of_memory = 1;
            return GDR_NO_INDEX;
        }
        t->nodes = grown;
        t->capacity = capacity;
    }
    t->nodes[t->count] = node;
    return t->count++;
}

/* An inner node over nodes items[0 .. n): n in 1 .. GDR_LOD_NODE_MAX_CHILDREN. */
static uint32_t add_inner(tree *t, const uint32_t *items, uint32_t n)
{
    if (t->out_of_memory)
        return GDR_NO_INDEX;
    if (t->child_count + n > t->child_capacity) {
        uint32_t capacity = t->child_capacity ? 2 * t->child_capacity : 256;
        uint32_t *grown = realloc(t->children, sizeof *grown * capacity);
        if (!grown) {
            t->out_of_memory = 1;
            return GDR_NO_INDEX;
        }
        t->children = grown;
        t->child_capacity = capacity;
    }
    gdr_vec4 spheres[GDR_LOD_NODE_MAX_CHILDREN];
    gdr_lod_node node = {.max_error = 0.0f, .min_refined_error = INFINITY, .first = t->child_count, .count = n,
                         .group = GDR_NO_INDEX};
    for (uint32_t i = 0; i < n; i++) {
        const gdr_lod_node *child = &t->nodes[items[i]];
        spheres[i] = child->sphere;
        node.max_error = fmaxf(node.max_error, child->max_error);
        node.min_refined_error = fminf(node.min_refined_error, child->min_refined_error);
        t->children[t->child_count++] = items[i];
    }
    node.sphere = gdr_lod_enclosing_sphere(spheres, n);
    return add_node(t, node);
}

/* Splits items[0 .. n) into `parts` runs of nearly equal size by median splits along the longest
 * axis of their centres; writes the run boundaries to bounds[0 .. parts]. */
static void split(tree *t, uint32_t *items, uint32_t n, uint32_t parts, sort_key *keys, uint32_t *bounds)
{
    if (parts == 1 || n <= 1) {
        bounds[0] = 0;
        for (uint32_t p = 1; p <= parts; p++)
            bounds[p] = n;
        return;
    }
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < n; i++) {
        const float *c = &t->nodes[items[i]].sphere.x;
        for (int k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], c[k]);
            hi[k] = fmaxf(hi[k], c[k]);
        }
    }
    int axis = 0;
    for (int k = 1; k < 3; k++)
        if (hi[k] - lo[k] > hi[axis] - lo[axis])
            axis = k;
    for (uint32_t i = 0; i < n; i++)
        keys[i] = (sort_key){(&t->nodes[items[i]].sphere.x)[axis], items[i]};
    qsort(keys, n, sizeof *keys, compare_keys);
    for (uint32_t i = 0; i < n; i++)
        items[i] = keys[i].item;
    uint32_t half = (uint32_t)((uint64_t)n * (parts / 2) / parts);
    split(t, items, half, parts / 2, keys, bounds);
    split(t, items + half, n - half, parts - parts / 2, keys, bounds + parts / 2);
    for (uint32_t p = parts / 2; p <= parts; p++)
        bounds[p] += half;
}

/* A subtree over nodes items[0 .. n) (n >= 1), spatially: its root. */
static uint32_t build_spatial(tree *t, uint32_t *items, uint32_t n, sort_key *keys)
{
    if (n == 1)
        return items[0];
    if (n <= GDR_LOD_NODE_MAX_CHILDREN)
        return add_inner(t, items, n);
    uint32_t bounds[GDR_LOD_NODE_MAX_CHILDREN + 1], roots[GDR_LOD_NODE_MAX_CHILDREN];
    split(t, items, n, GDR_LOD_NODE_MAX_CHILDREN, keys, bounds);
    uint32_t r = 0;
    for (uint32_t p = 0; p < GDR_LOD_NODE_MAX_CHILDREN; p++)
        if (bounds[p + 1] > bounds[p])
            roots[r++] = build_spatial(t, items + bounds[p], bounds[p + 1] - bounds[p], keys);
    return t->out_of_memory ? GDR_NO_INDEX : add_inner(t, roots, r);
}

/* A subtree over nodes items[0 .. n) (n >= 1) keeping their order: its root. */
static uint32_t build_in_order(tree *t, uint32_t *items, uint32_t n)
{
    while (n > 1 && !t->out_of_memory) {
        uint32_t out = 0;
        for (uint32_t i = 0; i < n; i += GDR_LOD_NODE_MAX_CHILDREN) {
            uint32_t k = n - i < GDR_LOD_NODE_MAX_CHILDREN ? n - i : GDR_LOD_NODE_MAX_CHILDREN;
            items[out++] = k == 1 ? items[i] : add_inner(t, items + i, k);
        }
        n = out;
    }
    return t->out_of_memory ? GDR_NO_INDEX : items[0];
}

/* The leaf of group g: its sphere reaches its group's, its clusters' and their refined groups'. */
static gdr_lod_node group_leaf(const gdr_mesh_clusters *c, uint32_t g, gdr_vec4 *spheres)
{
    const gdr_cluster_group *group = &c->groups[g];
    gdr_lod_node leaf = {.max_error = group->error, .min_refined_error = INFINITY, .first = group->first_cluster,
                         .count = group->cluster_count, .group = g, .flags = GDR_LOD_NODE_LEAF};
    uint32_t n = 0;
    spheres[n++] = group->sphere;
    for (uint32_t i = group->first_cluster; i < group->first_cluster + group->cluster_count; i++) {
        const gdr_cluster *cl = &c->clusters[i];
        spheres[n++] = cl->sphere;
        if (cl->refined_group == GDR_NO_INDEX) {
            leaf.min_refined_error = 0.0f;
        } else {
            spheres[n++] = c->groups[cl->refined_group].sphere;
            leaf.min_refined_error = fminf(leaf.min_refined_error, c->groups[cl->refined_group].error);
        }
    }
    leaf.sphere = gdr_lod_enclosing_sphere(spheres, n);
    return leaf;
}

/* Leaves of consecutive clusters for a mesh without a DAG: never skipped by the LOD test. */
static gdr_lod_node run_leaf(const gdr_mesh_clusters *c, uint32_t first, uint32_t count)
{
    gdr_vec4 spheres[GDR_LOD_LEAF_CLUSTERS_NO_DAG];
    for (uint32_t i = 0; i < count; i++)
        spheres[i] = c->clusters[first + i].sphere;
    return (gdr_lod_node){.sphere = gdr_lod_enclosing_sphere(spheres, count), .max_error = INFINITY,
                          .min_refined_error = 0.0f, .first = first, .count = count, .group = GDR_NO_INDEX,
                          .flags = GDR_LOD_NODE_LEAF};
}

/* Adds the leaves; items[] gets them ordered by DAG depth, coarsest first, and level_start[d] the
 * first item of depth d (level_start[levels] = leaf count). Returns the number of depths. */
static uint32_t add_leaves(tree *t, const gdr_mesh_clusters *c, uint32_t *items, uint32_t *level_start,
                           gdr_vec4 *spheres)
{
    if (c->group_count == 0) {
        const uint32_t run = GDR_LOD_LEAF_CLUSTERS_NO_DAG;
        for (uint32_t i = 0; i < c->cluster_count; i += run)
            items[i / run] = add_node(t, run_leaf(c, i, c->cluster_count - i < run ? c->cluster_count - i : run));
        level_start[0] = 0;
        level_start[1] = t->count;
        return 1;
    }
    uint32_t levels = c->dag_depth + 1, n = 0;
    for (uint32_t l = 0; l < levels; l++) {
        level_start[l] = n;
        for (uint32_t g = 0; g < c->group_count; g++)
            if ((c->groups[g].depth < c->dag_depth ? c->groups[g].depth : c->dag_depth) == c->dag_depth - l)
                items[n++] = add_node(t, group_leaf(c, g, spheres));
    }
    level_start[levels] = n;
    return levels;
}

/* Stores the tree breadth first from `root` into c->lod_nodes. */
static int store_breadth_first(const tree *t, uint32_t root, gdr_mesh_clusters *c)
{
    gdr_lod_node *out = malloc(sizeof *out * t->count);
    uint32_t *source = malloc(sizeof *source * t->count), *level = malloc(sizeof *level * t->count);
    if (!out || !source || !level) {
        free(out);
        free(source);
        free(level);
        return 0;
    }
    uint32_t stored = 1;
    source[0] = root;
    level[0] = 0;
    for (uint32_t i = 0; i < stored; i++) {
        out[i] = t->nodes[source[i]];
        if (out[i].flags & GDR_LOD_NODE_LEAF)
            continue;
        uint32_t first = stored;
        for (uint32_t k = 0; k < out[i].count; k++) {
            level[stored] = level[i] + 1;
            source[stored++] = t->children[out[i].first + k];
        }
        out[i].first = first;
    }
    free(c->lod_nodes);
    c->lod_nodes = out;
    c->lod_node_count = stored;
    c->lod_node_levels = level[stored - 1] + 1;
    free(source);
    free(level);
    return 1;
}

static void free_hierarchy(gdr_mesh_clusters *c)
{
    free(c->lod_nodes);
    c->lod_nodes = NULL;
    c->lod_node_count = c->lod_node_levels = 0;
}

gdr_status gdr_mesh_clusters_build_hierarchy(gdr_mesh_clusters *c, gdr_error *err)
{
    free_hierarchy(c);
    if (c->cluster_count == 0)
        return GDR_OK;
    const uint32_t run = GDR_LOD_LEAF_CLUSTERS_NO_DAG;
    uint32_t leaves = c->group_count ? c->group_count : (c->cluster_count + run - 1) / run;
    uint32_t widest = 1;
    for (uint32_t g = 0; g < c->group_count; g++)
        widest = c->groups[g].cluster_count > widest ? c->groups[g].cluster_count : widest;
    uint32_t levels = c->group_count ? c->dag_depth + 1 : 1;
    tree t = {0};
    uint32_t *items = malloc(sizeof *items * leaves), *level_start = malloc(sizeof *level_start * (levels + 1));
    uint32_t *roots = malloc(sizeof *roots * levels);
    sort_key *keys = malloc(sizeof *keys * leaves);
    gdr_vec4 *spheres = malloc(sizeof *spheres * (1 + 2 * (size_t)widest));
    int ok = items && level_start && roots && keys && spheres;
    if (ok) {
        levels = add_leaves(&t, c, items, level_start, spheres);
        for (uint32_t l = 0; l < levels && !t.out_of_memory; l++)
            roots[l] = build_spatial(&t, items + level_start[l], level_start[l + 1] - level_start[l], keys);
        uint32_t root = t.out_of_memory ? GDR_NO_INDEX : build_in_order(&t, roots, levels);
        ok = !t.out_of_memory && store_breadth_first(&t, root, c);
    }
    free(items);
    free(level_start);
    free(roots);
    free(keys);
    free(spheres);
    free(t.nodes);
    free(t.children);
    if (!ok)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "LOD hierarchy: out of memory for %u leaves", leaves);
    if (c->lod_node_levels > GDR_LOD_NODE_MAX_LEVELS) {
        uint32_t got = c->lod_node_levels;
        free_hierarchy(c);
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "LOD hierarchy: %u levels, more than %u", got,
                             GDR_LOD_NODE_MAX_LEVELS);
    }
    return GDR_OK;
}
