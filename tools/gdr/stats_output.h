/* Frame statistics printed for people and written as JSON for programs. */
#ifndef GDR_STATS_OUTPUT_H
#define GDR_STATS_OUTPUT_H

#include <stdio.h>

#include "gdr/renderer.h"

/* One frame along a camera path (gdr render --camera-path): what a plot along the path needs. */
typedef struct stats_path_frame {
    double gpu_ms;
    double cpu_ms;                     /* the renderer's recording and submission of the frame */
    double wall_ms;                    /* the pose's whole time on the host, settling frames included */
    uint64_t triangles;
    float lod_error_px;                /* streamed: the threshold drawn with */
    uint32_t wanted_pages, resident_pages, uploads, evictions, requests;
    gdr_pass_timing passes[GDR_MAX_PASSES]; /* the frame's passes on the GPU */
    uint32_t pass_count;
} stats_path_frame;

typedef struct stats_context {
    const char *scene;
    uint32_t width, height;
    const char *cull;
    const char *view;
    const stats_path_frame *path;      /* the JSON's "path": a row per frame (NULL: none) */
    uint32_t path_count;
} stats_context;

/* The figures of the frame just rendered, as a row of the path. */
stats_path_frame stats_path_row(const gdr_frame_stats *stats);

void stats_print(FILE *out, const stats_context *context, const gdr_frame_stats *stats);
typedef struct cJSON cJSON;
/* Adds the mesh pipeline's cluster and triangle counts (meshlets_*, triangles_*_culled). */
/* The occlusion-culling statistics of a frame (per phase) into a JSON object. */
void stats_add_traversal_json(cJSON *object, const gdr_frame_stats *s);
void stats_add_memory_json(cJSON *object, const gdr_frame_stats *s);
/* Streaming's figures (docs/STREAMING.md), where the scene streams. */
void stats_print_streaming(FILE *out, const gdr_streaming_stats *streaming);
void stats_add_occlusion_json(cJSON *object, const gdr_frame_stats *s);
void stats_add_meshlet_json(cJSON *object, const gdr_frame_stats *stats);
/* Returns a malloc'ed JSON text, or NULL when out of memory. */
char *stats_to_json(const stats_context *context, const gdr_frame_stats *stats);

#endif
