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
/* A typed GPU reference: in GLSL a buffer_reference type (declared with GDR_DECLARE_REF before
 * the structs that hold it, defined in glsl_buffers.h), in C its 64-bit device address. */
#define GDR_REF(reference_type) reference_type
#define GDR_DECLARE_REF(reference_type) layout(buffer_reference) buffer reference_type;
/* Layout checks are C's: GLSL ignores them. */
#define GDR_ASSERT_SIZE(type, size)
#define GDR_ASSERT_OFFSET(type, field, offset)
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
#include <stddef.h>
#define GDR_REF(reference_type) uint64_t
#define GDR_DECLARE_REF(reference_type)
/* The scalar block layout GLSL uses, checked where each struct is declared. */
#define GDR_ASSERT_SIZE(type, size) _Static_assert(sizeof(type) == (size), #type ": size")
#define GDR_ASSERT_OFFSET(type, field, offset) \
    _Static_assert(offsetof(type, field) == (offset), #type "." #field ": offset")
#endif

#endif
