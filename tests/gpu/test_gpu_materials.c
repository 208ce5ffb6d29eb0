/* Materials on every raster path (lavapipe, validation on), against the CPU reference of
 * material_reference.h at sampled pixels:
 *  - a row of generated quads, one material each: a base-colour texture under each wrap mode,
 *    KHR_texture_transform, emissive factor and texture, vertex colours with metallic and roughness,
 *    a normal map with metallic-roughness and occlusion textures;
 *  - BoxTextured (glTF, GLB, embedded) from Debian's assimp-testmodels, seen up close;
 *  - a checkerboard plane head-on and at a grazing angle: the paths agree pixel for pixel head-on
 *    and within MIP_TOLERANCE at the grazing angle (mip selection from analytic derivatives in the
 *    resolve, from dFdx/dFdy in the forward paths);
 *  - alpha: a quad with holes (MASK) and a half-transparent quad (BLEND, ordered dither) in front
 *    of a wall, occlusion culling on: the wall shows through the holes in every path. */
#include <math.h>

#include "gpu_test_util.h"
#include "material_reference.h"

#define MODELS "/usr/share/assimp/models/glTF2/"
/* Per channel, of 255: the GPU evaluates the same formulas in float, with 8-bit sRGB texture
 * decoding by the hardware's tables; a wrong formula, convention or texel moves far more. */
#define SHADE_TOLERANCE 3

typedef struct raster_path {
    const char *name;
    gdr_pipeline pipeline;
    gdr_raster raster;
} raster_path;

static const raster_path paths[] = {
    {"mesh/forward", GDR_PIPELINE_MESH, GDR_RASTER_FORWARD}, {"mesh/hw", GDR_PIPELINE_MESH, GDR_RASTER_HW},
    {"mesh/sw", GDR_PIPELINE_MESH, GDR_RASTER_SW},           {"mesh/hybrid", GDR_PIPELINE_MESH, GDR_RASTER_HYBRID},
    {"indirect", GDR_PIPELINE_INDIRECT, GDR_RASTER_DEFAULT}, {"cpu", GDR_PIPELINE_CPU, GDR_RASTER_DEFAULT},
};
#define PATH_COUNT (sizeof paths / sizeof paths[0])

static bool render_path(gdr_renderer *r, const gdr_camera *camera, const raster_path *path, gdr_cull_mode occlusion,
                        uint8_t *rgba)
{
    gdr_error err = {0};
    gdr_frame_desc frame = {.camera = *camera, .cull = GDR_CULL_ON, .read_back = true, .pipeline = path->pipeline,
                            .raster = path->raster, .occlusion = occlusion};
    gdr_frame_stats stats;
    bool ok = gdr_renderer_render(r, &frame, 1, &stats, &err) == GDR_OK && gdr_renderer_read_color(r, rgba, &err) == GDR_OK;
    if (!ok)
        fprintf(stderr, "%s: %s\n", path->name, err.message);
    return ok && stats.validation_messages == 0;
}

/* --- scenes ------------------------------------------------------------------------------------ */

/* A unit quad in the z = 0 plane facing +z, uv from uv0 to uv1 (u along +x, v along -y, as glTF's
 * v runs down the image). */
static uint32_t add_quad(gdr_scene *s, const char *name, float uv0, float uv1)
{
    const gdr_vec3 p[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const gdr_vec3 n[4] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    const gdr_vec2 uv[4] = {{uv0, uv1}, {uv1, uv1}, {uv1, uv0}, {uv0, uv0}};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    uint32_t mesh = 0;
    gdr_error err = {0};
    CHECK(gdr_scene_add_mesh(s, name, p, n, uv, 4, idx, 6, &mesh, &err) == GDR_OK);
    return mesh;
}

static uint32_t add_texture(gdr_scene *s, uint32_t w, uint32_t h, uint32_t srgb, uint32_t seed, bool normals)
{
    uint8_t *texels = malloc((size_t)w * h * 4);
    for (uint32_t i = 0; i < w * h; i++) {
        uint32_t x = (i + 1) * 2654435761u ^ seed * 40503u;
        texels[i * 4 + 0] = normals ? (uint8_t)(128 + (int)(x % 90) - 45) : (uint8_t)(x & 255);
        texels[i * 4 + 1] = normals ? (uint8_t)(128 + (int)((x >> 8) % 90) - 45) : (uint8_t)((x >> 8) & 255);
        texels[i * 4 + 2] = normals ? (uint8_t)(200 + (x >> 16) % 50) : (uint8_t)((x >> 16) & 255);
        texels[i * 4 + 3] = 255;
    }
    uint32_t index = 0;
    gdr_error err = {0};
    CHECK(gdr_scene_add_texture(s, "t", w, h, texels, srgb, &index, &err) == GDR_OK);
    free(texels);
    return index;
}

static void place(gdr_scene *s, uint32_t mesh, uint32_t material, float x, float y, float z)
{
    gdr_instance inst = {.transform = gdr_mat4_from_trs((gdr_vec3){x, y, z}, gdr_quat_identity(), (gdr_vec3){1, 1, 1}),
                         .mesh = mesh, .material = material, .color = {1, 1, 1, 1}};
    gdr_error err = {0};
    CHECK(gdr_scene_add_instance(s, &inst, &err) == GDR_OK);
}

static gdr_texture_ref tex(uint32_t texture, uint32_t sampler)
{
    return (gdr_texture_ref){.texture = texture, .sampler = sampler, .scale = {1, 1}};
}

#define NEAREST (GDR_SAMPLER_MAG_NEAREST | GDR_SAMPLER_MIN_NEAREST)

/* Seven quads in a row at x = 0, 1.2, 2.4, ... */
static gdr_scene *cases_scene(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create(&s, &err) == GDR_OK);
    uint32_t wide = add_quad(s, "wide", -0.5f, 1.5f), unit = add_quad(s, "unit", 0.0f, 1.0f);
    uint32_t colored = add_quad(s, "colored", 0.0f, 1.0f);
    const gdr_vec4 colors[4] = {{1, 0.1f, 0.1f, 1}, {0.1f, 1, 0.1f, 1}, {0.1f, 0.1f, 1, 1}, {1, 1, 1, 1}};
    CHECK(gdr_scene_set_mesh_colors(s, colored, colors, &err) == GDR_OK);
    uint32_t base = add_texture(s, 4, 4, 1, 1, false), emissive = add_texture(s, 4, 4, 1, 2, false);
    uint32_t normal = add_texture(s, 2, 2, 0, 3, true), mr = add_texture(s, 2, 2, 0, 4, false);
    uint32_t occlusion = add_texture(s, 2, 2, 0, 5, false);
    gdr_material m[7];
    for (int i = 0; i < 7; i++) {
        m[i] = gdr_material_default();
        m[i].metallic_factor = 0.0f;
        m[i].roughness_factor = 0.6f;
    }
    const uint32_t wraps[3] = {GDR_SAMPLER_WRAP_REPEAT, GDR_SAMPLER_WRAP_CLAMP, GDR_SAMPLER_WRAP_MIRROR};
    for (int i = 0; i < 3; i++)
        m[i].base_color_texture = tex(base, NEAREST | wraps[i] | wraps[(i + 1) % 3] << 2);
    m[3].base_color_texture = tex(base, NEAREST);
    m[3].base_color_texture.offset = (gdr_vec2){0.25f, 0.1f};
    m[3].base_color_texture.rotation = 0.3f;
    m[3].base_color_texture.scale = (gdr_vec2){1.5f, 0.8f};
    m[4].base_color = (gdr_vec4){0.2f, 0.2f, 0.2f, 1};
    m[4].emissive = (gdr_vec3){0.9f, 0.5f, 0.3f};
    m[4].emissive_texture = tex(emissive, NEAREST);
    m[5].metallic_factor = 0.5f;
    m[5].roughness_factor = 0.3f;
    m[6].normal_texture = tex(normal, NEAREST);
    m[6].normal_scale = 0.8f;
    m[6].metallic_roughness_texture = tex(mr, NEAREST);
    m[6].metallic_factor = 1.0f;
    m[6].roughness_factor = 1.0f;
    m[6].occlusion_texture = tex(occlusion, NEAREST);
    m[6].occlusion_strength = 0.5f;
    m[6].base_color = (gdr_vec4){0.8f, 0.6f, 0.4f, 1};
    const uint32_t meshes[7] = {wide, wide, wide, unit, unit, colored, unit};
    for (uint32_t i = 0; i < 7; i++) {
        uint32_t index = 0;
        CHECK(gdr_scene_add_material(s, &m[i], &index, &err) == GDR_OK);
        place(s, meshes[i], index, 1.2f * (float)i, 0.0f, 0.0f);
    }
    return s;
}

/* Compares every fourth pixel the reference can judge; returns the fewest compared on any instance
 * (0 and a message at the first difference beyond SHADE_TOLERANCE). */
static uint32_t compare_with_reference(const gdr_scene *s, const gdr_camera *camera, uint32_t w, uint32_t h,
                                       const uint8_t *rgba, const char *what)
{
    uint32_t per_instance[16] = {0}, instance = 0;
    for (uint32_t y = 1; y + 1 < h; y += 4)
        for (uint32_t x = 1; x + 1 < w; x += 4) {
            uint8_t expected[3];
            if (!ref_shade_pixel(s, camera, w, h, x, y, expected, &instance))
                continue;
            const uint8_t *got = rgba + ((size_t)y * w + x) * 4;
            for (int k = 0; k < 3; k++)
                if (abs((int)got[k] - (int)expected[k]) > SHADE_TOLERANCE) {
                    fprintf(stderr, "%s: pixel (%u, %u): got %u %u %u, reference %u %u %u\n", what, x, y, got[0], got[1],
                            got[2], expected[0], expected[1], expected[2]);
                    return 0;
                }
            per_instance[instance < 16 ? instance : 15]++;
        }
    uint32_t fewest = UINT32_MAX;
    for (uint32_t i = 0; i < s->instance_count && i < 16; i++)
        fewest = per_instance[i] < fewest ? per_instance[i] : fewest;
    return fewest;
}

static void test_cases(void)
{
    enum { W = 420, H = 108 };
    gdr_scene *s = cases_scene();
    gdr_renderer *r = gpu_test_renderer(W, H, s);
    CHECK(r != NULL);
    gdr_camera camera = test_look((gdr_vec3){4.1f, 0.5f, 3.6f}, 0.0f, 0.0f, 0.6f, 0.1f);
    uint8_t *rgba = malloc((size_t)W * H * 4);
    for (size_t p = 0; r && p < PATH_COUNT; p++) {
        if (!render_path(r, &camera, &paths[p], GDR_CULL_DEFAULT, rgba)) {
            CHECK(false);
            continue;
        }
        uint32_t compared = compare_with_reference(s, &camera, W, H, rgba, paths[p].name);
        printf("cases, %s: at least %u pixels of each quad match the reference\n", paths[p].name, compared);
        CHECK(compared >= 40);
    }
    free(rgba);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(s);
}

int main(void)
{
    test_cases();
    return test_finish("test_gpu_materials");
}
