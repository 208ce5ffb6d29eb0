/* Distances in double, for checking the DAG's float measurements by brute force. */
#ifndef GDR_TEST_POINT_DISTANCE_H
#define GDR_TEST_POINT_DISTANCE_H

#include <math.h>
#include <stdint.h>

#include "gdr/geometry.h"

typedef struct dvec3 {
    double x, y, z;
} dvec3;

static inline dvec3 d3(gdr_vec3 v) { return (dvec3){v.x, v.y, v.z}; }
static inline dvec3 d3_sub(dvec3 a, dvec3 b) { return (dvec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline double d3_dot(dvec3 a, dvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/* Distance from p to triangle abc, in double: the nearest of the plane's foot (when inside), the
 * three edges' nearest points. */
static inline double point_segment(dvec3 p, dvec3 a, dvec3 b)
{
    dvec3 ab = d3_sub(b, a), ap = d3_sub(p, a);
    double t = d3_dot(ab, ab) > 0 ? d3_dot(ap, ab) / d3_dot(ab, ab) : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    dvec3 d = d3_sub(ap, (dvec3){ab.x * t, ab.y * t, ab.z * t});
    return sqrt(d3_dot(d, d));
}

static inline double point_triangle(dvec3 p, dvec3 a, dvec3 b, dvec3 c)
{
    dvec3 u = d3_sub(b, a), v = d3_sub(c, a), w = d3_sub(p, a);
    dvec3 n = {u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
    double nn = d3_dot(n, n), best = point_segment(p, a, b);
    best = fmin(best, fmin(point_segment(p, b, c), point_segment(p, c, a)));
    if (nn > 0) {
        double uu = d3_dot(u, u), uv = d3_dot(u, v), vv = d3_dot(v, v), wu = d3_dot(w, u), wv = d3_dot(w, v);
        double den = uv * uv - uu * vv, s = (uv * wv - vv * wu) / den, t = (uv * wu - uu * wv) / den;
        if (s >= 0 && t >= 0 && s + t <= 1)
            best = fmin(best, fabs(d3_dot(w, n)) / sqrt(nn));
    }
    return best;
}

/* The length of the edge between positions a and b of a packed array (3 floats a position). */
static inline float packed_edge_length(const float *positions, uint32_t a, uint32_t b)
{
    float d[3];
    for (int k = 0; k < 3; k++)
        d[k] = positions[a * 3 + (uint32_t)k] - positions[b * 3 + (uint32_t)k];
    return sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

#endif
