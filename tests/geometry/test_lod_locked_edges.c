/* A group's simplification keeps every border edge it shares with a neighbour (an edge between two
 * locked positions that no other triangle of the group runs the other way), even where the
 * triangle along it hangs into a mesh hole: its other two edges open, its third corner free. Moving
 * that corner onto either locked end is cheap (the triangle is small) and takes the triangle with
 * it, and the edge with it: lod_group.c then rejects the whole group, whose clusters stay a level
 * behind (on the Stanford bunny one such triangle at a hole of its base got its group rejected at
 * four steps). The group here is a bumpy sheet with its rim locked (the neighbours) and three such
 * triangles on locked edges of their own; simplified to half, every locked border edge must remain,
 * and the sheet must still reach the target. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "geometry/lod_simplify.h"
#include "test_util.h"

#define SIDE 12 /* the sheet's vertices per side */
#define SHEET_POSITIONS (SIDE * SIDE)
#define SHEET_TRIANGLES ((SIDE - 1) * (SIDE - 1) * 2)
#define EARS 3
#define POSITIONS (SHEET_POSITIONS + EARS * 3)
#define TRIANGLES (SHEET_TRIANGLES + EARS)

static float positions[POSITIONS * 3];
static uint32_t indices[TRIANGLES * 3];
static uint8_t locked[POSITIONS];

static void set_position(uint32_t p, double x, double y, double z)
{
    positions[p * 3] = (float)x, positions[p * 3 + 1] = (float)y, positions[p * 3 + 2] = (float)z;
}

/* The sheet over [0, 1]^2 with bumps (so that its collapses cost something), its rim locked; each
 * ear a small triangle beside it: two locked corners 0.05 apart, the free one 0.0005 off their edge (a sliver: cheap to collapse). */
static void build_group(void)
{
    uint32_t n = 0;
    for (uint32_t j = 0; j < SIDE; j++)
        for (uint32_t i = 0; i < SIDE; i++) {
            double x = (double)i / (SIDE - 1), y = (double)j / (SIDE - 1);
            set_position(j * SIDE + i, x, y, 0.05 * sin(7.0 * x) * cos(5.0 * y) + 0.01 * test_hash_unit(j * SIDE + i));
            locked[j * SIDE + i] = i == 0 || j == 0 || i == SIDE - 1 || j == SIDE - 1;
        }
    for (uint32_t j = 0; j + 1 < SIDE; j++)
        for (uint32_t i = 0; i + 1 < SIDE; i++) {
            uint32_t p = j * SIDE + i;
            indices[n++] = p, indices[n++] = p + 1, indices[n++] = p + SIDE + 1;
            indices[n++] = p, indices[n++] = p + SIDE + 1, indices[n++] = p + SIDE;
        }
    for (uint32_t e = 0; e < EARS; e++) {
        uint32_t b = SHEET_POSITIONS + e * 3, x = b + 1, a = b + 2;
        double left = 0.2 + 0.3 * e;
        set_position(b, left, -0.2, 0.0);
        set_position(x, left + 0.05, -0.2, 0.0);
        set_position(a, left + 0.025, -0.2005, 0.0);
        locked[b] = locked[x] = 1;
        indices[n++] = b, indices[n++] = x, indices[n++] = a;
    }
}

/* Whether the triangle list holds the directed edge p -> q. */
static int holds_edge(const uint32_t *idx, size_t triangles, uint32_t p, uint32_t q)
{
    for (size_t t = 0; t < triangles; t++)
        for (uint32_t k = 0; k < 3; k++)
            if (idx[t * 3 + k] == p && idx[t * 3 + (k + 1) % 3] == q)
                return 1;
    return 0;
}

int main(void)
{
    build_group();
    static uint32_t identity[POSITIONS], out[TRIANGLES * 3];
    for (uint32_t p = 0; p < POSITIONS; p++)
        identity[p] = p;
    lod_simplify_input in = {.indices = indices, .index_count = TRIANGLES * 3, .vertex_count = POSITIONS,
                             .vertex_position = identity, .vertex_source = identity, .position_count = POSITIONS,
                             .positions = positions, .locked = locked, .target_index_count = TRIANGLES * 3 / 2};
    lod_simplify_scratch scratch = {0};
    lod_simplify_result result;
    CHECK_MSG(lod_simplify(&scratch, &in, out, &result), "out of memory");
    size_t kept = result.index_count / 3;
    printf("test_lod_locked_edges: %u -> %zu triangles\n", TRIANGLES, kept);
    CHECK_MSG(kept <= TRIANGLES * 6 / 10, "kept %zu of %u triangles (target %u)", kept, TRIANGLES, TRIANGLES / 2);
    uint32_t border = 0, lost = 0;
    for (size_t t = 0; t < TRIANGLES; t++)
        for (uint32_t k = 0; k < 3; k++) {
            uint32_t p = indices[t * 3 + k], q = indices[t * 3 + (k + 1) % 3];
            if (!locked[p] || !locked[q] || holds_edge(indices, TRIANGLES, q, p))
                continue;
            border++;
            if (!holds_edge(out, kept, p, q)) {
                lost++;
                fprintf(stderr, "test_lod_locked_edges: the border edge %u -> %u is gone\n", p, q);
            }
        }
    CHECK_MSG(border == 4 * (SIDE - 1) + EARS, "%u border edges (expected %u)", border, 4 * (SIDE - 1) + EARS);
    CHECK_MSG(lost == 0, "%u of %u locked border edges lost", lost, border);
    lod_simplify_scratch_free(&scratch);
    return test_finish("test_lod_locked_edges");
}
