/* The integer form of a quantized vertex (gdr_vertex_quantization, gdr/geometry.h), shared by the
 * quantization of a scene (vertex_quantize.c) and the cache's pages (io/cache_pages.c): a page
 * stores these integers and decodes them with the same functions that moved the mesh's vertices,
 * so a decoded vertex equals the mesh's, bit for bit. */
#ifndef GDR_GEOMETRY_VERTEX_QUANTIZE_H
#define GDR_GEOMETRY_VERTEX_QUANTIZE_H

#include <stdint.h>

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

/* The floats of an encoded vertex. Any integers decode to finite floats and a unit normal. */
void gdr_vertex_decode(const gdr_vertex_quantization *q, const gdr_quantized_vertex *v, gdr_vec3 *position,
                       gdr_vec3 *normal, gdr_vec2 *uv);

#endif
