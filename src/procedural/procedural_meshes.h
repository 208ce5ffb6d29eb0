/* Procedural meshes for the built-in scene. Each builds a triangle list (CCW front faces) into
 * caller-owned growing arrays and adds it to the scene. */
#ifndef GDR_PROCEDURAL_MESHES_H
#define GDR_PROCEDURAL_MESHES_H

#include "gdr/scene.h"

gdr_status gdr_procedural_sphere(gdr_scene *scene, uint32_t slices, uint32_t stacks, uint32_t *out_mesh,
                                 gdr_error *err);
gdr_status gdr_procedural_torus(gdr_scene *scene, float major_radius, float minor_radius, uint32_t segments,
                                uint32_t sides, uint32_t *out_mesh, gdr_error *err);
gdr_status gdr_procedural_box(gdr_scene *scene, gdr_vec3 half_extent, uint32_t *out_mesh, gdr_error *err);
/* An icosphere subdivided `levels` times with a smooth radial displacement: a dense closed mesh. */
gdr_status gdr_procedural_blob(gdr_scene *scene, uint32_t levels, uint32_t *out_mesh, gdr_error *err);
/* A bumpy (2, 3) torus knot: a tube along a trefoil, `segments` rings of `sides` vertices, welded
 * (closed and watertight: every edge has exactly two triangles), 2 * segments * sides triangles,
 * scaled so that every vertex lies within 1 of the origin. Normals come from the faces. Needs
 * segments >= 24 and sides >= 4. */
gdr_status gdr_procedural_torus_knot(gdr_scene *scene, uint32_t segments, uint32_t sides, uint32_t *out_mesh,
                                     gdr_error *err);
/* A square grid of quads in the XZ plane, facing +Y, centred on the origin. */
gdr_status gdr_procedural_ground(gdr_scene *scene, float half_size, uint32_t cells, uint32_t *out_mesh,
                                 gdr_error *err);

#endif
