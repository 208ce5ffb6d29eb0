/* The cull scene: a copy of the objects, their octree nodes, and updates. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cull/cull_internal.h"

/* The desc with every zero field given its default. */
static gdr_cull_scene_desc cull_scene_desc_defaults(const gdr_cull_scene_desc *in)
{
    gdr_cull_scene_desc d = *in;
    d.octree_max_depth = d.octree_max_depth ? d.octree_max_depth : CULL_OCTREE_DEFAULT_DEPTH;
    d.octree_leaf_objects = d.octree_leaf_objects ? d.octree_leaf_objects : CULL_OCTREE_DEFAULT_LEAF;
    return d;
}

gdr_status gdr_cull_scene_create(const gdr_cull_scene_desc *desc_in, gdr_cull_scene **out, gdr_error *err)
{
    *out = NULL;
    if (!desc_in)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "cull scene: objects is NULL");
    const gdr_cull_scene_desc d = cull_scene_desc_defaults(desc_in), *desc = &d;
    if (desc->object_count && !desc->objects)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "cull scene: objects is NULL");
    if (desc->octree_max_depth > CULL_OCTREE_MAX_DEPTH)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "cull scene: octree_max_depth %u exceeds %u",
                             desc->octree_max_depth, CULL_OCTREE_MAX_DEPTH);
    if (desc->object_count > UINT32_MAX - 64)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "cull scene: too many objects (%u)", desc->object_count);

    gdr_cull_scene *s = calloc(1, sizeof(*s));
    if (!s)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "cull scene: out of memory");
    s->object_count = desc->object_count;
    s->max_depth = desc->octree_max_depth;
    s->leaf_objects = desc->octree_leaf_objects;
    size_t n = s->object_count ? s->object_count : 1;
    s->objects = malloc(n * sizeof(*s->objects));
    s->object_node = malloc(n * sizeof(*s->object_node));
    if (!s->objects || !s->object_node) {
        gdr_cull_scene_destroy(s);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "cull scene: out of memory for %u objects",
                             desc->object_count);
    }
    if (s->object_count)
        memcpy(s->objects, desc->objects, (size_t)s->object_count * sizeof(*s->objects));
    for (uint32_t i = 0; i < s->object_count; i++)
        s->object_node[i] = cull_object_bounds_valid(&s->objects[i]) ? CULL_NODE_NONE : CULL_NODE_INVALID;
    gdr_status st = cull_octree_build(s, err);
    if (st != GDR_OK) {
        gdr_cull_scene_destroy(s);
        return st;
    }
    *out = s;
    return GDR_OK;
}

void gdr_cull_scene_destroy(gdr_cull_scene *s)
{
    if (!s)
        return;
    free(s->objects);
    free(s->object_node);
    free(s->nodes);
    free(s);
}

uint32_t gdr_cull_scene_object_count(const gdr_cull_scene *s) { return s->object_count; }
uint32_t gdr_cull_scene_node_count(const gdr_cull_scene *s) { return s->node_count; }

gdr_status gdr_cull_scene_update(gdr_cull_scene *s, uint32_t first, uint32_t count, const gdr_cull_object *objects,
                                 gdr_error *err)
{
    if (first > s->object_count || count > s->object_count - first)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "cull scene update: objects [%u, %u) exceed %u", first,
                             first + count, s->object_count);
    if (count && !objects)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "cull scene update: objects is NULL");
    for (uint32_t k = 0; k < count; k++) {
        uint32_t i = first + k;
        const gdr_cull_object *o = &objects[k];
        bool same_bounds = memcmp(&s->objects[i].center, &o->center, sizeof(o->center)) == 0 &&
                           memcmp(&s->objects[i].extent, &o->extent, sizeof(o->extent)) == 0 &&
                           memcmp(&s->objects[i].radius, &o->radius, sizeof(o->radius)) == 0;
        s->objects[i] = *o;
        if (same_bounds)
            continue; /* flags or limits only */
        s->object_node[i] = cull_object_bounds_valid(o) ? cull_octree_place(s, o->center, o->extent)
                                                        : CULL_NODE_INVALID;
    }
    return GDR_OK;
}

gdr_cull_mesh_bounds gdr_cull_mesh_bounds_of(const gdr_mesh *mesh)
{
    gdr_cull_mesh_bounds b = {.lo = {INFINITY, INFINITY, INFINITY}, .hi = {-INFINITY, -INFINITY, -INFINITY},
                              .sphere = mesh->bounds};
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        gdr_vec3 p = mesh->positions[v];
        b.lo = (gdr_vec3){fminf(b.lo.x, p.x), fminf(b.lo.y, p.y), fminf(b.lo.z, p.z)};
        b.hi = (gdr_vec3){fmaxf(b.hi.x, p.x), fmaxf(b.hi.y, p.y), fmaxf(b.hi.z, p.z)};
    }
    return b;
}

gdr_cull_object gdr_cull_object_from_mesh_bounds(const gdr_cull_mesh_bounds *b, const gdr_mat4 *transform)
{
    gdr_cull_object o = {0};
    if (!(b->lo.x <= b->hi.x)) {
        o.radius = -1.0f; /* invalid: nothing to draw */
        return o;
    }
    gdr_vec3 wlo = {INFINITY, INFINITY, INFINITY}, whi = {-INFINITY, -INFINITY, -INFINITY};
    for (int c = 0; c < 8; c++) {
        gdr_vec3 corner = {(c & 1) ? b->hi.x : b->lo.x, (c & 2) ? b->hi.y : b->lo.y, (c & 4) ? b->hi.z : b->lo.z};
        gdr_vec3 p = gdr_mat4_transform_point(*transform, corner);
        wlo = (gdr_vec3){fminf(wlo.x, p.x), fminf(wlo.y, p.y), fminf(wlo.z, p.z)};
        whi = (gdr_vec3){fmaxf(whi.x, p.x), fmaxf(whi.y, p.y), fmaxf(whi.z, p.z)};
    }
    o.center = gdr_vec3_scale(gdr_vec3_add(wlo, whi), 0.5f);
    o.extent = gdr_vec3_scale(gdr_vec3_sub(whi, wlo), 0.5f);
    gdr_vec3 sphere_center = gdr_mat4_transform_point(*transform, (gdr_vec3){b->sphere.x, b->sphere.y, b->sphere.z});
    float sphere_radius = b->sphere.w * gdr_mat4_max_axis_scale(*transform);
    float around_sphere = gdr_vec3_length(gdr_vec3_sub(sphere_center, o.center)) + sphere_radius;
    o.radius = fminf(gdr_vec3_length(o.extent), around_sphere);
    return o;
}

gdr_status gdr_cull_objects_from_scene(gdr_cull_object *objects, const gdr_scene *scene, gdr_error *err)
{
    gdr_cull_mesh_bounds *meshes = malloc(sizeof *meshes * (scene->mesh_count ? scene->mesh_count : 1));
    if (!meshes)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "cull objects: out of memory for %u meshes",
                             scene->mesh_count);
    for (uint32_t m = 0; m < scene->mesh_count; m++)
        meshes[m] = gdr_cull_mesh_bounds_of(&scene->meshes[m]);
    const gdr_cull_mesh_bounds missing = {.lo = {1, 1, 1}, .hi = {0, 0, 0}}; /* empty: an invalid object */
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        const gdr_instance *inst = &scene->instances[i];
        objects[i] = gdr_cull_object_from_mesh_bounds(inst->mesh < scene->mesh_count ? &meshes[inst->mesh] : &missing,
                                                      &inst->transform);
    }
    free(meshes);
    return GDR_OK;
}
