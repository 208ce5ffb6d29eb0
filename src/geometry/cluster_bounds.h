/* Culling bounds of a cluster, shared by the meshlet builder (meshlets.c, which defines it) and
 * the LOD DAG (lod_group.c), so clusters of every level keep the contract of gdr/geometry.h: a
 * sphere reaching every vertex and a conservative normal cone (or none). */
#ifndef GDR_GEOMETRY_CLUSTER_BOUNDS_H
#define GDR_GEOMETRY_CLUSTER_BOUNDS_H

#include <stdint.h>

#include "gdr/geometry.h"
#include "gdr/scene.h"

/* Sets c->sphere and the cone of cluster c (vertex_count and triangle_count set) whose vertex list
 * (mesh vertex indices) and local triangles are given. */
void gdr_cluster_compute_bounds(gdr_cluster *c, const uint32_t *vertices, const uint8_t *triangles,
                                const gdr_mesh *mesh);

#endif
