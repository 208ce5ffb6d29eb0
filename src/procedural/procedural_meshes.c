#include "procedural/procedural_meshes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f

typedef struct mesh_builder {
    gdr_vec3 *positions;
    gdr_vec3 *normals;
    gdr_vec2 *uvs;
    uint32_t *indices;
    uint32_t vertex_count, index_count;
} mesh_builder;

static gdr_status builder_alloc(mesh_builder *b, uint32_t vertices, uint32_t indices, gdr_error *err)
{
    memset(b, 0, sizeof *b);
    b->positions = malloc(sizeof(gdr_vec3) * vertices);
    b->normals = malloc(sizeof(gdr_vec3) * vertices);
    b->uvs = malloc(sizeof(gdr_vec2) * vertices);
    b->indices = malloc(sizeof(uint32_t) * indices);
    if (!b->positions || !b->normals || !b->uvs || !b->indices)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "procedural mesh: out of memory");
    return GDR_OK;
}

static void builder_free(mesh_builder *b)
{
    free(b->positions);
    free(b->normals);
    free(b->uvs);
    free(b->indices);
}

static void push_vertex(mesh_builder *b, gdr_vec3 p, gdr_vec3 n, gdr_vec2 uv)
{
    b->positions[b->vertex_count] = p;
    b->normals[b->vertex_count] = n;
    b->uvs[b->vertex_count] = uv;
    b->vertex_count++;
}

static void push_triangle(mesh_builder *b, uint32_t i0, uint32_t i1, uint32_t i2)
{
    b->indices[b->index_count++] = i0;
    b->indices[b->index_count++] = i1;
    b->indices[b->index_count++] = i2;
}

/* Adds a (cols+1) x (rows+1) vertex lattice as quads: (c, r) -> lattice index. */
static void push_lattice_quads(mesh_builder *b, uint32_t base, uint32_t cols, uint32_t rows)
{
    for (uint32_t r = 0; r < rows; r++)
        for (uint32_t c = 0; c < cols; c++) {
            uint32_t i00 = base + r * (cols + 1) + c, i01 = i00 + 1;
            uint32_t i10 = i00 + cols + 1, i11 = i10 + 1;
            push_triangle(b, i00, i10, i11);
            push_triangle(b, i00, i11, i01);
        }
}

static gdr_status builder_finish(mesh_builder *b, gdr_scene *scene, const char *name, bool with_normals,
                                 uint32_t *out_mesh, gdr_error *err)
{
    gdr_status status = gdr_scene_add_mesh(scene, name, b->positions, with_normals ? b->normals : NULL,
                                           b->uvs, b->vertex_count, b->indices, b->index_count, out_mesh, err);
    builder_free(b);
    return status;
}

gdr_status gdr_procedural_sphere(gdr_scene *scene, uint32_t slices, uint32_t stacks, uint32_t *out_mesh,
                                 gdr_error *err)
{
    mesh_builder b;
    if (builder_alloc(&b, (slices + 1) * (stacks + 1), slices * stacks * 6, err) != GDR_OK) {
        builder_free(&b);
        return err->status;
    }
    for (uint32_t r = 0; r <= stacks; r++) {
        float v = (float)r / (float)stacks, phi = v * PI_F; /* from +Y down to -Y */
        for (uint32_t c = 0; c <= slices; c++) {
            float u = (float)c / (float)slices, theta = u * 2.0f * PI_F;
            gdr_vec3 n = {sinf(phi) * sinf(theta), cosf(phi), sinf(phi) * cosf(theta)};
            push_vertex(&b, n, n, (gdr_vec2){u, v});
        }
    }
    push_lattice_quads(&b, 0, slices, stacks);
    return builder_finish(&b, scene, "sphere", true, out_mesh, err);
}

gdr_status gdr_procedural_torus(gdr_scene *scene, float major_radius, float minor_radius, uint32_t segments,
                                uint32_t sides, uint32_t *out_mesh, gdr_error *err)
{
    mesh_builder b;
    if (builder_alloc(&b, (segments + 1) * (sides + 1), segments * sides * 6, err) != GDR_OK) {
        builder_free(&b);
        return err->status;
    }
    for (uint32_t r = 0; r <= sides; r++) {
        float v = (float)r / (float)sides, phi = v * 2.0f * PI_F;
        for (uint32_t c = 0; c <= segments; c++) {
            float u = (float)c / (float)segments, theta = u * 2.0f * PI_F;
            gdr_vec3 ring = {cosf(theta), 0.0f, sinf(theta)};
            gdr_vec3 n = {ring.x * cosf(phi), sinf(phi), ring.z * cosf(phi)};
            gdr_vec3 p = gdr_vec3_add(gdr_vec3_scale(ring, major_radius), gdr_vec3_scale(n, minor_radius));
            push_vertex(&b, p, n, (gdr_vec2){u, v});
        }
    }
    push_lattice_quads(&b, 0, segments, sides);
    return builder_finish(&b, scene, "torus", true, out_mesh, err);
}

gdr_status gdr_procedural_box(gdr_scene *scene, gdr_vec3 h, uint32_t *out_mesh, gdr_error *err)
{
    static const float faces[6][3][3] = {
        /* normal, u axis, v axis (u x v = normal, so quads are CCW seen from outside) */
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}},  {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
        {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}},  {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
        {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},   {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
    };
    mesh_builder b;
    if (builder_alloc(&b, 24, 36, err) != GDR_OK) {
        builder_free(&b);
        return err->status;
    }
    for (int f = 0; f < 6; f++) {
        gdr_vec3 n = {faces[f][0][0], faces[f][0][1], faces[f][0][2]};
        gdr_vec3 u = {faces[f][1][0], faces[f][1][1], faces[f][1][2]};
        gdr_vec3 v = {faces[f][2][0], faces[f][2][1], faces[f][2][2]};
        uint32_t base = b.vertex_count;
        for (int corner = 0; corner < 4; corner++) {
            float su = (corner & 1) ? 1.0f : -1.0f, sv = (corner & 2) ? 1.0f : -1.0f;
            gdr_vec3 p = gdr_vec3_add(n, gdr_vec3_add(gdr_vec3_scale(u, su), gdr_vec3_scale(v, sv)));
            p = (gdr_vec3){p.x * h.x, p.y * h.y, p.z * h.z};
            push_vertex(&b, p, n, (gdr_vec2){su * 0.5f + 0.5f, sv * 0.5f + 0.5f});
        }
        push_triangle(&b, base, base + 1, base + 3);
        push_triangle(&b, base, base + 3, base + 2);
    }
    return builder_finish(&b, scene, "box", true, out_mesh, err);
}

/* Midpoint of edge (a, b) on the unit sphere, shared between the two triangles of the edge
 * through a small open-addressing table keyed by the vertex pair. */
typedef struct edge_table {
    uint64_t *keys;
    uint32_t *values;
    uint32_t capacity;
} edge_table;

static uint32_t edge_midpoint(edge_table *t, mesh_builder *b, uint32_t a, uint32_t c)
{
    uint64_t lo = a < c ? a : c, hi = a < c ? c : a;
    uint64_t key = (lo << 32) | hi;
    uint32_t slot = (uint32_t)((key * 0x9E3779B97F4A7C15ull) >> 33) & (t->capacity - 1);
    while (t->keys[slot] != UINT64_MAX) {
        if (t->keys[slot] == key)
            return t->values[slot];
        slot = (slot + 1) & (t->capacity - 1);
    }
    gdr_vec3 m = gdr_vec3_normalize(gdr_vec3_add(b->positions[a], b->positions[c]));
    t->keys[slot] = key;
    t->values[slot] = b->vertex_count;
    push_vertex(b, m, m, (gdr_vec2){0.0f, 0.0f});
    return t->values[slot];
}

gdr_status gdr_procedural_blob(gdr_scene *scene, uint32_t levels, uint32_t *out_mesh, gdr_error *err)
{
    uint32_t triangles = 20u << (2 * levels);
    uint32_t vertices = 10u * (1u << (2 * levels)) + 2u;
    mesh_builder b;
    uint32_t *scratch = malloc(sizeof(uint32_t) * triangles * 3);
    edge_table table = {0};
    table.capacity = 1;
    while (table.capacity < vertices * 4)
        table.capacity <<= 1;
    table.keys = malloc(sizeof(uint64_t) * table.capacity);
    table.values = malloc(sizeof(uint32_t) * table.capacity);
    gdr_status status = builder_alloc(&b, vertices, triangles * 3, err);
    if (status == GDR_OK && (!scratch || !table.keys || !table.values))
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "procedural blob: out of memory");
    if (status != GDR_OK) {
        builder_free(&b);
        free(scratch);
        free(table.keys);
        free(table.values);
        return status;
    }
    /* Icosahedron. */
    float t = (1.0f + sqrtf(5.0f)) * 0.5f;
    const float corners[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                  {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    static const uint32_t faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                          {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                          {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                          {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (int i = 0; i < 12; i++) {
        gdr_vec3 p = gdr_vec3_normalize((gdr_vec3){corners[i][0], corners[i][1], corners[i][2]});
        push_vertex(&b, p, p, (gdr_vec2){0.0f, 0.0f});
    }
    for (int f = 0; f < 20; f++)
        push_triangle(&b, faces[f][0], faces[f][1], faces[f][2]);
    for (uint32_t level = 0; level < levels; level++) {
        memset(table.keys, 0xff, sizeof(uint64_t) * table.capacity);
        uint32_t count = b.index_count;
        memcpy(scratch, b.indices, sizeof(uint32_t) * count);
        b.index_count = 0;
        for (uint32_t i = 0; i < count; i += 3) {
            uint32_t a = scratch[i], c1 = scratch[i + 1], c2 = scratch[i + 2];
            uint32_t ab = edge_midpoint(&table, &b, a, c1);
            uint32_t bc = edge_midpoint(&table, &b, c1, c2);
            uint32_t ca = edge_midpoint(&table, &b, c2, a);
            push_triangle(&b, a, ab, ca);
            push_triangle(&b, c1, bc, ab);
            push_triangle(&b, c2, ca, bc);
            push_triangle(&b, ab, bc, ca);
        }
    }
    /* Smooth radial displacement: a sum of low-frequency waves keeps the surface closed. */
    for (uint32_t v = 0; v < b.vertex_count; v++) {
        gdr_vec3 p = b.positions[v];
        float d = 1.0f + 0.12f * sinf(5.0f * p.x + 1.3f) * sinf(4.0f * p.y + 0.7f) +
                  0.08f * sinf(7.0f * p.z + 2.1f) * cosf(3.0f * p.x);
        b.positions[v] = gdr_vec3_scale(p, d);
        b.uvs[v] = (gdr_vec2){atan2f(p.z, p.x) / (2.0f * PI_F) + 0.5f, acosf(fmaxf(-1.0f, fminf(1.0f, p.y))) / PI_F};
    }
    free(scratch);
    free(table.keys);
    free(table.values);
    return builder_finish(&b, scene, "blob", false, out_mesh, err);
}

gdr_status gdr_procedural_ground(gdr_scene *scene, float half_size, uint32_t cells, uint32_t *out_mesh,
                                 gdr_error *err)
{
    mesh_builder b;
    if (builder_alloc(&b, (cells + 1) * (cells + 1), cells * cells * 6, err) != GDR_OK) {
        builder_free(&b);
        return err->status;
    }
    for (uint32_t r = 0; r <= cells; r++)
        for (uint32_t c = 0; c <= cells; c++) {
            float u = (float)c / (float)cells, v = (float)r / (float)cells;
            gdr_vec3 p = {(u * 2.0f - 1.0f) * half_size, 0.0f, (v * 2.0f - 1.0f) * half_size};
            push_vertex(&b, p, (gdr_vec3){0.0f, 1.0f, 0.0f}, (gdr_vec2){u, v});
        }
    push_lattice_quads(&b, 0, cells, cells);
    return builder_finish(&b, scene, "ground", true, out_mesh, err);
}

/* Centre line of the (2, 3) torus knot on a torus of radii 1 and 0.45, at t in [0, 2 pi). */
static gdr_vec3 knot_point(float t)
{
    float ring = 1.0f + 0.45f * cosf(3.0f * t);
    return (gdr_vec3){ring * cosf(2.0f * t), ring * sinf(2.0f * t), 0.45f * sinf(3.0f * t)};
}

gdr_status gdr_procedural_torus_knot(gdr_scene *scene, uint32_t segments, uint32_t sides, uint32_t *out_mesh,
                                     gdr_error *err)
{
    if (segments < 24 || sides < 4 || (uint64_t)segments * sides > UINT32_MAX / 6)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "torus knot: %u segments x %u sides", segments, sides);
    mesh_builder b;
    if (builder_alloc(&b, segments * sides, segments * sides * 6, err) != GDR_OK) {
        builder_free(&b);
        return err->status;
    }
    /* Strands of this knot stay 0.89 apart and bend no tighter than a radius of 0.74: a tube of
     * radius at most 0.15 * 1.35 never meets itself. */
    const float tube = 0.15f, scale = 1.0f / (1.0f + 0.45f + tube * 1.35f);
    for (uint32_t i = 0; i < segments; i++) {
        float u = (float)i / (float)segments, t = u * 2.0f * PI_F;
        gdr_vec3 c = knot_point(t);
        gdr_vec3 tangent = gdr_vec3_normalize(gdr_vec3_sub(knot_point(t + 1e-3f), knot_point(t - 1e-3f)));
        /* From the torus' core circle to the knot: perpendicular to the tangent in exact arithmetic
         * and never zero, so the frame is periodic and has no twist at the seam. */
        gdr_vec3 out = gdr_vec3_sub(c, (gdr_vec3){cosf(2.0f * t), sinf(2.0f * t), 0.0f});
        out = gdr_vec3_sub(out, gdr_vec3_scale(tangent, gdr_vec3_dot(out, tangent)));
        gdr_vec3 normal = gdr_vec3_normalize(out), binormal = gdr_vec3_cross(tangent, normal);
        for (uint32_t j = 0; j < sides; j++) {
            float v = (float)j / (float)sides, phi = v * 2.0f * PI_F;
            /* Knobs: 60 along the knot, 5 around the tube (silhouette detail at every distance),
             * over a slow swell along the knot. */
            float knobs = sinf(60.0f * t) * sinf(5.0f * phi);
            float radius = tube * (1.0f + 0.25f * knobs * fabsf(knobs) + 0.1f * sinf(7.0f * t));
            gdr_vec3 dir = gdr_vec3_add(gdr_vec3_scale(normal, cosf(phi)), gdr_vec3_scale(binormal, sinf(phi)));
            gdr_vec3 p = gdr_vec3_scale(gdr_vec3_add(c, gdr_vec3_scale(dir, radius)), scale);
            push_vertex(&b, p, dir, (gdr_vec2){u, v});
        }
    }
    /* The lattice wraps in both directions: ring `segments` is ring 0, side `sides` is side 0. */
    for (uint32_t i = 0; i < segments; i++) {
        uint32_t i1 = (i + 1) % segments;
        for (uint32_t j = 0; j < sides; j++) {
            uint32_t j1 = (j + 1) % sides;
            uint32_t a = i * sides + j, bb = i1 * sides + j, c = i1 * sides + j1, d = i * sides + j1;
            push_triangle(&b, a, d, c);
            push_triangle(&b, a, c, bb);
        }
    }
    return builder_finish(&b, scene, "torus_knot", false, out_mesh, err);
}
