/* The LOD hierarchy's contract (gdr/geometry.h "LOD hierarchy"), checked on what a builder or a
 * file holds: the tests and the cache reader use it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "gdr/geometry.h"
#include "gdr/scene.h"

static int contains(gdr_vec4 outer, gdr_vec4 inner)
{
    double dx = (double)inner.x - outer.x, dy = (double)inner.y - outer.y, dz = (double)inner.z - outer.z;
    return sqrt(dx * dx + dy * dy + dz * dz) + inner.w <= outer.w;
}

#define FAIL(...) do { snprintf(what, what_size, __VA_ARGS__); return 0; } while (0)

/* A leaf of a mesh without its clusters (read for streaming): its group's refinements stand for its
 * clusters' refined groups (the pages are checked against them as they arrive). The refinements are
 * in group order, so a binary search finds the group's. */
static int check_leaf_refinements(const gdr_mesh_clusters *c, uint32_t i, char *what, size_t what_size)
{
    const gdr_lod_node *n = &c->lod_nodes[i];
    uint32_t lo = 0, hi = c->refinement_count, refined = 0;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (c->refinements[mid].group < n->group)
            lo = mid + 1;
        else
            hi = mid;
    }
    for (uint32_t k = lo; k < c->refinement_count && c->refinements[k].group == n->group; k++) {
        const gdr_cluster_refinement *f = &c->refinements[k];
        if (f->refined_group >= c->group_count || !contains(n->sphere, c->groups[f->refined_group].sphere) ||
            !(n->min_refined_error <= c->groups[f->refined_group].error))
            FAIL("node %u: does not contain refined group %u's sphere or error", i, f->refined_group);
        refined += f->cluster_count;
    }
    if (refined < n->count && n->min_refined_error != 0.0f)
        FAIL("node %u: a cluster has no refined group, the refined error bound is not 0", i);
    return 1;
}

/* A leaf's own bounds: its clusters, their groups and refined groups. */
static int check_leaf(const gdr_mesh_clusters *c, uint32_t i, uint8_t *seen, char *what, size_t what_size)
{
    const gdr_lod_node *n = &c->lod_nodes[i];
    if (n->count == 0 || n->first > c->cluster_count || n->count > c->cluster_count - n->first)
        FAIL("node %u: clusters %u (+%u) lie outside the mesh's %u", i, n->first, n->count, c->cluster_count);
    if (c->group_count == 0) {
        if (n->group != GDR_NO_INDEX || n->max_error != INFINITY || n->min_refined_error != 0.0f)
            FAIL("node %u: a leaf without a DAG needs no group, error INFINITY and refined error 0", i);
    } else {
        if (n->group >= c->group_count || seen[n->group]++)
            FAIL("node %u: group %u is missing or named twice", i, n->group);
        const gdr_cluster_group *g = &c->groups[n->group];
        if (n->first != g->first_cluster || n->count != g->cluster_count)
            FAIL("node %u: clusters %u (+%u), its group %u has %u (+%u)", i, n->first, n->count, n->group,
                 g->first_cluster, g->cluster_count);
        if (!contains(n->sphere, g->sphere) || !(n->max_error >= g->error))
            FAIL("node %u: does not contain its group %u's sphere or error", i, n->group);
    }
    if (!c->clusters) /* read for streaming: the pages hold the clusters */
        return c->group_count ? check_leaf_refinements(c, i, what, what_size) : 1;
    for (uint32_t k = n->first; k < n->first + n->count; k++) {
        const gdr_cluster *cl = &c->clusters[k];
        if (c->group_count == 0 && seen[k]++)
            FAIL("node %u: cluster %u is in two leaves", i, k);
        if (c->group_count && cl->group != n->group)
            FAIL("node %u: cluster %u belongs to group %u, not %u", i, k, cl->group, n->group);
        if (!contains(n->sphere, cl->sphere))
            FAIL("node %u: does not contain cluster %u's sphere", i, k);
        if (cl->refined_group == GDR_NO_INDEX) {
            if (n->min_refined_error != 0.0f)
                FAIL("node %u: cluster %u has no refined group, the refined error bound is not 0", i, k);
        } else if (cl->refined_group >= c->group_count ||
                   !contains(n->sphere, c->groups[cl->refined_group].sphere) ||
                   !(n->min_refined_error <= c->groups[cl->refined_group].error)) {
            FAIL("node %u: does not contain cluster %u's refined group sphere or error", i, k);
        }
    }
    return 1;
}

/* An inner node: its children come after it and have no other parent; its bounds contain theirs. */
static int check_inner(const gdr_mesh_clusters *c, uint32_t i, uint8_t *has_parent, uint32_t *level, char *what,
                       size_t what_size)
{
    const gdr_lod_node *n = &c->lod_nodes[i];
    if (n->group != GDR_NO_INDEX || n->count == 0 || n->count > GDR_LOD_NODE_MAX_CHILDREN || n->first <= i ||
        n->first > c->lod_node_count || n->count > c->lod_node_count - n->first)
        FAIL("node %u: children %u (+%u) are not 1 to %u nodes after it", i, n->first, n->count,
             GDR_LOD_NODE_MAX_CHILDREN);
    for (uint32_t k = n->first; k < n->first + n->count; k++) {
        const gdr_lod_node *child = &c->lod_nodes[k];
        if (has_parent[k]++)
            FAIL("node %u: child %u has two parents", i, k);
        level[k] = level[i] + 1;
        if (level[k] >= GDR_LOD_NODE_MAX_LEVELS)
            FAIL("node %u: deeper than %u levels", k, GDR_LOD_NODE_MAX_LEVELS);
        if (!contains(n->sphere, child->sphere))
            FAIL("node %u: does not contain child %u's sphere", i, k);
        if (!(n->max_error >= child->max_error) || !(n->min_refined_error <= child->min_refined_error))
            FAIL("node %u: error bounds do not contain child %u's", i, k);
    }
    return 1;
}

int gdr_mesh_clusters_check_hierarchy(const gdr_mesh_clusters *c, char *what, size_t what_size)
{
    if (c->cluster_count == 0) {
        if (c->lod_node_count != 0)
            FAIL("%u nodes for no cluster", c->lod_node_count);
        return 1;
    }
    if (c->lod_node_count == 0 || !c->lod_nodes)
        FAIL("no hierarchy");
    size_t items = c->group_count ? c->group_count : c->cluster_count;
    uint8_t *seen = calloc(items, 1), *has_parent = calloc(c->lod_node_count, 1);
    uint32_t *level = calloc(c->lod_node_count, sizeof *level);
    int ok = seen && has_parent && level;
    if (!ok)
        snprintf(what, what_size, "out of memory checking %u nodes", c->lod_node_count);
    uint32_t levels = 1, next_child = 1; /* breadth first: the children of node i follow those of i - 1 */
    for (uint32_t i = 0; ok && i < c->lod_node_count; i++) {
        const gdr_lod_node *n = &c->lod_nodes[i];
        if (!isfinite(n->sphere.x) || !isfinite(n->sphere.y) || !isfinite(n->sphere.z) || !isfinite(n->sphere.w) ||
            !(n->sphere.w >= 0.0f) || isnan(n->max_error) || !(n->min_refined_error >= 0.0f) ||
            (n->flags & ~GDR_LOD_NODE_LEAF) || n->reserved[0] || n->reserved[1]) {
            snprintf(what, what_size, "node %u: bounds not finite, or reserved bits set", i);
            ok = 0;
        } else {
            ok = (n->flags & GDR_LOD_NODE_LEAF) ? check_leaf(c, i, seen, what, what_size)
                                                : check_inner(c, i, has_parent, level, what, what_size);
        }
        if (ok && !(n->flags & GDR_LOD_NODE_LEAF)) {
            if (n->first != next_child) {
                snprintf(what, what_size, "node %u: children at %u, breadth-first order puts them at %u", i, n->first,
                         next_child);
                ok = 0;
            }
            next_child += n->count;
        }
        levels = ok && level[i] + 1 > levels ? level[i] + 1 : levels;
        if (ok && i > 0 && !has_parent[i]) {
            snprintf(what, what_size, "node %u: no parent before it", i);
            ok = 0;
        }
    }
    if (ok && next_child != c->lod_node_count) {
        snprintf(what, what_size, "%u nodes, %u reached from the root", c->lod_node_count, next_child);
        ok = 0;
    }
    for (size_t k = 0; ok && k < items; k++)
        if (!seen[k]) {
            snprintf(what, what_size, "%s %zu is in no leaf", c->group_count ? "group" : "cluster", k);
            ok = 0;
        }
    if (ok && levels != c->lod_node_levels) {
        snprintf(what, what_size, "%u levels, the mesh says %u", levels, c->lod_node_levels);
        ok = 0;
    }
    free(seen);
    free(has_parent);
    free(level);
    return ok;
}
