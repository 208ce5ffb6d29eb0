/* Triangle lists as importers hand them to the scene: degenerate and duplicate triangles dropped,
 * vertices shared by very many triangles split, coordinates checked against GDR_IO_MAX_COORDINATE.
 * meshoptimizer's meshlet builder (0.18) scans every live triangle of every vertex in the current
 * meshlet, and a kd-tree leaf of every triangle whose centroid it cannot split: duplicate faces,
 * zero-area faces and fans around one vertex make it quadratic. Everything here is linear. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/io_internal.h"

static uint32_t hash_words(const uint32_t *w, int n)
{
    uint32_t h = 2166136261u;
    for (int i = 0; i < n; i++) {
        uint32_t word;
        memcpy(&word, w + i, sizeof word); /* positions are floats: read their bits */
        h ^= word;
        h *= 16777619u;
        h ^= h >> 13;
    }
    return h ^ (h >> 16);
}

/* Open-addressing set of n-word keys, each stored once; slots hold key index + 1. */
typedef struct key_set {
    uint32_t *slots, mask;
    const uint32_t *keys; /* key k is keys[k * words ..] */
    int words;
} key_set;

static int key_set_init(key_set *s, uint32_t capacity, const uint32_t *keys, int words)
{
    uint32_t size = 64;
    while (size < capacity * 2u && size < (1u << 31))
        size *= 2;
    s->slots = calloc(size, sizeof(uint32_t));
    s->mask = size - 1;
    s->keys = keys;
    s->words = words;
    return s->slots != NULL;
}

/* The index of the first key equal to key `k`, inserting k when there is none. */
static uint32_t key_set_find_or_add(key_set *s, uint32_t k)
{
    const uint32_t *key = s->keys + (size_t)k * s->words;
    uint32_t slot = hash_words(key, s->words) & s->mask;
    while (s->slots[slot]) {
        uint32_t other = s->slots[slot] - 1;
        if (memcmp(s->keys + (size_t)other * s->words, key, sizeof(uint32_t) * (size_t)s->words) == 0)
            return other;
        slot = (slot + 1) & s->mask;
    }
    s->slots[slot] = k + 1;
    return k;
}

gdr_status gdr_io_check_positions(const gdr_vec3 *positions, uint32_t count, const char *name, const char *place,
                                  gdr_error *err)
{
    for (uint32_t v = 0; v < count; v++) {
        const float *p = &positions[v].x;
        for (int k = 0; k < 3; k++)
            if (!isfinite(p[k]) || fabsf(p[k]) > GDR_IO_MAX_COORDINATE)
                return gdr_error_set(err, GDR_ERROR_PARSE, "%s: %s: vertex %u (%g, %g, %g) is not finite or beyond "
                                     "the %g limit on coordinates", name, place, v, p[0], p[1], p[2],
                                     GDR_IO_MAX_COORDINATE);
    }
    return GDR_OK;
}

/* Zero area in double: the cross product of two edges is exactly zero. */
static int zero_area(gdr_vec3 a, gdr_vec3 b, gdr_vec3 c)
{
    double ux = (double)b.x - a.x, uy = (double)b.y - a.y, uz = (double)b.z - a.z;
    double vx = (double)c.x - a.x, vy = (double)c.y - a.y, vz = (double)c.z - a.z;
    return uy * vz - uz * vy == 0.0 && uz * vx - ux * vz == 0.0 && ux * vy - uy * vx == 0.0;
}

gdr_status gdr_io_drop_bad_triangles(const gdr_vec3 *positions, uint32_t vertex_count, uint32_t *indices,
                                     uint32_t *index_count, uint32_t *degenerate, uint32_t *duplicate)
{
    *degenerate = *duplicate = 0;
    uint32_t triangles = *index_count / 3;
    /* Vertices with equal positions (bit for bit) share one id, so a face repeated over copies of its
     * vertices is still a duplicate. */
    uint32_t *weld = malloc(sizeof(uint32_t) * ((size_t)vertex_count + 1));
    uint32_t *keys = malloc(sizeof(uint32_t) * 3 * ((size_t)triangles + 1));
    key_set positions_set = {0}, triangle_set = {0};
    gdr_status status = GDR_ERROR_OUT_OF_MEMORY;
    if (!weld || !keys || !key_set_init(&positions_set, vertex_count, (const uint32_t *)positions, 3) ||
        !key_set_init(&triangle_set, triangles, keys, 3))
        goto done;
    for (uint32_t v = 0; v < vertex_count; v++)
        weld[v] = key_set_find_or_add(&positions_set, v);
    uint32_t kept = 0;
    for (uint32_t t = 0; t < triangles; t++) {
        uint32_t a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
        uint32_t p[3] = {weld[a], weld[b], weld[c]};
        if (p[0] == p[1] || p[1] == p[2] || p[0] == p[2] || zero_area(positions[a], positions[b], positions[c])) {
            ++*degenerate;
            continue;
        }
        /* The same face in any rotation of its corners (the winding is kept: a back face differs). */
        int first = p[0] < p[1] ? (p[0] < p[2] ? 0 : 2) : (p[1] < p[2] ? 1 : 2);
        uint32_t *key = keys + 3 * (size_t)kept;
        for (int k = 0; k < 3; k++)
            key[k] = p[(first + k) % 3];
        if (key_set_find_or_add(&triangle_set, kept) != kept) {
            ++*duplicate;
            continue;
        }
        indices[3 * kept] = a;
        indices[3 * kept + 1] = b;
        indices[3 * kept + 2] = c;
        kept++;
    }
    *index_count = 3 * kept;
    status = GDR_OK;
done:
    free(weld);
    free(keys);
    free(positions_set.slots);
    free(triangle_set.slots);
    return status;
}

/* Grows an array of `count` elements to `grown` elements, the new ones copies of sources[]. */
static void *extend(void *array, size_t element, uint32_t count, uint32_t grown, const uint32_t *sources)
{
    if (!array)
        return NULL;
    uint8_t *bigger = realloc(array, element * grown);
    if (!bigger)
        return NULL;
    for (uint32_t i = count; i < grown; i++)
        memcpy(bigger + element * i, bigger + element * sources[i - count], element);
    return bigger;
}

gdr_status gdr_io_split_shared_vertices(gdr_vec3 **positions, gdr_vec3 **normals, gdr_vec2 **uvs, gdr_vec4 **colors,
                                        uint32_t *vertex_count, uint32_t *indices, uint32_t index_count,
                                        uint32_t *added)
{
    *added = 0;
    uint32_t n = *vertex_count;
    uint32_t *uses = calloc((size_t)n + 1, sizeof(uint32_t));
    if (!uses)
        return GDR_ERROR_OUT_OF_MEMORY;
    uint64_t extra = 0;
    for (uint32_t i = 0; i < index_count; i++)
        if (++uses[indices[i]] > GDR_IO_MAX_VERTEX_VALENCE && uses[indices[i]] % GDR_IO_MAX_VERTEX_VALENCE == 1)
            extra++;
    if (extra == 0 || (uint64_t)n + extra > UINT32_MAX) {
        free(uses);
        return GDR_OK; /* nothing to split (or no room: left as it is) */
    }
    uint32_t grown = n + (uint32_t)extra;
    uint32_t *sources = malloc(sizeof(uint32_t) * extra), *copy = calloc((size_t)n + 1, sizeof(uint32_t));
    if (!sources || !copy) {
        free(uses), free(sources), free(copy);
        return GDR_ERROR_OUT_OF_MEMORY;
    }
    /* The k-th block of GDR_IO_MAX_VERTEX_VALENCE uses of a vertex goes to its k-th copy. */
    memset(uses, 0, sizeof(uint32_t) * n);
    uint32_t next = n;
    for (uint32_t i = 0; i < index_count; i++) {
        uint32_t v = indices[i];
        if (uses[v]++ % GDR_IO_MAX_VERTEX_VALENCE == 0 && uses[v] > 1) {
            sources[next - n] = v;
            copy[v] = next++;
        }
        if (uses[v] > GDR_IO_MAX_VERTEX_VALENCE)
            indices[i] = copy[v];
    }
    gdr_vec3 *p = extend(*positions, sizeof(gdr_vec3), n, grown, sources);
    if (p)
        *positions = p;
    gdr_vec3 *nn = *normals ? extend(*normals, sizeof(gdr_vec3), n, grown, sources) : NULL;
    if (nn)
        *normals = nn;
    gdr_vec2 *t = *uvs ? extend(*uvs, sizeof(gdr_vec2), n, grown, sources) : NULL;
    if (t)
        *uvs = t;
    gdr_vec4 *col = *colors ? extend(*colors, sizeof(gdr_vec4), n, grown, sources) : NULL;
    if (col)
        *colors = col;
    free(uses), free(sources), free(copy);
    if (!p || (*normals && !nn) || (*uvs && !t) || (*colors && !col))
        return GDR_ERROR_OUT_OF_MEMORY;
    *vertex_count = grown;
    *added = (uint32_t)extra;
    return GDR_OK;
}

gdr_status gdr_io_clean_unclustered_meshes(gdr_scene *scene, const char *name, gdr_error *err)
{
    for (uint32_t i = 0; i < scene->mesh_count; i++) {
        gdr_mesh *m = &scene->meshes[i];
        if (m->clusters.cluster_count || m->index_count == 0)
            continue;
        uint32_t degenerate, duplicate, added;
        gdr_status status = gdr_io_drop_bad_triangles(m->positions, m->vertex_count, m->indices, &m->index_count,
                                                      &degenerate, &duplicate);
        if (status == GDR_OK)
            status = gdr_io_split_shared_vertices(&m->positions, &m->normals, &m->uvs, &m->colors, &m->vertex_count, m->indices,
                                                  m->index_count, &added);
        if (status != GDR_OK)
            return gdr_error_set(err, status, "%s: mesh %u: out of memory", name, i);
    }
    return GDR_OK;
}
