/* The integer form of a quantized vertex (gdr_vertex_quantization, gdr/geometry.h), shared by the
 * quantization of a scene (vertex_quantize.c) and the cache's pages (io/cache_pages.c): a page
 * stores these integers and decodes them with the same functions that moved the mesh's vertices,
 * so a decoded vertex equals the mesh's, bit for bit. */
#ifndef GDR_GEOMETRY_VERTEX_QUANTIZE_H
#define GDR_GEOMETRY_VERTEX_QUANTIZE_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "gdr/geometry.h"

/* 20 bytes (meshoptimizer's vertex codec takes a multiple of 4): position, octahedral normal, a
 * zero pad, uv. */
typedef struct gdr_quantized_vertex {
    uint16_t position[3];
    int16_t normal[2]; /* octahedral, each in [-511, 511] */
    uint16_t pad;
    uint32_t uv[2];
} gdr_quantized_vertex;

/* The vertex as integers on the grid of q. Returns 0 when it does not lie within the grid's range
 * or does not decode back to exactly these floats (then the page stores floats). */
int gdr_vertex_encode(const gdr_vertex_quantization *q, gdr_vec3 position, gdr_vec3 normal, gdr_vec2 uv,
                      gdr_quantized_vertex *out);

/* A vertex as a page decodes it and the renderer reads it: position, normal, uv (32 bytes). */
typedef struct gdr_vertex_bytes {
    gdr_vec3 position, normal;
    gdr_vec2 uv;
} gdr_vertex_bytes;

/* The first 8 bytes of a vertex as a big-endian integer: two vertices whose keys differ compare
 * (memcmp) as their keys do, and only equal keys need the whole memcmp. Distinct vertices nearly
 * always differ in these bytes (position x and y, each float's low byte first as memcmp reads it). */
static inline uint64_t gdr_vertex_bytes_key(const gdr_vertex_bytes *v)
{
    uint8_t b[8];
    memcpy(b, v, sizeof b);
    /* gcc and clang turn this into one load and a byte swap. */
    return (uint64_t)b[0] << 56 | (uint64_t)b[1] << 48 | (uint64_t)b[2] << 40 | (uint64_t)b[3] << 32 |
           (uint64_t)b[4] << 24 | (uint64_t)b[5] << 16 | (uint64_t)b[6] << 8 | (uint64_t)b[7];
}

/* The corner (0, 1 or 2) a triangle starts with in its canonical rotation: the one whose vertex
 * bytes compare lowest (memcmp), the earliest on a tie. The pages' index codec may rotate a
 * triangle's corners; a quantized mesh's triangles are stored in this rotation and a page's are
 * put back into it when decoded, so both draw the same corners in the same order (the rasteriser's
 * interpolation depends on it). `key`: the corners' gdr_vertex_bytes_key, worked out once per
 * vertex where vertices are shared by many triangles. */
static inline uint32_t gdr_triangle_first_corner_keyed(const gdr_vertex_bytes *const corner[3], const uint64_t key[3])
{
    uint32_t first = 0;
    for (uint32_t k = 1; k < 3; k++)
        if (key[k] != key[first] ? key[k] < key[first] : memcmp(corner[k], corner[first], sizeof **corner) < 0)
            first = k;
    return first;
}

static inline uint32_t gdr_triangle_first_corner(const gdr_vertex_bytes *a, const gdr_vertex_bytes *b,
                                                 const gdr_vertex_bytes *c)
{
    const gdr_vertex_bytes *corner[3] = {a, b, c};
    uint64_t key[3] = {gdr_vertex_bytes_key(a), gdr_vertex_bytes_key(b), gdr_vertex_bytes_key(c)};
    return gdr_triangle_first_corner_keyed(corner, key);
}

/* The floats of an encoded vertex. Any integers decode to a unit normal; positions and uvs are
 * finite where the grid's are (gdr_vertex_grid_finite). */
void gdr_vertex_decode(const gdr_vertex_quantization *q, const gdr_quantized_vertex *v, gdr_vec3 *position,
                       gdr_vec3 *normal, gdr_vec2 *uv);

/* `count` vertices as gdr_vertex_decode gives them, bit for bit, with the grid's steps worked out
 * once (a page's vertices). */
void gdr_vertex_decode_many(const gdr_vertex_quantization *q, const gdr_quantized_vertex *in, size_t count,
                            gdr_vertex_bytes *out);

/* Whether every vertex that can be stored on grid q decodes to finite floats: those of the smallest
 * and the largest stored integers are (decoding is monotonic in each integer; normals are always
 * finite). A reader then needs no check of each decoded vertex. */
int gdr_vertex_grid_finite(const gdr_vertex_quantization *q);

#endif
