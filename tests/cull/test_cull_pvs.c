/* Precomputed visibility: the bake is conservative for its sampled points (fresh rays from them
 * only ever reach objects the cell lists), miss rates for fresh points, culling with it, the blob
 * round trip, damaged blobs refused cleanly, and the exact size of every chunk. */
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <zstd.h>

#include "gdr/thread_pool.h"
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

/* Each object's triangles in the BVH (they are listed instance by instance). */
typedef struct object_triangles {
    uint32_t *first; /* object_count + 1 */
} object_triangles;

static object_triangles map_objects(const gdr_bvh *bvh, uint32_t object_count)
{
    object_triangles m = {calloc(object_count + 1, sizeof(uint32_t))};
    for (uint32_t t = 0; t < gdr_bvh_triangle_count(bvh); t++) {
        gdr_vec3 c[3];
        uint32_t o;
        gdr_bvh_triangle(bvh, t, c, &o);
        CHECK(o < object_count);
        m.first[o + 1] = t + 1;
    }
    for (uint32_t o = 0; o < object_count; o++)
        if (m.first[o + 1] < m.first[o])
            m.first[o + 1] = m.first[o];
    return m;
}

/* A uniformly random point on one of triangles [first, last). */
static gdr_vec3 random_point(const gdr_bvh *bvh, uint32_t first, uint32_t last, unsigned *rng)
{
    gdr_vec3 c[3];
    uint32_t t = first + (uint32_t)(test_random(rng) * (float)(last - first)) % (last - first);
    gdr_bvh_triangle(bvh, t, c, NULL);
    float a = test_random(rng), b = test_random(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    return gdr_vec3_add(c[0], gdr_vec3_add(gdr_vec3_scale(gdr_vec3_sub(c[1], c[0]), a),
                                           gdr_vec3_scale(gdr_vec3_sub(c[2], c[0]), b)));
}

static gdr_vec3 random_direction(unsigned *rng)
{
    for (;;) {
        gdr_vec3 d = {test_random_range(rng, -1, 1), test_random_range(rng, -1, 1), test_random_range(rng, -1, 1)};
        float l = gdr_vec3_length(d);
        if (l > 0.01f && l <= 1.0f)
            return gdr_vec3_scale(d, 1.0f / l);
    }
}

typedef struct ray_tally {
    uint64_t rays, hits, misses;
} ray_tally;

/* Fresh rays from p: direction_rays uniformly random directions, and per object rays_per_object
 * rays at uniformly random points on its triangles (whatever they hit first counts). A miss is a
 * hit on an object the bitset does not list. */
static void check_point(const gdr_bvh *bvh, const object_triangles *map, uint32_t object_count, const uint32_t *bits,
                        gdr_vec3 p, unsigned *rng, uint32_t direction_rays, uint32_t rays_per_object, ray_tally *tally)
{
    for (uint32_t r = 0; r < direction_rays + object_count * rays_per_object; r++) {
        gdr_vec3 d;
        float t_max = INFINITY;
        if (r < direction_rays) {
            d = random_direction(rng);
        } else {
            uint32_t o = (r - direction_rays) / rays_per_object;
            if (map->first[o + 1] == map->first[o])
                continue;
            d = gdr_vec3_sub(random_point(bvh, map->first[o], map->first[o + 1], rng), p);
            t_max = 1.0001f;
        }
        tally->rays++;
        uint32_t o = first_hit(bvh, p, d, t_max);
        if (o == UINT32_MAX)
            continue;
        tally->hits++;
        tally->misses += !gdr_cull_bit(bits, o);
    }
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static void test_bake(gdr_scene *scene, gdr_thread_pool *pool, unsigned *rng, uint8_t **blob_out, size_t *size_out)
{
    gdr_pvs_bake_desc desc = {0};
    desc.scene = scene;
    desc.region_min = (gdr_vec3){-20, 1.6f, -20};
    desc.region_max = (gdr_vec3){20, 5.6f, 20};
    desc.cell_size = 4.0f;
    desc.samples_per_cell = 4;
    desc.cells_per_chunk = 32;
    desc.bucket_count_x = 2;
    desc.bucket_count_z = 2;
    desc.keep_samples = true;
    desc.pool = pool;
    gdr_pvs *pvs;
    gdr_pvs_bake_report report;
    gdr_error err;
    double start = now_ms();
    CHECK(gdr_pvs_bake(&desc, &pvs, &report, &err) == GDR_OK);
    double bake_ms = now_ms() - start;
    printf("bake (%u threads): %.0f ms; grid %u x %u x %u, %u cells baked, %u occupied, %llu samples, %llu object "
           "tests, %llu unproven samples, %llu visible pairs of %llu, %zu -> %zu bytes\n",
           gdr_thread_pool_thread_count(pool), bake_ms, report.grid[0], report.grid[1], report.grid[2],
           report.cells_baked, report.cells_occupied, (unsigned long long)report.samples_used,
           (unsigned long long)report.object_tests, (unsigned long long)report.unproven_samples,
           (unsigned long long)report.visible_pairs, (unsigned long long)report.cells_baked * scene->instance_count,
           report.uncompressed_bytes, report.compressed_bytes);
    CHECK(report.cells_total == 100);
    CHECK(report.cells_baked + report.cells_occupied == report.cells_total);
    CHECK(report.cells_baked > 50 && report.cells_occupied > 10);
    CHECK(report.compressed_bytes < report.uncompressed_bytes);
    CHECK(report.samples_used == (uint64_t)report.cells_baked * 4);
    CHECK(report.unproven_samples == 0);
    CHECK(report.object_tests > 0);
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
    object_triangles map = map_objects(bvh, scene->instance_count);
    gdr_pvs_cache *cache;
    CHECK(gdr_pvs_cache_create(pvs, &cache, &err) == GDR_OK);
    ray_tally sampled = {0}, fresh = {0};
    uint32_t fresh_points = 0;
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
            check_point(bvh, &map, scene->instance_count, bits, samples[s], rng, 512, 2, &sampled);
        }
        for (int f = 0; f < 4; f++) {
            gdr_vec3 p = {test_random_range(rng, lo.x, hi.x), test_random_range(rng, lo.y, hi.y),
                          test_random_range(rng, lo.z, hi.z)};
            const uint32_t *found = gdr_pvs_lookup(cache, p);
            if (!found)
                continue; /* on the far face: the next cell */
            memcpy(bits, found, words * 4);
            fresh_points++;
            check_point(bvh, &map, scene->instance_count, bits, p, rng, 512, 2, &fresh);
        }
    }
    printf("sampled points (%llu): %llu fresh rays, %llu hits, %llu on unlisted objects\n",
           (unsigned long long)report.samples_used, (unsigned long long)sampled.rays,
           (unsigned long long)sampled.hits, (unsigned long long)sampled.misses);
    printf("fresh unsampled points (%u): %llu rays, %llu hits, %llu on unlisted objects (miss rate %.4f%% of hits)\n",
           fresh_points, (unsigned long long)fresh.rays, (unsigned long long)fresh.hits,
           (unsigned long long)fresh.misses, 100.0 * (double)fresh.misses / (double)fresh.hits);
    /* The guarantee: nothing visible from a sampled point is missing, whatever the ray. */
    CHECK(sampled.hits > 150000);
    CHECK(sampled.misses == 0);
    /* Unsampled points have no guarantee; this bounds the measured rate (docs/CULLING.md). */
    CHECK(fresh.hits > 150000);
    CHECK((double)fresh.misses < 0.01 * (double)fresh.hits);
    free(map.first);

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
    gdr_error err;
    CHECK(gdr_cull_objects_from_scene(objects, scene, &err) == GDR_OK);
    objects[5].flags |= GDR_CULL_OBJECT_DYNAMIC;
    gdr_cull_scene_desc sd = {objects, n, 0, 0};
    gdr_cull_scene *cs;
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

/* --- the exact chunk size -------------------------------------------------------------------- */

static uint32_t get32le(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t get64le(const uint8_t *p) { return (uint64_t)get32le(p) | (uint64_t)get32le(p + 4) << 32; }

static void put64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

/* Where the tables of a blob are (docs/CULLING.md, blob layout). */
typedef struct blob_layout {
    uint32_t objects, cells, chunks;
    size_t cells_at, chunks_at, data_at;
} blob_layout;

static blob_layout layout_of(const uint8_t *b)
{
    blob_layout l = {get32le(b + 16), get32le(b + 56), get32le(b + 60), 0, 0, 0};
    l.cells_at = 80 + 8 * (size_t)get32le(b + 48) * get32le(b + 52);
    l.chunks_at = l.cells_at + 20 * (size_t)l.cells;
    l.data_at = l.chunks_at + 24 * (size_t)l.chunks;
    return l;
}

/* A copy of the blob whose chunk k holds `payload` (flags and uncompressed size as given), the
 * other chunks' data moved to follow, and the checksum fixed. */
static uint8_t *replace_chunk(const uint8_t *b, size_t size, uint32_t k, const void *payload, size_t payload_size,
                              uint32_t flags, uint32_t uncompressed, size_t *out_size)
{
    blob_layout l = layout_of(b);
    size_t data = 0;
    for (uint32_t j = 0; j < l.chunks; j++)
        data += j == k ? payload_size : get32le(b + l.chunks_at + 24 * (size_t)j + 8);
    uint8_t *out = malloc(l.data_at + data + 1);
    memcpy(out, b, l.data_at);
    size_t at = 0;
    for (uint32_t j = 0; j < l.chunks; j++) {
        uint8_t *e = out + l.chunks_at + 24 * (size_t)j;
        const uint8_t *src = j == k ? payload : b + l.data_at + get64le(e);
        size_t n = j == k ? payload_size : get32le(e + 8);
        memcpy(out + l.data_at + at, src, n);
        put64(e, at);
        put32(e + 8, (uint32_t)n);
        if (j == k) {
            put32(e + 12, uncompressed);
            put32(e + 16, flags);
        }
        at += n;
    }
    put64(out + 64, data);
    *out_size = l.data_at + data;
    fix_checksum(out, *out_size);
    (void)size;
    return out;
}

/* Sets the content size in a zstd frame header (RFC 8878 3.1.1.1) without touching the rest. */
static void patch_frame_content_size(uint8_t *frame, uint64_t size)
{
    uint8_t fhd = frame[4];
    unsigned fcs_flag = fhd >> 6, single = (fhd >> 5) & 1u, dict_flag = fhd & 3u;
    static const unsigned dict_bytes[4] = {0, 1, 2, 4}, fcs_bytes[4] = {1, 2, 4, 8};
    size_t at = 5 + (single ? 0 : 1) + dict_bytes[dict_flag];
    unsigned n = fcs_flag == 0 && !single ? 0 : fcs_bytes[fcs_flag];
    CHECK(n > 0);
    if (n == 2)
        size -= 256;
    for (unsigned i = 0; i < n; i++)
        frame[at + i] = (uint8_t)(size >> (8 * i));
}

/* Loads a blob that must be refused with GDR_ERROR_PARSE and a message holding `what`. */
static void expect_refused(const uint8_t *b, size_t n, const char *what)
{
    gdr_pvs *pvs = NULL;
    gdr_error err = {0};
    gdr_status st = gdr_pvs_load(b, n, &pvs, &err);
    CHECK(st == GDR_ERROR_PARSE && pvs == NULL);
    if (st == GDR_OK)
        gdr_pvs_destroy(pvs);
    if (!strstr(err.message, what)) {
        fprintf(stderr, "expected '%s' in: %s\n", what, err.message);
        CHECK(!"the message names the damage");
    }
}

/* A chunk's uncompressed size is exactly (its cells) x (bytes per bitset): refused otherwise, in
 * the chunk table, in the zstd frame header or in the decompressed data. */
static void test_exact_chunk_size(const uint8_t *blob, size_t size)
{
    blob_layout l = layout_of(blob);
    uint32_t cell_bytes = gdr_cull_word_count(l.objects) * 4;
    /* a zstd chunk of several cells */
    uint32_t k = UINT32_MAX, cells_in_k = 0;
    for (uint32_t j = 0; j < l.chunks && k == UINT32_MAX; j++) {
        const uint8_t *e = blob + l.chunks_at + 24 * (size_t)j;
        uint32_t n = 0;
        for (uint32_t c = 0; c < l.cells; c++)
            n += get32le(blob + l.cells_at + 20 * (size_t)c + 12) == j;
        if ((get32le(e + 16) & 1u) && n >= 2) {
            k = j;
            cells_in_k = n;
        }
    }
    CHECK(k != UINT32_MAX);
    if (k == UINT32_MAX)
        return;
    const uint8_t *entry = blob + l.chunks_at + 24 * (size_t)k;
    uint32_t exact = cells_in_k * cell_bytes;
    CHECK(get32le(entry + 12) == exact);
    const uint8_t *frame = blob + l.data_at + get64le(entry);
    size_t frame_size = get32le(entry + 8);
    uint8_t *raw = malloc(exact + cell_bytes + 1);
    CHECK(ZSTD_decompress(raw, exact, frame, frame_size) == exact);
    memset(raw + exact, 0, cell_bytes);
    uint8_t *bad = malloc(size);
    size_t n;

    /* the chunk table's size, off by a word, by a cell, or hostile (nothing that size is allocated) */
    uint32_t wrong[] = {exact + 4, exact - 4, exact + cell_bytes, exact - cell_bytes, 0, 0x0FFFFFFCu, 0xFFFFFFFCu};
    for (size_t i = 0; i < sizeof wrong / sizeof wrong[0]; i++) {
        memcpy(bad, blob, size);
        put32(bad + l.chunks_at + 24 * (size_t)k + 12, wrong[i]);
        fix_checksum(bad, size);
        char what[96];
        snprintf(what, sizeof what, "chunks[%u] uncompressed_size %u, its %u cells of %u objects need %u", k,
                 wrong[i], cells_in_k, l.objects, exact);
        expect_refused(bad, size, what);
    }
    /* the same data recompressed differently: loads (the rebuilt blob is sound) */
    size_t bound = ZSTD_compressBound(exact + cell_bytes);
    uint8_t *packed = malloc(bound + 64);
    size_t packed_size = ZSTD_compress(packed, bound, raw, exact, 19);
    CHECK(!ZSTD_isError(packed_size));
    uint8_t *b2 = replace_chunk(blob, size, k, packed, packed_size, 1, exact, &n);
    gdr_pvs *pvs = NULL;
    gdr_error err;
    CHECK(gdr_pvs_load(b2, n, &pvs, &err) == GDR_OK);
    gdr_pvs_destroy(pvs);
    free(b2);
    /* stored instead of compressed: loads; one word more (table and data agree): refused */
    b2 = replace_chunk(blob, size, k, raw, exact, 0, exact, &n);
    CHECK(gdr_pvs_load(b2, n, &pvs, &err) == GDR_OK);
    gdr_pvs_destroy(pvs);
    free(b2);
    b2 = replace_chunk(blob, size, k, raw, exact + 4, 0, exact + 4, &n);
    expect_refused(b2, n, "need");
    free(b2);
    /* a frame of one more cell, the table saying the exact size: the frame header is refused */
    packed_size = ZSTD_compress(packed, bound, raw, exact + cell_bytes, 3);
    b2 = replace_chunk(blob, size, k, packed, packed_size, 1, exact, &n);
    expect_refused(b2, n, "zstd frame states another number of bytes");
    free(b2);
    /* a frame that does not state its size */
    ZSTD_CCtx *cctx = ZSTD_createCCtx();
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_contentSizeFlag, 0);
    packed_size = ZSTD_compress2(cctx, packed, bound, raw, exact);
    ZSTD_freeCCtx(cctx);
    CHECK(!ZSTD_isError(packed_size));
    b2 = replace_chunk(blob, size, k, packed, packed_size, 1, exact, &n);
    expect_refused(b2, n, "zstd frame states no size");
    free(b2);
    /* the exact frame followed by an empty one: not one frame */
    packed_size = ZSTD_compress(packed, bound, raw, exact, 3);
    size_t tail = ZSTD_compress(packed + packed_size, bound + 64 - packed_size, raw, 0, 3);
    CHECK(!ZSTD_isError(tail));
    b2 = replace_chunk(blob, size, k, packed, packed_size + tail, 1, exact, &n);
    expect_refused(b2, n, "is not one zstd frame");
    free(b2);
    /* a frame that states the exact size but holds a word less: the decompression is refused */
    packed_size = ZSTD_compress(packed, bound, raw, exact - 4, 3);
    patch_frame_content_size(packed, exact);
    CHECK(ZSTD_getFrameContentSize(packed, packed_size) == exact);
    b2 = replace_chunk(blob, size, k, packed, packed_size, 1, exact, &n);
    expect_refused(b2, n, "does not decompress to its");
    free(b2);
    /* two cells of the chunk on one bitset (the chunk's size still matches its cell count) */
    uint32_t first = UINT32_MAX;
    for (uint32_t c = 0; c < l.cells; c++) {
        const uint8_t *e = blob + l.cells_at + 20 * (size_t)c;
        if (get32le(e + 12) != k)
            continue;
        if (first == UINT32_MAX) {
            first = c;
            continue;
        }
        memcpy(bad, blob, size);
        put32(bad + l.cells_at + 20 * (size_t)c + 16, get32le(blob + l.cells_at + 20 * (size_t)first + 16));
        fix_checksum(bad, size);
        expect_refused(bad, size, "share the bitset");
        /* an offset between bitsets, or past the chunk */
        put32(bad + l.cells_at + 20 * (size_t)c + 16, cell_bytes / 2);
        fix_checksum(bad, size);
        expect_refused(bad, size, "is not a bitset of chunk");
        put32(bad + l.cells_at + 20 * (size_t)c + 16, exact);
        fix_checksum(bad, size);
        expect_refused(bad, size, "is not a bitset of chunk");
        /* a cell moved to another chunk: both chunks' sizes are now wrong */
        memcpy(bad, blob, size);
        put32(bad + l.cells_at + 20 * (size_t)c + 12, k == 0 ? 1 : 0);
        fix_checksum(bad, size);
        expect_refused(bad, size, "need");
        break;
    }
    printf("exact chunk size: chunk %u of %u cells x %u bytes = %u; table, frame header, frame data and tiling "
           "damage refused\n", k, cells_in_k, cell_bytes, exact);
    free(packed);
    free(bad);
    free(raw);
}

/* A thin wall with a slit 1 cm wide: objects behind it are seen from the room only through the
 * slit, which rays shot at random rarely find. Rays through the slit from every sample point must
 * reach only listed objects, and the bake must still hide most of what is behind the wall. */
static void test_slit(gdr_thread_pool *pool, unsigned *rng)
{
    gdr_scene *scene;
    gdr_error err;
    CHECK(gdr_scene_create(&scene, &err) == GDR_OK);
    uint32_t box = box_mesh(scene);
    add_box(scene, box, (gdr_vec3){0, -0.5f, 0}, (gdr_vec3){10, 0.5f, 10});
    add_box(scene, box, (gdr_vec3){-4.85f, 2, 0}, (gdr_vec3){5.15f, 2, 0.005f}); /* x in [-10, 0.3] */
    add_box(scene, box, (gdr_vec3){5.155f, 2, 0}, (gdr_vec3){4.845f, 2, 0.005f}); /* x in [0.31, 10] */
    const uint32_t first_behind = 3;
    for (int i = 0; i < 60; i++) {
        gdr_vec3 h = {test_random_range(rng, 0.1f, 0.4f), test_random_range(rng, 0.1f, 0.4f),
                      test_random_range(rng, 0.1f, 0.4f)};
        add_box(scene, box, (gdr_vec3){test_random_range(rng, -9, 9), h.y, test_random_range(rng, -9, -1)}, h);
    }
    gdr_pvs_bake_desc desc = {0};
    desc.scene = scene;
    desc.region_min = (gdr_vec3){-8, 0.5f, 1};
    desc.region_max = (gdr_vec3){8, 2.5f, 9};
    desc.cell_size = 2.0f;
    desc.samples_per_cell = 4;
    desc.keep_samples = true;
    desc.pool = pool;
    gdr_pvs *pvs;
    gdr_pvs_bake_report report;
    CHECK(gdr_pvs_bake(&desc, &pvs, &report, &err) == GDR_OK);
    CHECK(report.cells_baked == 32 && report.unproven_samples == 0);
    gdr_bvh *bvh;
    CHECK(gdr_bvh_create_from_scene(scene, &bvh, &err) == GDR_OK);
    gdr_pvs_cache *cache;
    CHECK(gdr_pvs_cache_create(pvs, &cache, &err) == GDR_OK);
    uint32_t n = scene->instance_count, behind = n - first_behind;
    uint8_t *seen = malloc(n);
    uint64_t rays = 0, slit_hits = 0, misses = 0, seen_pairs = 0, listed_behind = 0;
    for (uint32_t c = 0; c < gdr_pvs_cell_count(pvs); c++) {
        uint32_t count;
        const gdr_vec3 *samples = gdr_pvs_samples(pvs, c, &count);
        const uint32_t *bits = gdr_pvs_lookup(cache, samples[0]);
        CHECK(bits != NULL);
        if (!bits)
            continue;
        for (uint32_t i = first_behind; i < n; i++)
            listed_behind += gdr_cull_bit(bits, i);
        for (uint32_t s = 0; s < count; s++) {
            memset(seen, 0, n);
            for (int r = 0; r < 2000; r++) {
                gdr_vec3 target = {test_random_range(rng, 0.3f, 0.31f), test_random_range(rng, 0, 4),
                                   test_random_range(rng, -0.005f, 0.005f)};
                rays++;
                uint32_t o = first_hit(bvh, samples[s], gdr_vec3_sub(target, samples[s]), INFINITY);
                if (o == UINT32_MAX || o < first_behind)
                    continue;
                slit_hits++;
                seen[o] = 1;
                misses += !gdr_cull_bit(bits, o);
            }
            for (uint32_t i = 0; i < n; i++)
                seen_pairs += seen[i];
        }
    }
    printf("slit: %llu rays through a 1 cm slit from %llu sample points, %llu reached %llu (sample, object) pairs "
           "behind the wall, %llu on unlisted objects; cells list %llu of %llu (cell, object) pairs behind it\n",
           (unsigned long long)rays, (unsigned long long)report.samples_used, (unsigned long long)slit_hits,
           (unsigned long long)seen_pairs, (unsigned long long)misses, (unsigned long long)listed_behind,
           (unsigned long long)gdr_pvs_cell_count(pvs) * behind);
    CHECK(seen_pairs > 50);
    CHECK(misses == 0);
    CHECK(listed_behind < (uint64_t)gdr_pvs_cell_count(pvs) * behind / 2);
    free(seen);
    gdr_pvs_cache_destroy(cache);
    gdr_bvh_destroy(bvh);
    gdr_pvs_destroy(pvs);
    gdr_scene_destroy(scene);
}

/* Meshes that are not boxes, for the proof's corner cases: an open quad, bumpy sheets (folds seen
 * from a point split them into front and back regions), a sheet with randomly flipped triangles
 * and one with unshared vertices (welded by position), a box wound inside out, a closed
 * non-convex blob, and a triangle soup. */
static uint32_t add_mesh(gdr_scene *scene, const gdr_vec3 *p, uint32_t n, const uint32_t *idx, uint32_t count)
{
    uint32_t mesh;
    gdr_error err;
    CHECK(gdr_scene_add_mesh(scene, "shape", p, NULL, NULL, n, idx, count, &mesh, &err) == GDR_OK);
    return mesh;
}

static uint32_t sheet_mesh(gdr_scene *scene, unsigned *rng, float bump, bool flips, bool split)
{
    enum { N = 8 };
    gdr_vec3 grid[N * N], unshared[(N - 1) * (N - 1) * 6];
    uint32_t idx[(N - 1) * (N - 1) * 6];
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            grid[j * N + i] = (gdr_vec3){-1 + 2.0f * i / (N - 1), bump * test_random_range(rng, -1, 1),
                                         -1 + 2.0f * j / (N - 1)};
    uint32_t count = 0;
    for (int j = 0; j + 1 < N; j++)
        for (int i = 0; i + 1 < N; i++) {
            uint32_t a = j * N + i, b = a + 1, c = a + N, d = c + 1;
            uint32_t tri[2][3] = {{a, c, b}, {b, c, d}};
            for (int t = 0; t < 2; t++) {
                bool flip = flips && test_random(rng) < 0.3f;
                idx[count++] = tri[t][0];
                idx[count++] = tri[t][flip ? 2 : 1];
                idx[count++] = tri[t][flip ? 1 : 2];
            }
        }
    if (!split)
        return add_mesh(scene, grid, N * N, idx, count);
    for (uint32_t k = 0; k < count; k++) {
        unshared[k] = grid[idx[k]];
        idx[k] = k;
    }
    return add_mesh(scene, unshared, count, idx, count);
}

static uint32_t blob_mesh(gdr_scene *scene, unsigned *rng)
{
    enum { RINGS = 6, SEG = 9 };
    gdr_vec3 p[2 + (RINGS - 1) * SEG];
    uint32_t idx[6 * SEG * (RINGS - 1)], count = 0, n = 0;
    p[n++] = (gdr_vec3){0, 1, 0};
    for (int r = 1; r < RINGS; r++)
        for (int k = 0; k < SEG; k++) {
            float theta = 3.14159265f * r / RINGS, phi = 6.2831853f * k / SEG;
            float radius = test_random_range(rng, 0.4f, 1.0f);
            p[n++] = (gdr_vec3){radius * sinf(theta) * cosf(phi), radius * cosf(theta), radius * sinf(theta) * sinf(phi)};
        }
    p[n++] = (gdr_vec3){0, -1, 0};
    for (int k = 0; k < SEG; k++) {
        idx[count++] = 0, idx[count++] = 1 + (k + 1) % SEG, idx[count++] = 1 + k;
        uint32_t last = 1 + (RINGS - 2) * SEG;
        idx[count++] = n - 1, idx[count++] = last + k, idx[count++] = last + (k + 1) % SEG;
    }
    for (int r = 1; r + 1 < RINGS; r++)
        for (int k = 0; k < SEG; k++) {
            uint32_t a = 1 + (r - 1) * SEG + k, b = 1 + (r - 1) * SEG + (k + 1) % SEG, c = a + SEG, d = b + SEG;
            idx[count++] = a, idx[count++] = b, idx[count++] = c;
            idx[count++] = b, idx[count++] = d, idx[count++] = c;
        }
    return add_mesh(scene, p, n, idx, count);
}

static void test_shapes(gdr_thread_pool *pool, unsigned *rng)
{
    gdr_scene *scene;
    gdr_error err;
    CHECK(gdr_scene_create(&scene, &err) == GDR_OK);
    uint32_t box = box_mesh(scene);
    gdr_vec3 quad_p[4] = {{-1, 0, -1}, {1, 0, -1}, {-1, 0, 1}, {1, 0, 1}};
    uint32_t quad_i[6] = {0, 2, 1, 1, 2, 3};
    gdr_vec3 box_p[8];
    for (int i = 0; i < 8; i++)
        box_p[i] = (gdr_vec3){(i & 1) ? 1.0f : -1.0f, (i & 2) ? 1.0f : -1.0f, (i & 4) ? 1.0f : -1.0f};
    uint32_t inverted_i[36] = {0, 1, 2, 1, 3, 2, 4, 6, 5, 5, 6, 7, 0, 4, 1, 1, 4, 5,
                               2, 3, 6, 3, 7, 6, 0, 2, 4, 2, 6, 4, 1, 5, 3, 3, 5, 7};
    gdr_vec3 soup[18];
    uint32_t soup_i[18];
    for (int i = 0; i < 18; i++) {
        soup[i] = (gdr_vec3){test_random_range(rng, -1, 1), test_random_range(rng, -1, 1), test_random_range(rng, -1, 1)};
        soup_i[i] = (uint32_t)i;
    }
    uint32_t meshes[] = {add_mesh(scene, quad_p, 4, quad_i, 6), sheet_mesh(scene, rng, 0.3f, false, false),
                         sheet_mesh(scene, rng, 0.3f, true, false), sheet_mesh(scene, rng, 0.2f, false, true),
                         add_mesh(scene, box_p, 8, inverted_i, 36), blob_mesh(scene, rng), blob_mesh(scene, rng),
                         add_mesh(scene, soup, 18, soup_i, 18), box};
    add_box(scene, box, (gdr_vec3){0, -0.5f, 0}, (gdr_vec3){10, 0.5f, 10});
    for (int i = 0; i < 70; i++) {
        gdr_vec3 axis = gdr_vec3_normalize((gdr_vec3){test_random_range(rng, -1, 1), test_random_range(rng, -1, 1),
                                                      test_random_range(rng, -1, 1)});
        float big = i < 24 ? 3.0f : 1.0f; /* the first ones are large occluders */
        gdr_vec3 scale = {big * test_random_range(rng, 0.2f, 1.5f), big * test_random_range(rng, 0.2f, 1.5f),
                          big * test_random_range(rng, 0.2f, 1.5f)};
        gdr_vec3 at = {test_random_range(rng, -9, 9), test_random_range(rng, 0, 5), test_random_range(rng, -9, 9)};
        gdr_instance inst = {gdr_mat4_from_trs(at, gdr_quat_from_axis_angle(axis, test_random_range(rng, 0, 6.28f)),
                                               scale),
                             meshes[i % (sizeof(meshes) / sizeof(meshes[0]))], GDR_NO_INDEX, {1, 1, 1, 1}};
        CHECK(gdr_scene_add_instance(scene, &inst, &err) == GDR_OK);
    }
    gdr_pvs_bake_desc desc = {0};
    desc.scene = scene;
    desc.region_min = (gdr_vec3){-10, 0.2f, -10};
    desc.region_max = (gdr_vec3){10, 5.2f, 10};
    desc.cell_size = 1.25f;
    desc.samples_per_cell = 2;
    desc.cube_resolution = 32;
    desc.keep_samples = true;
    desc.pool = pool;
    gdr_pvs *pvs;
    gdr_pvs_bake_report report;
    double start = now_ms();
    CHECK(gdr_pvs_bake(&desc, &pvs, &report, &err) == GDR_OK);
    double bake_ms = now_ms() - start;
    gdr_bvh *bvh;
    CHECK(gdr_bvh_create_from_scene(scene, &bvh, &err) == GDR_OK);
    object_triangles map = map_objects(bvh, scene->instance_count);
    gdr_pvs_cache *cache;
    CHECK(gdr_pvs_cache_create(pvs, &cache, &err) == GDR_OK);
    ray_tally tally = {0};
    for (uint32_t c = 0; c < gdr_pvs_cell_count(pvs); c++) {
        uint32_t count;
        const gdr_vec3 *samples = gdr_pvs_samples(pvs, c, &count);
        const uint32_t *bits = gdr_pvs_lookup(cache, samples[0]);
        CHECK(bits != NULL);
        for (uint32_t s = 0; bits && s < count; s++)
            check_point(bvh, &map, scene->instance_count, bits, samples[s], rng, 400, 2, &tally);
    }
    printf("shapes: bake %.0f ms, %u cells baked, %llu samples, %llu visible pairs of %llu; %llu fresh rays from the "
           "samples, %llu hits, %llu on unlisted objects\n",
           bake_ms, report.cells_baked, (unsigned long long)report.samples_used,
           (unsigned long long)report.visible_pairs, (unsigned long long)report.cells_baked * scene->instance_count,
           (unsigned long long)tally.rays, (unsigned long long)tally.hits, (unsigned long long)tally.misses);
    CHECK(report.cells_baked > 100 && report.unproven_samples == 0);
    CHECK(tally.hits > 50000);
    CHECK(tally.misses == 0);
    CHECK(report.visible_pairs < (uint64_t)report.cells_baked * scene->instance_count);
    free(map.first);
    gdr_pvs_cache_destroy(cache);
    gdr_bvh_destroy(bvh);
    gdr_pvs_destroy(pvs);
    gdr_scene_destroy(scene);
}

/* Small blobs for the fuzz target's seed corpus (tests/fuzz/corpus/pvs): one flag byte (1: the
 * fuzzer recomputes the checksum) and the blob. Zstd chunks of several cells, stored chunks of
 * one cell each, and one with the checksum left as written. */
static int write_seeds(const char *dir, gdr_scene *scene)
{
    struct {
        const char *name;
        uint8_t flag;
        float cell;
        uint32_t cells_per_chunk, buckets;
    } seeds[] = {{"zstd_chunks.pvs", 1, 8.0f, 8, 1}, {"stored_chunks.pvs", 1, 10.0f, 1, 3}, {"checksummed.pvs", 0, 13.5f, 2, 1}};
    for (size_t k = 0; k < sizeof(seeds) / sizeof(seeds[0]); k++) {
        gdr_pvs_bake_desc desc = {0};
        desc.scene = scene;
        desc.region_min = (gdr_vec3){-20, 1.6f, -20};
        desc.region_max = (gdr_vec3){20, 5.6f, 20};
        desc.cell_size = seeds[k].cell;
        desc.samples_per_cell = 1;
        desc.cube_resolution = 16;
        desc.cells_per_chunk = seeds[k].cells_per_chunk;
        desc.bucket_count_x = desc.bucket_count_z = seeds[k].buckets;
        gdr_pvs *pvs;
        gdr_error err;
        CHECK(gdr_pvs_bake(&desc, &pvs, NULL, &err) == GDR_OK);
        size_t size = gdr_pvs_serialized_size(pvs);
        uint8_t *blob = malloc(size + 1);
        blob[0] = seeds[k].flag;
        CHECK(gdr_pvs_serialize(pvs, blob + 1, size, &err) == GDR_OK);
        char path[4096];
        snprintf(path, sizeof(path), "%s/%s", dir, seeds[k].name);
        FILE *f = fopen(path, "wb");
        CHECK(f && fwrite(blob, 1, size + 1, f) == size + 1);
        if (f)
            fclose(f);
        printf("%s: %zu bytes\n", path, size + 1);
        free(blob);
        gdr_pvs_destroy(pvs);
    }
    return test_finish("test_cull_pvs --write-seeds");
}

int main(int argc, char **argv)
{
    unsigned rng = 99;
    gdr_thread_pool *pool;
    gdr_error err;
    CHECK(gdr_thread_pool_create(3, &pool, &err) == GDR_OK);
    gdr_scene *scene = make_scene(&rng);
    if (argc == 3 && strcmp(argv[1], "--write-seeds") == 0) {
        int status = write_seeds(argv[2], scene);
        gdr_scene_destroy(scene);
        gdr_thread_pool_destroy(pool);
        return status;
    }
    uint8_t *blob = NULL;
    size_t size = 0;
    test_bake(scene, pool, &rng, &blob, &size);
    test_blob(scene, blob, size, &rng);
    test_exact_chunk_size(blob, size);
    free(blob);
    test_slit(pool, &rng);
    test_shapes(pool, &rng);

    gdr_pvs_bake_desc bad = {0};
    gdr_pvs *pvs;
    CHECK(gdr_pvs_bake(&bad, &pvs, NULL, &err) == GDR_ERROR_INVALID_ARGUMENT);
    bad.scene = scene;
    bad.cell_size = 1e-4f;
    CHECK(gdr_pvs_bake(&bad, &pvs, NULL, &err) == GDR_ERROR_CAPACITY);
    bad.cell_size = 0.0f;
    bad.cube_resolution = 2;
    CHECK(gdr_pvs_bake(&bad, &pvs, NULL, &err) == GDR_ERROR_INVALID_ARGUMENT);
    bad.cube_resolution = 2048;
    CHECK(gdr_pvs_bake(&bad, &pvs, NULL, &err) == GDR_ERROR_INVALID_ARGUMENT);
    gdr_scene_destroy(scene);
    gdr_thread_pool_destroy(pool);
    return test_finish("test_cull_pvs");
}
