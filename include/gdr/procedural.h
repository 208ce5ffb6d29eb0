/* gdr procedural scenes: the built-in scenes, generated (a module beside the importers, above the
 * scene model and the geometry builders: each scene comes with its level-0 clusters).
 * gdr_scene_load (gdr/io.h) builds them from a name such as "demo:instances=100". */
#ifndef GDR_PROCEDURAL_H
#define GDR_PROCEDURAL_H

#include <stdbool.h>
#include <stdint.h>

#include "gdr/core.h"
#include "gdr/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The built-in procedural scene: procedural meshes (sphere, torus, box, a dense displaced shape)
 * instanced on a square grid over a ground plane, with a camera inside the grid. */
typedef struct gdr_demo_desc {
    uint32_t instances; /* 0: 10000 */
    uint32_t seed;      /* 0: 1 */
    float spacing;      /* grid spacing in metres; 0: 4 */
    uint32_t textures;  /* 1: every shape and the ground get a textured material (base colour, normal and
                         * metallic-roughness maps, generated); 0: plain colours */
} gdr_demo_desc;

GDR_API gdr_status gdr_scene_create_demo(const gdr_demo_desc *desc, gdr_scene **out, gdr_error *err);

/* --- LOD field: many copies of one dense mesh, from near to far -------------------------------
 *
 * One dense closed mesh, a bumpy (2, 3) torus knot named "torus_knot" (a welded tube: watertight,
 * every edge shared by exactly two triangles; bounding radius about 1 m), instanced `instances`
 * times in randomly rotated copies on a jittered grid of `spacing` metres that fills a wedge
 * in front of the camera (half-angle 40 degrees around -Z), nearest first: instance i is never
 * nearer to the camera than instance i - 1's grid row. Copies never overlap (their bounding
 * spheres are disjoint); every other row is shifted by half a cell. With the defaults the field
 * runs from 4 m to about 100 m in front of the origin (rows from z = -4 on), so the LOD cut varies
 * along it. No ground, no materials (per-instance colours). Camera 0, at (0, 4.5, 1) looking down
 * -Z and 17 degrees down, sees the field from its near end to the horizon; yfov 60 degrees, znear
 * 0.1, infinite far. Deterministic: the same desc gives the same bytes.
 * gdr_scene_create_lod_field builds level-0 clusters; gdr_scene_load("lod-field...") also builds
 * the LOD DAG. */
typedef struct gdr_lod_field_desc {
    uint32_t instances; /* 0: 1000; at most 16000000 */
    uint32_t seed;      /* 0: 1 */
    uint32_t triangles; /* triangles of the mesh, approximately (the tube's lattice rounds it);
                           0: 100000; in [1000, 16000000] */
    float spacing;      /* grid spacing in metres; 0: 3; in [2.5, 1000] */
} gdr_lod_field_desc;

GDR_API gdr_status gdr_scene_create_lod_field(const gdr_lod_field_desc *desc, gdr_scene **out, gdr_error *err);

/* --- Unique field: many different dense meshes, one copy each ---------------------------------
 *
 * `meshes` different closed meshes (tori whose tube radius follows waves of the mesh's own
 * frequencies and phases, named "unique_M"; about `triangles` triangles each, welded: every edge
 * has exactly two triangles; within 0.95 m of the mesh origin), one instance each, on a square
 * grid of `spacing` metres in the XZ plane (rows from z = -4 along -Z, centres at y = 1), each
 * turned randomly about Y and tilted a little. The processed geometry grows with meshes x
 * triangles and no instance shares another's: the scene for geometry streaming. Camera 0 at
 * (0, 3.5, 0), 20 degrees down, looks along the field. Deterministic: the same desc gives the same
 * bytes. gdr_scene_create_unique_field builds level-0 clusters; gdr_scene_load("unique-field...")
 * also builds the LOD DAG. */
typedef struct gdr_unique_field_desc {
    uint32_t meshes;    /* 0: 100; at most 100000 */
    uint32_t seed;      /* 0: 1 */
    uint32_t triangles; /* per mesh, approximately (the lattice rounds it); 0: 100000; in [1000, 16000000] */
    float spacing;      /* grid spacing in metres; 0: 3; in [2.5, 1000] */
} gdr_unique_field_desc;

GDR_API gdr_status gdr_scene_create_unique_field(const gdr_unique_field_desc *desc, gdr_scene **out,
                                                 gdr_error *err);

/* The same scene one mesh at a time, for a cache written mesh by mesh (gdr_cache_write_meshes):
 * the skeleton holds every instance and the camera and, for each mesh, its name only (a scene whose
 * geometry_in_pages is set: no arrays); gdr_scene_create_unique_field_mesh makes mesh `mesh` alone in
 * a scene of its own, its vertices and triangles those gdr_scene_create_unique_field gives it, without
 * clusters. Invalid desc: GDR_ERROR_INVALID_ARGUMENT, as gdr_scene_create_unique_field says it. */
GDR_API gdr_status gdr_scene_create_unique_field_skeleton(const gdr_unique_field_desc *desc, gdr_scene **out,
                                                          gdr_error *err);
GDR_API gdr_status gdr_scene_create_unique_field_mesh(const gdr_unique_field_desc *desc, uint32_t mesh,
                                                      gdr_scene **out, gdr_error *err);

/* --- Occlusion scene: a wall of buildings in front of many small objects -----------------------
 *
 * Right-handed, Y up; the default camera stands at (0, 1.7, 0) looking down -Z. Instances, in
 * this order:
 *   [0]                       the ground, a 260 m square at y = 0 (mesh "ground")
 *   [1, 1 + buildings)        the wall: a row of tall boxes (mesh "building", scaled; 10 to 24 m
 *                             high, 6 to 10 m deep) from x = -70 to 70 with its front at z = -20
 *                             to -21.5, open at two fixed gaps, x in [-9, -6] and [7, 10.5], through
 *                             which the default camera sees some hidden objects, and at a few
 *                             random narrower ones further out; x in [-6, 7] is always a building
 *   [.., + visible)           small objects (meshes "sphere", "torus", "box") resting on the
 *                             ground in front of the wall, x in [-40, 40], z in [-17, -3]: visible
 *   [.., + hidden)            the last `hidden` instances: small objects behind the wall, x in
 *                             [-60, 60], z in [-100, -36], up to 4 m above the ground: hidden from
 *                             the default camera except through the gaps
 * Small objects get smaller as they get denser (radius up to 0.6 m, 0.35 of the grid cell) and
 * never overlap anything. The extents do not depend on the desc, only the density and the random
 * details do; gdr_scene_occlusion_camera_path holds for every desc. The cameras are frames of
 * that path: 0 "front" (frame 0, the default camera), 1 "behind" (70), 2 "past-end" (159),
 * 3 "above" (199), 4 "close" (200), 5 "gap" (228). Deterministic: the same desc gives the same
 * bytes. gdr_scene_create_occlusion builds level-0 clusters; gdr_scene_load("occlusion...") also
 * builds the LOD DAG. */
typedef struct gdr_occlusion_scene_desc {
    uint32_t seed;    /* 0: 1 */
    uint32_t hidden;  /* objects behind the wall; 0: 4000; at most 1000000 */
    uint32_t visible; /* objects in front of the wall; 0: 300; at most 1000000 */
} gdr_occlusion_scene_desc;

GDR_API gdr_status gdr_scene_create_occlusion(const gdr_occlusion_scene_desc *desc, gdr_scene **out,
                                              gdr_error *err);

/* Length of the occlusion scene's camera path; frames past it repeat it (frame % length). */
#define GDR_OCCLUSION_PATH_FRAMES 240u

/* The camera of `frame` on the occlusion scene's path, for tests that render a sequence with
 * occlusion culling on and off. *camera_cut (may be NULL) is set to true on the first frame of each
 * shot, where the camera jumps (no usable history), false elsewhere. The shots:
 *     0 ..  39  dolly from the default camera towards the wall, swaying a little
 *    40 ..  69  turns in place: left by 75 degrees, then right to 30 degrees
 *    70 .. 109  cut behind the wall, 5 m up, looking back at it over the hidden objects, moving closer
 *   110 .. 159  cut to a strafe in front of the wall past its end (x 40 -> 95) while turning
 *               left: hidden objects come out from behind the wall's end
 *   160 .. 199  cut to a crane shot rising from 1.7 m to 45 m and tilting down: hidden objects
 *               come out above the wall
 *   200 .. 215  cut to 1.5 m in front of the wall, spinning 22.5 degrees a frame
 *   216 .. 239  cut to a strafe in front of the gap at x in [-9, -6]: hidden objects appear
 *               through it and disappear again
 * The camera never enters a building or an object; yfov 60 degrees, znear 0.1, infinite far. */
GDR_API gdr_camera gdr_scene_occlusion_camera_path(uint32_t frame, bool *camera_cut);

/* The rooms scene (docs/SCENES.md), made for precomputed visibility: `rooms` rooms of 8 m x 8 m on
 * a square grid (columns = ceil(sqrt(rooms)), room k at column k % columns, row k / columns, rows
 * going towards -Z, 12.6 m apart), walls 0.3 m thick and 3 m high, joined into a maze by corridors
 * 4 m long and 1.4 m wide (a random spanning tree of the grid: one way between any two rooms,
 * doorways at random places along the walls), so that walls hide most rooms from any point.
 * Instances, in order:
 *   [0]                       the ground under the whole grid (mesh "ground")
 *   [1, ..)                   the rooms' walls, room after room (mesh "wall", a 2 m cube scaled): a
 *                             side without a doorway is one box, a side with one two boxes
 *   [.., ..)                  the corridors' side walls, two per corridor (mesh "wall")
 *   [.., + rooms x objects)   the last instances: `objects` props per room (meshes "sphere", "torus",
 *                             "box"), room after room, on a jittered grid over its floor, at most
 *                             0.92 m high, 0.6 m or more from its walls
 * Cameras at 1.6 m: 0 "first-room" (room 0, looking -Z across the grid), 1 "middle" (the middle
 * room, looking +X), 2 "corner" (room 0, looking diagonally into the grid). Deterministic: the same
 * desc gives the same bytes. gdr_scene_create_rooms builds level-0 clusters; gdr_scene_load("rooms...")
 * also builds the LOD DAG. */
#define GDR_ROOMS_MAX 4096u
#define GDR_ROOMS_MAX_OBJECTS 1000u
typedef struct gdr_rooms_scene_desc {
    uint32_t rooms;   /* 0: 16; at most GDR_ROOMS_MAX */
    uint32_t seed;    /* 0: 1 */
    uint32_t objects; /* props per room; 0: 24; at most GDR_ROOMS_MAX_OBJECTS */
} gdr_rooms_scene_desc;

GDR_API gdr_status gdr_scene_create_rooms(const gdr_rooms_scene_desc *desc, gdr_scene **out, gdr_error *err);

#ifdef __cplusplus
}
#endif
#endif
