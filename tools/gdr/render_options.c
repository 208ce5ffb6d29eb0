/* The options of gdr render, shared by gdr view (render_options.h): parsing, and what they make of
 * a scene's camera and a frame description. */
#include <stdio.h>
#include <string.h>

#include "cli_args.h"
#include "render_options.h"

/* What an option at argv[i] did: taken, not one of this group's, or bad (printed why). */
typedef enum option_result { OPTION_TAKEN, OPTION_UNKNOWN, OPTION_BAD } option_result;

static option_result taken_if(bool ok) { return ok ? OPTION_TAKEN : OPTION_BAD; }

/* The switches without a value. */
static option_result parse_flag(render_options *o, const char *arg)
{
    if (strcmp(arg, "--validate") == 0)
        o->validate = true;
    else if (strcmp(arg, "--no-cache") == 0)
        o->load.no_cache = 1;
    else if (strcmp(arg, "--strict") == 0)
        o->warnings.strict = true;
    else if (strcmp(arg, "--allow-outside-files") == 0)
        o->load.allow_outside_files = 1;
    else
        return OPTION_UNKNOWN;
    return OPTION_TAKEN;
}

/* Outputs, frame counts, the target's size and the camera. */
static option_result parse_frame_option(render_options *o, const char *arg, const char *value)
{
    if (strcmp(arg, "--out") == 0 || strcmp(arg, "-o") == 0)
        o->out_png = value;
    else if (strcmp(arg, "--stats") == 0)
        o->stats_json = value;
    else if (strcmp(arg, "--width") == 0)
        return taken_if(cli_parse_u32(arg, value, 1, 16384, &o->width));
    else if (strcmp(arg, "--height") == 0)
        return taken_if(cli_parse_u32(arg, value, 1, 16384, &o->height));
    else if (strcmp(arg, "--frames") == 0)
        return taken_if(o->frames_given = cli_parse_u32(arg, value, 1, 100000, &o->frames));
    else if (strcmp(arg, "--camera-path") == 0)
        o->camera_path = value;
    else if (strcmp(arg, "--settle") == 0)
        return taken_if(cli_parse_u32(arg, value, 1, 100000, &o->settle_frames));
    else if (strcmp(arg, "--warm-up") == 0)
        return taken_if(cli_parse_u32(arg, value, 0, 100000, &o->warm_up_frames));
    else if (strcmp(arg, "--camera") == 0)
        return taken_if(o->has_camera = cli_parse_camera(arg, value, &o->camera_position, &o->camera_rotation));
    else if (strcmp(arg, "--camera-index") == 0)
        return taken_if(o->has_camera_index = cli_parse_u32(arg, value, 0, 1000000, &o->camera_index));
    else if (strcmp(arg, "--device") == 0)
        o->device = value;
    else
        return OPTION_UNKNOWN;
    return OPTION_TAKEN;
}

/* Culling at each level. */
static option_result parse_cull_option(render_options *o, const char *arg, const char *value)
{
    if (strcmp(arg, "--cull") == 0)
        return taken_if(cli_parse_on_off(arg, value, &o->cull));
    if (strcmp(arg, "--meshlet-cull") == 0)
        return taken_if(cli_parse_on_off(arg, value, &o->meshlet_cull));
    if (strcmp(arg, "--cone-cull") == 0)
        return taken_if(cli_parse_on_off(arg, value, &o->cone_cull));
    if (strcmp(arg, "--triangle-cull") == 0)
        return taken_if(cli_parse_on_off(arg, value, &o->triangle_cull));
    if (strcmp(arg, "--occlusion") == 0)
        return taken_if(o->occlusion_given = cli_parse_on_off(arg, value, &o->occlusion));
    if (strcmp(arg, "--pvs") == 0) {
        bool on = false;
        bool ok = cli_parse_on_off(arg, value, &on) && (!on || cli_needs_cull("--pvs on"));
        o->pvs = on ? GDR_CULL_ON : GDR_CULL_OFF;
        return taken_if(ok);
    }
    if (strcmp(arg, "--min-screen-size") == 0)
        return taken_if(cli_parse_float(arg, value, 0.0f, 1e6f, &o->min_screen_size));
    if (strcmp(arg, "--clip-plane") == 0) {
        if (cli_parse_floats(value, 4, &o->clip_plane.x))
            return OPTION_TAKEN;
        fprintf(stderr, "gdr: %s %s: expected 4 finite numbers a,b,c,d (the plane a x + b y + c z + d = 0)\n", arg,
                value);
        return OPTION_BAD;
    }
    return OPTION_UNKNOWN;
}

/* The pipeline, the rasteriser, the debug view and the LOD cut. */
static option_result parse_draw_option(render_options *o, const char *arg, const char *value)
{
    static const char *const view_names[] = {"shaded", "meshlets", "instances", "triangles", "overdraw", "lod"};
    if (strcmp(arg, "--pipeline") == 0)
        return taken_if(cli_parse_pipeline(arg, value, &o->pipeline));
    if (strcmp(arg, "--raster") == 0)
        return taken_if(cli_parse_raster(arg, value, &o->raster));
    if (strcmp(arg, "--sw-threshold") == 0)
        return taken_if(cli_parse_float(arg, value, 0.01f, 1e6f, &o->sw_threshold));
    if (strcmp(arg, "--view") == 0) {
        int view;
        bool ok = cli_parse_choice(arg, value, view_names, 6, &view);
        o->view = (gdr_view)view;
        return taken_if(ok);
    }
    if (strcmp(arg, "--lod-error") == 0)
        return taken_if(cli_parse_float(arg, value, 0.0f, 1e6f, &o->lod_error));
    if (strcmp(arg, "--lod-depth") == 0)
        return taken_if(o->has_lod_depth = cli_parse_u32(arg, value, 0, 64, &o->lod_depth));
    if (strcmp(arg, "--lod-hierarchy") == 0)
        return taken_if(cli_parse_on_off(arg, value, &o->lod_hierarchy));
    if (strcmp(arg, "--point-level") == 0)
        return taken_if(cli_parse_on_off(arg, value, &o->point_level));
    return OPTION_UNKNOWN;
}

/* Streaming, the loader's cache and its memory budget. */
static option_result parse_resource_option(render_options *o, const char *arg, const char *value)
{
    if (strcmp(arg, "--geometry-budget") == 0)
        return taken_if(
            cli_parse_u32(arg, value, 1, (uint32_t)(GDR_GEOMETRY_BUDGET_MAX >> 20), &o->geometry_budget_mib));
    if (strcmp(arg, "--upload-budget") == 0)
        return taken_if(cli_parse_u32(arg, value, 1, 4096, &o->upload_budget_mib));
    if (strcmp(arg, "--cache-dir") == 0) {
        o->load.cache_dir = value;
        return OPTION_TAKEN;
    }
    if (strcmp(arg, "--cache-max") == 0)
        return taken_if(cli_parse_cache_max(arg, value, &o->load.cache_max_bytes));
    if (strcmp(arg, "--budget") == 0)
        return taken_if(cli_parse_budget(arg, value, &o->load.budget));
    return OPTION_UNKNOWN;
}

/* An option that takes a value, the value taken from argv (advancing *i): each group in turn. */
static option_result parse_value_option(const char *command, render_options *o, int argc, char **argv, int *i)
{
    static const char *const known[] = {
        "--out", "-o", "--stats", "--width", "--height", "--frames", "--camera-path", "--settle", "--warm-up", "--camera",
        "--camera-index", "--cull", "--meshlet-cull", "--cone-cull", "--triangle-cull", "--occlusion",
        "--lod-hierarchy", "--point-level", "--pipeline", "--raster", "--sw-threshold", "--view", "--lod-error",
        "--min-screen-size", "--clip-plane", "--lod-depth", "--device", "--geometry-budget",
        "--upload-budget", "--cache-dir", "--cache-max", "--budget", "--pvs", NULL};
    const char *arg = argv[*i], *value = cli_known_value(command, known, argc, argv, i);
    if (!value)
        return OPTION_BAD;
    option_result r = parse_frame_option(o, arg, value);
    if (r == OPTION_UNKNOWN)
        r = parse_cull_option(o, arg, value);
    if (r == OPTION_UNKNOWN)
        r = parse_draw_option(o, arg, value);
    if (r == OPTION_UNKNOWN)
        r = parse_resource_option(o, arg, value);
    if (r == OPTION_UNKNOWN) {
        fprintf(stderr, "gdr %s: unknown option '%s' (see gdr --help)\n", command, arg);
        return OPTION_BAD;
    }
    return r;
}

static render_options default_options(void)
{
    return (render_options){.width = 1280, .height = 720, .frames = 1, .cull = true, .meshlet_cull = true,
                            .cone_cull = true, .triangle_cull = true, .lod_error = 1.0f, .occlusion = true,
                            .lod_hierarchy = true, .point_level = true};
}

int render_options_parse(const char *command, int argc, char **argv, render_options *o, render_extra_option extra,
                         void *context)
{
    *o = default_options();
    o->load.warning = cli_warning;
    o->load.warning_user = &o->warnings;
    o->load.report = &o->report;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (arg[0] != '-' || strcmp(arg, "-") == 0) {
            if (o->scene) {
                fprintf(stderr, "gdr %s: only one scene, got '%s' and '%s'\n", command, o->scene, arg);
                return 2;
            }
            o->scene = arg;
            continue;
        }
        if (parse_flag(o, arg) == OPTION_TAKEN)
            continue;
        int consumed = extra ? extra(context, argc, argv, &i) : 0;
        if (consumed < 0)
            return 2;
        if (consumed == 0 && parse_value_option(command, o, argc, argv, &i) == OPTION_BAD)
            return 2;
    }
    if (!o->scene) {
        fprintf(stderr, "gdr %s: which scene? e.g. 'gdr %s demo' (see gdr --help)\n", command, command);
        return 2;
    }
    return 0;
}

gdr_camera render_options_camera(const gdr_scene *scene, const render_options *o)
{
    gdr_camera camera = scene->camera_count > 0 ? scene->cameras[o->has_camera_index ? o->camera_index : 0]
                                                : gdr_scene_framing_camera(scene);
    if (o->has_camera) {
        camera.position = o->camera_position;
        camera.rotation = o->camera_rotation;
    }
    return camera;
}

gdr_frame_desc render_options_frame(const render_options *o, gdr_camera camera)
{
    return (gdr_frame_desc){.camera = camera, .cull = o->cull ? GDR_CULL_ON : GDR_CULL_OFF,
                            .read_back = o->out_png != NULL, .pipeline = o->pipeline, .view = o->view,
                            .raster = o->raster, .sw_threshold_px = o->sw_threshold,
                            .meshlet_frustum_cull = o->meshlet_cull ? GDR_CULL_ON : GDR_CULL_OFF,
                            .meshlet_cone_cull = o->cone_cull ? GDR_CULL_ON : GDR_CULL_OFF,
                            .triangle_cull = o->triangle_cull ? GDR_CULL_ON : GDR_CULL_OFF,
                            .lod_error_px = o->lod_error, .lod_fixed_depth = o->has_lod_depth, .lod_depth = o->lod_depth,
                            .occlusion = !o->occlusion_given ? GDR_CULL_DEFAULT
                                         : o->occlusion       ? GDR_CULL_ON
                                                             : GDR_CULL_OFF,
                            .lod_hierarchy = o->lod_hierarchy ? GDR_CULL_ON : GDR_CULL_OFF,
                            .point_level = o->point_level ? GDR_CULL_ON : GDR_CULL_OFF,
                            .min_screen_size = o->min_screen_size, .clip_plane = o->clip_plane, .pvs = o->pvs};
}
