/* gdr scene: the flat scene model every importer produces and the renderer consumes.
 *
 * A scene is arrays: meshes (geometry), materials, instances (a global transform, a mesh and a
 * material) and cameras. There is no node tree: importers flatten it into global transforms. */
#ifndef GDR_SCENE_H
#define GDR_SCENE_H

#include <stdint.h>

#include "gdr/core.h"
#include "gdr/math.h"
#include "gdr/mesh_clusters.h"

#ifdef __cplusplus
extern "C" {
#endif

#define GDR_NAME_MAX 64
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
    gdr_mesh_clusters clusters; /* meshlets and LOD DAG (gdr/mesh_clusters.h, built by gdr/geometry.h); empty until built */
    gdr_vertex_quantization quantization; /* the grid its vertices lie on, or not enabled (gdr/mesh_clusters.h) */
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

/* How a texture's levels are stored. RGBA8: tightly packed texels. The BC formats: 4 x 4 blocks
 * in rows, top row first, ceil(w / 4) x ceil(h / 4) blocks a level (levels below 4 x 4 take one
 * partly used block), as Vulkan's BCn_*_BLOCK formats lay them out. What each samples as:
 *   BC1    8 bytes a block: RGB (alpha 1); colour without alpha, or linear RGB
 *   BC3   16 bytes: RGBA; colour whose alpha a MASK or BLEND material uses
 *   BC4    8 bytes: (R, 0, 0, 1); one channel (occlusion)
 *   BC5   16 bytes: (R, G, 0, 1); two channels (a normal map's x and y; z = sqrt(1 - x^2 - y^2))
 *   BC5_GB 16 bytes: (0, G, B, 1), the block's two channels being G and B (metallic-roughness):
 *          sampled through the image view's swizzle. */
typedef enum gdr_texture_format {
    GDR_TEXTURE_RGBA8 = 0,
    GDR_TEXTURE_BC1 = 1,
    GDR_TEXTURE_BC3 = 2,
    GDR_TEXTURE_BC4 = 3,
    GDR_TEXTURE_BC5 = 4,
    GDR_TEXTURE_BC5_GB = 5,
    GDR_TEXTURE_FORMAT_COUNT
} gdr_texture_format;

/* An image with its full mip chain: level l is max(width >> l, 1) x max(height >> l, 1) texels,
 * top row first, stored as `format` says; the levels follow each other in `rgba`, level 0 first,
 * down to 1 x 1 (gdr_texture_level_count, gdr_texture_format_level_offset). */
typedef struct gdr_texture {
    char name[GDR_NAME_MAX];
    uint32_t width, height; /* level 0 */
    uint32_t levels;        /* gdr_texture_level_count(width, height) */
    uint8_t *rgba;          /* every level: gdr_texture_format_level_offset(format, width, height, levels)
                               bytes (RGBA8 texels, or blocks for a BC format) */
    uint32_t srgb; /* 1: colour data (base colour, emissive); 0: linear data (normals, metallic-roughness, occlusion) */
    uint32_t format; /* gdr_texture_format; RGBA8 unless compressed (gdr_scene_compress_textures) */
} gdr_texture;

/* Levels of a full mip chain of a width x height image, down to 1 x 1. */
GDR_API uint32_t gdr_texture_level_count(uint32_t width, uint32_t height);
/* Byte offset of level `level` in a chain of a width x height image (level = the count: the chain's size). */
GDR_API size_t gdr_texture_level_offset(uint32_t width, uint32_t height, uint32_t level);
/* Bytes of one 4 x 4 block of a BC format (8 or 16); 0 for RGBA8. */
GDR_API uint32_t gdr_texture_block_bytes(uint32_t format);
/* Byte offset of level `level` in a chain stored in `format` (level = the count: the chain's size). */
GDR_API size_t gdr_texture_format_level_offset(uint32_t format, uint32_t width, uint32_t height, uint32_t level);
/* The format's name ("rgba8", "bc1", ...), or "?" for an unknown value. */
GDR_API const char *gdr_texture_format_name(uint32_t format);

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
    float aspect;      /* the file's aspect ratio (0: none given), kept for information: the renderer
                          keeps yfov and takes the render target's aspect (glTF's rule when the
                          two differ: the image is neither stretched nor cropped) */
    float ymag;        /* > 0: an orthographic camera seeing ymag metres above and below its axis (glTF's
                          ymag; yfov unused; its width follows the image's aspect), zfar > znear >= 0
                          (zfar finite); 0: perspective */
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
/* Adds a texture whose whole mip chain is stored in `format` (a gdr_texture_format;
 * gdr_texture_format_level_offset(format, width, height, levels) bytes, copied as it is). */
GDR_API gdr_status gdr_scene_add_texture_format(gdr_scene *scene, const char *name, uint32_t width, uint32_t height,
                                                uint32_t format, const uint8_t *chain, uint32_t srgb,
                                                uint32_t *out_index, gdr_error *err);
/* Replaces the scene's extension list (copied; NULL clears it). */
GDR_API gdr_status gdr_scene_set_extensions(gdr_scene *scene, const char *extensions, gdr_error *err);

/* A camera that sees every instance: for scenes that bring no camera. */
GDR_API gdr_camera gdr_scene_framing_camera(const gdr_scene *scene);

/* Total triangles over all instances. */
GDR_API uint64_t gdr_scene_triangle_count(const gdr_scene *scene);

#ifdef __cplusplus
}
#endif
#endif
