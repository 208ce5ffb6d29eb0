/* gdr render SCENE: renders frames of a scene headless, writes a PNG and statistics. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli_args.h"
#include "commands.h"
#include "cli_pvs.h"
#include "gdr/gdr.h"
#include "gdr/io.h"
#include "camera_path.h"
#include "render_options.h"
#include "stats_output.h"


static int fail(const gdr_error *err)
{
    fprintf(stderr, "gdr: %s\n", err->message);
    return 1;
}

/* Whether a streamed frame left nothing to do: no page asked for, being read, waiting or copied. */
static bool streaming_settled(const gdr_frame_stats *stats)
{
    const gdr_streaming_stats *st = &stats->streaming;
    return st->requests == 0 && st->loads == 0 && st->uploads == 0 && st->pending == 0 && st->deferred == 0;
}

/* One pose: one frame, or with --settle N frames at the pose until streaming settles (at most N),
 * then one more, whose figures are the pose's (the converged frame at that pose). */
static gdr_status render_pose(gdr_renderer *renderer, gdr_frame_desc *frame, const render_options *o,
                              gdr_frame_stats *stats, gdr_error *err)
{
    gdr_status status = gdr_renderer_render(renderer, frame, 1, stats, err);
    for (uint32_t n = 0; o->settle_frames && n < o->settle_frames && status == GDR_OK && !streaming_settled(stats); n++)
        status = gdr_renderer_render(renderer, frame, 1, stats, err);
    if (o->settle_frames && status == GDR_OK)
        status = gdr_renderer_render(renderer, frame, 1, stats, err);
    return status;
}

static double monotonic_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec;
}

/* The frames asked for: o->frames of one view, or with a camera path (path->count > 0) one frame per
 * pose (the path repeated to make --frames N, N the path's length by default; with --settle, each
 * pose's settled frame), each frame's figures a row of *rows (malloc'ed; the JSON's "path"); the
 * statistics are the last call's. With --warm-up N, N frames at the first pose come before them, in
 * no row or statistic. */
static gdr_status render_frames(gdr_renderer *renderer, gdr_frame_desc *frame, const render_options *o,
                                const camera_path *path, gdr_frame_stats *stats, stats_path_frame **rows,
                                gdr_error *err)
{
    if (path->count) {
        frame->camera.position = path->poses[0].position;
        frame->camera.rotation = path->poses[0].rotation;
    }
    bool read_back = frame->read_back;
    frame->read_back = false;
    gdr_status status = o->warm_up_frames ? gdr_renderer_render(renderer, frame, o->warm_up_frames, NULL, err) : GDR_OK;
    frame->read_back = read_back;
    if (status != GDR_OK)
        return status;
    if (path->count == 0)
        return gdr_renderer_render(renderer, frame, o->frames, stats, err);
    uint32_t frames = o->frames_given ? o->frames : path->count;
    *rows = calloc(frames, sizeof **rows);
    if (!*rows)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "render: out of memory for %u frames' figures", frames);
    for (uint32_t f = 0; f < frames && status == GDR_OK; f++) {
        frame->camera.position = path->poses[f % path->count].position;
        frame->camera.rotation = path->poses[f % path->count].rotation;
        frame->read_back = read_back && f + 1 == frames;
        double start = monotonic_ms();
        status = render_pose(renderer, frame, o, stats, err);
        if (status == GDR_OK) {
            (*rows)[f] = stats_path_row(stats);
            (*rows)[f].wall_ms = monotonic_ms() - start;
        }
    }
    return status;
}

/* A streamed scene is read from its paged cache without the geometry the pages hold (a source file
 * or built-in scene gets one built first, in the cache folder). A file's cache may hold the scene's
 * precomputed visibility (*pvs, else NULL), streamed or not. */
static gdr_status load_scene(render_options *o, gdr_scene **scene, gdr_pvs **pvs, gdr_error *err)
{
    *pvs = NULL;
    o->load.pvs = pvs;
    return render_options_load(o, scene, err);
}

/* The scene the options name, checked against them: loaded, within --strict, holding the
 * precomputed visibility --pvs on needs and the camera --camera-index names. 0, or the exit status
 * after printing why. */
static int load_checked_scene(render_options *o, gdr_scene **scene, gdr_pvs **pvs, gdr_error *err)
{
    if (load_scene(o, scene, pvs, err) != GDR_OK)
        return cli_load_failed(o->scene, err);
    int strict = cli_strict_check(&o->warnings, o->scene);
    if (strict)
        return strict;
    if (o->pvs == GDR_CULL_ON && !*pvs) {
        fprintf(stderr, "gdr: --pvs on: %s holds no precomputed visibility (write it with gdr build %s -o FILE.gdrc "
                "--pvs)\n", o->scene, o->scene);
        return 2;
    }
    if (o->has_camera_index && o->camera_index >= (*scene)->camera_count)
        return cli_camera_index_refused("render", o->camera_index, *scene, &o->report);
    return 0;
}

/* The last frame's image (--out), the statistics printed and in --stats, and the validation
 * layer's verdict: 0, or the exit status. */
static int write_outputs(gdr_renderer *renderer, const render_options *o, const stats_context *context,
                         const gdr_frame_stats *stats, gdr_error *err)
{
    if (o->out_png) {
        uint8_t *pixels = malloc((size_t)o->width * o->height * 4);
        if (!pixels)
            return 1;
        gdr_status status = gdr_renderer_read_color(renderer, pixels, err);
        if (status == GDR_OK)
            status = gdr_write_png(o->out_png, pixels, o->width, o->height, err);
        free(pixels);
        if (status != GDR_OK)
            return fail(err);
    }
    stats_print(stdout, context, stats);
    if (o->out_png)
        printf("image               %s\n", o->out_png);
    int result = 0;
    if (o->stats_json) {
        char *json = stats_to_json(context, stats);
        if (!json || gdr_write_file_atomic(o->stats_json, json, strlen(json), err) != GDR_OK)
            result = json ? fail(err) : 1;
        free(json);
    }
    if (result == 0 && stats->validation_messages > 0) {
        fprintf(stderr, "gdr: the validation layer reported %u message(s)\n", stats->validation_messages);
        result = 3;
    }
    return result;
}

int gdr_cmd_render(int argc, char **argv)
{
    render_options o;
    int usage = render_options_parse("render", argc, argv, &o, NULL, NULL);
    if (usage)
        return usage;
    if (o.settle_frames && !o.camera_path) {
        fprintf(stderr, "gdr render: --settle needs --camera-path (it settles each pose of the path)\n");
        return 2;
    }
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_pvs *pvs = NULL;
    /* The camera path first: a bad one is reported before the scene is imported and uploaded. */
    camera_path path = {0};
    if (o.camera_path && camera_path_read(o.camera_path, &path, &err) != GDR_OK) {
        fprintf(stderr, "gdr: --camera-path: %s\n", err.message);
        return 1;
    }
    /* The renderer next: a device or target size the machine cannot give is a command-line value,
     * refused (exit 2) before the scene is loaded. */
    gdr_renderer_desc desc = {.width = o.width, .height = o.height, .device = o.device, .validate = o.validate,
                              .disable_texture_compression_bc = cli_bc_textures_disabled()};
    gdr_renderer *renderer = NULL;
    gdr_paged_cache *paged = NULL;
    gdr_frame_stats stats;
    stats_path_frame *rows = NULL;
    int result = 0;
    if (gdr_renderer_create(&desc, &renderer, &err) != GDR_OK)
        result = cli_renderer_failed(&err);
    else
        result = load_checked_scene(&o, &scene, &pvs, &err);
    if (result == 0) {
        gdr_frame_desc frame = render_options_frame(&o, render_options_camera(scene, &o));
        if (render_options_set_scene(renderer, scene, &o, &paged, &err) != GDR_OK ||
            gdr_renderer_set_pvs(renderer, pvs, &err) != GDR_OK ||
            render_frames(renderer, &frame, &o, &path, &stats, &rows, &err) != GDR_OK)
            result = fail(&err);
    }
    if (result == 0) {
        stats_context context = {o.scene, o.width, o.height, o.cull ? "on" : "off", gdr_view_name(o.view), rows,
                                 rows ? (o.frames_given ? o.frames : path.count) : 0};
        result = write_outputs(renderer, &o, &context, &stats, &err);
    }
    gdr_import_report_free(&o.report);
    camera_path_free(&path);
    free(rows);
    gdr_renderer_destroy(renderer);
    gdr_paged_cache_close(paged);
    cli_pvs_destroy(pvs);
    gdr_scene_destroy(scene);
    return result;
}
