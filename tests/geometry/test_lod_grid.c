/* The LOD builder's nearest-triangle grid (src/geometry/lod_grid.h): its answer must be the exact
 * nearest distance on sound meshes, checked against brute force; its nearest-point grid's answer,
 * the exact nearest point (the lowest index on ties). The builder's error bound is only
 * as tight as these queries: a query that misses the nearest triangle overstates a group's error. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "geometry/lod_grid.h"
#include "test_util.h"

typedef struct soup {
    float *positions; /* 3 floats a vertex */
    uint32_t *corners;
    uint32_t vertex_count, triangle_count;
} soup;

static gdr_vec3 sub(gdr_vec3 a, gdr_vec3 b) { return (gdr_vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static float dot(gdr_vec3 a, gdr_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static gdr_vec3 cross(gdr_vec3 a, gdr_vec3 b)
{
    return (gdr_vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

/* Squared distance from p to segment ab. */
static float segment_d2(gdr_vec3 p, gdr_vec3 a, gdr_vec3 b)
{
    gdr_vec3 ab = sub(b, a), ap = sub(p, a);
    float len2 = dot(ab, ab), t = len2 > 0.0f ? dot(ap, ab) / len2 : 0.0f;
    t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
    gdr_vec3 d = {ap.x - t * ab.x, ap.y - t * ab.y, ap.z - t * ab.z};
    return dot(d, d);
}

/* Squared distance from p to triangle abc: to the plane where p projects inside, else to the
 * nearest edge. Written independently of the builder's: the test compares the grid's choice of
 * triangle, whatever the distance function. */
static float test_point_triangle_d2(gdr_vec3 p, gdr_vec3 a, gdr_vec3 b, gdr_vec3 c)
{
    gdr_vec3 n = cross(sub(b, a), sub(c, a));
    float n2 = dot(n, n);
    if (n2 > 0.0f) {
        gdr_vec3 ap = sub(p, a);
        int inside = dot(cross(sub(b, a), ap), n) >= 0.0f && dot(cross(sub(c, b), sub(p, b)), n) >= 0.0f &&
                     dot(cross(sub(a, c), sub(p, c)), n) >= 0.0f;
        if (inside) {
            float h = dot(ap, n);
            return h * h / n2;
        }
    }
    float d = segment_d2(p, a, b), e = segment_d2(p, b, c), f = segment_d2(p, c, a);
    return fminf(d, fminf(e, f));
}

static gdr_vec3 vertex(const soup *s, uint32_t v)
{
    const float *x = s->positions + (size_t)v * 3;
    return (gdr_vec3){x[0], x[1], x[2]};
}

static void add_triangle(soup *s, gdr_vec3 a, gdr_vec3 b, gdr_vec3 c)
{
    const gdr_vec3 v[3] = {a, b, c};
    for (int k = 0; k < 3; k++) {
        float *x = s->positions + (size_t)s->vertex_count * 3;
        x[0] = v[k].x;
        x[1] = v[k].y;
        x[2] = v[k].z;
        s->corners[(size_t)s->triangle_count * 3 + (size_t)k] = s->vertex_count++;
    }
    s->triangle_count++;
}

static float brute_force_d2(const soup *s, gdr_vec3 p)
{
    float best = INFINITY;
    for (uint32_t t = 0; t < s->triangle_count; t++) {
        const uint32_t *c = s->corners + (size_t)t * 3;
        best = fminf(best, test_point_triangle_d2(p, vertex(s, c[0]), vertex(s, c[1]), vertex(s, c[2])));
    }
    return best;
}

/* Queries whose grid answer differs from brute force (beyond float rounding), printing the first. */
static int count_misses(const lod_triangle_grid *g, const soup *s, const gdr_vec3 *queries, int n)
{
    int misses = 0;
    for (int i = 0; i < n; i++) {
        float grid_d2, exact_d2 = brute_force_d2(s, queries[i]);
        uint32_t t = lod_triangle_grid_nearest(g, queries[i], test_point_triangle_d2, &grid_d2);
        CHECK(t < s->triangle_count);
        CHECK(grid_d2 >= exact_d2); /* never below the true distance */
        if (grid_d2 > exact_d2 * (1.0f + 1e-5f) + 1e-12f) {
            if (!misses)
                fprintf(stderr, "query (%g, %g, %g): grid %g, brute force %g\n", (double)queries[i].x,
                        (double)queries[i].y, (double)queries[i].z, sqrt(grid_d2), sqrt(exact_d2));
            misses++;
        }
    }
    return misses;
}

#define SMALL_COUNT 2000u
#define NEEDLE_COUNT 400u
#define QUERY_COUNT 600

/* Many small triangles (they make the cells small), then long thin triangles ("needles") across
 * the whole box along its diagonal, as a coarse simplified group has: a needle's bounding box
 * covers most cells while it crosses only a line of them. Queries next to the far end of each
 * needle, and anywhere in the box. */
static void test_needles_exact(void)
{
    soup s = {0};
    uint32_t triangles = SMALL_COUNT + NEEDLE_COUNT;
    s.positions = malloc((size_t)triangles * 9 * sizeof *s.positions);
    s.corners = malloc((size_t)triangles * 3 * sizeof *s.corners);
    gdr_vec3 *queries = malloc(QUERY_COUNT * sizeof *queries);
    CHECK(s.positions && s.corners && queries);
    if (!s.positions || !s.corners || !queries)
        return;
    unsigned state = 12345;
    for (uint32_t i = 0; i < SMALL_COUNT; i++) {
        gdr_vec3 a = {test_random_range(&state, 0.0f, 2.0f), test_random_range(&state, 0.0f, 2.0f),
                      test_random_range(&state, 0.0f, 1.0f)};
        add_triangle(&s, a, (gdr_vec3){a.x + 0.01f, a.y, a.z}, (gdr_vec3){a.x, a.y + 0.01f, a.z + 0.005f});
    }
    int q = 0;
    for (uint32_t i = 0; i < NEEDLE_COUNT; i++) {
        gdr_vec3 a = {test_random(&state), test_random(&state), 0.0f}, b = {a.x + 1.0f, a.y + 1.0f, 1.0f};
        add_triangle(&s, a, b, (gdr_vec3){b.x + 0.004f, b.y - 0.004f, b.z});
        /* Beside the needle, near its far end: this needle is the nearest triangle or nearly. */
        queries[q++] = (gdr_vec3){a.x + 0.9f + 0.002f, a.y + 0.9f - 0.001f, 0.9f};
    }
    while (q < QUERY_COUNT)
        queries[q++] = (gdr_vec3){test_random_range(&state, -0.1f, 2.1f), test_random_range(&state, -0.1f, 2.1f),
                                  test_random_range(&state, -0.1f, 1.1f)};
    lod_triangle_grid g = {0};
    CHECK(lod_triangle_grid_build(&g, s.positions, s.corners, s.triangle_count));
    int misses = count_misses(&g, &s, queries, QUERY_COUNT);
    if (misses)
        fprintf(stderr, "%d of %d queries missed the nearest triangle\n", misses, QUERY_COUNT);
    CHECK(misses == 0);
    /* Built again over the same arrays (the builder reuses its grids): the same answers. */
    CHECK(lod_triangle_grid_build(&g, s.positions, s.corners, s.triangle_count));
    CHECK(count_misses(&g, &s, queries, QUERY_COUNT) == misses);
    lod_triangle_grid_free(&g);
    free(s.positions);
    free(s.corners);
    free(queries);
}

#define BAND_STEPS 150u
#define BAND_ROWS 6u
#define BAND_QUERY_COUNT 2000

/* A point of the unit sphere at arc position u (radians) and row offset v along a wavy path. */
static gdr_vec3 band_point(float u, float v)
{
    float latitude = 0.7f * sinf(6.0f * u) + v;
    return (gdr_vec3){cosf(latitude) * cosf(u), cosf(latitude) * sinf(u), sinf(latitude)};
}

/* A band a few triangles wide, winding over a sphere, as a group of a coarse DAG level often is: its
 * box is mostly empty, and cells sized to keep the box's cell count near the triangle count hold
 * dozens of its triangles each, past the per-cell limit. Queries on either side of the band. */
static void test_band_exact(void)
{
    soup s = {0};
    uint32_t triangles = BAND_STEPS * BAND_ROWS * 2;
    s.positions = malloc((size_t)triangles * 9 * sizeof *s.positions);
    s.corners = malloc((size_t)triangles * 3 * sizeof *s.corners);
    gdr_vec3 *queries = malloc(BAND_QUERY_COUNT * sizeof *queries);
    CHECK(s.positions && s.corners && queries);
    if (!s.positions || !s.corners || !queries)
        return;
    const float step = 0.012f, length = step * (float)BAND_STEPS, width = step * (float)BAND_ROWS;
    for (uint32_t i = 0; i < BAND_STEPS; i++)
        for (uint32_t j = 0; j < BAND_ROWS; j++) {
            gdr_vec3 p[4];
            for (uint32_t k = 0; k < 4; k++)
                p[k] = band_point(step * (float)(i + (k & 1)), step * (float)(j + k / 2));
            add_triangle(&s, p[0], p[1], p[3]);
            add_triangle(&s, p[0], p[3], p[2]);
        }
    unsigned state = 777;
    for (int q = 0; q < BAND_QUERY_COUNT; q++) {
        gdr_vec3 p = band_point(test_random_range(&state, 0.0f, length), test_random_range(&state, -0.01f, width + 0.01f));
        float r = test_random_range(&state, 0.99f, 1.01f);
        queries[q] = (gdr_vec3){r * p.x, r * p.y, r * p.z};
    }
    lod_triangle_grid g = {0};
    CHECK(lod_triangle_grid_build(&g, s.positions, s.corners, s.triangle_count));
    int misses = count_misses(&g, &s, queries, BAND_QUERY_COUNT);
    if (misses)
        fprintf(stderr, "band: %d of %d queries missed the nearest triangle\n", misses, BAND_QUERY_COUNT);
    CHECK(misses == 0);
    lod_triangle_grid_free(&g);
    free(s.positions);
    free(s.corners);
    free(queries);
}

/* A fan of thousands of triangles around one vertex: the hub's cells are given up to a limit, so
 * answers there may be farther than the nearest triangle, but never nearer (some are: the limit
 * binds). With the limit lifted (cell_limit; the step's grid of lod_redirect.c raises it to 4,096),
 * every answer is the nearest. */
static void test_fan_bounded(void)
{
    const uint32_t n = 4000;
    soup s = {0};
    s.positions = malloc((size_t)n * 9 * sizeof *s.positions);
    s.corners = malloc((size_t)n * 3 * sizeof *s.corners);
    CHECK(s.positions && s.corners);
    if (!s.positions || !s.corners)
        return;
    for (uint32_t i = 0; i < n; i++) {
        float a0 = 6.2831853f * (float)i / (float)n, a1 = 6.2831853f * (float)(i + 1) / (float)n;
        add_triangle(&s, (gdr_vec3){0, 0, 0}, (gdr_vec3){cosf(a0), sinf(a0), 0.1f * (float)(i % 3)},
                     (gdr_vec3){cosf(a1), sinf(a1), 0.1f * (float)((i + 1) % 3)});
    }
    lod_triangle_grid g = {0};
    CHECK(lod_triangle_grid_build(&g, s.positions, s.corners, s.triangle_count));
    unsigned state = 99;
    gdr_vec3 queries[200];
    for (int i = 0; i < 200; i++) {
        gdr_vec3 p = {test_random_range(&state, -1.2f, 1.2f), test_random_range(&state, -1.2f, 1.2f),
                      test_random_range(&state, -0.3f, 0.5f)};
        float d2;
        uint32_t t = lod_triangle_grid_nearest(&g, p, test_point_triangle_d2, &d2);
        CHECK(t < n);
        CHECK(d2 >= brute_force_d2(&s, p));
        queries[i] = p;
    }
    int bounded = count_misses(&g, &s, queries, 200);
    g.cell_limit = UINT32_MAX;
    int lifted = count_misses(&g, &s, queries, 200);
    printf("fan: %d of 200 answers farther than the nearest with cells limited, %d lifted\n", bounded, lifted);
    CHECK(bounded > 0);
    CHECK(lifted == 0);
    lod_triangle_grid_free(&g);
    free(s.positions);
    free(s.corners);
}

/* A fan of n triangles on a circle, flat, each reaching from the hub to the rim: in cells sized by
 * the triangles' spacing each would be listed in O(sqrt n) cells (about 80 each at 20,000
 * triangles, 1.6 M entries and as many clippings), so the cells are made larger until about 16 a
 * triangle; the answers stay distances to the fan's triangles, never below the nearest. */
static void test_fan_listing_linear(void)
{
    const uint32_t n = 20000;
    soup s = {0};
    s.positions = malloc((size_t)n * 9 * sizeof *s.positions);
    s.corners = malloc((size_t)n * 3 * sizeof *s.corners);
    CHECK(s.positions && s.corners);
    if (!s.positions || !s.corners)
        return;
    for (uint32_t i = 0; i < n; i++) {
        float a0 = 6.2831853f * (float)i / (float)n, a1 = 6.2831853f * (float)(i + 1) / (float)n;
        add_triangle(&s, (gdr_vec3){0, 0, 0}, (gdr_vec3){cosf(a0), sinf(a0), 0}, (gdr_vec3){cosf(a1), sinf(a1), 0});
    }
    lod_triangle_grid g = {0};
    CHECK(lod_triangle_grid_build(&g, s.positions, s.corners, s.triangle_count));
    size_t cells = (size_t)g.dim[0] * g.dim[1] * g.dim[2], listed = g.start[cells];
    printf("fan of %u: %zu cells, %zu entries (%.1f a triangle)\n", n, cells, listed, (double)listed / n);
    CHECK(listed < 20u * n + 65536u);
    unsigned state = 5;
    double excess = 0.0; /* how much farther than the nearest the answers are, summed */
    for (int i = 0; i < 200; i++) {
        gdr_vec3 p = {test_random_range(&state, -1.1f, 1.1f), test_random_range(&state, -1.1f, 1.1f),
                      test_random_range(&state, -0.1f, 0.1f)};
        float d2, exact_d2 = brute_force_d2(&s, p);
        uint32_t t = lod_triangle_grid_nearest(&g, p, test_point_triangle_d2, &d2);
        CHECK(t < n);
        CHECK(d2 >= exact_d2);
        excess += sqrt(d2) - sqrt(exact_d2);
    }
    /* Its cells hold hundreds of triangles, of which a query looks at 64: spread over the cell's
     * list, in triangle order (around the fan), the nearest of them is close to the nearest of all;
     * the first 64 would cover a corner of the cell. */
    printf("fan of %u: answers farther than the nearest by %.5f on average, cells of %.3f\n", n, excess / 200,
           (double)g.cell);
    CHECK(excess / 200 < 0.01 * g.cell);
    lod_triangle_grid_free(&g);
    free(s.positions);
    free(s.corners);
}

/* The point nearest to p by brute force, the lowest index on ties, computed as the grid does. */
static uint32_t brute_force_point(const gdr_vec3 *points, uint32_t n, gdr_vec3 p, float *best_d2)
{
    uint32_t best = UINT32_MAX;
    *best_d2 = INFINITY;
    for (uint32_t i = 0; i < n; i++) {
        float dx = points[i].x - p.x, dy = points[i].y - p.y, dz = points[i].z - p.z;
        float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < *best_d2) {
            *best_d2 = d2;
            best = i;
        }
    }
    return best;
}

/* Points on a bumpy sphere (a surface, as the builder's are), each written twice so that every
 * query near one meets a tie, and queries near the surface, far off it and on the points: the
 * grid's answer is brute force's, index and distance. Its search looks only at cells within the
 * best distance so far along every axis, so it is checked where a tie sits on a cell's face too
 * (points on a lattice of the cell size). */
static void test_points_exact(void)
{
    const uint32_t n = 6000;
    gdr_vec3 *points = malloc((size_t)n * sizeof *points);
    CHECK(points != NULL);
    if (!points)
        return;
    unsigned state = 7;
    for (uint32_t i = 0; i < n; i += 2) {
        float u = test_random_range(&state, 0.0f, 6.2831853f), v = test_random_range(&state, -1.0f, 1.0f);
        float r = 1.0f + 0.05f * sinf(7.0f * u), h = sqrtf(1.0f - v * v);
        points[i] = points[i + 1] = (gdr_vec3){r * h * cosf(u), r * h * sinf(u), r * v};
    }
    for (int pass = 0; pass < 2; pass++) {
        lod_grid g = {0};
        CHECK(lod_grid_build(&g, points, n, pass == 0 ? 4.0 : 1.0));
        CHECK(!g.use_tree); /* a surface: the grid answers */
        for (int i = 0; i < 3000; i++) {
            float scale = i % 3 == 0 ? 1.02f : i % 3 == 1 ? 1.6f : 1.0f;
            gdr_vec3 p = i % 3 == 2 ? points[(uint32_t)i % n]
                                    : (gdr_vec3){scale * test_random_range(&state, -1.0f, 1.0f),
                                                 scale * test_random_range(&state, -1.0f, 1.0f),
                                                 scale * test_random_range(&state, -1.0f, 1.0f)};
            float d2, want_d2;
            uint32_t got = lod_grid_nearest(&g, p, &d2), want = brute_force_point(points, n, p, &want_d2);
            CHECK(got == want);
            CHECK(d2 == want_d2);
        }
        lod_grid_free(&g);
    }
    /* A lattice: points on the cells' corners, queries midway between two (exact ties). */
    uint32_t m = 0;
    for (int x = 0; x < 10; x++)
        for (int y = 0; y < 10; y++)
            for (int z = 0; z < 10 && m < n; z++)
                points[m++] = (gdr_vec3){0.25f * (float)x, 0.25f * (float)y, 0.25f * (float)z};
    lod_grid g = {0};
    CHECK(lod_grid_build(&g, points, m, 1.0));
    for (int i = 0; i < 2000; i++) {
        gdr_vec3 p = points[(uint32_t)i % m];
        int axis = i % 3;
        float *c = axis == 0 ? &p.x : axis == 1 ? &p.y : &p.z;
        *c += 0.125f * (float)(i % 2 ? 1 : -1);
        float d2, want_d2;
        uint32_t got = lod_grid_nearest(&g, p, &d2), want = brute_force_point(points, m, p, &want_d2);
        CHECK(got == want);
        CHECK(d2 == want_d2);
    }
    lod_grid_free(&g);
    free(points);
}

/* Points on a circle (a fan's rim; each written twice, for ties) and its centre: a grid of O(n) cells
 * over their box holds O(sqrt n) of them in each cell they occupy, so the k-d tree answers
 * (lod_point_tree.c); its answer is brute force's, index and distance, for queries inside the
 * circle, outside, on the points and on the axes (where the splits lie), with the grid's cells
 * counted either way. */
static void test_points_on_a_curve_exact(void)
{
    const uint32_t n = 40000;
    gdr_vec3 *points = malloc((size_t)n * sizeof *points);
    CHECK(points != NULL);
    if (!points)
        return;
    points[0] = (gdr_vec3){0, 0, 0};
    for (uint32_t i = 1; i + 1 < n; i += 2) {
        float a = 6.2831853f * (float)i / (float)n;
        points[i] = points[i + 1] = (gdr_vec3){cosf(a), sinf(a), 0.0f};
    }
    points[n - 1] = points[1];
    for (int pass = 0; pass < 2; pass++) {
        lod_grid g = {0};
        CHECK(lod_grid_build(&g, points, n, pass == 0 ? 4.0 : 1.0));
        CHECK(g.use_tree);
        unsigned state = 21;
        for (int i = 0; i < 1500; i++) {
            float scale = i % 4 == 0 ? 0.5f : i % 4 == 1 ? 1.3f : 1.0f;
            gdr_vec3 p = i % 4 == 2 ? points[(uint32_t)(i * 13) % n]
                                    : (gdr_vec3){scale * test_random_range(&state, -1.0f, 1.0f),
                                                 scale * test_random_range(&state, -1.0f, 1.0f),
                                                 test_random_range(&state, -0.1f, 0.1f)};
            if (i % 4 == 3)
                p.y = 0.0f;
            float d2, want_d2;
            uint32_t got = lod_grid_nearest(&g, p, &d2), want = brute_force_point(points, n, p, &want_d2);
            CHECK(got == want);
            CHECK(d2 == want_d2);
        }
        lod_grid_free(&g);
    }
    free(points);
}

int main(void)
{
    test_points_exact();
    test_needles_exact();
    test_band_exact();
    test_fan_bounded();
    test_fan_listing_linear();
    test_points_on_a_curve_exact();
    return test_finish("test_lod_grid");
}
