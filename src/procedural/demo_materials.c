/* The textured demo's materials (gdr_demo_desc.textures): generated textures, so that the material
 * path can be measured and looked at without external files. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "gdr/procedural.h"
#include "procedural/demo_materials.h"

#define SIDE 256
#define PI_F 3.14159265f

/* A height field of round bumps on a grid of `cells` per side, in [0, 1]. */
static float bump_height(float u, float v, float cells)
{
    float x = u * cells - floorf(u * cells) - 0.5f, y = v * cells - floorf(v * cells) - 0.5f;
    float r2 = (x * x + y * y) * 4.0f;
    return r2 < 1.0f ? sqrtf(1.0f - r2) : 0.0f;
}

/* Texture `kind` (0 base colour, 1 normals, 2 metallic-roughness) of style `style`. */
static void fill(uint8_t *t, int kind, uint32_t style)
{
    float cells = (float)(4 + 2 * style);
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++) {
            float u = ((float)x + 0.5f) / SIDE, v = ((float)y + 0.5f) / SIDE;
            uint8_t *p = t + (y * SIDE + x) * 4;
            float h = bump_height(u, v, cells);
            if (kind == 0) { /* tiles: a light grout between darker, slightly varied cells */
                bool grout = h == 0.0f;
                float shade = 0.75f + 0.25f * sinf(7.0f * floorf(u * cells) + 3.0f * floorf(v * cells));
                p[0] = (uint8_t)(grout ? 225 : 200 * shade);
                p[1] = (uint8_t)(grout ? 220 : 190 * shade);
                p[2] = (uint8_t)(grout ? 210 : 170 * shade);
            } else if (kind == 1) { /* the bumps' normals, tangent space */
                float e = 1.0f / SIDE, s = 0.15f * SIDE / cells;
                float dx = (bump_height(u + e, v, cells) - bump_height(u - e, v, cells)) * s;
                float dy = (bump_height(u, v + e, cells) - bump_height(u, v - e, cells)) * s;
                /* +y of the normal map is up the image (towards smaller v): the slope along v flips. */
                float n[3] = {-dx, dy, 1.0f}, l = sqrtf(n[0] * n[0] + n[1] * n[1] + 1.0f);
                for (int k = 0; k < 3; k++)
                    p[k] = (uint8_t)lroundf((n[k] / l * 0.5f + 0.5f) * 255.0f);
            } else { /* G roughness: smooth bumps, rough grout; B metallic: every other style's bumps */
                p[0] = 255;
                p[1] = (uint8_t)(h > 0.0f ? 70 : 230);
                p[2] = (uint8_t)(h > 0.0f && (style & 1) ? 255 : 0);
            }
            p[3] = 255;
        }
}

gdr_status gdr_demo_add_materials(gdr_scene *scene, uint32_t count, uint32_t *out, gdr_error *err)
{
    uint8_t *texels = malloc((size_t)SIDE * SIDE * 4);
    if (!texels)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "demo: out of memory for its textures");
    gdr_status status = GDR_OK;
    for (uint32_t m = 0; m < count && status == GDR_OK; m++) {
        uint32_t textures[3] = {0, 0, 0};
        for (int kind = 0; kind < 3 && status == GDR_OK; kind++) {
            fill(texels, kind, m);
            const char *names[3] = {"demo base colour", "demo normals", "demo metallic-roughness"};
            status = gdr_scene_add_texture(scene, names[kind], SIDE, SIDE, texels, kind == 0, &textures[kind], err);
        }
        gdr_material material = gdr_material_default();
        snprintf(material.name, sizeof material.name, "demo %u", m);
        material.base_color_texture.texture = textures[0];
        material.normal_texture.texture = textures[1];
        material.metallic_roughness_texture.texture = textures[2];
        material.base_color_texture.scale = material.normal_texture.scale =
            material.metallic_roughness_texture.scale = (gdr_vec2){2.0f, 2.0f};
        if (status == GDR_OK)
            status = gdr_scene_add_material(scene, &material, &out[m], err);
    }
    free(texels);
    return status;
}
