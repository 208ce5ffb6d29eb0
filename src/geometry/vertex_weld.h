/* Vertices whose attributes are all bit-equal made one before a mesh is cut into clusters
 * (docs/GEOMETRY.md, "Welding equal vertices"). */
#ifndef GDR_GEOMETRY_VERTEX_WELD_H
#define GDR_GEOMETRY_VERTEX_WELD_H

#include <stdint.h>

#include "gdr/core.h"
#include "gdr/scene.h"

/* A welded vertex serves at most this many triangle corners; equal vertices beyond that stay
 * separate copies. The importers split vertices of more uses into copies of this many
 * (GDR_IO_MAX_VERTEX_VALENCE, which must equal it), and meshoptimizer's meshlet builder is
 * quadratic in a vertex's uses: the weld must not join the copies again. */
#define GDR_WELD_MAX_VERTEX_USES 128u

/* Makes the mesh's vertices whose position, normal, uv and colour are equal bit for bit one
 * vertex (meshoptimizer's remap), in the order of their first vertex, as long as the one vertex
 * serves at most GDR_WELD_MAX_VERTEX_USES corners. A mesh with no two such vertices, or with an
 * index out of range (left for gdr_meshlets_build to report), is left exactly as it is. Must run
 * before the mesh has clusters. Sets *welded to the number of vertices removed (may be NULL). */
gdr_status gdr_mesh_weld_vertices(gdr_mesh *mesh, uint32_t *welded, gdr_error *err);

#endif
