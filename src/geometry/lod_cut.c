/* The CPU reference of the LOD cut (lod_cut.h): each cluster on its own, as the GPU does it. */
#include "geometry/lod_cut.h"

#include <math.h>

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

uint32_t gdr_lod_cut_select(const gdr_mesh_clusters *clusters, const gdr_lod_view *view, uint8_t *selected)
{
    uint32_t count = 0;
    for (uint32_t i = 0; i < clusters->cluster_count; i++) {
        const gdr_cluster *c = &clusters->clusters[i];
        bool refined = c->refined_group == GDR_NO_INDEX || gdr_lod_group_passes(clusters, c->refined_group, view);
        bool group = c->group != GDR_NO_INDEX && gdr_lod_group_passes(clusters, c->group, view);
        selected[i] = gdr_lod_cluster_drawn(refined, group);
        count += selected[i];
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
