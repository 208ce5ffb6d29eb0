/* gdr_lod_enclosing_sphere (include/gdr/geometry.h): every input sphere lies inside the result when
 * the distances are evaluated in float, as the culling shaders evaluate them; the result is not
 * much larger than the spheres' bounding box needs. */
#include <math.h>
#include <stdint.h>

#include "gdr/geometry.h"
#include "test_util.h"

static uint32_t next_random(uint32_t *state)
{
    *state = *state * 1664525u + 1013904223u;
    return *state >> 8;
}

static float random_in(uint32_t *state, float lo, float hi)
{
    return lo + (hi - lo) * (float)next_random(state) / (float)(1u << 24);
}

/* Every sphere inside `outer`, in float arithmetic. */
static int contains_all(gdr_vec4 outer, const gdr_vec4 *s, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        float dx = s[i].x - outer.x, dy = s[i].y - outer.y, dz = s[i].z - outer.z;
        if (sqrtf(dx * dx + dy * dy + dz * dz) + s[i].w > outer.w)
            return 0;
    }
    return 1;
}

int main(void)
{
    gdr_vec4 none = gdr_lod_enclosing_sphere(NULL, 0);
    CHECK(none.x == 0.0f && none.y == 0.0f && none.z == 0.0f && none.w == 0.0f);

    gdr_vec4 one = {1.5f, -2.0f, 3.25f, 0.75f};
    gdr_vec4 same = gdr_lod_enclosing_sphere(&one, 1);
    CHECK(same.x == one.x && same.y == one.y && same.z == one.z);
    CHECK(same.w >= one.w && same.w <= one.w * (1.0f + 1e-5f));

    /* Two spheres side by side: the smallest enclosing sphere is their span. */
    gdr_vec4 pair[2] = {{-3.0f, 0.0f, 0.0f, 1.0f}, {3.0f, 0.0f, 0.0f, 1.0f}};
    gdr_vec4 both = gdr_lod_enclosing_sphere(pair, 2);
    CHECK(contains_all(both, pair, 2));
    CHECK_NEAR(both.w, 4.0, 1e-4);

    /* A sphere and a point off along the box's diagonal: the box's centre needs 25.98 (the point's
     * distance from it), the smallest sphere is the span from the sphere's far side to the point,
     * 10 + 20 sqrt(3) = 44.64, radius 22.32. Group spheres enclose those of the groups below them,
     * so slack here compounds over the DAG's depths. */
    gdr_vec4 corner[2] = {{0.0f, 0.0f, 0.0f, 10.0f}, {20.0f, 20.0f, 20.0f, 0.0f}};
    gdr_vec4 span = gdr_lod_enclosing_sphere(corner, 2);
    CHECK(contains_all(span, corner, 2));
    CHECK(span.w <= 1.01f * 0.5f * (10.0f + 20.0f * sqrtf(3.0f)));

    /* Points on a quarter circle of radius 10 and a sphere of radius 1 at its centre: the box
     * [-1, 10]^2 is centred at (4.5, 4.5), which needs 4.5 sqrt(2) + 1 = 7.36; the smallest sphere
     * is centred at (t, t) with sqrt((10 - t)^2 + t^2) = sqrt(2) t + 1, t = 99 / (20 + 2 sqrt(2)),
     * radius 7.13. */
    gdr_vec4 arc[8];
    for (int i = 0; i < 7; i++)
        arc[i] = (gdr_vec4){10.0f * cosf(0.2617994f * (float)i), 10.0f * sinf(0.2617994f * (float)i), 0.0f, 0.0f};
    arc[7] = (gdr_vec4){0.0f, 0.0f, 0.0f, 1.0f};
    gdr_vec4 around = gdr_lod_enclosing_sphere(arc, 8);
    CHECK(contains_all(around, arc, 8));
    double t = 99.0 / (20.0 + 2.0 * sqrt(2.0));
    CHECK(around.w <= 1.01 * (sqrt(2.0) * t + 1.0));

    /* Clouds far from the origin, of very different radii: containment in float must hold. */
    uint32_t state = 12345u;
    for (int trial = 0; trial < 200; trial++) {
        gdr_vec4 s[64];
        size_t n = 1 + next_random(&state) % 64;
        float offset = random_in(&state, -1e4f, 1e4f), spread = random_in(&state, 1e-3f, 1e2f);
        for (size_t i = 0; i < n; i++)
            s[i] = (gdr_vec4){offset + random_in(&state, -spread, spread), offset + random_in(&state, -spread, spread),
                              random_in(&state, -spread, spread), random_in(&state, 0.0f, spread)};
        gdr_vec4 e = gdr_lod_enclosing_sphere(s, n);
        CHECK(contains_all(e, s, n));
        /* Never larger than the bounding box's half diagonal plus the largest radius, and a little. */
        CHECK(e.w <= spread * 2.0f * sqrtf(3.0f) + spread + 1e-2f * (fabsf(offset) + spread));
    }
    return test_finish("test_enclosing_sphere");
}
