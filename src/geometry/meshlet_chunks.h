/* Meshlet building whose work stays linear on hostile meshes (meshlet_chunks.c): meshoptimizer
 * 0.18's builder is quadratic when its kd-tree of triangle centroids cannot split them. */
#ifndef GDR_GEOMETRY_MESHLET_CHUNKS_H
#define GDR_GEOMETRY_MESHLET_CHUNKS_H

#include "gdr/scene.h"

/* Triangles per chunk for a mesh gdr_meshlet_needs_chunks flags: the most one kd-tree leaf can
 * then hold, so a meshlet search costs at most that. */
#define GDR_MESHLET_HOSTILE_CHUNK 4096u

/* True when meshoptimizer's kd-tree over this mesh's triangles would hold a leaf of more than 256
 * triangles (or building it would take more than 64 passes): build its meshlets in chunks of
 * GDR_MESHLET_HOSTILE_CHUNK triangles. */
int gdr_meshlet_needs_chunks(const gdr_mesh *mesh);

#endif
