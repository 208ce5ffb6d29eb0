#include <math.h>

#include "gdr/math.h"

gdr_vec3 gdr_vec3_make(float x, float y, float z) { return (gdr_vec3){x, y, z}; }
gdr_vec3 gdr_vec3_add(gdr_vec3 a, gdr_vec3 b) { return (gdr_vec3){a.x + b.x, a.y + b.y, a.z + b.z}; }
gdr_vec3 gdr_vec3_sub(gdr_vec3 a, gdr_vec3 b) { return (gdr_vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
gdr_vec3 gdr_vec3_scale(gdr_vec3 a, float s) { return (gdr_vec3){a.x * s, a.y * s, a.z * s}; }
float gdr_vec3_dot(gdr_vec3 a, gdr_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

gdr_vec3 gdr_vec3_cross(gdr_vec3 a, gdr_vec3 b)
{
    return (gdr_vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

float gdr_vec3_length(gdr_vec3 a) { return sqrtf(gdr_vec3_dot(a, a)); }

gdr_vec3 gdr_vec3_normalize(gdr_vec3 a)
{
    float length = gdr_vec3_length(a);
    return length > 0.0f ? gdr_vec3_scale(a, 1.0f / length) : a;
}
