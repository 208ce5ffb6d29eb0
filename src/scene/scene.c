#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/scene.h"
#include "scene/texture_mips.h"

/* Grows *array (of element_size bytes each) so it holds at least count + 1 elements. */
static gdr_status reserve_one(void **array, uint32_t *capacity, uint32_t count, size_t element_size,
                              gdr_error *err)
{
    if (count < *capacity)
        return GDR_OK;
    if (count == UINT32_MAX)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "scene: more than %u elements", UINT32_MAX - 1);
    uint64_t wanted = *capacity ? (uint64_t)*capacity * 2 : 16;
    if (wanted > UINT32_MAX)
        wanted = UINT32_MAX;
    void *grown = realloc(*array, (size_t)wanted * element_size);
    if (!grown)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene: out of memory growing an array to %llu",
                             (unsigned long long)wanted);
    *array = grown;
    *capacity = (uint32_t)wanted;
    return GDR_OK;
}

gdr_status gdr_scene_create(gdr_scene **out, gdr_error *err)
{
    *out = calloc(1, sizeof **out);
    return *out ? GDR_OK : gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene: out of memory");
}

void gdr_scene_destroy(gdr_scene *scene)
{
    if (!scene)
        return;
    for (uint32_t i = 0; i < scene->mesh_count; i++) {
        free(scene->meshes[i].positions);
        free(scene->meshes[i].normals);
        free(scene->meshes[i].uvs);
        free(scene->meshes[i].colors);
        free(scene->meshes[i].indices);
        gdr_mesh_clusters_free(&scene->meshes[i].clusters);
    }
    free(scene->meshes);
    free(scene->materials);
    free(scene->instances);
    free(scene->cameras);
    for (uint32_t i = 0; i < scene->texture_count; i++)
        free(scene->textures[i].rgba);
    free(scene->textures);
    free(scene->extensions);
    free(scene);
}

/* Area-weighted face normals summed per vertex; degenerate vertices get +Y. */
static void generate_normals(gdr_mesh *mesh)
{
    memset(mesh->normals, 0, sizeof(gdr_vec3) * mesh->vertex_count);
    for (uint32_t t = 0; t + 2 < mesh->index_count; t += 3) {
        uint32_t a = mesh->indices[t], b = mesh->indices[t + 1], c = mesh->indices[t + 2];
        gdr_vec3 n = gdr_vec3_cross(gdr_vec3_sub(mesh->positions[b], mesh->positions[a]),
                                    gdr_vec3_sub(mesh->positions[c], mesh->positions[a]));
        mesh->normals[a] = gdr_vec3_add(mesh->normals[a], n);
        mesh->normals[b] = gdr_vec3_add(mesh->normals[b], n);
        mesh->normals[c] = gdr_vec3_add(mesh->normals[c], n);
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        float length = gdr_vec3_length(mesh->normals[v]);
        mesh->normals[v] = length > 0.0f ? gdr_vec3_scale(mesh->normals[v], 1.0f / length)
                                         : (gdr_vec3){0.0f, 1.0f, 0.0f};
    }
}

/* Sphere around the centre of the bounding box: not minimal, but contains every vertex. */
static gdr_vec4 compute_bounds(const gdr_vec3 *positions, uint32_t count)
{
    if (count == 0)
        return (gdr_vec4){0.0f, 0.0f, 0.0f, 0.0f};
    gdr_vec3 lo = positions[0], hi = positions[0];
    for (uint32_t i = 1; i < count; i++) {
        lo = (gdr_vec3){fminf(lo.x, positions[i].x), fminf(lo.y, positions[i].y), fminf(lo.z, positions[i].z)};
        hi = (gdr_vec3){fmaxf(hi.x, positions[i].x), fmaxf(hi.y, positions[i].y), fmaxf(hi.z, positions[i].z)};
    }
    gdr_vec3 center = gdr_vec3_scale(gdr_vec3_add(lo, hi), 0.5f);
    float radius = 0.0f;
    for (uint32_t i = 0; i < count; i++)
        radius = fmaxf(radius, gdr_vec3_length(gdr_vec3_sub(positions[i], center)));
    /* One ulp of slack per unit so float rounding in transforms cannot shrink the sphere. */
    radius *= 1.0f + 1e-6f;
    return (gdr_vec4){center.x, center.y, center.z, radius};
}

gdr_status gdr_scene_add_mesh(gdr_scene *scene, const char *name, const gdr_vec3 *positions,
                              const gdr_vec3 *normals, const gdr_vec2 *uvs, uint32_t vertex_count,
                              const uint32_t *indices, uint32_t index_count, uint32_t *out_index,
                              gdr_error *err)
{
    if (index_count % 3 != 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': index count %u is not a multiple of 3",
                             name, index_count);
    for (uint32_t i = 0; i < index_count; i++)
        if (indices[i] >= vertex_count)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                 "mesh '%s': index %u (at %u) is out of range (vertex count %u)", name,
                                 indices[i], i, vertex_count);
    for (uint32_t v = 0; v < vertex_count; v++)
        if (!(fabsf(positions[v].x) <= GDR_MAX_COORDINATE) || !(fabsf(positions[v].y) <= GDR_MAX_COORDINATE) ||
            !(fabsf(positions[v].z) <= GDR_MAX_COORDINATE))
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': position %u (%g, %g, %g) is not "
                                 "finite or beyond the %g limit on coordinates", name, v, positions[v].x,
                                 positions[v].y, positions[v].z, GDR_MAX_COORDINATE);
    gdr_status status = reserve_one((void **)&scene->meshes, &scene->mesh_capacity, scene->mesh_count,
                                    sizeof(gdr_mesh), err);
    if (status != GDR_OK)
        return status;

    gdr_mesh mesh = {0};
    snprintf(mesh.name, sizeof mesh.name, "%s", name ? name : "");
    mesh.vertex_count = vertex_count;
    mesh.index_count = index_count;
    size_t vertex_bytes = sizeof(gdr_vec3) * (size_t)vertex_count;
    mesh.positions = malloc(vertex_bytes ? vertex_bytes : 1);
    mesh.normals = malloc(vertex_bytes ? vertex_bytes : 1);
    mesh.uvs = calloc(vertex_count ? vertex_count : 1, sizeof(gdr_vec2));
    mesh.indices = malloc(sizeof(uint32_t) * (index_count ? index_count : 1));
    if (!mesh.positions || !mesh.normals || !mesh.uvs || !mesh.indices) {
        free(mesh.positions);
        free(mesh.normals);
        free(mesh.uvs);
        free(mesh.indices);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory", name);
    }
    memcpy(mesh.positions, positions, vertex_bytes);
    memcpy(mesh.indices, indices, sizeof(uint32_t) * index_count);
    if (uvs)
        memcpy(mesh.uvs, uvs, sizeof(gdr_vec2) * vertex_count);
    if (normals)
        memcpy(mesh.normals, normals, vertex_bytes);
    else
        generate_normals(&mesh);
    mesh.bounds = compute_bounds(positions, vertex_count);

    if (out_index)
        *out_index = scene->mesh_count;
    scene->meshes[scene->mesh_count++] = mesh;
    return GDR_OK;
}

gdr_status gdr_scene_add_paged_mesh(gdr_scene *scene, const char *name, uint32_t vertex_count, uint32_t index_count,
                                    gdr_vec4 bounds, gdr_error *err)
{
    if (!scene->geometry_in_pages)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': a mesh without geometry needs a scene "
                             "whose geometry is in pages", name ? name : "");
    if (index_count % 3 != 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': index count %u is not a multiple of 3",
                             name ? name : "", index_count);
    gdr_status status = reserve_one((void **)&scene->meshes, &scene->mesh_capacity, scene->mesh_count,
                                    sizeof(gdr_mesh), err);
    if (status != GDR_OK)
        return status;
    gdr_mesh mesh = {.vertex_count = vertex_count, .index_count = index_count, .bounds = bounds};
    snprintf(mesh.name, sizeof mesh.name, "%s", name ? name : "");
    scene->meshes[scene->mesh_count++] = mesh;
    return GDR_OK;
}

gdr_material gdr_material_default(void)
{
    const gdr_texture_ref none = {.texture = GDR_NO_INDEX, .scale = {1.0f, 1.0f}};
    return (gdr_material){.base_color = {1, 1, 1, 1}, .base_color_texture = none,
                          .metallic_roughness_texture = none, .normal_texture = none,
                          .occlusion_texture = none, .emissive_texture = none, .metallic_factor = 1.0f,
                          .roughness_factor = 1.0f, .normal_scale = 1.0f, .occlusion_strength = 1.0f,
                          .alpha_cutoff = 0.5f, .alpha_mode = GDR_ALPHA_OPAQUE};
}

gdr_status gdr_scene_set_mesh_colors(gdr_scene *scene, uint32_t mesh, const gdr_vec4 *colors, gdr_error *err)
{
    if (mesh >= scene->mesh_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "vertex colours: mesh %u does not exist (%u meshes)",
                             mesh, scene->mesh_count);
    gdr_mesh *m = &scene->meshes[mesh];
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        const float *c = &colors[i].x;
        for (int k = 0; k < 4; k++)
            if (!(c[k] >= 0.0f && c[k] <= 1.0f))
                return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                     "mesh '%s': vertex colour %u is not in [0, 1]", m->name, i);
    }
    gdr_vec4 *copy = malloc(sizeof *copy * (m->vertex_count ? m->vertex_count : 1));
    if (!copy)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory for vertex colours", m->name);
    memcpy(copy, colors, sizeof *copy * m->vertex_count);
    free(m->colors);
    m->colors = copy;
    return GDR_OK;
}

gdr_status gdr_scene_add_material(gdr_scene *scene, const gdr_material *material, uint32_t *out_index,
                                  gdr_error *err)
{
    const char *problem = gdr_material_problem(material);
    if (problem)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "material %u ('%.*s'): %s", scene->material_count, GDR_NAME_MAX - 1,
                             material->name, problem);
    gdr_status status = reserve_one((void **)&scene->materials, &scene->material_capacity,
                                    scene->material_count, sizeof(gdr_material), err);
    if (status != GDR_OK)
        return status;
    if (out_index)
        *out_index = scene->material_count;
    scene->materials[scene->material_count++] = *material;
    return GDR_OK;
}

/* How far from the origin (largest coordinate, plus the radius) a transform places a mesh's bounding
 * sphere, in doubles so that nothing overflows. World space has the limit of mesh space: beyond
 * about 1e18 the view, the culling planes and the screen-size tests stop being finite, and the
 * pipelines disagreed (one refused with no file named, the others drew nothing). */
static double world_reach(const gdr_mesh *mesh, const gdr_mat4 *t)
{
    const float *m = t->m;
    double centre[3], scale = 0.0;
    for (int r = 0; r < 3; r++)
        centre[r] = (double)m[r] * mesh->bounds.x + (double)m[4 + r] * mesh->bounds.y +
                    (double)m[8 + r] * mesh->bounds.z + (double)m[12 + r];
    for (int col = 0; col < 3; col++) {
        double length = sqrt((double)m[4 * col] * m[4 * col] + (double)m[4 * col + 1] * m[4 * col + 1] +
                             (double)m[4 * col + 2] * m[4 * col + 2]);
        scale = length > scale ? length : scale;
    }
    double largest = fmax(fabs(centre[0]), fmax(fabs(centre[1]), fabs(centre[2])));
    return largest + scale * fabs((double)mesh->bounds.w);
}

gdr_status gdr_scene_add_instance(gdr_scene *scene, const gdr_instance *instance, gdr_error *err)
{
    if (instance->mesh >= scene->mesh_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "instance %u: mesh %u does not exist (%u meshes)",
                             scene->instance_count, instance->mesh, scene->mesh_count);
    if (instance->material != GDR_NO_INDEX && instance->material >= scene->material_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "instance %u: material %u does not exist (%u materials)", scene->instance_count,
                             instance->material, scene->material_count);
    for (int i = 0; i < 16; i++)
        if (!isfinite(instance->transform.m[i]))
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "instance %u: transform is not finite",
                                 scene->instance_count);
    /* A scene that holds mesh counts only (the paged reader's holder of instances) has no bounds:
     * the scene read beside it checks them. */
    double reach = scene->meshes ? world_reach(&scene->meshes[instance->mesh], &instance->transform) : 0.0;
    if (!(reach <= (double)GDR_MAX_COORDINATE))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "instance %u: its transform places mesh %u %g from the "
                             "origin, beyond the %g limit on coordinates", scene->instance_count, instance->mesh, reach,
                             (double)GDR_MAX_COORDINATE);
    if (!(instance->min_screen_size >= 0.0f && instance->min_screen_size <= FLT_MAX) ||
        !(instance->max_screen_size >= 0.0f && instance->max_screen_size <= FLT_MAX))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "instance %u: screen sizes must be finite and >= 0 (min %g, max %g)", scene->instance_count,
                             (double)instance->min_screen_size, (double)instance->max_screen_size);
    gdr_status status = reserve_one((void **)&scene->instances, &scene->instance_capacity,
                                    scene->instance_count, sizeof(gdr_instance), err);
    if (status != GDR_OK)
        return status;
    scene->instances[scene->instance_count++] = *instance;
    return GDR_OK;
}

gdr_status gdr_scene_add_camera(gdr_scene *scene, const gdr_camera *camera, gdr_error *err)
{
    gdr_status status = reserve_one((void **)&scene->cameras, &scene->camera_capacity, scene->camera_count,
                                    sizeof(gdr_camera), err);
    if (status != GDR_OK)
        return status;
    scene->cameras[scene->camera_count++] = *camera;
    return GDR_OK;
}

uint64_t gdr_scene_triangle_count(const gdr_scene *scene)
{
    uint64_t total = 0;
    for (uint32_t i = 0; i < scene->instance_count; i++)
        total += scene->meshes[scene->instances[i].mesh].index_count / 3;
    return total;
}

/* A texture of `levels` levels (width x height at level 0) whose chain is copied from `chain`, all
 * of it when `whole_chain`, else level 0 only and the rest built here. */
static gdr_status add_texture(gdr_scene *scene, const char *name, uint32_t width, uint32_t height, uint32_t format,
                              const uint8_t *chain, bool whole_chain, uint32_t srgb, uint32_t *out_index, gdr_error *err)
{
    if (width == 0 || height == 0 || width > 32768 || height > 32768)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "texture '%s': size %ux%u is out of range",
                             name ? name : "", width, height);
    if (format >= GDR_TEXTURE_FORMAT_COUNT || (format != GDR_TEXTURE_RGBA8 && !whole_chain))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "texture '%s': format %u is not one gdr knows",
                             name ? name : "", format);
    gdr_status status = reserve_one((void **)&scene->textures, &scene->texture_capacity, scene->texture_count,
                                    sizeof(gdr_texture), err);
    if (status != GDR_OK)
        return status;
    gdr_texture texture = {.width = width, .height = height, .levels = gdr_texture_level_count(width, height),
                           .srgb = srgb ? 1u : 0u, .format = format};
    snprintf(texture.name, sizeof texture.name, "%s", name ? name : "");
    size_t chain_bytes = gdr_texture_format_level_offset(format, width, height, texture.levels);
    texture.rgba = malloc(chain_bytes);
    if (!texture.rgba)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "texture '%s': out of memory", texture.name);
    memcpy(texture.rgba, chain, whole_chain ? chain_bytes : (size_t)width * height * 4);
    if (!whole_chain && !gdr_texture_build_levels(width, height, texture.srgb, texture.rgba)) {
        free(texture.rgba);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "texture '%s': out of memory for its mip levels",
                             texture.name);
    }
    if (out_index)
        *out_index = scene->texture_count;
    scene->textures[scene->texture_count++] = texture;
    return GDR_OK;
}

gdr_status gdr_scene_add_texture(gdr_scene *scene, const char *name, uint32_t width, uint32_t height,
                                 const uint8_t *rgba, uint32_t srgb, uint32_t *out_index, gdr_error *err)
{
    return add_texture(scene, name, width, height, GDR_TEXTURE_RGBA8, rgba, false, srgb, out_index, err);
}

gdr_status gdr_scene_add_texture_levels(gdr_scene *scene, const char *name, uint32_t width, uint32_t height,
                                        const uint8_t *chain, uint32_t srgb, uint32_t *out_index, gdr_error *err)
{
    return add_texture(scene, name, width, height, GDR_TEXTURE_RGBA8, chain, true, srgb, out_index, err);
}

gdr_status gdr_scene_add_texture_format(gdr_scene *scene, const char *name, uint32_t width, uint32_t height,
                                        uint32_t format, const uint8_t *chain, uint32_t srgb, uint32_t *out_index,
                                        gdr_error *err)
{
    return add_texture(scene, name, width, height, format, chain, true, srgb, out_index, err);
}

gdr_status gdr_scene_set_extensions(gdr_scene *scene, const char *extensions, gdr_error *err)
{
    char *copy = NULL;
    if (extensions) {
        size_t length = strlen(extensions);
        copy = malloc(length + 1);
        if (!copy)
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "scene: out of memory");
        memcpy(copy, extensions, length + 1);
    }
    free(scene->extensions);
    scene->extensions = copy;
    return GDR_OK;
}
