/* Simplifying a group the edge-collapse simplifier cannot: by vertex clustering
 * (meshopt_simplifySloppy). The DAG's steps only reach this where a whole step formed no group
 * (lod_dag.c, sloppy_step): then the whole frontier is one group, nothing of it locked (it has no
 * neighbour), and clustering its vertices on a grid merges what edge collapses never can: separate
 * pieces, and positions held by many vertices. Its output's corners are vertices of its input
 * (one kept per grid cell: meshoptimizer.h, "references vertices from the original vertex buffer"),
 * so the group's new clusters are mesh vertices like every other cluster's, and their error is
 * measured against level 0 like every other group's (lod_error.c), whatever the topology. */
#include <float.h>

#include "geometry/lod_internal.h"

/* The shares of the input a sloppy group asks for, in turn, until one keeps some triangles and at
 * most LOD_MAX_KEPT_SHARE of them (the share a group must reach to form). meshoptimizer 0.18 keeps
 * the finest grid it finds whose triangle count is at most the target, searching a few grid sizes,
 * and returns nothing where every grid it tried left none; on a small group the count jumps between
 * grid sizes, and another target leads its search to other sizes. */
static const double sloppy_shares[] = {0.5, 0.65, 0.8, 0.35, 0.25, 0.15};

/* Grids of at most this many cells a side are tried one by one where no target found a grid, on a
 * group of at most one cluster's triangles (a lone cluster on its way to the small root, where the
 * triangle count jumps between grid sizes; on larger groups the scan would cost more than the rest
 * of the build). */
#define SLOPPY_MAX_GRID 64

/* Clusters on a grid of `target` triangles (grid 0) or of `grid` cells a side: meshoptimizer 0.18
 * starts its search at 1 / target_error cells and stops there when that grid keeps at least the
 * target (one triangle). Returns the index count where it kept some triangles and at most
 * LOD_MAX_KEPT_SHARE of them (the share a group must reach to form), else 0. */
static size_t cluster(lod_scratch *s, size_t index_count, uint32_t vertex_count, size_t target, int grid)
{
    float target_error = grid ? 1.0f / ((float)grid + 0.5f) : FLT_MAX;
    size_t out = meshopt_simplifySloppy(s->simplified, s->indices, index_count, s->positions, vertex_count,
                                        sizeof(float) * 3, grid ? 3 : target, target_error, NULL);
    for (size_t k = 0; k < out; k++)
        if (s->simplified[k] >= vertex_count) /* never, by meshoptimizer's contract: then nothing */
            return 0;
    return out > 0 && (double)out <= (double)index_count * LOD_MAX_KEPT_SHARE ? out : 0;
}

size_t gdr_lod_simplify_sloppy(lod_scratch *s, size_t index_count, uint32_t vertex_count)
{
    for (size_t i = 0; i < sizeof sloppy_shares / sizeof sloppy_shares[0]; i++) {
        size_t target = (size_t)((double)(index_count / 3) * sloppy_shares[i]) * 3;
        size_t out = cluster(s, index_count, vertex_count, target < 3 ? 3 : target, 0);
        if (out)
            return out;
    }
    /* The finest grid that forms the group. */
    if (index_count / 3 > GDR_CLUSTER_MAX_TRIANGLES)
        return 0;
    int best = 0;
    for (int grid = 2; grid <= SLOPPY_MAX_GRID; grid++)
        if (cluster(s, index_count, vertex_count, 0, grid))
            best = grid;
    return best ? cluster(s, index_count, vertex_count, 0, best) : 0;
}
