/* The options of gdr render, shared by gdr view: the scene, the camera and the frame description. */
#ifndef GDR_RENDER_OPTIONS_H
#define GDR_RENDER_OPTIONS_H

#include <stdbool.h>
#include <stdint.h>

#include "gdr/gdr.h"
#include "cli_warnings.h"

typedef struct render_options {
    const char *scene;
    const char *out_png;
    const char *stats_json;
    uint32_t width, height, frames, camera_index;
    bool has_camera, has_camera_index, cull, validate;
    bool meshlet_cull, cone_cull, triangle_cull, occlusion, occlusion_given, lod_hierarchy, point_level;
    gdr_pipeline pipeline;
    gdr_cull_mode pvs;     /* --pvs on|off; DEFAULT when not given */
    gdr_raster raster;
    float sw_threshold;
    gdr_view view;
    float lod_error;
    bool has_lod_depth;
    uint32_t lod_depth;
    gdr_vec3 camera_position;
    gdr_quat camera_rotation;
    float min_screen_size;
    gdr_vec4 clip_plane;
    const char *device;
    const char *camera_path; /* --camera-path FILE: one pose per frame (docs/VIEWER.md) */
    bool frames_given;
    uint32_t settle_frames; /* --settle N: with a camera path, each pose drawn until streaming settles */
    uint32_t warm_up_frames; /* --warm-up N: frames at the first pose before those measured */
    uint32_t geometry_budget_mib, upload_budget_mib; /* streaming (docs/STREAMING.md): 0 unless given */
    gdr_load_options load;   /* its warning sink is `warnings`, its report `report` */
    cli_warnings warnings;   /* counted; --strict makes them errors (exit GDR_EXIT_STRICT) */
    gdr_import_report report; /* the import's, for --camera-index; freed with gdr_import_report_free */
    char paged_cache[4096]; /* streaming: the paged cache the scene was read from */
} render_options;

/* Another command's own option at argv[*i]: returns 1 when it took it (advancing *i past a value),
 * 0 when it does not know it, -1 after printing why its value is bad. */
typedef int (*render_extra_option)(void *context, int argc, char **argv, int *i);

/* Parses `gdr COMMAND` arguments into *o; returns 0, or 2 after printing what is wrong. */
int render_options_parse(const char *command, int argc, char **argv, render_options *o, render_extra_option extra,
                         void *context);
/* The scene's camera (--camera-index, or one framing the scene), with --camera's pose. */
gdr_camera render_options_camera(const gdr_scene *scene, const render_options *o);
/* Streaming (docs/STREAMING.md): whether a budget was given. */
bool render_options_streamed(const render_options *o);
/* The scene the options name; streamed, read from its paged cache (built in the cache folder where
 * a source file or built-in scene has no fresh one), its path kept in o->paged_cache. */
gdr_status render_options_load(render_options *o, gdr_scene **scene, gdr_error *err);
/* The scene into the renderer: uploaded whole, or streamed from o->paged_cache (opened into *paged,
 * closed by the caller after the renderer). */
gdr_status render_options_set_scene(gdr_renderer *renderer, const gdr_scene *scene, const render_options *o,
                                    gdr_paged_cache **paged, gdr_error *err);
/* The frame description the options ask for, seen from `camera`. */
gdr_frame_desc render_options_frame(const render_options *o, gdr_camera camera);

#endif
