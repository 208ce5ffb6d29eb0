/* The streaming page table on the GPU (page_table.c). */
#ifndef GDR_RENDER_PAGE_TABLE_H
#define GDR_RENDER_PAGE_TABLE_H

#include "render/renderer_internal.h"

/* The page table and the per-node absent counts (page_table.c), every group resident; fills the
 * meshes' page_table_offset. */
gdr_status gdr_page_table_create(gdr_renderer *r, const gdr_mesh_clusters *const *clusters, uint32_t mesh_count,
                                 gdr_error *err);
void gdr_page_table_destroy(gdr_renderer *r);
/* Counts mesh `mesh`'s absent groups into the scene's total (GDR_FRAME_PARTIAL_RESIDENCY). */
gdr_status gdr_page_table_set_absent(gdr_renderer *r, uint32_t mesh, uint32_t absent, gdr_error *err);

#endif
