/* What the texture shows where it slides: the textures a mesh's materials sample, kept as min/max
 * pyramids, so that the simplifier can weigh a texture slide by how much the image can change
 * under it (docs/GEOMETRY.md, "A slide weighed by what the texture shows"). A slide across a
 * region of one colour changes no pixel; across detail it changes them as much as the detail
 * differs. Not part of the public API. */
#ifndef GDR_GEOMETRY_LOD_TEXTURE_H
#define GDR_GEOMETRY_LOD_TEXTURE_H

#include <stdint.h>

#include "gdr/core.h"
#include "gdr/scene.h"

/* One texture's per-channel minimum and maximum over cells of LOD_TEXTURE_CELL x LOD_TEXTURE_CELL
 * texels (pyramid level 0), then over 2 x 2 cells of the level before, up to one cell. */
typedef struct lod_texture_pyramid {
    uint32_t width, height; /* the texture's level 0, in texels */
    uint32_t levels;
    uint32_t *level_width, *level_height;
    uint8_t **lo, **hi; /* per level, RGBA per cell */
} lod_texture_pyramid;

/* One texture a material samples: its pyramid (NULL: unknown, any change), how the mesh's uvs
 * reach it (KHR_texture_transform, the sampler's wrap modes), which channels the material reads
 * (bit k: channel k of RGBA) and the factor it multiplies them by (at most 1 counted as given). */
typedef struct lod_texture_use {
    const lod_texture_pyramid *pyramid;
    uint32_t sampler;
    double offset[2], m[2][2]; /* uv' = offset + m uv */
    uint32_t channels;
    double weight;
} lod_texture_use;

/* The textures of one mesh: every use of every material an instance of it has. */
typedef struct lod_texture_set {
    const lod_texture_use *uses;
    uint32_t count;
} lod_texture_set;

/* The pyramids of a scene's textures (those a textured mesh samples) and each mesh's set. */
typedef struct lod_scene_textures {
    lod_texture_pyramid *pyramids; /* per scene texture; levels 0 where not built */
    uint32_t pyramid_count;
    lod_texture_use *uses;
    lod_texture_set *sets; /* per mesh */
    uint32_t mesh_count;
} lod_scene_textures;

/* The largest change, in [0, 1] of the 8-bit range, that the channels any use reads can show
 * between two points of the box of the `count` uvs given (the mesh's own uvs, before each use's
 * transform), each reading the texels its bilinear sample touches at level 0; times the use's
 * factor, at most 1. NULL set: 1 (nothing known, any change). */
double lod_texture_variation(const lod_texture_set *set, const double (*uv)[2], uint32_t count);

/* Builds the pyramids of the textures that the materials of textured meshes (textured[m] != 0)
 * sample and every such mesh's set. A texture that is not RGBA8 (already block-compressed) or has no
 * texels gets no pyramid: its uses count as any change. */
gdr_status lod_scene_textures_build(const gdr_scene *scene, const uint8_t *textured, lod_scene_textures *out,
                                    gdr_error *err);
void lod_scene_textures_free(lod_scene_textures *t);

/* One texture's pyramid from RGBA8 texels (width x height), for tests and the scene build; returns 0
 * when out of memory. */
int lod_texture_pyramid_build(lod_texture_pyramid *p, const uint8_t *rgba, uint32_t width, uint32_t height);
void lod_texture_pyramid_free(lod_texture_pyramid *p);

#endif
