/* The CPU reference of the LOD cut (lod_cut.h): each cluster on its own, as the GPU does it. */
#include "geometry/lod_cut.h"

#include <math.h>

#include <string.h>

#include "gdr/scene.h"

float gdr_lod_projection_scale(const gdr_lod_view *view)
{
    return view->projection_y * 0.5f * view->viewport_height;
}

bool gdr_lod_group_passes(const gdr_mesh_clusters *clusters, uint32_t group, const gdr_lod_view *view)
{
    const float *m = view->transform.m;
    gdr_vec3 c0 = {m[0], m[1], m[2]}, c1 = {m[4], m[5], m[6]}, c2 = {m[8], m[9], m[10]}, c3 = {m[12], m[13], m[14]};
    const gdr_cluster_group *g = &clusters->groups[group];
    float e = gdr_lod_group_projected_error(g->sphere, g->error, c0, c1, c2, c3, view->camera_position, view->znear,
                                            gdr_lod_projection_scale(view));
    return e <= view->threshold;
}

static uint32_t select_cluster(const gdr_mesh_clusters *clusters, uint32_t i, const gdr_lod_view *view,
                               uint8_t *selected)
{
    const gdr_cluster *c = &clusters->clusters[i];
    bool refined = c->refined_group == GDR_NO_INDEX || gdr_lod_group_passes(clusters, c->refined_group, view);
    bool group = c->group != GDR_NO_INDEX && gdr_lod_group_passes(clusters, c->group, view);
    selected[i] = gdr_lod_cluster_drawn(refined, group);
    return selected[i];
}

uint32_t gdr_lod_cut_select(const gdr_mesh_clusters *clusters, const gdr_lod_view *view, uint8_t *selected)
{
    uint32_t count = 0;
    for (uint32_t i = 0; i < clusters->cluster_count; i++)
        count += select_cluster(clusters, i, view, selected);
    return count;
}

/* The rule with absent groups counted as passing (lod_cut.h). */
static uint32_t select_cluster_resident(const gdr_mesh_clusters *clusters, uint32_t i, const gdr_lod_view *view,
                                        const uint8_t *group_resident, uint8_t *selected)
{
    const gdr_cluster *c = &clusters->clusters[i];
    uint32_t r = c->refined_group, g = c->group;
    bool refined = r == GDR_NO_INDEX || !group_resident[r] || gdr_lod_group_passes(clusters, r, view);
    bool group = g != GDR_NO_INDEX && (!group_resident[g] || gdr_lod_group_passes(clusters, g, view));
    selected[i] = gdr_lod_cluster_drawn(refined, group);
    return selected[i];
}

uint32_t gdr_lod_cut_select_resident(const gdr_mesh_clusters *clusters, const gdr_lod_view *view,
                                     const uint8_t *group_resident, uint8_t *selected)
{
    uint32_t count = 0;
    for (uint32_t i = 0; i < clusters->cluster_count; i++)
        count += select_cluster_resident(clusters, i, view, group_resident, selected);
    return count;
}

static bool node_may_draw(const gdr_lod_node *n, const gdr_lod_view *view)
{
    const float *m = view->transform.m;
    gdr_vec3 c0 = {m[0], m[1], m[2]}, c1 = {m[4], m[5], m[6]}, c2 = {m[8], m[9], m[10]}, c3 = {m[12], m[13], m[14]};
    return gdr_lod_node_may_draw(n->sphere, n->max_error, n->min_refined_error, c0, c1, c2, c3, view->camera_position,
                                 view->znear, gdr_lod_projection_scale(view), view->threshold);
}

uint32_t gdr_lod_cut_select_hierarchical(const gdr_mesh_clusters *clusters, const gdr_lod_view *view,
                                         uint8_t *selected, gdr_lod_traversal_stats *stats)
{
    if (clusters->lod_node_count == 0) {
        if (stats)
            stats->clusters_tested += clusters->cluster_count;
        return gdr_lod_cut_select(clusters, view, selected);
    }
    memset(selected, 0, clusters->cluster_count);
    /* Depth first; a node's children wait on the stack: at most (MAX_CHILDREN - 1) per level. */
    uint32_t stack[GDR_LOD_NODE_MAX_CHILDREN * GDR_LOD_NODE_MAX_LEVELS], top = 0, count = 0;
    gdr_lod_traversal_stats local = {0};
    stack[top++] = 0;
    while (top > 0) {
        const gdr_lod_node *n = &clusters->lod_nodes[stack[--top]];
        local.nodes_tested++;
        if (!node_may_draw(n, view))
            continue;
        if (!(n->flags & GDR_LOD_NODE_LEAF)) {
            for (uint32_t k = n->count; k-- > 0;)
                stack[top++] = n->first + k;
            continue;
        }
        local.leaves_accepted++;
        local.clusters_tested += n->count;
        for (uint32_t i = n->first; i < n->first + n->count; i++)
            count += select_cluster(clusters, i, view, selected);
    }
    if (stats) {
        stats->nodes_tested += local.nodes_tested;
        stats->leaves_accepted += local.leaves_accepted;
        stats->clusters_tested += local.clusters_tested;
    }
    return count;
}

void gdr_lod_nodes_count_absent_refined(const gdr_mesh_clusters *clusters, const uint8_t *group_resident,
                                        uint32_t *absent)
{
    /* Breadth first: children come after their parent, so a reverse walk sees them first. */
    for (uint32_t n = clusters->lod_node_count; n-- > 0;) {
        const gdr_lod_node *node = &clusters->lod_nodes[n];
        uint32_t count = 0;
        for (uint32_t i = node->first; i < node->first + node->count; i++) {
            if (!(node->flags & GDR_LOD_NODE_LEAF)) {
                count += absent[i];
                continue;
            }
            uint32_t r = clusters->clusters[i].refined_group;
            count += r != GDR_NO_INDEX && !group_resident[r];
        }
        absent[n] = count;
    }
}

/* The node test with absent groups: side (1) (every group below passes) holds as it is; side (2)
 * (no refined group below passes) only where none below is absent. */
static bool node_may_draw_resident(const gdr_lod_node *n, uint32_t absent, const gdr_lod_view *view)
{
    gdr_lod_node relaxed = *n;
    if (absent > 0)
        relaxed.min_refined_error = 0.0f; /* a cluster below always "passes" its refined side */
    return node_may_draw(&relaxed, view);
}

uint32_t gdr_lod_cut_select_hierarchical_resident(const gdr_mesh_clusters *clusters, const gdr_lod_view *view,
                                                  const uint8_t *group_resident, const uint32_t *absent,
                                                  uint8_t *selected, gdr_lod_traversal_stats *stats)
{
    memset(selected, 0, clusters->cluster_count);
    uint32_t stack[GDR_LOD_NODE_MAX_CHILDREN * GDR_LOD_NODE_MAX_LEVELS], top = 0, count = 0;
    gdr_lod_traversal_stats local = {0};
    if (clusters->lod_node_count)
        stack[top++] = 0;
    while (top > 0) {
        uint32_t index = stack[--top];
        const gdr_lod_node *n = &clusters->lod_nodes[index];
        local.nodes_tested++;
        if (!node_may_draw_resident(n, absent[index], view))
            continue;
        if (!(n->flags & GDR_LOD_NODE_LEAF)) {
            for (uint32_t k = n->count; k-- > 0;)
                stack[top++] = n->first + k;
            continue;
        }
        local.leaves_accepted++;
        local.clusters_tested += n->count;
        for (uint32_t i = n->first; i < n->first + n->count; i++)
            count += select_cluster_resident(clusters, i, view, group_resident, selected);
    }
    if (stats) {
        stats->nodes_tested += local.nodes_tested;
        stats->leaves_accepted += local.leaves_accepted;
        stats->clusters_tested += local.clusters_tested;
    }
    return count;
}

static bool depth_passes(const gdr_mesh_clusters *clusters, uint32_t group, uint32_t depth)
{
    return clusters->groups[group].depth < depth && !isinf(clusters->groups[group].error);
}

uint32_t gdr_lod_cut_select_depth(const gdr_mesh_clusters *clusters, uint32_t depth, uint8_t *selected)
{
    uint32_t count = 0;
    for (uint32_t i = 0; i < clusters->cluster_count; i++) {
        const gdr_cluster *c = &clusters->clusters[i];
        bool refined = c->refined_group == GDR_NO_INDEX || depth_passes(clusters, c->refined_group, depth);
        bool group = c->group != GDR_NO_INDEX && depth_passes(clusters, c->group, depth);
        selected[i] = gdr_lod_cluster_drawn(refined, group);
        count += selected[i];
    }
    return count;
}
