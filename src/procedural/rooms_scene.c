/* The rooms scene: rooms on a grid joined by corridors into a maze, whose walls hide most rooms
 * from any point, for precomputed visibility (docs/SCENES.md, docs/CULLING.md). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "gdr/geometry.h"
#include "gdr/procedural.h"
#include "gdr/scene.h"
#include "procedural/procedural_meshes.h"
#include "procedural/scene_random.h"

#define PI_F 3.14159265358979f

/* The plan, in metres: rooms of ROOM_HALF * 2 square inside, walls WALL_THICK thick and
 * WALL_HEIGHT high, sunk WALL_SINK into the ground (no face shares the ground's plane), corridors
 * CORRIDOR_LENGTH long between the rooms' outer faces and DOOR_WIDTH wide. */
#define ROOM_HALF 4.0f
#define WALL_THICK 0.3f
#define WALL_HEIGHT 3.0f
#define WALL_SINK 0.05f
#define CORRIDOR_LENGTH 4.0f
#define DOOR_WIDTH 1.4f
#define PITCH (2.0f * ROOM_HALF + 2.0f * WALL_THICK + CORRIDOR_LENGTH)
#define PROP_MARGIN 0.6f /* props keep this far from the walls' inner faces */

enum { SIDE_EAST, SIDE_NORTH, SIDE_WEST, SIDE_SOUTH, SIDE_COUNT }; /* +x, -z, -x, +z */
enum { SHAPE_SPHERE, SHAPE_TORUS, SHAPE_BOX, SHAPE_COUNT };

typedef struct rooms_builder {
    gdr_scene *scene;
    gdr_rooms_scene_desc desc;
    uint32_t columns, rows;
    uint32_t box_mesh;              /* a 2 m cube, scaled into walls */
    uint32_t shapes[SHAPE_COUNT];
    float shape_reach[SHAPE_COUNT]; /* radius of a ball around the mesh origin holding the mesh */
    /* Per room and side: whether a doorway opens there, and its offset from the wall's middle. */
    uint8_t (*door)[SIDE_COUNT];
    float (*door_offset)[SIDE_COUNT];
} rooms_builder;

static gdr_vec3 room_centre(const rooms_builder *b, uint32_t room)
{
    return (gdr_vec3){(float)(room % b->columns) * PITCH, 0.0f, -(float)(room / b->columns) * PITCH};
}

/* --- The maze: a random spanning tree over the grid's neighbouring rooms (Kruskal) ------------- */

static uint32_t find_root(uint32_t *parent, uint32_t i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

typedef struct grid_edge {
    uint32_t a, b; /* rooms; b is east (+x) or north (-z) of a */
    float order;
} grid_edge;

static int compare_edges(const void *x, const void *y)
{
    const grid_edge *p = x, *q = y;
    return p->order < q->order ? -1 : p->order > q->order;
}

/* Opens a doorway between rooms a and b (b east or north of a) at a random offset. */
static void open_door(rooms_builder *b, const grid_edge *e, uint32_t k)
{
    bool east = e->b == e->a + 1;
    float reach = ROOM_HALF - 0.5f * DOOR_WIDTH - 0.4f;
    float offset = reach * (2.0f * gdr_hash_unit(b->desc.seed ^ 0xD002u, k, 0) - 1.0f);
    int side_a = east ? SIDE_EAST : SIDE_NORTH, side_b = east ? SIDE_WEST : SIDE_SOUTH;
    b->door[e->a][side_a] = b->door[e->b][side_b] = 1;
    b->door_offset[e->a][side_a] = b->door_offset[e->b][side_b] = offset;
}

static gdr_status plan_maze(rooms_builder *b, gdr_error *err)
{
    uint32_t n = b->desc.rooms;
    grid_edge *edges = malloc(sizeof *edges * 2 * n);
    uint32_t *parent = malloc(sizeof *parent * n);
    if (!edges || !parent) {
        free(edges);
        free(parent);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "rooms: out of memory for %u rooms", n);
    }
    uint32_t count = 0;
    for (uint32_t r = 0; r < n; r++) {
        parent[r] = r;
        if (r % b->columns + 1 < b->columns && r + 1 < n)
            edges[count++] = (grid_edge){r, r + 1, gdr_hash_unit(b->desc.seed ^ 0x3A2Eu, r, 0)};
        if (r + b->columns < n)
            edges[count++] = (grid_edge){r, r + b->columns, gdr_hash_unit(b->desc.seed ^ 0x3A2Eu, r, 1)};
    }
    qsort(edges, count, sizeof *edges, compare_edges);
    for (uint32_t e = 0; e < count; e++) {
        uint32_t x = find_root(parent, edges[e].a), y = find_root(parent, edges[e].b);
        if (x == y)
            continue;
        parent[x] = y;
        open_door(b, &edges[e], edges[e].a * 2 + (edges[e].b != edges[e].a + 1));
    }
    free(edges);
    free(parent);
    return GDR_OK;
}

/* --- Walls ------------------------------------------------------------------------------------ */

/* A wall box from `lo` to `hi` in x and z (y from the sink to the wall's top). */
static gdr_status add_box(rooms_builder *b, float x0, float z0, float x1, float z1, float grey, gdr_error *err)
{
    gdr_vec3 centre = {0.5f * (x0 + x1), 0.5f * (WALL_HEIGHT - WALL_SINK), 0.5f * (z0 + z1)};
    gdr_vec3 half = {0.5f * fabsf(x1 - x0), 0.5f * (WALL_HEIGHT + WALL_SINK), 0.5f * fabsf(z1 - z0)};
    gdr_instance instance = {.transform = gdr_mat4_from_trs(centre, gdr_quat_identity(), half), /* the mesh: 2 m */
                             .mesh = b->box_mesh, .material = GDR_NO_INDEX, .color = {grey, grey, grey * 0.92f, 1.0f}};
    return gdr_scene_add_instance(b->scene, &instance, err);
}

/* One side of a room: a box along the side, or two beside its doorway. Walls along x run over the
 * corners; walls along z reach halfway into them, so that no two boxes meet face to face. */
static gdr_status add_side(rooms_builder *b, uint32_t room, int side, gdr_error *err)
{
    gdr_vec3 c = room_centre(b, room);
    bool along_x = side == SIDE_NORTH || side == SIDE_SOUTH;
    float reach = along_x ? ROOM_HALF + WALL_THICK : ROOM_HALF + 0.5f * WALL_THICK;
    float sign = side == SIDE_EAST || side == SIDE_SOUTH ? 1.0f : -1.0f;
    float inner = sign * ROOM_HALF, outer = sign * (ROOM_HALF + WALL_THICK);
    float grey = 0.62f + 0.12f * gdr_hash_unit(b->desc.seed ^ 0x3A11u, room, (uint32_t)side);
    float spans[2][2] = {{-reach, reach}};
    int span_count = 1;
    if (b->door[room][side]) {
        float u = b->door_offset[room][side];
        spans[0][1] = u - 0.5f * DOOR_WIDTH;
        spans[1][0] = u + 0.5f * DOOR_WIDTH;
        spans[1][1] = reach;
        span_count = 2;
    }
    gdr_status status = GDR_OK;
    for (int s = 0; s < span_count && status == GDR_OK; s++) {
        if (along_x)
            status = add_box(b, c.x + spans[s][0], c.z + inner, c.x + spans[s][1], c.z + outer, grey, err);
        else
            status = add_box(b, c.x + inner, c.z + spans[s][0], c.x + outer, c.z + spans[s][1], grey, err);
    }
    return status;
}

/* The two side walls of the corridor leaving `room` through its east or north doorway; they reach
 * halfway into both rooms' walls. */
static gdr_status add_corridor(rooms_builder *b, uint32_t room, int side, gdr_error *err)
{
    gdr_vec3 c = room_centre(b, room);
    float u = b->door_offset[room][side];
    float start = ROOM_HALF + 0.5f * WALL_THICK, end = ROOM_HALF + 1.5f * WALL_THICK + CORRIDOR_LENGTH;
    float grey = 0.5f;
    gdr_status status = GDR_OK;
    for (int s = -1; s <= 1 && status == GDR_OK; s += 2) {
        float near_face = u + (float)s * 0.5f * DOOR_WIDTH, far_face = near_face + (float)s * WALL_THICK;
        if (side == SIDE_EAST)
            status = add_box(b, c.x + start, c.z + near_face, c.x + end, c.z + far_face, grey, err);
        else
            status = add_box(b, c.x + near_face, c.z - start, c.x + far_face, c.z - end, grey, err);
    }
    return status;
}

/* --- Props ------------------------------------------------------------------------------------ */

/* The room's props on a jittered grid over its floor, resting on the ground, at most 0.92 m high. */
static gdr_status add_props(rooms_builder *b, uint32_t room, gdr_error *err)
{
    uint32_t n = b->desc.objects, side = 1;
    while (side * side < n)
        side++;
    float span = 2.0f * (ROOM_HALF - PROP_MARGIN), cell = span / (float)side;
    float max_radius = fminf(0.45f, 0.35f * cell);
    gdr_vec3 c = room_centre(b, room);
    gdr_status status = GDR_OK;
    for (uint32_t i = 0; i < n && status == GDR_OK; i++) {
        uint32_t k = room * n + i, seed = b->desc.seed ^ 0x960Bu;
        uint32_t shape = (uint32_t)(gdr_hash_unit(seed, k, 0) * (float)SHAPE_COUNT) % SHAPE_COUNT;
        float radius = max_radius * (0.6f + 0.4f * gdr_hash_unit(seed, k, 1));
        float room_left = 0.5f * cell - radius; /* >= 0.15 cell */
        gdr_vec3 position = {
            c.x - 0.5f * span + ((float)(i % side) + 0.5f) * cell + room_left * (2.0f * gdr_hash_unit(seed, k, 2) - 1.0f),
            radius + 0.02f,
            c.z - 0.5f * span + ((float)(i / side) + 0.5f) * cell + room_left * (2.0f * gdr_hash_unit(seed, k, 3) - 1.0f),
        };
        float yaw = 2.0f * PI_F * gdr_hash_unit(seed, k, 4);
        gdr_quat rotation = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, yaw);
        float scale = radius / b->shape_reach[shape];
        gdr_instance instance = {.transform = gdr_mat4_from_trs(position, rotation, (gdr_vec3){scale, scale, scale}),
                                 .mesh = b->shapes[shape], .material = GDR_NO_INDEX,
                                 .color = gdr_hue_color(gdr_hash_unit(seed, k, 5))};
        status = gdr_scene_add_instance(b->scene, &instance, err);
    }
    return status;
}

static gdr_status add_meshes(rooms_builder *b, gdr_error *err)
{
    gdr_scene *s = b->scene;
    uint32_t ground;
    float extent = fmaxf((float)b->columns, (float)b->rows) * PITCH;
    gdr_status status = gdr_procedural_ground(s, 0.5f * extent, 16, &ground, err);
    if (status == GDR_OK) status = gdr_procedural_box(s, (gdr_vec3){1.0f, 1.0f, 1.0f}, &b->box_mesh, err);
    if (status == GDR_OK) status = gdr_procedural_sphere(s, 12, 6, &b->shapes[SHAPE_SPHERE], err);
    if (status == GDR_OK) status = gdr_procedural_torus(s, 0.7f, 0.3f, 12, 6, &b->shapes[SHAPE_TORUS], err);
    if (status == GDR_OK) status = gdr_procedural_box(s, (gdr_vec3){0.6f, 0.6f, 0.6f}, &b->shapes[SHAPE_BOX], err);
    if (status != GDR_OK)
        return status;
    snprintf(s->meshes[b->box_mesh].name, GDR_NAME_MAX, "wall");
    for (int i = 0; i < SHAPE_COUNT; i++) {
        gdr_vec4 bounds = s->meshes[b->shapes[i]].bounds;
        b->shape_reach[i] = gdr_vec3_length((gdr_vec3){bounds.x, bounds.y, bounds.z}) + bounds.w;
    }
    /* The ground under the whole grid (its middle), a little wider than the walls' outline. */
    gdr_vec3 middle = {0.5f * (float)(b->columns - 1) * PITCH, 0.0f, -0.5f * (float)(b->rows - 1) * PITCH};
    gdr_instance floor = {gdr_mat4_from_trs(middle, gdr_quat_identity(), (gdr_vec3){1, 1, 1}), ground, GDR_NO_INDEX,
                          {0.45f, 0.42f, 0.38f, 1.0f}};
    return gdr_scene_add_instance(s, &floor, err);
}

/* --- Cameras ---------------------------------------------------------------------------------- */

static gdr_camera room_camera(const rooms_builder *b, uint32_t room, const char *name, gdr_vec3 offset, float yaw)
{
    gdr_vec3 c = room_centre(b, room);
    gdr_camera camera = {.position = {c.x + offset.x, 1.6f, c.z + offset.z},
                         .rotation = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, yaw),
                         .yfov = 60.0f * PI_F / 180.0f, .znear = 0.1f};
    snprintf(camera.name, GDR_NAME_MAX, "%s", name);
    return camera;
}

/* 0 "first-room": in room 0 near its south wall, looking north (-Z) over the grid;
 * 1 "middle": in the middle room, looking east (+X) along the rows;
 * 2 "corner": in room 0's south-west corner, looking diagonally into the grid. */
static gdr_status add_cameras(rooms_builder *b, gdr_error *err)
{
    uint32_t middle = (b->rows / 2) * b->columns + b->columns / 2;
    middle = middle < b->desc.rooms ? middle : 0;
    gdr_camera cameras[3] = {
        room_camera(b, 0, "first-room", (gdr_vec3){0.0f, 0.0f, ROOM_HALF - 1.3f}, 0.0f),
        room_camera(b, middle, "middle", (gdr_vec3){-ROOM_HALF + 1.0f, 0.0f, 0.3f}, -0.5f * PI_F),
        room_camera(b, 0, "corner", (gdr_vec3){-ROOM_HALF + 1.6f, 0.0f, ROOM_HALF - 1.6f}, -0.25f * PI_F),
    };
    gdr_status status = GDR_OK;
    for (int i = 0; i < 3 && status == GDR_OK; i++)
        status = gdr_scene_add_camera(b->scene, &cameras[i], err);
    return status;
}

static gdr_rooms_scene_desc rooms_desc_defaults(const gdr_rooms_scene_desc *in)
{
    gdr_rooms_scene_desc d = in ? *in : (gdr_rooms_scene_desc){0};
    d.rooms = d.rooms ? d.rooms : 16;
    d.seed = d.seed ? d.seed : 1;
    d.objects = d.objects ? d.objects : 24;
    return d;
}

static gdr_status build(rooms_builder *b, gdr_error *err)
{
    gdr_status status = plan_maze(b, err);
    if (status == GDR_OK)
        status = add_meshes(b, err);
    for (uint32_t r = 0; r < b->desc.rooms && status == GDR_OK; r++)
        for (int side = 0; side < SIDE_COUNT && status == GDR_OK; side++)
            status = add_side(b, r, side, err);
    for (uint32_t r = 0; r < b->desc.rooms && status == GDR_OK; r++)
        for (int side = SIDE_EAST; side <= SIDE_NORTH && status == GDR_OK; side++)
            if (b->door[r][side])
                status = add_corridor(b, r, side, err);
    for (uint32_t r = 0; r < b->desc.rooms && status == GDR_OK; r++)
        status = add_props(b, r, err);
    if (status == GDR_OK)
        status = add_cameras(b, err);
    if (status == GDR_OK)
        status = gdr_scene_build_clusters(b->scene, NULL, err); /* meshlets (src/geometry) */
    return status;
}

gdr_status gdr_scene_create_rooms(const gdr_rooms_scene_desc *desc_in, gdr_scene **out, gdr_error *err)
{
    *out = NULL;
    gdr_rooms_scene_desc d = rooms_desc_defaults(desc_in);
    if (d.rooms > GDR_ROOMS_MAX || d.objects > GDR_ROOMS_MAX_OBJECTS)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "rooms: %s %u is outside [1, %u]",
                             d.rooms > GDR_ROOMS_MAX ? "rooms" : "objects", d.rooms > GDR_ROOMS_MAX ? d.rooms : d.objects,
                             d.rooms > GDR_ROOMS_MAX ? GDR_ROOMS_MAX : GDR_ROOMS_MAX_OBJECTS);
    rooms_builder b = {.desc = d};
    b.columns = 1;
    while (b.columns * b.columns < d.rooms)
        b.columns++;
    b.rows = (d.rooms + b.columns - 1) / b.columns;
    b.door = calloc(d.rooms, sizeof *b.door);
    b.door_offset = calloc(d.rooms, sizeof *b.door_offset);
    gdr_status status = b.door && b.door_offset ? gdr_scene_create(&b.scene, err)
                                                : gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "rooms: out of memory");
    if (status == GDR_OK)
        status = build(&b, err);
    free(b.door);
    free(b.door_offset);
    if (status != GDR_OK) {
        gdr_scene_destroy(b.scene);
        return status;
    }
    *out = b.scene;
    return GDR_OK;
}
