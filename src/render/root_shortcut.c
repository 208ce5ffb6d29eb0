/* The root shortcut and root chain of a mesh (root_shortcut.h). */
#include "render/root_shortcut.h"

#include <math.h>

#include "gdr/geometry.h" /* gdr_lod_enclosing_sphere */

uint32_t gdr_cluster_refined_of_clusters(const void *user, uint32_t cluster, bool *known)
{
    const gdr_mesh_clusters *c = user;
    *known = c->clusters && cluster < c->cluster_count;
    return *known ? c->clusters[cluster].refined_group : GDR_NO_INDEX;
}

/* The root chain (GdrGpuMesh.root_chain): from a root group of one cluster, the lone clusters it was
 * made from, step by step, while each is its group's only cluster and lies just before the one
 * made from it. Such a group was the whole frontier of its step (its step made one cluster, the
 * next frontier whole), so every other group of the DAG is below the group it was made from: where
 * that group passes, the cut is this one cluster. */
static uint32_t root_chain(const gdr_mesh_clusters *c, gdr_cluster_refined_fn *refined, const void *user)
{
    const gdr_cluster_group *root = &c->groups[c->group_count - 1];
    if (root->cluster_count != 1)
        return 0;
    uint32_t chain = 1, at = root->first_cluster;
    while (chain < GDR_LOD_ROOT_CHAIN && at > 0) {
        bool known = true;
        uint32_t from = refined(user, at, &known);
        if (!known || from == GDR_NO_INDEX || from >= c->group_count || c->groups[from].cluster_count != 1 ||
            c->groups[from].first_cluster != at - 1)
            break;
        at--;
        chain++;
    }
    return chain;
}

/* The root shortcut of a mesh with a DAG (GdrGpuMesh.root_*): the root group is the last one. */
void gdr_root_shortcut_set(const gdr_mesh_clusters *c, gdr_cluster_refined_fn *refined_of, const void *user,
                           GdrGpuMesh *mesh)
{
    const gdr_cluster_group *root = &c->groups[c->group_count - 1];
    mesh->root_first = root->first_cluster;
    mesh->root_cluster_count = root->cluster_count;
    /* Each distinct refined group once: the root's clusters come from a handful of groups. */
    gdr_vec4 spheres[64];
    uint32_t seen[64], n = 0;
    float error = 0.0f;
    bool fits = true;
    for (uint32_t i = root->first_cluster; i < root->first_cluster + root->cluster_count && fits; i++) {
        bool known = true;
        uint32_t refined = refined_of(user, i, &known);
        if (!known || (refined != GDR_NO_INDEX && refined >= c->group_count)) {
            fits = false;
            break;
        }
        if (refined == GDR_NO_INDEX)
            continue; /* always passes */
        bool listed = false;
        for (uint32_t j = 0; j < n && !listed; j++)
            listed = seen[j] == refined;
        if (listed)
            continue;
        if (n == 64) {
            fits = false;
            break;
        }
        seen[n] = refined;
        spheres[n++] = c->groups[refined].sphere;
        error = fmaxf(error, c->groups[refined].error);
    }
    if (!fits) { /* no shortcut: the per-cluster test decides */
        mesh->root_cluster_count = 0;
        return;
    }
    /* One refined group: its own sphere, so that the shortcut tests what the cluster test would. */
    mesh->root_refined_sphere = n > 1 ? gdr_lod_enclosing_sphere(spheres, n) : n ? spheres[0] : (gdr_vec4){0, 0, 0, 0};
    mesh->root_refined_error = error;
    mesh->root_chain = root_chain(c, refined_of, user);
}

