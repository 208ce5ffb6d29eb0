/* Lets one header be compiled by both C and GLSL (glslc -DGDR_GLSL=1).
 * Shared code uses only component access (v.x) and scalar arithmetic, plus the names below. */
#ifndef GDR_GLSL_C_BRIDGE_H
#define GDR_GLSL_C_BRIDGE_H

#ifdef GDR_GLSL
#define GDR_SHARED_FN
#define gdr_vec2 vec2
#define gdr_vec3 vec3
#define gdr_vec4 vec4
#define gdr_mat4 mat4
#define gdr_uint uint
#define gdr_int int
#define gdr_uint64 uint64_t
#define GDR_STRUCT_BEGIN(name) struct name {
#define GDR_STRUCT_END(name) };
#define gdr_abs abs
#define gdr_max max
#define gdr_sqrt sqrt
#else
#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#include "gdr/math.h"
#define GDR_SHARED_FN static inline
typedef uint32_t gdr_uint;
typedef int32_t gdr_int;
typedef uint64_t gdr_uint64;
#define GDR_STRUCT_BEGIN(name) typedef struct name {
#define GDR_STRUCT_END(name) } name;
#define gdr_abs fabsf
#define gdr_max fmaxf
#define gdr_sqrt sqrtf
#endif

#endif
