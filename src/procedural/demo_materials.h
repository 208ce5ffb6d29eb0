/* The textured demo's materials: generated base-colour, normal and metallic-roughness textures. */
#ifndef GDR_SCENE_DEMO_MATERIALS_H
#define GDR_SCENE_DEMO_MATERIALS_H

#include "gdr/scene.h"

/* Adds `count` materials, each with three 256 x 256 textures of its own pattern, indices in out. */
gdr_status gdr_demo_add_materials(gdr_scene *scene, uint32_t count, uint32_t *out, gdr_error *err);

#endif
