/* The procedural meshes the LOD benches share by name: blob, knot, torus-1m, and torus-UxV
 * (torus-1m's shape with U x V quads). */
#ifndef GDR_BENCH_PROCEDURAL_SET_H
#define GDR_BENCH_PROCEDURAL_SET_H

#include "gdr/scene.h"

/* Adds the procedural mesh `name` to the scene (its index in *mesh, which may be NULL). Returns 0
 * where `name` is none of the set (nothing added), 1 where it is (*status then says how it went). */
int bench_procedural_mesh(gdr_scene *scene, const char *name, uint32_t *mesh, gdr_status *status, gdr_error *err);

#endif
