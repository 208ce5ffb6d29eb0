/* gdr scene: the flat scene model every importer produces and the renderer consumes.
 *
 * A scene is arrays: meshes (geometry), materials, instances (a global transform, a mesh and a
 * material) and cameras. There is no node tree: importers flatten it into global transforms. */
#ifndef GDR_SCENE_H
#define GDR_SCENE_H

#include <stdint.h>

#include "gdr/core.h"
#include "gdr/geometry.h"
#include "gdr/math.h"

#ifdef __cplusplus
extern "C" {
#endif

#define GDR_NAME_MAX 64
#define GDR_NO_INDEX UINT32_MAX
/* Largest magnitude of a mesh-space coordinate (metres) gdr accepts anywhere: far beyond any real
 * scene, small enough that squared distances and areas stay finite in float. */
#define GDR_MAX_COORDINATE 1e12f

typedef struct gdr_mesh {
    char name[GDR_NAME_MAX];
    uint32_t vertex_count;
    gdr_vec3 *positions; /* vertex_count entries */
    gdr_vec3 *normals;   /* vertex_count entries, unit length */
    gdr_vec2 *uvs;       /* vertex_count entries (zero when the source has none) */
    gdr_vec4 *colors;    /* vertex_count linear RGBA vertex colours (glTF COLOR_0), or NULL: white */
    uint32_t index_count; /* a multiple of 3: a triangle list, counter-clockwise front faces */
    uint32_t *indices;
    gdr_vec4 bounds; /* bounding sphere in mesh space: centre xyz, radius w */
    gdr_mesh_clusters clusters; /* meshlets and LOD DAG (gdr/geometry.h); empty until built */
    gdr_vertex_quantization quantization; /* the grid its vertices lie on, or not enabled (gdr/geometry.h) */
} gdr_mesh;

/* A texture reference's sampler state (glTF's sampler object), packed in a uint32: zero is glTF's
 * default, repeat in both directions with linear filtering and linear mip selection. */
#define GDR_SAMPLER_WRAP_REPEAT 0u
#define GDR_SAMPLER_WRAP_CLAMP 1u
#define GDR_SAMPLER_WRAP_MIRROR 2u
#define GDR_SAMPLER_WRAP_S(bits) ((bits) & 3u)        /* a GDR_SAMPLER_WRAP_* for u */
#define GDR_SAMPLER_WRAP_T(bits) (((bits) >> 2) & 3u) /* a GDR_SAMPLER_WRAP_* for v */
#define GDR_SAMPLER_MAG_NEAREST (1u << 4)
#define GDR_SAMPLER_MIN_NEAREST (1u << 5)
#define GDR_SAMPLER_MIP_NEAREST (1u << 6)
#define GDR_SAMPLER_MIP_NONE (1u << 7)  /* minification reads level 0 only */
#define GDR_SAMPLER_STATES 256u         /* every packed state is below this */

/* A material's use of a texture (glTF's textureInfo): which texture, its sampler, and the
 * KHR_texture_transform of the texture coordinate, uv' = offset + R(rotation) (scale * uv) with
 * the rows of R(a) (cos a, sin a) and (-sin a, cos a): the extension's matrix T * R * S, a
 * counter-clockwise rotation of the image as seen with v running down (glTF's TextureTransformTest). The coordinate is the
 * mesh's one uv set (TEXCOORD_0). */
typedef struct gdr_texture_ref {
    uint32_t texture;  /* texture index or GDR_NO_INDEX */
    uint32_t sampler;  /* GDR_SAMPLER_* bits */
    gdr_vec2 offset;   /* (0, 0) without a transform */
    gdr_vec2 scale;    /* (1, 1) without a transform */
    float rotation;    /* radians, 0 without a transform */
} gdr_texture_ref;

/* A glTF metallic-roughness material. Start from gdr_material_default() (glTF's defaults); a
 * zero-initialised material references texture 0 everywhere. */
typedef struct gdr_material {
    char name[GDR_NAME_MAX];
    gdr_vec4 base_color; /* linear RGBA factor */
    gdr_texture_ref base_color_texture;         /* sRGB RGBA, multiplied with base_color */
    gdr_texture_ref metallic_roughness_texture; /* linear: G roughness, B metallic (times the factors) */
    gdr_texture_ref normal_texture;             /* linear tangent-space normal, xy scaled by normal_scale */
    gdr_texture_ref occlusion_texture;          /* linear: R, blended in by occlusion_strength */
    gdr_texture_ref emissive_texture;           /* sRGB RGB, multiplied with emissive */
    gdr_vec3 emissive;        /* linear emissive factor, KHR_materials_emissive_strength applied */
    float metallic_factor;
    float roughness_factor;
    float normal_scale;       /* 1 by default */
    float occlusion_strength; /* 1 by default */
    float alpha_cutoff;       /* used when alpha_mode is GDR_ALPHA_MASK; 0.5 by default */
    uint32_t alpha_mode;      /* gdr_alpha_mode */
    uint32_t double_sided;    /* 0 or 1 */
} gdr_material;

/* glTF's default material: white, metallic 1, roughness 1, no textures (every reference
 * GDR_NO_INDEX with the default sampler and no transform), opaque with cutoff 0.5, single-sided. */
GDR_API gdr_material gdr_material_default(void);
/* NULL when every value of the material is sound (every float finite, sampler states below
 * GDR_SAMPLER_STATES, a known alpha mode, double_sided 0 or 1), else what is wrong, in words. The
 * one rule that gdr_scene_add_material, the importers, the cache writer and the cache reader apply. */
GDR_API const char *gdr_material_problem(const gdr_material *material);

typedef enum gdr_alpha_mode { GDR_ALPHA_OPAQUE = 0, GDR_ALPHA_MASK = 1, GDR_ALPHA_BLEND = 2 } gdr_alpha_mode;

/* A decoded image with its full mip chain: level l is max(width >> l, 1) x max(height >> l, 1)
 * tightly packed RGBA8 texels, top row first; the levels follow each other in `rgba`, level 0
 * first, down to 1 x 1 (gdr_texture_level_count, gdr_texture_level_offset). */
typedef struct gdr_texture {
    char name[GDR_NAME_MAX];
    uint32_t width, height; /* level 0 */
    uint32_t levels;        /* gdr_texture_level_count(width, height) */
    uint8_t *rgba;          /* every level: gdr_texture_level_offset(width, height, levels) bytes */
    uint32_t srgb; /* 1: colour data (base colour, emissive); 0: linear data (normals, metallic-roughness, occlusion) */
} gdr_texture;

/* Levels of a full mip chain of a width x height image, down to 1 x 1. */
GDR_API uint32_t gdr_texture_level_count(uint32_t width, uint32_t height);
/* Byte offset of level `level` in a chain of a width x height image (level = the count: the chain's size). */
GDR_API size_t gdr_texture_level_offset(uint32_t width, uint32_t height, uint32_t level);

typedef struct gdr_instance {
    gdr_mat4 transform; /* mesh space -> world space */
    uint32_t mesh;
    uint32_t material; /* material index or GDR_NO_INDEX (then `color` is used) */
    gdr_vec4 color;    /* per-instance colour, multiplied with the material's base colour */
    /* Screen-size culling (gdr_frame_desc): drawn while the bounding sphere's screen size, about its
     * projected diameter over the viewport height, is at least min_screen_size and below
     * max_screen_size (LOD-range swaps, small-detail culling); 0: no limit. Finite, >= 0. */
    float min_screen_size;
    float max_screen_size;
} gdr_instance;

typedef struct gdr_camera {
    char name[GDR_NAME_MAX];
    gdr_vec3 position;
    gdr_quat rotation; /* identity looks down -Z */
    float yfov;        /* radians */
    float znear;
    float zfar;        /* 0 for the infinite projection */
    float aspect;      /* 0: take it from the render target */
} gdr_camera;

typedef struct gdr_scene {
    gdr_mesh *meshes;
    uint32_t mesh_count, mesh_capacity;
    gdr_material *materials;
    uint32_t material_count, material_capacity;
    gdr_instance *instances;
    uint32_t instance_count, instance_capacity;
    gdr_camera *cameras;
    uint32_t camera_count, camera_capacity;
    /* Decoded images the materials index (base colour, normal, metallic-roughness). */
    gdr_texture *textures;
    uint32_t texture_count, texture_capacity;
    char *extensions; /* the source's extensionsUsed, comma-separated, or NULL */
    /* 1: read for streaming (gdr_cache_read_for_streaming, gdr_load_options.geometry_in_pages): every
     * mesh has its counts, bounds, cluster and group records and hierarchy, but no vertex, index,
     * colour, cluster vertex or triangle arrays (NULL); those stay in the cache's pages. Such a scene
     * renders only through gdr_renderer_set_scene_streamed and cannot be written to a cache. */
    int geometry_in_pages;
} gdr_scene;

GDR_API gdr_status gdr_scene_create(gdr_scene **out, gdr_error *err);
GDR_API void gdr_scene_destroy(gdr_scene *scene);

/* Adds a mesh whose arrays are copied; normals may be NULL (generated from the faces), uvs may
 * be NULL (zeros). Computes the bounding sphere. Checks every index against vertex_count and every
 * position (finite, within GDR_MAX_COORDINATE). */
GDR_API gdr_status gdr_scene_add_mesh(gdr_scene *scene, const char *name, const gdr_vec3 *positions,
                                      const gdr_vec3 *normals, const gdr_vec2 *uvs,
                                      uint32_t vertex_count, const uint32_t *indices,
                                      uint32_t index_count, uint32_t *out_index, gdr_error *err);
/* Adds a mesh of a scene whose geometry stays in a cache's pages (geometry_in_pages): its name,
 * counts and bounds only. */
GDR_API gdr_status gdr_scene_add_paged_mesh(gdr_scene *scene, const char *name, uint32_t vertex_count,
                                            uint32_t index_count, gdr_vec4 bounds, gdr_error *err);
GDR_API gdr_status gdr_scene_add_material(gdr_scene *scene, const gdr_material *material,
                                          uint32_t *out_index, gdr_error *err);
GDR_API gdr_status gdr_scene_add_instance(gdr_scene *scene, const gdr_instance *instance,
                                          gdr_error *err);
GDR_API gdr_status gdr_scene_add_camera(gdr_scene *scene, const gdr_camera *camera, gdr_error *err);
/* Gives mesh `mesh` vertex colours (vertex_count linear RGBA values, each in [0, 1]; copied). */
GDR_API gdr_status gdr_scene_set_mesh_colors(gdr_scene *scene, uint32_t mesh, const gdr_vec4 *colors, gdr_error *err);
/* Adds a texture whose level 0 (width * height * 4 bytes, RGBA8) is copied; the other levels of its
 * mip chain are built here (a box filter, in linear light for sRGB data, alpha-weighted). */
GDR_API gdr_status gdr_scene_add_texture(gdr_scene *scene, const char *name, uint32_t width, uint32_t height,
                                         const uint8_t *rgba, uint32_t srgb, uint32_t *out_index,
                                         gdr_error *err);
/* Adds a texture whose whole mip chain (gdr_texture_level_offset(width, height, levels) bytes, the
 * layout gdr_texture describes) is copied as it is: a chain built before, e.g. read from a cache. */
GDR_API gdr_status gdr_scene_add_texture_levels(gdr_scene *scene, const char *name, uint32_t width, uint32_t height,
                                                const uint8_t *chain, uint32_t srgb, uint32_t *out_index,
                                                gdr_error *err);
/* Replaces the scene's extension list (copied; NULL clears it). */
GDR_API gdr_status gdr_scene_set_extensions(gdr_scene *scene, const char *extensions, gdr_error *err);

/* A camera that sees every instance: for scenes that bring no camera. */
GDR_API gdr_camera gdr_scene_framing_camera(const gdr_scene *scene);

/* Total triangles over all instances. */
GDR_API uint64_t gdr_scene_triangle_count(const gdr_scene *scene);

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

/* True when `spec` names a built-in scene ("demo", "lod-field", "occlusion", "unique-field", alone or followed by
 * ":options"), which gdr_scene_load builds instead of reading a file. */
GDR_API bool gdr_scene_spec_is_builtin(const char *spec);

/* Warnings from importers (a file that loads, but not entirely as written): `message` names the
 * file and the place, e.g. "box.gltf: meshes[0].primitives[1]: mode 1 (lines) skipped". */
typedef void (*gdr_warning_fn)(void *user, const char *message);

/* Limits on what one untrusted scene or cache file may make gdr do (docs/SECURITY.md). Each is
 * checked before the memory it bounds is allocated; a file over one is refused with an error that
 * names the budget and the option that raises it. Zero-initialise: 0 takes the default below. */
typedef struct gdr_budget {
    uint64_t triangles;      /* triangles over all meshes as read (before duplicates are dropped);
                                0: GDR_DEFAULT_MAX_TRIANGLES */
    uint64_t instances;      /* instances the file creates; 0: GDR_DEFAULT_MAX_INSTANCES */
    uint64_t texture_pixels; /* pixels over all decoded images; 0: GDR_DEFAULT_MAX_TEXTURE_PIXELS */
    uint64_t decoded_bytes;  /* bytes made by decoding (base64 data: URIs, EXT_meshopt_compression
                                views, accessors without a bufferView); 0: GDR_DEFAULT_MAX_DECODED_BYTES */
} gdr_budget;

#define GDR_DEFAULT_MAX_TRIANGLES (1ull << 26)      /* 67,108,864 */
#define GDR_DEFAULT_MAX_INSTANCES (1ull << 22)      /* 4,194,304 */
#define GDR_DEFAULT_MAX_TEXTURE_PIXELS (1ull << 27) /* 134,217,728: 512 MiB of RGBA8 */
#define GDR_DEFAULT_MAX_DECODED_BYTES (1ull << 31)  /* 2 GiB */

/* The budget with every 0 replaced by its default. */
GDR_API gdr_budget gdr_budget_resolve(const gdr_budget *budget);

/* Options of gdr_scene_load; zero-initialise, every field has a default. */
typedef struct gdr_load_options {
    int no_cache;          /* 1: import the source, never read or write a .gdrc cache */
    const char *cache_dir; /* NULL: next to the source (FILE.gdrc), falling back to
                              $XDG_CACHE_HOME/gdr or ~/.cache/gdr when that is not writable */
    int no_progress;       /* 1: never draw a progress bar (default: on a terminal only) */
    gdr_warning_fn warning; /* NULL: warnings go to stderr as "gdr: warning: ..." */
    void *warning_user;
    gdr_budget budget;      /* limits for untrusted files; zero: the defaults */
    int allow_outside_files; /* 1: a glTF may name buffers and images outside its own folder
                                (absolute paths, '..', symlinks out); 0: refused */
    int geometry_in_pages;   /* 1: for streaming, a .gdrc with geometry pages is read without the
                                geometry its pages hold (gdr_cache_read_for_streaming); any other
                                scene is refused */
} gdr_load_options;

/* Loads a scene from a specification, a built-in scene with its level-0 clusters and LOD DAG:
 *     "demo[:instances=N,seed=S,spacing=X]"                 gdr_scene_create_demo
 *     "lod-field[:instances=N,seed=S,triangles=T,spacing=X]" gdr_scene_create_lod_field
 *     "occlusion[:seed=S,hidden=N,visible=N]"               gdr_scene_create_occlusion
 *     "unique-field[:meshes=M,seed=S,triangles=T,spacing=X]" gdr_scene_create_unique_field
 * (options in any order, each at most once; values as in the desc, 0 refused), or a file path of
 * a supported format. Source files (.gltf, .glb, .obj) go through the processed-scene cache unless
 * options->no_cache; a .gdrc file is read directly. options: NULL for the defaults. */
GDR_API gdr_status gdr_scene_load(const char *spec, const gdr_load_options *options, gdr_scene **out,
                                  gdr_error *err);

#ifdef __cplusplus
}
#endif
#endif
