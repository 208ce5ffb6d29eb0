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

typedef struct gdr_mesh {
    char name[GDR_NAME_MAX];
    uint32_t vertex_count;
    gdr_vec3 *positions; /* vertex_count entries */
    gdr_vec3 *normals;   /* vertex_count entries, unit length */
    gdr_vec2 *uvs;       /* vertex_count entries (zero when the source has none) */
    uint32_t index_count; /* a multiple of 3: a triangle list, counter-clockwise front faces */
    uint32_t *indices;
    gdr_vec4 bounds; /* bounding sphere in mesh space: centre xyz, radius w */
    gdr_mesh_clusters clusters; /* meshlets and LOD DAG (gdr/geometry.h); empty until built */
} gdr_mesh;

typedef struct gdr_material {
    char name[GDR_NAME_MAX];
    gdr_vec4 base_color; /* linear RGBA factor */
    uint32_t base_color_texture;         /* texture index or GDR_NO_INDEX */
    uint32_t normal_texture;             /* recorded for later use, or GDR_NO_INDEX */
    uint32_t metallic_roughness_texture; /* recorded for later use, or GDR_NO_INDEX */
    /* Additions (issue 3). A zero-initialised material keeps its old meaning: opaque,
     * single-sided; metallic/roughness 0 unless an importer sets them. */
    float metallic_factor;
    float roughness_factor;
    float alpha_cutoff;   /* used when alpha_mode is GDR_ALPHA_MASK */
    uint32_t alpha_mode;  /* gdr_alpha_mode */
    uint32_t double_sided; /* 0 or 1 */
} gdr_material;

typedef enum gdr_alpha_mode { GDR_ALPHA_OPAQUE = 0, GDR_ALPHA_MASK = 1, GDR_ALPHA_BLEND = 2 } gdr_alpha_mode;

/* A decoded image: tightly packed RGBA8 rows, top row first (issue 3). */
typedef struct gdr_texture {
    char name[GDR_NAME_MAX];
    uint32_t width, height;
    uint8_t *rgba; /* width * height * 4 bytes */
    uint32_t srgb; /* 1: colour data (base colour); 0: linear data (normals, metallic-roughness) */
} gdr_texture;

typedef struct gdr_instance {
    gdr_mat4 transform; /* mesh space -> world space */
    uint32_t mesh;
    uint32_t material; /* material index or GDR_NO_INDEX (then `color` is used) */
    gdr_vec4 color;    /* per-instance colour, multiplied with the material's base colour */
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
    /* Additions (issue 3). */
    gdr_texture *textures;
    uint32_t texture_count, texture_capacity;
    char *extensions; /* the source's extensionsUsed, comma-separated, or NULL */
} gdr_scene;

GDR_API gdr_status gdr_scene_create(gdr_scene **out, gdr_error *err);
GDR_API void gdr_scene_destroy(gdr_scene *scene);

/* Adds a mesh whose arrays are copied; normals may be NULL (generated from the faces), uvs may
 * be NULL (zeros). Computes the bounding sphere. Checks every index against vertex_count. */
GDR_API gdr_status gdr_scene_add_mesh(gdr_scene *scene, const char *name, const gdr_vec3 *positions,
                                      const gdr_vec3 *normals, const gdr_vec2 *uvs,
                                      uint32_t vertex_count, const uint32_t *indices,
                                      uint32_t index_count, uint32_t *out_index, gdr_error *err);
GDR_API gdr_status gdr_scene_add_material(gdr_scene *scene, const gdr_material *material,
                                          uint32_t *out_index, gdr_error *err);
GDR_API gdr_status gdr_scene_add_instance(gdr_scene *scene, const gdr_instance *instance,
                                          gdr_error *err);
GDR_API gdr_status gdr_scene_add_camera(gdr_scene *scene, const gdr_camera *camera, gdr_error *err);
/* Adds a texture whose pixels (width * height * 4 bytes, RGBA8) are copied. */
GDR_API gdr_status gdr_scene_add_texture(gdr_scene *scene, const char *name, uint32_t width, uint32_t height,
                                         const uint8_t *rgba, uint32_t srgb, uint32_t *out_index,
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
} gdr_demo_desc;

GDR_API gdr_status gdr_scene_create_demo(const gdr_demo_desc *desc, gdr_scene **out, gdr_error *err);

/* Loads a scene from a specification: "demo" or "demo:instances=N,seed=S,spacing=X", or a file
 * path of a supported format. */
GDR_API gdr_status gdr_scene_load(const char *spec, gdr_scene **out, gdr_error *err);

/* Warnings from importers (a file that loads, but not entirely as written): `message` names the
 * file and the place, e.g. "box.gltf: meshes[0].primitives[1]: mode 1 (lines) skipped". */
typedef void (*gdr_warning_fn)(void *user, const char *message);

/* Options of gdr_scene_load_ex; zero-initialise, every field has a default. */
typedef struct gdr_load_options {
    int no_cache;          /* 1: import the source, never read or write a .gdrc cache */
    const char *cache_dir; /* NULL: next to the source (FILE.gdrc), falling back to
                              $XDG_CACHE_HOME/gdr or ~/.cache/gdr when that is not writable */
    int no_progress;       /* 1: never draw a progress bar (default: on a terminal only) */
    gdr_warning_fn warning; /* NULL: warnings go to stderr as "gdr: warning: ..." */
    void *warning_user;
} gdr_load_options;

/* gdr_scene_load with options (NULL: defaults). Source files (.gltf, .glb, .obj) go through the
 * processed-scene cache unless options->no_cache; a .gdrc file is read directly. */
GDR_API gdr_status gdr_scene_load_ex(const char *spec, const gdr_load_options *options, gdr_scene **out,
                                     gdr_error *err);

#ifdef __cplusplus
}
#endif
#endif
