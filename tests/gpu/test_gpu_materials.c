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

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gpu_test_util.h"
#include "material_reference.h"
#include "procedural/procedural_meshes.h"

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
 * it sees (0 and a message at the first difference beyond SHADE_TOLERANCE). */
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
    uint32_t fewest = UINT32_MAX; /* over the instances the reference sees (a culled back face is not) */
    for (uint32_t i = 0; i < s->instance_count && i < 16; i++)
        fewest = per_instance[i] && per_instance[i] < fewest ? per_instance[i] : fewest;
    return fewest == UINT32_MAX ? 0 : fewest;
}

static void test_cases(void)
{
    enum { W = 420, H = 108 };
    gdr_scene *s = cases_scene();
    CHECK(s && gdr_scene_build_clusters(s, NULL, &(gdr_error){0}) == GDR_OK); /* the renderer never builds them */
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

static int image_difference(const uint8_t *a, const uint8_t *b, uint32_t pixels, int tolerance, double *share_over);

/* The block bytes of every texture's chain: what a device sampling the formats holds, less its
 * images' alignment. */
static uint64_t chain_bytes(const gdr_scene *s, bool as_rgba8)
{
    uint64_t bytes = 0;
    for (uint32_t i = 0; i < s->texture_count; i++) {
        const gdr_texture *t = &s->textures[i];
        bytes += gdr_texture_format_level_offset(as_rgba8 ? GDR_TEXTURE_RGBA8 : t->format, t->width, t->height, t->levels);
    }
    return bytes;
}

/* The cases with every texture block-compressed: the format each use gets, every path against the
 * reference (which reads the decoded blocks), the renderer's texture memory against the blocks'
 * size, and a device without BC sampling (the decoding fallback) giving the same image. */
static void test_cases_compressed(void)
{
    enum { W = 420, H = 108 };
    gdr_scene *s = cases_scene();
    gdr_error err = {0};
    CHECK(s && gdr_scene_build_clusters(s, NULL, &err) == GDR_OK);
    CHECK(gdr_scene_compress_textures(s, NULL, &err) == GDR_OK);
    /* base colour and emissive (opaque): BC1; normal: BC5; metallic-roughness: BC5_GB; occlusion: BC4 */
    const uint32_t expected[5] = {GDR_TEXTURE_BC1, GDR_TEXTURE_BC1, GDR_TEXTURE_BC5, GDR_TEXTURE_BC5_GB, GDR_TEXTURE_BC4};
    for (uint32_t i = 0; i < 5 && i < s->texture_count; i++)
        CHECK(s->textures[i].format == expected[i]);
    gdr_renderer *bc = gpu_test_renderer(W, H, s), *decoding = NULL;
    gdr_renderer_desc desc = {.width = W, .height = H, .validate = true, .disable_texture_compression_bc = true};
    CHECK(gdr_renderer_create(&desc, &decoding, &err) == GDR_OK && gdr_renderer_set_scene(decoding, s, &err) == GDR_OK);
    CHECK(bc != NULL);
    gdr_camera camera = test_look((gdr_vec3){4.1f, 0.5f, 3.6f}, 0.0f, 0.0f, 0.6f, 0.1f);
    uint8_t *rgba = malloc((size_t)W * H * 4), *fallback = malloc((size_t)W * H * 4);
    for (size_t p = 0; bc && p < PATH_COUNT; p++) {
        if (!render_path(bc, &camera, &paths[p], GDR_CULL_DEFAULT, rgba)) {
            CHECK(false);
            continue;
        }
        uint32_t compared = compare_with_reference(s, &camera, W, H, rgba, paths[p].name);
        printf("cases compressed, %s: at least %u pixels of each quad match the reference\n", paths[p].name, compared);
        CHECK(compared >= 40);
        CHECK(render_path(decoding, &camera, &paths[p], GDR_CULL_DEFAULT, fallback));
        double share = 0;
        int largest = image_difference(rgba, fallback, W * H, 1, &share);
        printf("cases compressed, %s: decoded at upload vs sampled as BC: largest difference %d\n", paths[p].name, largest);
        CHECK(largest <= 1);
    }
    gdr_frame_stats stats[2];
    gdr_frame_desc frame = {.camera = camera};
    CHECK(gdr_renderer_render(bc, &frame, 1, &stats[0], &err) == GDR_OK);
    CHECK(gdr_renderer_render(decoding, &frame, 1, &stats[1], &err) == GDR_OK);
    uint64_t blocks = chain_bytes(s, false), texels = chain_bytes(s, true);
    printf("cases compressed: texture memory %llu bytes as BC (blocks %llu), %llu decoded (RGBA8 %llu)\n",
           (unsigned long long)stats[0].memory.texture_bytes, (unsigned long long)blocks,
           (unsigned long long)stats[1].memory.texture_bytes, (unsigned long long)texels);
    CHECK(stats[0].memory.textures_compressed == 5 && stats[0].memory.textures_decoded == 0);
    CHECK(stats[1].memory.textures_compressed == 0 && stats[1].memory.textures_decoded == 5);
    CHECK(stats[0].memory.texture_bytes >= blocks && stats[1].memory.texture_bytes >= texels);
    free(rgba);
    free(fallback);
    gdr_renderer_destroy(bc);
    gdr_renderer_destroy(decoding);
    gdr_scene_destroy(s);
}

/* BoxTextured up close: the front face's texture magnified, so that the reference's level-0
 * bilinear sample is what every path reads. */
static void test_box_textured(const char *relative)
{
    enum { W = 240, H = 240 };
    char path[256];
    snprintf(path, sizeof path, "%s%s", MODELS, relative);
    gdr_scene *s = NULL;
    gdr_error err = {0};
    gdr_load_options options = {.no_cache = 1, .no_progress = 1};
    if (gdr_scene_load(path, &options, &s, &err) != GDR_OK) {
        fprintf(stderr, "%s: %s\n", relative, err.message);
        CHECK(false);
        return;
    }
    CHECK(s->texture_count == 1 && s->material_count >= 1);
    CHECK(s && gdr_scene_build_clusters(s, NULL, &(gdr_error){0}) == GDR_OK); /* the renderer never builds them */
    gdr_renderer *r = gpu_test_renderer(W, H, s);
    gdr_camera camera = gdr_scene_framing_camera(s);
    gdr_vec4 b = s->meshes[0].bounds;
    gdr_vec3 centre = gdr_mat4_transform_point(s->instances[0].transform, (gdr_vec3){b.x, b.y, b.z});
    camera.position = gdr_vec3_add(centre, gdr_vec3_scale(gdr_vec3_sub(camera.position, centre), 0.3f));
    camera.aspect = 0.0f;
    uint8_t *rgba = malloc((size_t)W * H * 4);
    for (size_t p = 0; r && p < PATH_COUNT; p++) {
        CHECK(render_path(r, &camera, &paths[p], GDR_CULL_DEFAULT, rgba));
        uint32_t compared = compare_with_reference(s, &camera, W, H, rgba, relative);
        printf("%s, %s: %u pixels match the reference\n", relative, paths[p].name, compared);
        CHECK(compared >= 200);
    }
    /* its one texture, base colour without alpha, sampled as BC1: 8 bytes per 4 x 4 block, a level
     * below 4 texels a side taking one whole block */
    const gdr_texture *t = &s->textures[0];
    CHECK(t->format == GDR_TEXTURE_BC1);
    uint64_t blocks = 0;
    for (uint32_t w = t->width, h = t->height;; w = w > 1 ? w / 2 : 1, h = h > 1 ? h / 2 : 1) {
        blocks += 8ull * ((w + 3) / 4) * ((h + 3) / 4);
        if (w == 1 && h == 1)
            break;
    }
    CHECK(blocks == chain_bytes(s, false));
    gdr_frame_stats stats;
    gdr_frame_desc frame = {.camera = camera};
    CHECK(r && gdr_renderer_render(r, &frame, 1, &stats, &err) == GDR_OK);
    printf("%s: %ux%u, texture memory %llu bytes, its BC1 blocks %llu\n", relative, t->width, t->height,
           (unsigned long long)stats.memory.texture_bytes, (unsigned long long)blocks);
    CHECK(stats.memory.textures_compressed == 1 && stats.memory.texture_bytes >= blocks &&
          stats.memory.texture_bytes < blocks + 4096);
    free(rgba);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(s);
}

/* A plane of 8 x 8 units with a 64 x 64 checkerboard (8-texel squares) repeated 8 times, glTF's
 * default sampler (trilinear, repeat): every pixel minified, so mip selection decides its colour. */
static gdr_scene *checker_scene(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create(&s, &err) == GDR_OK);
    uint8_t texels[64 * 64 * 4];
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            uint8_t v = ((x / 8 + y / 8) & 1) ? 230 : 20;
            uint8_t *t = texels + (y * 64 + x) * 4;
            t[0] = v;
            t[1] = (uint8_t)(255 - v);
            t[2] = 128;
            t[3] = 255;
        }
    uint32_t texture = 0, material = 0, mesh = add_quad(s, "plane", 0.0f, 8.0f);
    CHECK(gdr_scene_add_texture(s, "checker", 64, 64, texels, 1, &texture, &err) == GDR_OK);
    gdr_material m = gdr_material_default();
    m.metallic_factor = 0.0f;
    m.base_color_texture = tex(texture, 0);
    CHECK(gdr_scene_add_material(s, &m, &material, &err) == GDR_OK);
    gdr_instance inst = {.transform = gdr_mat4_from_trs((gdr_vec3){-4, -4, 0}, gdr_quat_identity(), (gdr_vec3){8, 8, 1}),
                         .mesh = mesh, .material = material, .color = {1, 1, 1, 1}};
    CHECK(gdr_scene_add_instance(s, &inst, &err) == GDR_OK);
    return s;
}

/* Largest channel difference and the share of pixels differing by more than `tolerance`. */
static int image_difference(const uint8_t *a, const uint8_t *b, uint32_t pixels, int tolerance, double *share_over)
{
    int largest = 0;
    uint32_t over = 0;
    for (uint32_t p = 0; p < pixels; p++) {
        int worst = 0;
        for (int k = 0; k < 3; k++) {
            int d = abs((int)a[p * 4 + k] - (int)b[p * 4 + k]);
            worst = d > worst ? d : worst;
        }
        largest = worst > largest ? worst : largest;
        over += worst > tolerance;
    }
    *share_over = (double)over / pixels;
    return largest;
}

/* Head-on, every path gives the forward mesh path's image to within one step of 255 (the same mip
 * level and weights, rounded differently); at a grazing angle the resolve's derivatives (the next
 * pixel's) and the forward paths' (a 2 x 2 quad's) differ by up to a pixel's change of the
 * derivative, which moves the trilinear weights: MIP_TOLERANCE bounds that. A wrong mip level (one
 * off) moves many pixels by tens of steps. */
#define MIP_TOLERANCE 6
static void test_checker_mips(void)
{
    enum { W = 160, H = 120 };
    gdr_scene *s = checker_scene();
    CHECK(s && gdr_scene_build_clusters(s, NULL, &(gdr_error){0}) == GDR_OK); /* the renderer never builds them */
    gdr_renderer *r = gpu_test_renderer(W, H, s);
    CHECK(r != NULL);
    const gdr_camera views[2] = {test_look((gdr_vec3){0.3f, 0.2f, 5.0f}, 0.0f, 0.0f, 0.9f, 0.1f),
                                 test_look((gdr_vec3){0.0f, -5.0f, 0.9f}, 0.0f, 1.35f, 0.9f, 0.1f)};
    uint8_t *reference = malloc((size_t)W * H * 4), *rgba = malloc((size_t)W * H * 4);
    for (int v = 0; r && v < 2; v++) {
        CHECK(render_path(r, &views[v], &paths[0], GDR_CULL_DEFAULT, reference));
        for (size_t p = 1; p < PATH_COUNT; p++) {
            CHECK(render_path(r, &views[v], &paths[p], GDR_CULL_DEFAULT, rgba));
            double share = 0.0;
            int largest = image_difference(reference, rgba, W * H, v == 0 ? 1 : MIP_TOLERANCE, &share);
            printf("checker %s, %s vs %s: largest difference %d, %.3f%% of pixels beyond %d\n",
                   v == 0 ? "head-on" : "grazing", paths[p].name, paths[0].name, largest, 100.0 * share,
                   v == 0 ? 1 : MIP_TOLERANCE);
            CHECK(v == 0 ? largest <= 1 : share <= 0.002);
        }
    }
    free(reference);
    free(rgba);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(s);
}

/* A MASK quad with holes (alpha 0 on alternate texels of a 4 x 4 texture) and a BLEND quad (alpha
 * 0.5 everywhere) in front of a red wall, and a yellow tile hidden behind the middle of each quad
 * but for the holes: if a quad were drawn opaque, or counted as an opaque occluder, its tile would
 * be hidden or culled. */
#define TILE_X(i) ((i) == 0 ? -0.8f : 0.4f)
#define TILE_Y 0.3f
#define TILE_Z -0.2f
#define TILE_SIZE 0.4f
static gdr_scene *alpha_scene(void)
{
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create(&s, &err) == GDR_OK);
    uint8_t texels[4 * 4 * 4];
    for (int i = 0; i < 16; i++) {
        texels[i * 4 + 0] = 40;
        texels[i * 4 + 1] = 90;
        texels[i * 4 + 2] = 220;
        texels[i * 4 + 3] = ((i % 4 + i / 4) & 1) ? 0 : 255;
    }
    uint32_t texture = 0, mesh = add_quad(s, "quad", 0.0f, 1.0f), ids[4];
    CHECK(gdr_scene_add_texture(s, "holes", 4, 4, texels, 1, &texture, &err) == GDR_OK);
    gdr_material m[4] = {gdr_material_default(), gdr_material_default(), gdr_material_default(),
                         gdr_material_default()};
    m[0].alpha_mode = GDR_ALPHA_MASK;
    m[0].base_color_texture = tex(texture, NEAREST);
    m[1].alpha_mode = GDR_ALPHA_BLEND;
    m[1].base_color = (gdr_vec4){0.15f, 0.35f, 0.85f, 0.5f};
    m[2].base_color = (gdr_vec4){1.0f, 0.05f, 0.05f, 1.0f}; /* the wall */
    m[3].base_color = (gdr_vec4){1.0f, 1.0f, 0.05f, 1.0f};  /* the tiles */
    for (int i = 0; i < 4; i++) {
        m[i].metallic_factor = 0.0f;
        CHECK(gdr_scene_add_material(s, &m[i], &ids[i], &err) == GDR_OK);
    }
    place(s, mesh, ids[0], -1.1f, 0.0f, 0.0f);
    place(s, mesh, ids[1], 0.1f, 0.0f, 0.0f);
    gdr_instance wall = {.transform = gdr_mat4_from_trs((gdr_vec3){-2.0f, -0.5f, -0.5f}, gdr_quat_identity(), (gdr_vec3){4, 2, 1}),
                         .mesh = mesh, .material = ids[2], .color = {1, 1, 1, 1}};
    CHECK(gdr_scene_add_instance(s, &wall, &err) == GDR_OK);
    for (int i = 0; i < 2; i++) {
        gdr_instance tile = {.transform = gdr_mat4_from_trs((gdr_vec3){TILE_X(i), TILE_Y, TILE_Z}, gdr_quat_identity(),
                                                            (gdr_vec3){TILE_SIZE, TILE_SIZE, 1}),
                             .mesh = mesh, .material = ids[3], .color = {1, 1, 1, 1}};
        CHECK(gdr_scene_add_instance(s, &tile, &err) == GDR_OK);
    }
    return s;
}

static bool is_red(const uint8_t *c) { return c[0] > 2 * c[2] && c[0] > 100; }
static bool is_blue(const uint8_t *c) { return c[2] > 2 * c[0]; }
static bool is_yellow(const uint8_t *c) { return c[0] > 100 && c[1] > 100 && c[2] < c[1] / 2; }

/* Whether the ray (o, d) passes through tile i (behind quad i). */
static bool through_tile(ref_vec3 o, ref_vec3 d, int i)
{
    double t = (TILE_Z - o.z) / d.z, x = o.x + t * d.x - TILE_X(i), y = o.y + t * d.y - TILE_Y;
    return x > 0.02 && x < TILE_SIZE - 0.02 && y > 0.02 && y < TILE_SIZE - 0.02;
}

static void test_alpha(void)
{
    enum { W = 200, H = 100 };
    gdr_scene *s = alpha_scene();
    CHECK(s && gdr_scene_build_clusters(s, NULL, &(gdr_error){0}) == GDR_OK); /* the renderer never builds them */
    gdr_renderer *r = gpu_test_renderer(W, H, s);
    CHECK(r != NULL);
    gdr_camera camera = test_look((gdr_vec3){0.0f, 0.5f, 2.2f}, 0.0f, 0.0f, 0.6f, 0.1f);
    uint8_t *rgba = malloc((size_t)W * H * 4);
    for (size_t p = 0; r && p < PATH_COUNT; p++) {
        /* Two frames with occlusion culling on: the second tests against the first's pyramid. */
        gdr_cull_mode occlusion = paths[p].pipeline == GDR_PIPELINE_CPU ? GDR_CULL_DEFAULT : GDR_CULL_ON;
        CHECK(render_path(r, &camera, &paths[p], occlusion, rgba) && render_path(r, &camera, &paths[p], occlusion, rgba));
        uint32_t hole_red = 0, hole_other = 0, solid_blue = 0, solid_other = 0, blend_red = 0, blend_blue = 0;
        uint32_t tile_seen[2] = {0, 0}, tile_missed[2] = {0, 0};
        for (uint32_t y = 0; y < H; y++)
            for (uint32_t x = 0; x < W; x++) {
                ref_vec3 o, d;
                ref_pixel_ray(&camera, W, H, x, y, &o, &d);
                ref_hit h = ref_raycast(s, o, d); /* the quads are nearer than the wall */
                if (!h.hit || h.instance >= 2)
                    continue;
                const uint8_t *c = rgba + ((size_t)y * W + x) * 4;
                bool tile = through_tile(o, d, (int)h.instance);
                double u = h.position.x - (h.instance == 0 ? -1.1 : 0.1), v = 1.0 - h.position.y;
                double fu = u * 4 - floor(u * 4), fv = v * 4 - floor(v * 4);
                if (fu < 0.1 || fu > 0.9 || fv < 0.1 || fv > 0.9)
                    continue; /* texel edges */
                if (h.instance == 0) {
                    bool hole = (((int)(u * 4) + (int)(v * 4)) & 1) != 0;
                    hole_red += hole && !tile && is_red(c);
                    hole_other += hole && !tile && !is_red(c);
                    tile_seen[0] += hole && tile && is_yellow(c);
                    tile_missed[0] += hole && tile && !is_yellow(c);
                    solid_blue += !hole && is_blue(c);
                    solid_other += !hole && !is_blue(c);
                } else {
                    blend_red += !tile && is_red(c);
                    blend_blue += !tile && is_blue(c);
                    tile_seen[1] += tile && is_yellow(c);
                    tile_missed[1] += tile && !is_yellow(c) && !is_blue(c);
                }
            }
        double blend_share = (double)blend_red / (blend_red + blend_blue + 1e-9);
        printf("alpha, %s: mask holes %u red, %u not; solid %u blue, %u not; blend %.2f red; tiles seen %u, %u, "
               "missed %u, %u\n", paths[p].name, hole_red, hole_other, solid_blue, solid_other, blend_share,
               tile_seen[0], tile_seen[1], tile_missed[0], tile_missed[1]);
        CHECK(hole_red > 200 && hole_other == 0 && solid_blue > 200 && solid_other == 0);
        CHECK(tile_seen[0] > 20 && tile_seen[1] > 20 && tile_missed[0] == 0 && tile_missed[1] == 0);
        CHECK(blend_share > 0.4 && blend_share < 0.6 && blend_red + blend_blue > 400);
    }
    free(rgba);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(s);
}

/* Three quads turned away from the camera in front of a wall: a double-sided one (shaded with its
 * normal reversed, against the reference), a single-sided one (culled: the wall shows) and a
 * double-sided MASK one; the reference ray-caster skips single-sided back faces. */
static void test_double_sided(void)
{
    enum { W = 240, H = 80 };
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create(&s, &err) == GDR_OK);
    uint32_t mesh = add_quad(s, "quad", 0.0f, 1.0f), base = add_texture(s, 4, 4, 1, 7, false), ids[4];
    gdr_material m[4] = {gdr_material_default(), gdr_material_default(), gdr_material_default(),
                         gdr_material_default()};
    m[0].double_sided = 1;
    m[0].base_color_texture = tex(base, NEAREST);
    m[1].base_color = (gdr_vec4){0.1f, 0.9f, 0.1f, 1};
    m[2].double_sided = 1;
    m[2].alpha_mode = GDR_ALPHA_MASK;
    m[2].base_color_texture = tex(base, NEAREST);
    m[2].alpha_cutoff = 0.0f;
    m[3].base_color = (gdr_vec4){0.9f, 0.2f, 0.2f, 1};
    for (int i = 0; i < 4; i++) {
        m[i].metallic_factor = 0.0f;
        m[i].roughness_factor = 0.7f;
        CHECK(gdr_scene_add_material(s, &m[i], &ids[i], &err) == GDR_OK);
    }
    gdr_quat turned = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, 3.14159265f);
    for (int i = 0; i < 3; i++) {
        gdr_instance q = {.transform = gdr_mat4_from_trs((gdr_vec3){1.2f * (float)i, 0, 0}, turned, (gdr_vec3){1, 1, 1}),
                          .mesh = mesh, .material = ids[i], .color = {1, 1, 1, 1}};
        CHECK(gdr_scene_add_instance(s, &q, &err) == GDR_OK);
    }
    gdr_instance wall = {.transform = gdr_mat4_from_trs((gdr_vec3){-3, -1, -1}, gdr_quat_identity(), (gdr_vec3){6, 3, 1}),
                         .mesh = mesh, .material = ids[3], .color = {1, 1, 1, 1}};
    CHECK(gdr_scene_add_instance(s, &wall, &err) == GDR_OK);
    CHECK(s && gdr_scene_build_clusters(s, NULL, &(gdr_error){0}) == GDR_OK); /* the renderer never builds them */
    gdr_renderer *r = gpu_test_renderer(W, H, s);
    CHECK(r != NULL);
    gdr_camera camera = test_look((gdr_vec3){0.6f, 0.5f, 2.6f}, 0.0f, 0.0f, 0.6f, 0.1f);
    uint8_t *rgba = malloc((size_t)W * H * 4);
    for (size_t p = 0; r && p < PATH_COUNT; p++) {
        CHECK(render_path(r, &camera, &paths[p], GDR_CULL_DEFAULT, rgba));
        uint32_t compared = compare_with_reference(s, &camera, W, H, rgba, paths[p].name);
        printf("double-sided, %s: at least %u pixels of each surface match the reference\n", paths[p].name, compared);
        CHECK(compared >= 20);
    }
    free(rgba);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(s);
}

/* Peak signal-to-noise ratio of b against a (RGB, 8 bits), in dB. */
static double psnr(const uint8_t *a, const uint8_t *b, uint32_t pixels)
{
    double sum = 0.0;
    for (uint32_t p = 0; p < pixels; p++)
        for (int k = 0; k < 3; k++) {
            double d = (double)a[p * 4 + k] - (double)b[p * 4 + k];
            sum += d * d;
        }
    double mse = sum / (pixels * 3.0);
    return mse > 0.0 ? 10.0 * log10(255.0 * 255.0 / mse) : 99.0;
}

/* Pixels of b whose colour is more than `tolerance` from every pixel of a within one pixel (a
 * tear, a hole or a texture slid by more than a pixel shows as such pixels). */
static uint32_t beyond_one_pixel(const uint8_t *a, const uint8_t *b, uint32_t w, uint32_t h, int tolerance)
{
    uint32_t count = 0;
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++) {
            bool near = false;
            for (int dy = -1; dy <= 1 && !near; dy++)
                for (int dx = -1; dx <= 1 && !near; dx++) {
                    int nx = (int)x + dx, ny = (int)y + dy;
                    if (nx < 0 || ny < 0 || nx >= (int)w || ny >= (int)h)
                        continue;
                    const uint8_t *pa = a + ((size_t)ny * w + nx) * 4, *pb = b + ((size_t)y * w + x) * 4;
                    near = abs(pa[0] - pb[0]) <= tolerance && abs(pa[1] - pb[1]) <= tolerance &&
                           abs(pa[2] - pb[2]) <= tolerance;
                }
            count += !near;
        }
    return count;
}

/* A textured torus (a u seam: the first and last ring of vertices share positions, not uvs) with
 * its LOD DAG, at a LOD threshold of 1 pixel against full detail: UVs and normals are the kept
 * vertices' own, so the image stays within a pixel of full detail and the seam does not open. */
static void test_textured_lod(void)
{
    enum { W = 256, H = 160 };
    gdr_scene *s = NULL;
    gdr_error err = {0};
    CHECK(gdr_scene_create(&s, &err) == GDR_OK);
    uint32_t mesh = 0, texture = 0, material = 0;
    CHECK(gdr_procedural_torus(s, 1.0f, 0.35f, 300, 100, &mesh, &err) == GDR_OK);
    uint8_t texels[32 * 32 * 4];
    for (int i = 0; i < 32 * 32; i++) {
        bool dark = ((i % 32) / 4 + (i / 32) / 4) & 1;
        texels[i * 4 + 0] = dark ? 40 : 220;
        texels[i * 4 + 1] = dark ? 60 : 180;
        texels[i * 4 + 2] = dark ? 160 : 90;
        texels[i * 4 + 3] = 255;
    }
    CHECK(gdr_scene_add_texture(s, "checker", 32, 32, texels, 1, &texture, &err) == GDR_OK);
    gdr_material m = gdr_material_default();
    m.metallic_factor = 0.0f;
    m.base_color_texture = tex(texture, 0);
    m.base_color_texture.scale = (gdr_vec2){4.0f, 2.0f};
    CHECK(gdr_scene_add_material(s, &m, &material, &err) == GDR_OK);
    gdr_instance inst = {.transform = gdr_mat4_identity(), .mesh = mesh, .material = material, .color = {1, 1, 1, 1}};
    CHECK(gdr_scene_add_instance(s, &inst, &err) == GDR_OK);
    gdr_lod_options options = {0};
    CHECK(gdr_scene_build_lod(s, &options, NULL, &err) == GDR_OK);
    CHECK(s && gdr_scene_build_clusters(s, NULL, &(gdr_error){0}) == GDR_OK); /* the renderer never builds them */
    gdr_renderer *r = gpu_test_renderer(W, H, s);
    CHECK(r != NULL);
    gdr_camera camera = test_look((gdr_vec3){0.0f, 2.2f, 2.6f}, 0.0f, -0.7f, 0.8f, 0.1f);
    uint8_t *full = malloc((size_t)W * H * 4), *lod = malloc((size_t)W * H * 4);
    gdr_frame_desc frame = {.camera = camera, .cull = GDR_CULL_ON, .read_back = true, .pipeline = GDR_PIPELINE_MESH};
    gdr_frame_stats full_stats = {0}, lod_stats = {0};
    CHECK(r && gdr_renderer_render(r, &frame, 1, &full_stats, &err) == GDR_OK && gdr_renderer_read_color(r, full, &err) == GDR_OK);
    frame.lod_error_px = 1.0f;
    CHECK(r && gdr_renderer_render(r, &frame, 1, &lod_stats, &err) == GDR_OK && gdr_renderer_read_color(r, lod, &err) == GDR_OK);
    double quality = psnr(full, lod, W * H);
    uint32_t beyond = beyond_one_pixel(full, lod, W, H, 24) + beyond_one_pixel(lod, full, W, H, 24);
    printf("textured LOD at 1 px: %llu of %llu triangles, PSNR %.1f dB against full detail, %u pixels beyond a "
           "pixel's reach\n", (unsigned long long)lod_stats.triangles, (unsigned long long)full_stats.triangles, quality,
           beyond);
    CHECK(lod_stats.triangles * 2 < full_stats.triangles); /* the cut is well coarser than level 0 */
    CHECK(quality >= 30.0 && beyond <= W * H / 200);
    free(full);
    free(lod);
    gdr_renderer_destroy(r);
    gdr_scene_destroy(s);
}

int main(void)
{
    test_cases();
    test_cases_compressed();
    test_box_textured("BoxTextured-glTF/BoxTextured.gltf");
    test_box_textured("BoxTextured-glTF-Binary/BoxTextured.glb");
    test_box_textured("BoxTextured-glTF-Embedded/BoxTextured.gltf");
    test_checker_mips();
    test_alpha();
    test_double_sided();
    test_textured_lod();
    return test_finish("test_gpu_materials");
}
