/* The glTF importer's shared state: JSON helpers, buffers, buffer views and accessors
 * (gltf_buffers.c) and the scene structure (gltf.c). */
#ifndef GDR_GLTF_INTERNAL_H
#define GDR_GLTF_INTERNAL_H

#include <stdint.h>

#include <cJSON.h>

#include "io/io_internal.h"

typedef struct gltf_buffer {
    int state;            /* 0: not loaded, 1: loaded */
    uint8_t *owned;       /* data we allocated (file contents, decoded data: URI) */
    const uint8_t *data;
    size_t size;          /* the declared byteLength (the data holds at least this much) */
} gltf_buffer;

typedef struct gltf_view {
    int state;            /* 0: not resolved, 1: resolved */
    uint8_t *owned;       /* meshopt-decoded data */
    const uint8_t *data;
    size_t length;
    uint32_t stride;      /* byteStride, 0 when absent */
} gltf_view;

/* What a primitive's geometry is made of: mode, indices, POSITION, NORMAL, TEXCOORD_0, COLOR_0
 * (accessor indices, GDR_NO_INDEX when absent). */
typedef struct gltf_geometry_key {
    uint32_t values[6];
} gltf_geometry_key;

typedef struct gltf_shared_mesh {
    gltf_geometry_key key;
    uint32_t mesh; /* the gdr mesh, or GDR_NO_INDEX when the primitive made none */
    int used;
} gltf_shared_mesh;

/* The meshes made so far, by geometry key (gltf_shared_mesh.c). */
typedef struct gltf_shared_meshes {
    gltf_shared_mesh *slots;
    size_t capacity, count;
} gltf_shared_meshes;

int gltf_shared_mesh_find(const gltf_shared_meshes *t, const gltf_geometry_key *key, uint32_t *mesh);
/* Returns 0 when out of memory. */
int gltf_shared_mesh_add(gltf_shared_meshes *t, const gltf_geometry_key *key, uint32_t mesh);
void gltf_shared_meshes_free(gltf_shared_meshes *t);

typedef struct gltf_ctx {
    const char *name;     /* file name for messages */
    const char *base_dir; /* NULL: external URIs are refused */
    gdr_error *err;
    gdr_io_warnings warnings;
    gdr_source_list *sources;
    int no_progress;

    cJSON *root;
    const uint8_t *glb_bin;
    size_t glb_bin_size;
    int is_glb;

    cJSON *accessors, *buffer_views, *buffers_json, *meshes, *nodes, *materials, *textures, *images, *cameras,
        *scenes, *samplers;
    uint32_t accessor_count, view_count, buffer_count, mesh_count, node_count, material_count, texture_count,
        image_count, camera_count, scene_count, sampler_count;
    /* The elements of each top-level array by index (count + 1 entries, malloc'ed). */
    const cJSON **accessor_at, **view_at, **buffer_at, **mesh_at, **node_at, **material_at, **texture_at,
        **image_at, **camera_at, **scene_at, **sampler_at;
    gdr_io_budget budget;
    uint32_t default_material_plus_one; /* the scene's glTF default material + 1; 0 until a primitive needs it */
    int allow_outside_files;

    gltf_buffer *buffers;
    gltf_view *views;

    gdr_scene *scene;
    /* glTF mesh m's primitives become gdr meshes prim_mesh[mesh_first[m] + p] (GDR_NO_INDEX when a
     * primitive has no triangles); converted once, on first use. */
    uint32_t *mesh_first;     /* per glTF mesh, GDR_NO_INDEX until converted */
    uint32_t *prim_mesh;      /* grows as meshes are converted */
    uint32_t *prim_material;
    uint32_t prim_count, prim_capacity;
    gltf_shared_meshes shared; /* primitives of the same accessors share one mesh */
    uint32_t file_cameras;    /* nodes with a camera met in the scene's walk, used or not */
    uint32_t *image_texture;  /* per glTF image, linear then sRGB: gdr texture, GDR_NO_INDEX, or UINT32_MAX - 1 (failed) */
} gltf_ctx;

#define GLTF_IMAGE_FAILED (UINT32_MAX - 1u)

/* Records an error "NAME: <message>" and returns status. */
gdr_status gltf_fail(gltf_ctx *c, gdr_status status, const char *format, ...) __attribute__((format(printf, 3, 4)));

/* JSON accessors: each checks the type and names the place ("meshes[2].primitives[0].mode") in
 * its error. Absent optional members leave *out unchanged (set the default first). */
gdr_status gltf_get_uint(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, int required,
                         uint32_t max, uint32_t *out);
gdr_status gltf_get_number(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, double *out);
/* The largest magnitude a number read into a float may have (a little below FLT_MAX, so that rounding
 * never makes it infinite). */
#define GLTF_MAX_FLOAT 3.0e38
/* A number read into a float: refused unless finite and at most GLTF_MAX_FLOAT in magnitude. */
gdr_status gltf_get_float(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, float *out);
gdr_status gltf_get_string(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, const char **out);
gdr_status gltf_get_object(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, int required,
                           const cJSON **out);
gdr_status gltf_get_array(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, const cJSON **out,
                          uint32_t *count);
gdr_status gltf_get_floats(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, uint32_t n,
                           float *out);
/* The extension object obj.extensions.NAME, or NULL. */
const cJSON *gltf_extension(const cJSON *obj, const char *name);

/* One warning per feature the file uses that gdr does not draw (skins, morph targets, animation,
 * each unsupported material extension), naming the first place it occurs (gltf_unsupported.c). */
void gltf_report_unsupported(gltf_ctx *c);

/* Buffers and views. */
/* Loads every buffer that the meshes of the file's nodes read through their accessors, so that a
 * missing or short buffer is reported before any image is decoded. */
gdr_status gltf_load_mesh_buffers(gltf_ctx *c);
gdr_status gltf_buffer_get(gltf_ctx *c, uint32_t index, const char *place, const uint8_t **data, size_t *size);
gdr_status gltf_view_get(gltf_ctx *c, uint32_t index, const char *place, const gltf_view **out);
void gltf_buffers_free(gltf_ctx *c);
/* Loads a URI (data: or a file relative to base_dir) into a malloc'ed buffer. */
gdr_status gltf_load_uri(gltf_ctx *c, const char *uri, const char *place, uint8_t **out, size_t *size);

/* Accessors: read every element into out (count * components), converting component types,
 * applying `normalized` and sparse substitution. `use` names the referencing place. */
typedef struct gltf_accessor_info {
    uint32_t count;
    uint32_t components;  /* 1 (SCALAR) .. 4 (VEC4); matrices are refused */
    uint32_t component_type;
    int normalized;
} gltf_accessor_info;

gdr_status gltf_accessor_info_get(gltf_ctx *c, uint32_t index, const char *use, gltf_accessor_info *info);
gdr_status gltf_accessor_read_floats(gltf_ctx *c, uint32_t index, const char *use, uint32_t components,
                                     float *out);
gdr_status gltf_accessor_read_uints(gltf_ctx *c, uint32_t index, const char *use, uint32_t *out);

#endif
