/* Knobs for tests only, kept out of the public API: capacities forced small to provoke overflows,
 * a deliberately wrong LOD hierarchy, residency set by hand. */
#ifndef GDR_RENDERER_DEBUG_H
#define GDR_RENDERER_DEBUG_H

#include <stdbool.h>
#include <stdint.h>

#include "gdr/renderer.h"

typedef struct gdr_renderer_debug {
    /* The task list's and the LOD traversal's capacities per frame phase, and the occluded-node
     * list's (0: sized from the scene), to provoke their overflow, which the statistics report. */
    uint32_t task_capacity;
    uint32_t traversal_capacity;
    uint32_t occluded_node_capacity;
    /* A deliberately wrong LOD hierarchy (node spheres shrunk), to show that the image tests catch
     * a node test that is not conservative. */
    bool shrink_lod_nodes;
    /* The compute rasteriser's tiny path (several tiny clusters per workgroup): off, every cluster
     * then one to a workgroup as without it; or its part of the visible-cluster list forced small
     * (0: sized from the scene), to show that the clusters that find it full are still drawn. */
    bool tiny_raster_off;
    uint32_t tiny_raster_capacity;
    /* Streamed: every record of the record pool set up as one that any test would find drawn (no
     * group, no refined group, no triangles, a sphere over everything) until a page writes it, to
     * show that no shader reads a record no resident page wrote (none is uploaded otherwise). */
    bool poison_absent_records;
} gdr_renderer_debug;

/* Applies `debug` to the scenes set after this call (call it between gdr_renderer_create and
 * gdr_renderer_set_scene). */
void gdr_renderer_set_debug(gdr_renderer *renderer, const gdr_renderer_debug *debug);

/* Tests: marks the groups of mesh `mesh` absent where group_resident[g] is 0 (its cluster data's
 * group_count entries), as a streaming residency would, with node_absent_refined its
 * lod_node_count counts of the clusters below each node whose refined group is absent. The
 * traversal and the cluster tests then draw the cut over resident groups (docs/STREAMING.md): an
 * absent group counts as passing. The geometry itself stays uploaded. Waits for the GPU. */
gdr_status gdr_renderer_debug_set_residency(gdr_renderer *renderer, uint32_t mesh,
                                                    const uint8_t *group_resident,
                                                    const uint32_t *node_absent_refined, gdr_error *err);

/* Tests: reads back mesh `mesh`'s LOD nodes' absent counts as the GPU holds them (lod_node_count
 * words): with gdr_renderer_read_residency, a check that the incremental updates of a streamed
 * scene's counts equal gdr_lod_nodes_count_absent_refined over its page table. Waits for the GPU. */
gdr_status gdr_renderer_debug_read_node_counts(gdr_renderer *renderer, uint32_t mesh, uint32_t *counts,
                                               gdr_error *err);

#endif
