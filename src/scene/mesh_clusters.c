/* Ownership of gdr_mesh_clusters. */
#include <stdlib.h>
#include <string.h>

#include "gdr/mesh_clusters.h"

void gdr_mesh_clusters_free(gdr_mesh_clusters *clusters)
{
    if (!clusters)
        return;
    free(clusters->clusters);
    free(clusters->vertices);
    free(clusters->triangles);
    free(clusters->groups);
    free(clusters->lod_nodes);
    free(clusters->group_bounds);
    free(clusters->refinements);
    memset(clusters, 0, sizeof *clusters);
}
