/* Precomputed visibility: the bake is conservative for its sampled points (fresh rays from them
 * only ever reach objects the cell lists), miss rates for fresh points, culling with it, the blob
 * round trip, and damaged blobs refused cleanly. */
#include <stdlib.h>
#include <string.h>

#include "core/thread_pool.h"
#include "gdr/cull.h"
#include "test_util.h"

static uint32_t box_mesh(gdr_scene *scene)
{
    gdr_vec3 p[8];
    for (int i = 0; i < 8; i++)
        p[i] = (gdr_vec3){(i & 1) ? 1.0f : -1.0f, (i & 2) ? 1.0f : -1.0f, (i & 4) ? 1.0f : -1.0f};
    uint32_t idx[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                        2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    uint32_t mesh;
    gdr_error err;
    CHECK(gdr_scene_add_mesh(scene, "box", p, NULL, NULL, 8, idx, 36, &mesh, &err) == GDR_OK);
    return mesh;
}

static void add_box(gdr_scene *scene, uint32_t mesh, gdr_vec3 center, gdr_vec3 half)
{
    gdr_instance inst = {gdr_mat4_from_trs(center, gdr_quat_identity(), half), mesh, GDR_NO_INDEX, {1, 1, 1, 1}};
    gdr_error err;
    CHECK(gdr_scene_add_instance(scene, &inst, &err) == GDR_OK);
}

/* A 40 x 40 room: a floor, walls with doorways that split it, pillars and small crates. */
static gdr_scene *make_scene(unsigned *rng)
{
    gdr_scene *scene;
    gdr_error err;
    CHECK(gdr_scene_create(&scene, &err) == GDR_OK);
    uint32_t box = box_mesh(scene);
    add_box(scene, box, (gdr_vec3){0, -0.5f, 0}, (gdr_vec3){20, 0.5f, 20});
    add_box(scene, box, (gdr_vec3){-11, 2.5f, 0}, (gdr_vec3){9, 2.5f, 0.3f}); /* wall with a gap at x ~ 0 */
    add_box(scene, box, (gdr_vec3){12, 2.5f, 0}, (gdr_vec3){8, 2.5f, 0.3f});
    add_box(scene, box, (gdr_vec3){0, 2.5f, -12}, (gdr_vec3){0.3f, 2.5f, 8}); /* a second wall, north side */
    for (int i = 0; i < 260; i++) {
        gdr_vec3 c = {test_random_range(rng, -19, 19), 0, test_random_range(rng, -19, 19)};
        gdr_vec3 h = {test_random_range(rng, 0.2f, 1.2f), test_random_range(rng, 0.2f, 0.7f),
                      test_random_range(rng, 0.2f, 1.2f)};
        if (i >= 60) /* pebbles: many small objects, so the bitsets have runs that compress */
            h = (gdr_vec3){0.1f, 0.1f, 0.1f};
        c.y = h.y;
        add_box(scene, box, c, h);
    }
    return scene;
}

/* The first object a ray reaches (brute force over every triangle), or UINT32_MAX. */
static uint32_t first_hit(const gdr_bvh *bvh, gdr_vec3 o, gdr_vec3 d, float t_max)
{
    gdr_ray_hit hit;
    return gdr_bvh_raycast(bvh, o, d, t_max, &hit) ? hit.object : UINT32_MAX;
}

static gdr_vec3 random_target(const gdr_bvh *bvh, unsigned *rng)
{
    gdr_vec3 c[3];
    uint32_t t = (uint32_t)(test_random(rng) * (float)gdr_bvh_triangle_count(bvh)) % gdr_bvh_triangle_count(bvh);
    gdr_bvh_triangle(bvh, t, c, NULL);
    float a = test_random(rng), b = test_random(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    return gdr_vec3_add(c[0], gdr_vec3_add(gdr_vec3_scale(gdr_vec3_sub(c[1], c[0]), a),
                                           gdr_vec3_scale(gdr_vec3_sub(c[2], c[0]), b)));
}

/* Fresh rays from p: random directions and rays at random points on random triangles. Returns
 * the misses (hits on objects the bitset does not hold); counts the hits. */
static uint32_t check_point(const gdr_bvh *bvh, const uint32_t *bits, gdr_vec3 p, unsigned *rng, uint32_t rays,
                            uint64_t *hits)
{
    uint32_t misses = 0;
    for (uint32_t r = 0; r < rays; r++) {
        gdr_vec3 d;
        float t_max = INFINITY;
        if (r % 2) {
            d = gdr_vec3_normalize((gdr_vec3){test_random_range(rng, -1, 1), test_random_range(rng, -1, 1),
                                              test_random_range(rng, -1, 1)});
        } else {
            d = gdr_vec3_sub(random_target(bvh, rng), p);
            t_max = 1.0001f;
        }
        uint32_t o = first_hit(bvh, p, d, t_max);
        if (o == UINT32_MAX)
            continue;
        (*hits)++;
        misses += !gdr_cull_bit(bits, o);
    }
    return misses;
}

static void test_bake(gdr_scene *scene, gdr_thread_pool *pool, unsigned *rng, uint8_t **blob_out, size_t *size_out)
{
    gdr_pvs_bake_desc desc = {0};
    desc.scene = scene;
    desc.region_min = (gdr_vec3){-20, 1.6f, -20};
    desc.region_max = (gdr_vec3){20, 5.6f, 20};
    desc.cell_size = 4.0f;
    desc.samples_per_cell = 4;
    desc.direction_rays = 64;
    desc.rays_per_object = 16;
    desc.cells_per_chunk = 32;
    desc.bucket_count_x = 2;
    desc.bucket_count_z = 2;
    desc.keep_samples = true;
    desc.pool = pool;
    gdr_pvs *pvs;
    gdr_pvs_bake_report report;
    gdr_error err;
    CHECK(gdr_pvs_bake(&desc, &pvs, &report, &err) == GDR_OK);
    printf("bake: grid %u x %u x %u, %u cells baked, %u occupied, %llu samples, %llu rays, %llu visible pairs, "
           "%zu -> %zu bytes\n",
           report.grid[0], report.grid[1], report.grid[2], report.cells_baked, report.cells_occupied,
           (unsigned long long)report.samples_used, (unsigned long long)report.rays_cast,
           (unsigned long long)report.visible_pairs, report.uncompressed_bytes, report.compressed_bytes);
    CHECK(report.cells_total == 100);
    CHECK(report.cells_baked + report.cells_occupied == report.cells_total);
    CHECK(report.cells_baked > 50 && report.cells_occupied > 10);
    CHECK(report.compressed_bytes < report.uncompressed_bytes);
    CHECK(report.samples_used == (uint64_t)report.cells_baked * 4);
    CHECK(gdr_pvs_cell_count(pvs) == report.cells_baked);
    CHECK(gdr_pvs_object_count(pvs) == scene->instance_count);
    /* the walls hide things: cells do not see everything */
    CHECK(report.visible_pairs < (uint64_t)report.cells_baked * scene->instance_count);

    /* the same bake on another thread count gives the same bytes */
    gdr_pvs *again;
    desc.pool = NULL;
    CHECK(gdr_pvs_bake(&desc, &again, NULL, &err) == GDR_OK);
    size_t size = gdr_pvs_serialized_size(pvs);
    CHECK(size == gdr_pvs_serialized_size(again));
    uint8_t *blob = malloc(size), *blob2 = malloc(size);
    CHECK(gdr_pvs_serialize(pvs, blob, size, &err) == GDR_OK);
    CHECK(gdr_pvs_serialize(again, blob2, size, &err) == GDR_OK);
    CHECK(memcmp(blob, blob2, size) == 0);
    CHECK(gdr_pvs_serialize(pvs, blob2, size - 1, &err) == GDR_ERROR_INVALID_ARGUMENT);
    gdr_pvs_destroy(again);
    free(blob2);

    gdr_bvh *bvh;
    CHECK(gdr_bvh_create_from_scene(scene, &bvh, &err) == GDR_OK);
    gdr_pvs_cache *cache;
    CHECK(gdr_pvs_cache_create(pvs, &cache, &err) == GDR_OK);
    uint64_t sampled_hits = 0, fresh_hits = 0, sampled_misses = 0, fresh_misses = 0;
    uint32_t words = gdr_cull_word_count(gdr_pvs_object_count(pvs));
    uint32_t *bits = malloc(words * 4);
    for (uint32_t c = 0; c < gdr_pvs_cell_count(pvs); c++) {
        uint32_t n;
        const gdr_vec3 *samples = gdr_pvs_samples(pvs, c, &n);
        CHECK(n == 4 && samples);
        gdr_vec3 lo, hi;
        gdr_pvs_cell_bounds(pvs, c, &lo, &hi);
        for (uint32_t s = 0; s < n; s++) {
            const uint32_t *found = gdr_pvs_lookup(cache, samples[s]);
            CHECK(found != NULL);
            if (!found)
                continue;
            memcpy(bits, found, words * 4);
            sampled_misses += check_point(bvh, bits, samples[s], rng, 300, &sampled_hits);
        }
        for (int f = 0; f < 4; f++) {
            gdr_vec3 p = {test_random_range(rng, lo.x, hi.x), test_random_range(rng, lo.y, hi.y),
                          test_random_range(rng, lo.z, hi.z)};
            const uint32_t *found = gdr_pvs_lookup(cache, p);
            if (!found)
                continue; /* on the far face: the next cell */
            memcpy(bits, found, words * 4);
            fresh_misses += check_point(bvh, bits, p, rng, 300, &fresh_hits);
        }
    }
    printf("sampled points, fresh rays: %llu misses of %llu hits (%.4f%%)\n", (unsigned long long)sampled_misses,
           (unsigned long long)sampled_hits, 100.0 * (double)sampled_misses / (double)sampled_hits);
    printf("fresh unsampled points: %llu misses of %llu hits (miss rate %.4f%%)\n", (unsigned long long)fresh_misses,
           (unsigned long long)fresh_hits, 100.0 * (double)fresh_misses / (double)fresh_hits);
    /* Rays sample visibility: an object seen from a sampled point only through a gap that no bake
     * ray went through can be missed. Every miss must be that rare case. */
    CHECK((double)sampled_misses <= 0.001 * (double)sampled_hits);
    CHECK((double)fresh_misses < 0.02 * (double)fresh_hits);

    /* outside the grid, and inside an occupied cell: no data */
    CHECK(gdr_pvs_lookup(cache, (gdr_vec3){100, 2, 0}) == NULL);
    CHECK(gdr_pvs_lookup(cache, (gdr_vec3){NAN, 2, 0}) == NULL);
    CHECK(gdr_pvs_lookup(cache, (gdr_vec3){0, 0.5f, 0}) == NULL);

    /* the chunk cache: a second lookup in the same cell decompresses nothing */
    gdr_vec3 lo, hi;
    gdr_pvs_cell_bounds(pvs, 0, &lo, &hi);
    gdr_vec3 mid = gdr_vec3_scale(gdr_vec3_add(lo, hi), 0.5f);
    CHECK(gdr_pvs_lookup(cache, mid) != NULL);
    uint64_t before = gdr_pvs_cache_decompressions(cache);
    CHECK(gdr_pvs_lookup(cache, mid) != NULL);
    CHECK(gdr_pvs_cache_decompressions(cache) == before);

    gdr_pvs_cache_destroy(cache);
    gdr_bvh_destroy(bvh);
    free(bits);
    gdr_pvs_destroy(pvs);
    *blob_out = blob;
    *size_out = size;
}

/* Culling with precomputed visibility: objects the camera's cell cannot see are culled, except
 * DYNAMIC ones and ALWAYS_VISIBLE ones. */
static void test_culling(gdr_scene *scene, const gdr_pvs *pvs)
{
    uint32_t n = scene->instance_count;
    gdr_cull_object *objects = malloc(n * sizeof(*objects));
    gdr_cull_objects_from_scene(objects, scene);
    objects[5].flags |= GDR_CULL_OBJECT_DYNAMIC;
    gdr_cull_scene_desc sd = {objects, n, 0, 0};
    gdr_cull_scene *cs;
    gdr_error err;
    CHECK(gdr_cull_scene_create(&sd, &cs, &err) == GDR_OK);
    gdr_pvs_cache *cache;
    CHECK(gdr_pvs_cache_create(pvs, &cache, &err) == GDR_OK);
    uint32_t words = gdr_cull_word_count(n);
    uint32_t *with = calloc(words, 4), *without = calloc(words, 4);
    uint32_t culled_total = 0;
    for (uint32_t c = 0; c < gdr_pvs_cell_count(pvs); c++) {
        gdr_vec3 lo, hi;
        gdr_pvs_cell_bounds(pvs, c, &lo, &hi);
        gdr_vec3 eye = gdr_vec3_scale(gdr_vec3_add(lo, hi), 0.5f);
        gdr_cull_view v = {0};
        v.view = gdr_view_from_pose(eye, gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, (float)c));
        v.projection = gdr_perspective_reverse_z_infinite(1.2f, 1.5f, 0.1f);
        gdr_cull_result r = {without, NULL, NULL};
        CHECK(gdr_cull_execute(cs, &v, NULL, &r, NULL, &err) == GDR_OK);
        v.visibility = cache;
        r.visible = with;
        gdr_cull_stats st;
        CHECK(gdr_cull_execute(cs, &v, NULL, &r, &st, &err) == GDR_OK);
        CHECK(st.visibility_cell_found);
        const uint32_t *cell = gdr_pvs_lookup(cache, eye);
        for (uint32_t i = 0; i < n; i++) {
            bool expect = gdr_cull_bit(without, i) && (i == 5 || gdr_cull_bit(cell, i));
            CHECK(gdr_cull_bit(with, i) == expect);
        }
        culled_total += st.precomputed;
    }
    printf("culling with precomputed visibility: %u objects culled by it over %u cells\n", culled_total,
           gdr_pvs_cell_count(pvs));
    CHECK(culled_total > 0);
    free(with);
    free(without);
    gdr_pvs_cache_destroy(cache);
    gdr_cull_scene_destroy(cs);
    free(objects);
}

static uint64_t fnv(const uint8_t *d, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < n; i++)
        h = (h ^ ((i >= 72 && i < 80) ? 0 : d[i])) * 0x100000001b3ull;
    return h;
}

static void fix_checksum(uint8_t *b, size_t n)
{
    uint64_t h = fnv(b, n);
    for (int i = 0; i < 8; i++)
        b[72 + i] = (uint8_t)(h >> (8 * i));
}

static void put32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

/* Loads a damaged blob: it must be refused with GDR_ERROR_PARSE or, if it happens to be valid,
 * be safe to query everywhere. */
static int try_load(const uint8_t *b, size_t n, gdr_status *status)
{
    gdr_pvs *pvs;
    gdr_error err;
    *status = gdr_pvs_load(b, n, &pvs, &err);
    if (*status != GDR_OK)
        return 0;
    gdr_pvs_cache *cache;
    if (gdr_pvs_cache_create(pvs, &cache, &err) == GDR_OK) {
        for (float x = -22; x < 22; x += 1.7f)
            for (float z = -22; z < 22; z += 1.9f)
                (void)gdr_pvs_lookup(cache, (gdr_vec3){x, 2, z});
        gdr_pvs_cache_destroy(cache);
    }
    gdr_pvs_destroy(pvs);
    return 1;
}

static void test_blob(gdr_scene *scene, const uint8_t *blob, size_t size, unsigned *rng)
{
    gdr_pvs *pvs;
    gdr_error err;
    CHECK(gdr_pvs_load(blob, size, &pvs, &err) == GDR_OK);
    CHECK(gdr_pvs_samples(pvs, 0, &(uint32_t){0}) == NULL); /* samples are not serialised */
    size_t size2 = gdr_pvs_serialized_size(pvs);
    CHECK(size2 == size);
    uint8_t *round = malloc(size2);
    CHECK(gdr_pvs_serialize(pvs, round, size2, &err) == GDR_OK);
    CHECK(memcmp(round, blob, size) == 0);
    free(round);
    test_culling(scene, pvs);
    gdr_pvs_destroy(pvs);

    uint8_t *bad = malloc(size);
    gdr_status st;
    /* every truncation */
    uint32_t refused = 0;
    for (size_t n = 0; n < size; n += n < 700 ? 1 : 37) {
        CHECK(try_load(blob, n, &st) == 0);
        CHECK(st == GDR_ERROR_PARSE);
        refused++;
    }
    /* every single-byte flip is caught (by the checksum at least) */
    for (size_t i = 0; i < size; i += i < 300 ? 1 : 13) {
        memcpy(bad, blob, size);
        bad[i] ^= (uint8_t)(1u << (i % 8));
        CHECK(try_load(bad, size, &st) == 0);
        CHECK(st == GDR_ERROR_PARSE);
    }
    /* structural damage with a valid checksum: each field of the header and tables set to
     * hostile values; refused with GDR_ERROR_PARSE, or (when harmless) loaded and safe */
    uint32_t hostile[] = {0, 1, 3, 0xFFFFFFFFu, 0x80000000u, 0x7FFFFFFFu, 4096, 65536};
    size_t tables_end = size < 2000 ? size : 2000;
    uint32_t structural_refused = 0, structural_loaded = 0;
    for (size_t off = 8; off + 4 <= tables_end; off += 4) {
        if (off >= 72 && off < 80)
            continue;
        for (size_t h = 0; h < sizeof(hostile) / sizeof(hostile[0]); h++) {
            memcpy(bad, blob, size);
            put32(bad + off, hostile[h]);
            fix_checksum(bad, size);
            if (try_load(bad, size, &st))
                structural_loaded++;
            else {
                CHECK(st == GDR_ERROR_PARSE);
                structural_refused++;
            }
        }
    }
    /* random garbage in the compressed data, checksum fixed */
    for (int k = 0; k < 300; k++) {
        memcpy(bad, blob, size);
        size_t at = size - 1 - (size_t)(test_random(rng) * (float)(size / 3));
        bad[at] = (uint8_t)(test_random(rng) * 256);
        fix_checksum(bad, size);
        if (try_load(bad, size, &st))
            structural_loaded++;
        else
            structural_refused++;
    }
    printf("damaged blobs: %u truncations refused; with fixed checksums %u refused, %u harmless and loaded\n",
           refused, structural_refused, structural_loaded);
    CHECK(structural_refused > 100);
    free(bad);
}

int main(void)
{
    unsigned rng = 99;
    gdr_thread_pool *pool;
    gdr_error err;
    CHECK(gdr_thread_pool_create(3, &pool, &err) == GDR_OK);
    gdr_scene *scene = make_scene(&rng);
    uint8_t *blob = NULL;
    size_t size = 0;
    test_bake(scene, pool, &rng, &blob, &size);
    test_blob(scene, blob, size, &rng);
    free(blob);

    gdr_pvs_bake_desc bad = {0};
    gdr_pvs *pvs;
    CHECK(gdr_pvs_bake(&bad, &pvs, NULL, &err) == GDR_ERROR_INVALID_ARGUMENT);
    bad.scene = scene;
    bad.cell_size = 1e-4f;
    CHECK(gdr_pvs_bake(&bad, &pvs, NULL, &err) == GDR_ERROR_CAPACITY);
    gdr_scene_destroy(scene);
    gdr_thread_pool_destroy(pool);
    return test_finish("test_cull_pvs");
}
