/* Stateless hashing for the built-in scenes: object i's properties come from (seed, i, channel)
 * alone, so they never depend on how many objects come before it or on the order of the calls. */
#ifndef GDR_SCENE_RANDOM_H
#define GDR_SCENE_RANDOM_H

#include <math.h>
#include <stdint.h>

#include "gdr/math.h"
#include "gpu_shared/hash.h"

/* A number in [0, 1) for object `index`, property `channel` (below 8). */
static inline float gdr_hash_unit(uint32_t seed, uint32_t index, uint32_t channel)
{
    return (float)(gdr_hash(seed * 0x9E3779B9U ^ gdr_hash(index * 8U + channel)) >> 8) / 16777216.0f;
}

/* A saturated colour of the given hue in [0, 1), lifted so that shading stays readable. */
static inline gdr_vec4 gdr_hue_color(float hue)
{
    float r = fabsf(hue * 6.0f - 3.0f) - 1.0f;
    float g = 2.0f - fabsf(hue * 6.0f - 2.0f);
    float b = 2.0f - fabsf(hue * 6.0f - 4.0f);
    r = fminf(fmaxf(r, 0.0f), 1.0f);
    g = fminf(fmaxf(g, 0.0f), 1.0f);
    b = fminf(fmaxf(b, 0.0f), 1.0f);
    return (gdr_vec4){0.25f + 0.7f * r, 0.25f + 0.7f * g, 0.25f + 0.7f * b, 1.0f};
}

#endif
