/* The public API of a library built without the culling module, as an application sees it:
 * test_optional_modules.sh compiles this against the installed headers of that build (where
 * gdr/cull.h is missing) and runs it. It checks what docs/ARCHITECTURE.md ("Optional modules")
 * promises: gdr/config.h says 0, frames asking for the CPU pipeline or the PVS fail with
 * GDR_ERROR_UNSUPPORTED and the message, gdr_renderer_set_pvs takes NULL only, a default frame
 * renders, and (given a cache written with a PVS) gdr_scene_load reads it and returns no PVS, and
 * gdr_cache_write refuses to write one.
 *   usage: lean_api WORK_DIR [CACHE_WITH_PVS.gdrc]      exit 0: every check passed */
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <gdr/gdr.h>

#define WITHOUT_CULL "built without the culling module (GDR_EXCLUDE_MODULES)"

static int failures;

static void check(int ok, const char *what)
{
    if (!ok) {
        fprintf(stderr, "FAIL: %s\n", what);
        failures++;
    }
}

/* The call failed with GDR_ERROR_UNSUPPORTED and the message naming the missing module. */
static void check_unsupported(gdr_status status, const gdr_error *err, const char *what)
{
    check(status == GDR_ERROR_UNSUPPORTED, what);
    if (!strstr(err->message, WITHOUT_CULL)) {
        fprintf(stderr, "FAIL: %s: message '%s'\n", what, err->message);
        failures++;
    }
}

static void check_frames(gdr_renderer *renderer, const gdr_camera *camera)
{
    static char elsewhere; /* a pointer this build cannot have made a PVS from */
    const gdr_pvs *foreign = (const gdr_pvs *)(const void *)&elsewhere;
    gdr_error err = {0};
    gdr_frame_stats stats;
    gdr_frame_desc cpu = {.camera = *camera, .pipeline = GDR_PIPELINE_CPU};
    check_unsupported(gdr_renderer_render(renderer, &cpu, 1, &stats, &err), &err, "the CPU pipeline");
    gdr_frame_desc pvs_on = {.camera = *camera, .pvs = GDR_CULL_ON};
    check_unsupported(gdr_renderer_render(renderer, &pvs_on, 1, &stats, &err), &err, "a frame with the PVS on");
    check_unsupported(gdr_renderer_set_pvs(renderer, foreign, &err), &err, "set_pvs with a PVS");
    check(gdr_renderer_set_pvs(renderer, NULL, &err) == GDR_OK, "set_pvs(NULL)");
    gdr_frame_desc plain = {.camera = *camera};
    gdr_status status = gdr_renderer_render(renderer, &plain, 1, &stats, &err);
    check(status == GDR_OK, err.message);
    check(status != GDR_OK || (stats.instances_visible > 0 && !stats.pvs.enabled && stats.pvs.cells == 0),
          "a default frame draws, without a PVS");
    check(stats.validation_messages == 0, "validation messages");
}

static void check_cache(const char *work, const char *path)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    static char elsewhere;
    gdr_pvs *pvs = (gdr_pvs *)(void *)&elsewhere; /* must be overwritten */
    gdr_load_options options = {.pvs = &pvs};
    check(gdr_scene_load(path, &options, &scene, &err) == GDR_OK, err.message);
    check(pvs == NULL, "a cache with a PVS returned one");
    if (!scene)
        return;
    char out[4096];
    snprintf(out, sizeof out, "%s/lean_api.gdrc", work);
    gdr_cache_write_options write = {.pvs = (const gdr_pvs *)(const void *)&elsewhere};
    check_unsupported(gdr_cache_write(out, scene, &write, &err), &err, "writing a cache with a PVS");
    check(access(out, F_OK) != 0, "a refused cache was written");
    gdr_scene_destroy(scene);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: lean_api WORK_DIR [CACHE_WITH_PVS.gdrc]\n");
        return 2;
    }
    check(!GDR_HAVE_CULL && !GDR_HAVE_PRESENT, "gdr/config.h says a module is in");
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_renderer *renderer = NULL;
    gdr_renderer_desc desc = {.width = 96, .height = 64, .validate = true};
    if (gdr_scene_load("demo:instances=10", NULL, &scene, &err) != GDR_OK ||
        gdr_renderer_create(&desc, &renderer, &err) != GDR_OK || gdr_renderer_set_scene(renderer, scene, &err) != GDR_OK) {
        fprintf(stderr, "FAIL: %s\n", err.message);
        failures++;
    } else {
        check_frames(renderer, &scene->cameras[0]);
    }
    gdr_renderer_destroy(renderer);
    gdr_scene_destroy(scene);
    if (argc > 2)
        check_cache(argv[1], argv[2]);
    if (failures) {
        fprintf(stderr, "lean_api: %d check(s) failed\n", failures);
        return 1;
    }
    printf("lean_api: all checks passed\n");
    return 0;
}
