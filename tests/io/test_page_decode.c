/* What a decoded geometry page holds, byte for byte (docs/STREAMING.md, "Decoding a page"): every
 * page of a few paged caches (float vertices, quantized vertices, a real glTF model) decoded and
 * compared with the page worked out from the scene itself by the plain rule the decoder must follow:
 * the page's groups' clusters in order, each cluster record with its running vertex and triangle
 * offsets, each triangle in its canonical rotation (the corner whose 32 vertex bytes compare lowest
 * with memcmp first, the earliest on a tie), the cluster's vertices in order of first use by those
 * triangles, local indices as bytes, zero bytes up to a multiple of 4 (where two lowest corners have
 * equal bytes, as quantized vertices can, the index codec's rotation decides: such a cluster is
 * held to the rule up to that choice). Independent of how the pages
 * are laid out on disk: only the scene and the decoded page are compared. Also the vertex codec
 * alone: decoding many vertices at once gives gdr_vertex_decode's bits (and those of the plain
 * formula, ldexpf per coordinate) for any stored integers, and a grid whose largest values
 * overflow is said to be one. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "geometry/vertex_quantize.h"
#include "test_util.h"

#ifndef ASSIMP_GLTF2_DIR
#define ASSIMP_GLTF2_DIR "/usr/share/assimp/models/glTF2"
#endif

static gdr_vertex_bytes bytes_of(const gdr_mesh *mesh, uint32_t v)
{
    gdr_vertex_bytes b;
    memset(&b, 0, sizeof b);
    b.position = mesh->positions[v], b.normal = mesh->normals[v], b.uv = mesh->uvs[v];
    return b;
}

/* A decoded page as the rule says it must be, built from the scene. */
typedef struct expected_page {
    gdr_page_cluster *clusters;
    gdr_vertex_bytes *vertices;
    uint8_t *triangles;
    uint8_t *tied;   /* per cluster: a triangle of it ties (its rotation is then the index codec's) */
    uint32_t cluster_count, vertex_count, triangle_bytes;
    uint32_t ties;   /* tied triangles in all */
} expected_page;

/* Scene cluster c appended to *e: its record, its triangles in canonical rotation, its vertices in
 * order of first use. A triangle whose lowest corners tie (equal bytes, as quantized vertices can
 * be) marks its cluster. */
static void expect_cluster(const gdr_mesh *mesh, uint32_t c, expected_page *e)
{
    const gdr_mesh_clusters *mc = &mesh->clusters;
    const gdr_cluster *sc = &mc->clusters[c];
    uint32_t index = e->cluster_count++;
    gdr_page_cluster *pc = &e->clusters[index];
    *pc = (gdr_page_cluster){.group = sc->group, .refined_group = sc->refined_group, .vertex_offset = e->vertex_count,
                             .vertex_count = sc->vertex_count, .triangle_offset = e->triangle_bytes,
                             .triangle_count = sc->triangle_count, .sphere = sc->sphere, .cone_apex = sc->cone_apex,
                             .cone_axis = sc->cone_axis, .cone_cutoff = sc->cone_cutoff};
    uint32_t used[GDR_CLUSTER_MAX_VERTICES + 3], seen = 0;
    for (uint32_t t = 0; t < sc->triangle_count; t++) {
        uint32_t mv[3];
        gdr_vertex_bytes b[3];
        for (int k = 0; k < 3; k++) {
            mv[k] = mc->vertices[sc->vertex_offset + mc->triangles[sc->triangle_offset + 3 * t + k]];
            b[k] = bytes_of(mesh, mv[k]);
        }
        int first = 0, tie = 0;
        for (int k = 1; k < 3; k++)
            if (memcmp(&b[k], &b[first], sizeof b[k]) < 0)
                first = k;
        for (int k = 0; k < 3; k++)
            tie |= k != first && memcmp(&b[k], &b[first], sizeof b[k]) == 0;
        e->ties += (uint32_t)tie;
        e->tied[index] |= (uint8_t)tie;
        for (int k = 0; k < 3; k++) {
            uint32_t v = mv[(first + k) % 3], local = 0;
            while (local < seen && used[local] != v)
                local++;
            if (local == seen && seen < GDR_CLUSTER_MAX_VERTICES + 3) {
                used[seen++] = v;
                e->vertices[e->vertex_count++] = bytes_of(mesh, v);
            }
            e->triangles[e->triangle_bytes + 3 * t + k] = (uint8_t)local;
        }
    }
    e->triangle_bytes += (3 * sc->triangle_count + 3) & ~3u;
}

/* A cluster with a tied triangle: each decoded triangle is the expected one up to a rotation that
 * starts at a lowest corner, and the decoded vertices are in order of first use by the decoded
 * triangles, each used. */
static int same_tied_cluster(const gdr_page *page, const expected_page *e, uint32_t c)
{
    const gdr_page_cluster *pc = &e->clusters[c];
    const uint8_t *dt = page->triangles + pc->triangle_offset, *et = e->triangles + pc->triangle_offset;
    const gdr_page_vertex *dv = page->vertices + pc->vertex_offset;
    const gdr_vertex_bytes *ev = e->vertices + pc->vertex_offset;
    uint32_t next = 0;
    for (uint32_t i = 0; i < 3 * pc->triangle_count; i++) {
        if (dt[i] > next || dt[i] >= pc->vertex_count)
            return 0;
        next += dt[i] == next;
    }
    for (uint32_t t = 0; t < pc->triangle_count; t++) {
        int found = 0;
        for (int r = 0; r < 3 && !found; r++) {
            int all = 1;
            for (int k = 0; k < 3; k++)
                all &= !memcmp(&dv[dt[3 * t + (k + r) % 3]], &ev[et[3 * t + k]], sizeof *ev);
            found = all && !memcmp(&dv[dt[3 * t]], &ev[et[3 * t]], sizeof *ev);
        }
        if (!found)
            return 0;
    }
    return next == pc->vertex_count;
}

/* The decoded page is the expected one: records exact; each cluster's vertices and triangles
 * exact, or as same_tied_cluster says where a triangle ties; the padding zero. */
static int same_page(const gdr_page *page, const expected_page *e)
{
    if (page->cluster_count != e->cluster_count || page->vertex_count != e->vertex_count ||
        page->triangle_byte_count != e->triangle_bytes ||
        memcmp(page->clusters, e->clusters, sizeof *e->clusters * e->cluster_count))
        return 0;
    for (uint32_t c = 0; c < e->cluster_count; c++) {
        const gdr_page_cluster *pc = &e->clusters[c];
        uint32_t bytes = (3 * pc->triangle_count + 3) & ~3u;
        if (e->tied[c] ? !same_tied_cluster(page, e, c)
                       : memcmp(page->vertices + pc->vertex_offset, e->vertices + pc->vertex_offset,
                                sizeof *e->vertices * pc->vertex_count) ||
                             memcmp(page->triangles + pc->triangle_offset, e->triangles + pc->triangle_offset, bytes))
            return 0;
        for (uint32_t i = 3 * pc->triangle_count; i < bytes; i++)
            if (page->triangles[pc->triangle_offset + i] != 0)
                return 0;
    }
    return 1;
}

/* Page p of mesh m as the rule says; the arrays sized from the page index. */
static void expect_page(const gdr_mesh *mesh, const gdr_paged_mesh *pm, uint32_t p, expected_page *e)
{
    const gdr_page_info *pi = &pm->pages[p];
    *e = (expected_page){0};
    e->clusters = calloc(pi->cluster_count + 1, sizeof *e->clusters);
    e->vertices = calloc(pi->vertex_count + 1, sizeof *e->vertices);
    e->triangles = calloc(4 * (size_t)pi->triangle_count + 4, 1);
    e->tied = calloc(pi->cluster_count + 1, 1);
    for (uint32_t g = 0; g < pi->group_count; g++) {
        const gdr_cluster_group *sg = &mesh->clusters.groups[pm->page_groups[pi->first + g]];
        for (uint32_t c = 0; c < sg->cluster_count && e->cluster_count < pi->cluster_count; c++)
            expect_cluster(mesh, sg->first_cluster + c, e);
    }
}

/* Every page of the cache at `path` against the scene; returns the pages compared. */
static uint32_t check_exact(const char *path, const gdr_scene *scene, const char *what)
{
    gdr_error err = {0};
    gdr_paged_cache *pc = NULL;
    CHECK(gdr_paged_cache_open(path, &pc, &err) == GDR_OK);
    if (!pc)
        return 0;
    uint32_t pages = 0, wrong = 0, ties = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_paged_mesh *pm = gdr_paged_cache_mesh(pc, m);
        for (uint32_t p = 0; p < pm->page_count; p++, pages++) {
            gdr_page page;
            expected_page e;
            CHECK(gdr_paged_cache_read_page(pc, m, p, &page, &err) == GDR_OK);
            expect_page(&scene->meshes[m], pm, p, &e);
            ties += e.ties;
            int same = same_page(&page, &e);
            if (!same && wrong++ == 0)
                fprintf(stderr, "%s: mesh %u page %u does not decode to the scene's bytes\n", what, m, p);
            gdr_page_free(&page);
            free(e.clusters), free(e.vertices), free(e.triangles), free(e.tied);
        }
    }
    printf("%s: %u pages, %u decoded to other bytes than the scene's (%u tied triangles)\n", what, pages, wrong,
           ties);
    CHECK(wrong == 0 && pages > 0);
    gdr_paged_cache_close(pc);
    return pages;
}

/* The scene written with pages of `kib` KiB, checked as read, then quantized, written and checked
 * again. */
static void check_scene(const char *source, uint32_t kib, const char *name)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1, .no_cache = 1};
    if (gdr_scene_load(source, &load, &scene, &err) != GDR_OK) {
        printf("%s: not loaded (%s): skipped\n", source, err.message);
        return;
    }
    char path[1024], what[300];
    snprintf(path, sizeof path, "%s/page_decode_%s.gdrc", GDR_IO_TEST_TMP, name);
    gdr_cache_write_options write = {.page_bytes = kib << 10};
    CHECK(gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    snprintf(what, sizeof what, "%s, float vertices", name);
    check_exact(path, scene, what);
    CHECK(gdr_scene_quantize_vertices(scene, &err) == GDR_OK);
    CHECK(gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    snprintf(what, sizeof what, "%s, quantized vertices", name);
    check_exact(path, scene, what);
    remove(path);
    gdr_scene_destroy(scene);
}

/* The plain formula a page's integers decode by: ldexpf per coordinate, oct_decode's steps. */
static gdr_vertex_bytes plain_decode(const gdr_vertex_quantization *q, const gdr_quantized_vertex *v)
{
    gdr_vertex_bytes b;
    memset(&b, 0, sizeof b);
    const float *po = &q->position_origin.x, *to = &q->uv_origin.x;
    float *p = &b.position.x, *t = &b.uv.x;
    for (int k = 0; k < 3; k++)
        p[k] = po[k] + ldexpf((float)v->position[k], q->position_exponent);
    for (int k = 0; k < 2; k++)
        t[k] = to[k] + ldexpf((float)v->uv[k], q->uv_exponent);
    float x = fmaxf((float)v->normal[0] / 511.0f, -1.0f), y = fmaxf((float)v->normal[1] / 511.0f, -1.0f);
    float z = 1.0f - fabsf(x) - fabsf(y);
    if (z < 0.0f) {
        float fx = (1.0f - fabsf(y)) * (x < 0.0f ? -1.0f : 1.0f), fy = (1.0f - fabsf(x)) * (y < 0.0f ? -1.0f : 1.0f);
        x = fx, y = fy;
    }
    float length = sqrtf(x * x + y * y + z * z);
    b.normal = (gdr_vec3){x / length + 0.0f, y / length + 0.0f, z / length + 0.0f};
    return b;
}

static uint32_t next_random(uint32_t *seed)
{
    *seed = *seed * 1664525u + 1013904223u;
    return *seed >> 8 ^ *seed << 13;
}

/* Random stored integers (normals beyond +-511 as a hostile page may hold, every uv bit) on grids
 * from the finest exponent to the coarsest, and beyond the range a float step holds: the batch
 * decode, the single one and the plain formula agree bit for bit. */
static void check_codec(void)
{
    static const int exponents[] = {-300, -150, -149, -140, -127, -126, -60, -7, 0, 9, 100, 127, 128, 300};
    uint32_t seed = 99, mismatches = 0, count = 1003; /* not a multiple of the decoder's block */
    gdr_quantized_vertex *in = malloc(sizeof *in * count);
    gdr_vertex_bytes *out = malloc(sizeof *out * count);
    for (size_t e = 0; e < sizeof exponents / sizeof *exponents; e++) {
        gdr_vertex_quantization q = {.enabled = 1, .position_exponent = exponents[e], .uv_exponent = -exponents[e],
                                     .position_origin = {-3.25f, 0.0f, 1e6f}, .uv_origin = {0.5f, -1e-3f}};
        for (uint32_t i = 0; i < count; i++) {
            in[i] = (gdr_quantized_vertex){0};
            for (int k = 0; k < 3; k++)
                in[i].position[k] = (uint16_t)next_random(&seed);
            for (int k = 0; k < 2; k++) {
                uint32_t r = next_random(&seed);
                in[i].normal[k] = (int16_t)(i % 3 ? (int)(r % 1023) - 511 : (int)(int16_t)r);
                in[i].uv[k] = i % 5 ? r % (1u << 20) : r;
            }
        }
        gdr_vertex_decode_many(&q, in, count, out);
        for (uint32_t i = 0; i < count; i++) {
            gdr_vertex_bytes one, plain = plain_decode(&q, &in[i]);
            memset(&one, 0, sizeof one);
            gdr_vertex_decode(&q, &in[i], &one.position, &one.normal, &one.uv);
            mismatches += memcmp(&out[i], &one, sizeof one) != 0 || memcmp(&one, &plain, sizeof one) != 0;
        }
    }
    printf("vertex codec: %u of %zu decoded vertices differ between the batch, single and plain decodes\n",
           mismatches, (size_t)count * (sizeof exponents / sizeof *exponents));
    CHECK(mismatches == 0);
    free(in);
    free(out);
}

/* A grid's largest stored values overflow to infinity: it is said not to be finite, and a vertex
 * near its top decodes to infinity, as the plain formula gives (the page reader checks each vertex
 * of such a grid). An ordinary grid is finite everywhere. */
static void check_grid_finite(void)
{
    gdr_vertex_quantization ordinary = {.enabled = 1, .position_exponent = -10, .uv_exponent = -20,
                                        .position_origin = {-8.0f, -8.0f, -8.0f}};
    CHECK(gdr_vertex_grid_finite(&ordinary));
    gdr_vertex_quantization top = {.enabled = 1, .position_exponent = 100, .uv_exponent = -20,
                                   .position_origin = {FLT_MAX, 0.0f, 0.0f}};
    CHECK(!gdr_vertex_grid_finite(&top));
    gdr_vertex_quantization uv_top = {.enabled = 1, .position_exponent = -10, .uv_exponent = 100};
    CHECK(!gdr_vertex_grid_finite(&uv_top)); /* 2^32 - 1 steps of 2^100 */
    gdr_quantized_vertex v = {.position = {65535, 0, 0}};
    gdr_vertex_bytes b;
    gdr_vertex_decode_many(&top, &v, 1, &b);
    CHECK(isinf(b.position.x) && !memcmp(&b, &(gdr_vertex_bytes){plain_decode(&top, &v).position, b.normal, b.uv},
                                        sizeof b));
}

int main(void)
{
    check_codec();
    check_grid_finite();
    /* Pages of about three groups: several pages per mesh, several groups per page. */
    check_scene("unique-field:meshes=3,triangles=3000,seed=4", 48, "unique-field");
    check_scene("unique-field:meshes=1,triangles=20000,seed=11", 128, "unique-field-20k");
    char model[1024];
    snprintf(model, sizeof model, "%s/2CylinderEngine-glTF-Binary/2CylinderEngine.glb", ASSIMP_GLTF2_DIR);
    check_scene(model, 64, "2CylinderEngine");
    return test_finish("test_page_decode");
}
