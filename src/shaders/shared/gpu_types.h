/* Every struct the GPU reads or writes, declared once for C and GLSL (scalar block layout).
 * The C side checks sizes and offsets in src/render/gpu_types_check.c. */
#ifndef GDR_GPU_TYPES_H
#define GDR_GPU_TYPES_H

#include "glsl_c_bridge.h"
#include "gpu_config.h"

/* One vertex of the geometry pool (vertex input binding 0). */
GDR_STRUCT_BEGIN(GdrGpuVertex)
    gdr_vec3 position;
    gdr_vec3 normal;
    gdr_vec2 uv;
GDR_STRUCT_END(GdrGpuVertex)

/* Where a mesh lives in the merged vertex and index buffers, and its bounds (seed 003, plan A). */
GDR_STRUCT_BEGIN(GdrGpuMesh)
    gdr_uint vertex_offset;
    gdr_uint first_index;
    gdr_uint index_count;
    gdr_uint reserved;
    gdr_vec4 bounds; /* mesh-space sphere: centre xyz, radius w */
GDR_STRUCT_END(GdrGpuMesh)

/* One instance of the persistent instance buffer. */
GDR_STRUCT_BEGIN(GdrGpuInstance)
    gdr_mat4 model;
    gdr_vec4 color;
    gdr_uint mesh;
    gdr_uint flags;
    gdr_uint reserved0;
    gdr_uint reserved1;
GDR_STRUCT_END(GdrGpuInstance)

/* A fixed-size "tag + data" record of the per-frame instance ring (seed 000). */
#define GDR_UPDATE_TAG_INSTANCE 1u /* replace instance `index` with `instance` */
GDR_STRUCT_BEGIN(GdrGpuInstanceUpdate)
    gdr_uint tag;
    gdr_uint index;
    gdr_uint reserved0;
    gdr_uint reserved1;
    GdrGpuInstance instance;
GDR_STRUCT_END(GdrGpuInstanceUpdate)

/* VkDrawIndexedIndirectCommand, written by the cull pass. first_instance carries the instance index. */
GDR_STRUCT_BEGIN(GdrGpuDrawCommand)
    gdr_uint index_count;
    gdr_uint instance_count;
    gdr_uint first_index;
    gdr_int vertex_offset;
    gdr_uint first_instance;
GDR_STRUCT_END(GdrGpuDrawCommand)

/* Counters of the cull pass; draw_count (offset 0) is the count for vkCmdDrawIndexedIndirectCount. */
GDR_STRUCT_BEGIN(GdrGpuDrawStats)
    gdr_uint draw_count;
    gdr_uint triangles_low;  /* 64-bit triangle count as two words: the carry is added by the */
    gdr_uint triangles_high; /* thread whose add wrapped the low word                          */
    gdr_uint reserved;
GDR_STRUCT_END(GdrGpuDrawStats)

/* Per-frame constants, written by the CPU into its frame's slot. */
GDR_STRUCT_BEGIN(GdrGpuFrameGlobals)
    gdr_mat4 view;
    gdr_mat4 view_projection;
    gdr_vec4 frustum;         /* symmetric (i, j, k, l) */
    gdr_vec4 camera_position; /* world space, w unused */
    gdr_vec4 light_direction; /* world space, towards the light */
    float znear;
    float zfar;               /* +inf for the infinite projection */
    gdr_uint instance_count;
    gdr_uint cull_enabled;
    gdr_uint update_count;    /* records in this frame's ring slot */
    gdr_uint reserved0;
    gdr_uint reserved1;
    gdr_uint reserved2;
GDR_STRUCT_END(GdrGpuFrameGlobals)

/* Push constants of every pass: device addresses of the buffers it uses. */
GDR_STRUCT_BEGIN(GdrGpuPushConstants)
    gdr_uint64 globals;    /* GdrGpuFrameGlobals */
    gdr_uint64 instances;  /* GdrGpuInstance[] */
    gdr_uint64 meshes;     /* GdrGpuMesh[] */
    gdr_uint64 draws;      /* GdrGpuDrawCommand[] */
    gdr_uint64 draw_stats; /* GdrGpuDrawStats */
    gdr_uint64 updates;    /* GdrGpuInstanceUpdate[] of this frame's ring slot */
GDR_STRUCT_END(GdrGpuPushConstants)

#endif
