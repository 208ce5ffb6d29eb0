/* Meshlet building whose work stays linear on hostile meshes (meshlet_chunks.c): meshoptimizer
 * 0.18's builder is quadratic when its kd-tree of triangle centroids cannot split them. */
#ifndef GDR_GEOMETRY_MESHLET_CHUNKS_H
#define GDR_GEOMETRY_MESHLET_CHUNKS_H

#include <stddef.h>
#include <stdint.h>

#include "gdr/scene.h"

struct meshopt_Meshlet;

/* True when meshoptimizer's kd-tree over this mesh's triangles would hold a leaf of more than 256
 * triangles (or building it would take more than 64 passes): then build in chunks. */
int gdr_meshlet_needs_chunks(const gdr_mesh *mesh);
/* The meshlets, vertices (times max_vertices) and triangle bytes (times max_triangles * 3) that
 * gdr_meshlet_build_chunks may write. */
size_t gdr_meshlet_chunks_bound(const gdr_mesh *mesh, uint32_t max_vertices, uint32_t max_triangles);
/* meshopt_buildMeshlets over consecutive chunks of 4096 triangles, results concatenated as one
 * build would lay them out (vertex indices global, triangle data 4-byte aligned per meshlet).
 * Returns the meshlet count, 0 on failure. */
size_t gdr_meshlet_build_chunks(const gdr_mesh *mesh, uint32_t max_vertices, uint32_t max_triangles,
                                float cone_weight, struct meshopt_Meshlet *meshlets, unsigned int *vertices,
                                unsigned char *triangles);

#endif
