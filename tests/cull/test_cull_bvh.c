/* The BVH against brute force: nearest ray hits and triangle/box overlap. */
#include <stdlib.h>

#include "gdr/cull.h"
#include "test_util.h"

static gdr_vec3 rnd3(unsigned *rng, float lo, float hi)
{
    return (gdr_vec3){test_random_range(rng, lo, hi), test_random_range(rng, lo, hi), test_random_range(rng, lo, hi)};
}

int main(void)
{
    unsigned rng = 4242;
    const uint32_t count = 3000;
    gdr_vec3 *pos = malloc(3 * count * sizeof(gdr_vec3));
    uint32_t *obj = malloc(count * sizeof(uint32_t));
    for (uint32_t t = 0; t < count; t++) {
        gdr_vec3 c = rnd3(&rng, -50, 50);
        float s = test_random(&rng) < 0.9f ? 2.0f : 20.0f;
        for (int k = 0; k < 3; k++)
            pos[3 * t + (uint32_t)k] = gdr_vec3_add(c, rnd3(&rng, -s, s));
        obj[t] = t / 7;
    }
    /* a few degenerate triangles */
    pos[3] = pos[4] = pos[5];
    gdr_bvh *bvh;
    gdr_error err;
    CHECK(gdr_bvh_create(pos, obj, count, &bvh, &err) == GDR_OK);
    CHECK(gdr_bvh_triangle_count(bvh) == count);

    uint32_t hits = 0;
    for (int r = 0; r < 3000; r++) {
        gdr_vec3 o = rnd3(&rng, -70, 70);
        gdr_vec3 d = r % 3 ? rnd3(&rng, -1, 1) : gdr_vec3_sub(pos[3 * (uint32_t)(r * 7 % count)], o);
        if (r % 17 == 0)
            d.x = 0.0f; /* axis-parallel slabs */
        float t_max = r % 5 ? INFINITY : test_random_range(&rng, 1, 60);
        float best = t_max;
        uint32_t best_tri = UINT32_MAX;
        for (uint32_t t = 0; t < count; t++) {
            float tt, u, v;
            if (gdr_ray_triangle(o, d, &pos[3 * t], &tt, &u, &v) && tt > 0.0f && tt <= best &&
                !(tt == best && best_tri != UINT32_MAX)) {
                best = tt;
                best_tri = t;
            }
        }
        gdr_ray_hit hit;
        bool found = gdr_bvh_raycast(bvh, o, d, t_max, &hit);
        CHECK(found == (best_tri != UINT32_MAX));
        if (found && best_tri != UINT32_MAX) {
            CHECK(hit.triangle == best_tri);
            CHECK(hit.t == best);
            CHECK(hit.object == obj[best_tri]);
            hits++;
        }
    }
    printf("ray casts: %u hits of 3000\n", hits);
    CHECK(hits > 300);

    uint32_t overlaps = 0;
    for (int b = 0; b < 1000; b++) {
        gdr_vec3 c = rnd3(&rng, -60, 60), e = rnd3(&rng, 0, 6);
        bool brute = false;
        for (uint32_t t = 0; t < count && !brute; t++)
            brute = gdr_triangle_overlaps_box(&pos[3 * t], c, e);
        CHECK(gdr_bvh_overlaps_box(bvh, c, e) == brute);
        overlaps += brute;
    }
    printf("box queries: %u of 1000 overlap\n", overlaps);
    CHECK(overlaps > 50 && overlaps < 950);

    /* triangle/box: a sampled point of the triangle inside the box implies overlap; far boxes never */
    for (int k = 0; k < 5000; k++) {
        gdr_vec3 tri[3] = {rnd3(&rng, -3, 3), rnd3(&rng, -3, 3), rnd3(&rng, -3, 3)};
        gdr_vec3 c = rnd3(&rng, -3, 3), e = rnd3(&rng, 0.1f, 1.5f);
        bool overlap = gdr_triangle_overlaps_box(tri, c, e);
        for (int s = 0; s < 50; s++) {
            float a = test_random(&rng), b = test_random(&rng);
            if (a + b > 1) a = 1 - a, b = 1 - b;
            gdr_vec3 p = gdr_vec3_add(tri[0], gdr_vec3_add(gdr_vec3_scale(gdr_vec3_sub(tri[1], tri[0]), a),
                                                           gdr_vec3_scale(gdr_vec3_sub(tri[2], tri[0]), b)));
            gdr_vec3 d = gdr_vec3_sub(p, c);
            if (fabsf(d.x) < e.x * 0.999f && fabsf(d.y) < e.y * 0.999f && fabsf(d.z) < e.z * 0.999f)
                CHECK(overlap);
        }
        CHECK(!gdr_triangle_overlaps_box(tri, gdr_vec3_add(c, (gdr_vec3){20, 0, 0}), e));
    }
    /* a big triangle crossing a small box with no vertex in it */
    gdr_vec3 big[3] = {{-10, 0, -10}, {10, 0, -10}, {0, 0, 10}};
    CHECK(gdr_triangle_overlaps_box(big, (gdr_vec3){0, 0.5f, 0}, (gdr_vec3){1, 1, 1}));
    CHECK(!gdr_triangle_overlaps_box(big, (gdr_vec3){0, 1.5f, 0}, (gdr_vec3){1, 1, 1}));

    gdr_bvh_destroy(bvh);
    gdr_bvh *empty;
    CHECK(gdr_bvh_create(NULL, NULL, 0, &empty, &err) == GDR_OK);
    gdr_ray_hit hit;
    CHECK(!gdr_bvh_raycast(empty, (gdr_vec3){0, 0, 0}, (gdr_vec3){0, 0, 1}, INFINITY, &hit));
    CHECK(!gdr_bvh_overlaps_box(empty, (gdr_vec3){0, 0, 0}, (gdr_vec3){1, 1, 1}));
    gdr_bvh_destroy(empty);
    free(pos);
    free(obj);
    return test_finish("test_cull_bvh");
}
