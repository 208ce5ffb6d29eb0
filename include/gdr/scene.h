/* gdr scene: the flat scene model every importer produces and the renderer consumes.
 *
 * A scene is arrays: meshes (geometry), materials, instances (a global transform, a mesh and a
 * material) and cameras. There is no node tree: importers flatten it into global transforms. */
#ifndef GDR_SCENE_H
#define GDR_SCENE_H

#include <stdint.h>

#include "gdr/core.h"
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
} gdr_mesh;

typedef struct gdr_material {
    char name[GDR_NAME_MAX];
    gdr_vec4 base_color; /* linear RGBA factor */
    uint32_t base_color_texture;         /* texture index or GDR_NO_INDEX */
    uint32_t normal_texture;             /* recorded for later use, or GDR_NO_INDEX */
    uint32_t metallic_roughness_texture; /* recorded for later use, or GDR_NO_INDEX */
} gdr_material;

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

#ifdef __cplusplus
}
#endif
#endif
