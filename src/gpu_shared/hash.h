/* A well-spread 32-bit hash (multiply-xorshift rounds), for C and GLSL alike: the built-in scenes'
 * stateless randomness and the debug views' colours. */
#ifndef GDR_HASH_H
#define GDR_HASH_H

#include "math/glsl_c_bridge.h"

GDR_SHARED_FN gdr_uint gdr_hash(gdr_uint x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

#endif
