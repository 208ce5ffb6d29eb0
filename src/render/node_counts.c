/* The LOD nodes' absent counts, updated per changed group (node_counts.h). For each group, the
 * leaves holding clusters made from it and how many (the group's references); for each node, its
 * parent. A group's change adds or takes its references' counts along each leaf's path to the root. */
#include "render/node_counts.h"

#include <stdlib.h>
#include <string.h>

#include "geometry/lod_cut.h"

#define NO_NODE UINT32_MAX

/* One reference of a group: `count` clusters of leaf `leaf` (global node) were made from it. */
typedef struct node_ref {
    uint32_t leaf, count;
} node_ref;

struct gdr_node_counts {
    uint32_t mesh_count, node_total, group_total;
    uint32_t *group_base;          /* per mesh + 1: its first global group */
    uint32_t *parent;              /* per global node: its parent, NO_NODE for a root */
    uint32_t *ref_first, *ref_len; /* per global group: its references in refs */
    node_ref *refs;
    uint32_t *counts;              /* per global node */
    uint8_t *resident;             /* per global group */
    uint32_t *absent;              /* per mesh: absent groups */
    uint8_t *changed;              /* per global node: listed in changed_list */
    uint32_t *changed_list, changed_count;
};

static void mark_changed(gdr_node_counts *nc, uint32_t node)
{
    if (!nc->changed[node]) {
        nc->changed[node] = 1;
        nc->changed_list[nc->changed_count++] = node;
    }
}

/* The parents of mesh m's nodes. A child always comes after its parent (breadth first); children
 * that do not, or lie beyond the mesh's nodes, are left out (a checked hierarchy has none), so that
 * every walk up ends. */
static void link_parents(gdr_node_counts *nc, const gdr_mesh_clusters *c, uint32_t offset)
{
    for (uint32_t n = 0; n < c->lod_node_count; n++) {
        const gdr_lod_node *node = &c->lod_nodes[n];
        if (node->flags & GDR_LOD_NODE_LEAF)
            continue;
        for (uint32_t k = node->first; k < node->first + node->count && k < c->lod_node_count; k++)
            if (k > n)
                nc->parent[offset + k] = offset + n;
    }
}

/* Leaf n's refinements in a mesh read for streaming (no clusters): visit(group of each, leaf, its
 * clusters). */
static void for_each_leaf_refinement(gdr_node_counts *nc, const gdr_mesh_clusters *c, uint32_t n, uint32_t offset,
                                     uint32_t group_base, void (*visit)(gdr_node_counts *, uint32_t, uint32_t, uint32_t))
{
    uint32_t group = c->lod_nodes[n].group;
    for (uint32_t k = gdr_lod_first_refinement(c, group); k < c->refinement_count && c->refinements[k].group == group;
         k++)
        if (c->refinements[k].refined_group < c->group_count)
            visit(nc, group_base + c->refinements[k].refined_group, offset + n, c->refinements[k].cluster_count);
}

/* Calls visit(nc, global group, global leaf, clusters) for the clusters of every leaf of mesh m
 * that have a refined group: one cluster at a time, or where the mesh was read for streaming,
 * its leaf's group's refinements (how many of its clusters came from each group). */
static void for_each_ref(gdr_node_counts *nc, const gdr_mesh_clusters *c, uint32_t offset, uint32_t group_base,
                         void (*visit)(gdr_node_counts *, uint32_t, uint32_t, uint32_t))
{
    for (uint32_t n = 0; n < c->lod_node_count; n++) {
        const gdr_lod_node *node = &c->lod_nodes[n];
        if (!(node->flags & GDR_LOD_NODE_LEAF))
            continue;
        if (!c->clusters) {
            for_each_leaf_refinement(nc, c, n, offset, group_base, visit);
            continue;
        }
        for (uint32_t i = node->first; i < node->first + node->count && i < c->cluster_count; i++) {
            uint32_t r = c->clusters[i].refined_group;
            if (r != GDR_NO_INDEX && r < c->group_count)
                visit(nc, group_base + r, offset + n, 1);
        }
    }
}

static void count_ref(gdr_node_counts *nc, uint32_t group, uint32_t leaf, uint32_t clusters)
{
    (void)leaf, (void)clusters;
    nc->ref_len[group]++;
}

/* Leaves are visited in order, so a leaf's clusters of one group are consecutive references. */
static void add_ref(gdr_node_counts *nc, uint32_t group, uint32_t leaf, uint32_t clusters)
{
    node_ref *list = nc->refs + nc->ref_first[group];
    uint32_t *len = &nc->ref_len[group];
    if (*len > 0 && list[*len - 1].leaf == leaf)
        list[*len - 1].count += clusters;
    else
        list[(*len)++] = (node_ref){leaf, clusters};
}

/* The per-mesh passes of the creation, one task per mesh on a thread pool: each writes only its own
 * mesh's nodes (parents, counts) and groups (references), so the result does not depend on the
 * threads. */
typedef struct create_job {
    gdr_node_counts *nc;
    const gdr_mesh_clusters *const *meshes;
    const uint32_t *offsets;
} create_job;

/* Mesh m's parents and its groups' reference counts. */
static void link_task(void *user, uint32_t m, uint32_t worker)
{
    const create_job *job = user;
    (void)worker;
    link_parents(job->nc, job->meshes[m], job->offsets[m]);
    for_each_ref(job->nc, job->meshes[m], job->offsets[m], job->nc->group_base[m], count_ref);
}

/* Mesh m's counts with every group absent, from its groups' references. */
static void count_absent_from_refs(gdr_node_counts *nc, uint32_t m)
{
    for (uint32_t g = nc->group_base[m]; g < nc->group_base[m + 1]; g++)
        for (uint32_t i = 0; i < nc->ref_len[g]; i++) {
            const node_ref *ref = &nc->refs[nc->ref_first[g] + i];
            for (uint32_t node = ref->leaf; node != NO_NODE; node = nc->parent[node])
                nc->counts[node] += ref->count;
        }
}

/* Mesh m's references, then its counts with every group absent. A mesh read for streaming has no
 * clusters to count: each group's references add up the same counts along their paths. */
static void count_task(void *user, uint32_t m, uint32_t worker)
{
    const create_job *job = user;
    gdr_node_counts *nc = job->nc;
    (void)worker;
    for_each_ref(nc, job->meshes[m], job->offsets[m], nc->group_base[m], add_ref);
    if (job->meshes[m]->clusters)
        gdr_lod_nodes_count_absent_refined(job->meshes[m], nc->resident + nc->group_base[m],
                                           nc->counts + job->offsets[m]);
    else
        count_absent_from_refs(nc, m);
}

/* Runs task over every mesh, on the pool where there is one. */
static void for_each_mesh(gdr_thread_pool *pool, const create_job *job, gdr_task_fn *task)
{
    if (pool)
        gdr_thread_pool_run(pool, job->nc->mesh_count, task, (void *)job);
    else
        for (uint32_t m = 0; m < job->nc->mesh_count; m++)
            task((void *)job, m, 0);
}

/* The groups' references: counted per mesh (link_task), placed, then filled with the counts
 * (count_task). */
static gdr_status build_refs(gdr_node_counts *nc, const create_job *job, gdr_thread_pool *pool, gdr_error *err)
{
    for_each_mesh(pool, job, link_task);
    uint64_t total = 0;
    for (uint32_t g = 0; g < nc->group_total; g++) {
        nc->ref_first[g] = (uint32_t)total;
        total += nc->ref_len[g];
        nc->ref_len[g] = 0;
    }
    if (total > UINT32_MAX || !(nc->refs = malloc(sizeof *nc->refs * (total ? total : 1))))
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "node counts: out of memory for %llu references",
                             (unsigned long long)total);
    for_each_mesh(pool, job, count_task);
    return GDR_OK;
}

static gdr_status allocate(gdr_node_counts *nc, const gdr_mesh_clusters *const *meshes, const uint32_t *offsets,
                           gdr_error *err)
{
    uint64_t groups = 0, nodes = 0;
    for (uint32_t m = 0; m < nc->mesh_count; m++) {
        groups += meshes[m]->group_count;
        uint64_t end = (uint64_t)offsets[m] + meshes[m]->lod_node_count;
        nodes = end > nodes ? end : nodes;
    }
    if (groups > UINT32_MAX / 2 || nodes > UINT32_MAX / 2)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "node counts: %llu groups, %llu nodes",
                             (unsigned long long)groups, (unsigned long long)nodes);
    nc->group_total = (uint32_t)groups;
    nc->node_total = (uint32_t)nodes;
    size_t g = groups ? groups : 1, n = nodes ? nodes : 1;
    nc->group_base = malloc(sizeof *nc->group_base * ((size_t)nc->mesh_count + 1));
    nc->parent = malloc(sizeof *nc->parent * n);
    nc->ref_first = malloc(sizeof *nc->ref_first * g);
    nc->ref_len = calloc(g, sizeof *nc->ref_len);
    nc->counts = calloc(n, sizeof *nc->counts);
    nc->resident = calloc(g, 1);
    nc->absent = calloc(nc->mesh_count ? nc->mesh_count : 1, sizeof *nc->absent);
    nc->changed = calloc(n, 1);
    nc->changed_list = malloc(sizeof *nc->changed_list * n);
    if (!nc->group_base || !nc->parent || !nc->ref_first || !nc->ref_len || !nc->counts || !nc->resident ||
        !nc->absent || !nc->changed || !nc->changed_list)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "node counts: out of memory for %llu nodes",
                             (unsigned long long)nodes);
    return GDR_OK;
}


gdr_status gdr_node_counts_create(const gdr_mesh_clusters *const *meshes, const uint32_t *node_offsets,
                                  uint32_t mesh_count, gdr_node_counts **out, gdr_error *err)
{
    return gdr_node_counts_create_on(meshes, node_offsets, mesh_count, NULL, out, err);
}

gdr_status gdr_node_counts_create_on(const gdr_mesh_clusters *const *meshes, const uint32_t *node_offsets,
                                     uint32_t mesh_count, gdr_thread_pool *pool, gdr_node_counts **out,
                                     gdr_error *err)
{
    *out = NULL;
    gdr_node_counts *nc = calloc(1, sizeof *nc);
    if (!nc)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "node counts: out of memory");
    nc->mesh_count = mesh_count;
    gdr_status status = allocate(nc, meshes, node_offsets, err);
    if (status == GDR_OK) {
        uint32_t groups = 0;
        for (uint32_t m = 0; m < mesh_count; m++) {
            nc->group_base[m] = groups;
            groups += meshes[m]->group_count;
            nc->absent[m] = meshes[m]->group_count;
        }
        nc->group_base[mesh_count] = groups;
        memset(nc->parent, 0xff, sizeof *nc->parent * nc->node_total);
        create_job job = {nc, meshes, node_offsets};
        status = build_refs(nc, &job, pool, err);
    }
    if (status != GDR_OK) {
        gdr_node_counts_destroy(nc);
        return status;
    }
    /* Every group absent (the counts build_refs made): every node changed. */
    for (uint32_t m = 0; m < mesh_count; m++)
        for (uint32_t n = 0; n < meshes[m]->lod_node_count; n++)
            mark_changed(nc, node_offsets[m] + n);
    *out = nc;
    return GDR_OK;
}

void gdr_node_counts_destroy(gdr_node_counts *nc)
{
    if (!nc)
        return;
    free(nc->group_base), free(nc->parent), free(nc->ref_first), free(nc->ref_len), free(nc->refs);
    free(nc->counts), free(nc->resident), free(nc->absent), free(nc->changed), free(nc->changed_list);
    free(nc);
}

uint32_t gdr_node_counts_set(gdr_node_counts *nc, uint32_t mesh, uint32_t group, bool resident)
{
    uint32_t g = nc->group_base[mesh] + group, touched = 0;
    if (group >= nc->group_base[mesh + 1] - nc->group_base[mesh] || nc->resident[g] == resident)
        return 0;
    nc->resident[g] = resident;
    nc->absent[mesh] += resident ? (uint32_t)-1 : 1u;
    const node_ref *refs = nc->refs + nc->ref_first[g];
    for (uint32_t i = 0; i < nc->ref_len[g]; i++) {
        /* The leaf and each ancestor count these clusters once. */
        for (uint32_t node = refs[i].leaf; node != NO_NODE; node = nc->parent[node], touched++) {
            nc->counts[node] += resident ? (uint32_t)0 - refs[i].count : refs[i].count;
            mark_changed(nc, node);
        }
    }
    return touched;
}

const uint32_t *gdr_node_counts_words(const gdr_node_counts *nc) { return nc->counts; }
uint32_t gdr_node_counts_absent_groups(const gdr_node_counts *nc, uint32_t mesh) { return nc->absent[mesh]; }
uint32_t gdr_node_counts_node_total(const gdr_node_counts *nc) { return nc->node_total; }

static int compare_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* The changed nodes in ascending order into changed_list: sorted where they are few, read off the
 * flags in one pass where they are many (the first frame changes every node: a sort of the whole
 * scene's nodes would cost O(n log n) where the pass costs O(n)). */
static void order_changes(gdr_node_counts *nc)
{
    if (nc->changed_count < nc->node_total / 16) {
        qsort(nc->changed_list, nc->changed_count, sizeof *nc->changed_list, compare_u32);
        return;
    }
    uint32_t at = 0;
    for (uint32_t node = 0; node < nc->node_total; node++)
        if (nc->changed[node])
            nc->changed_list[at++] = node;
}

uint32_t gdr_node_counts_take_changes(gdr_node_counts *nc, gdr_node_run *runs, uint32_t *words)
{
    order_changes(nc);
    uint32_t count = 0;
    for (uint32_t i = 0; i < nc->changed_count; i++) {
        uint32_t node = nc->changed_list[i];
        nc->changed[node] = 0;
        if (count > 0 && runs[count - 1].first + runs[count - 1].count == node)
            runs[count - 1].count++;
        else
            runs[count++] = (gdr_node_run){node, 1};
    }
    *words = nc->changed_count;
    nc->changed_count = 0;
    return count;
}
