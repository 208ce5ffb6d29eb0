/* Source files -> scenes, through the processed-scene cache when allowed. */
#define _XOPEN_SOURCE 700 /* realpath */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gdr/io.h"
#include "gdr/geometry.h"
#include "io/cache_pvs.h"
#include "io/io_internal.h"
#include "io/loaders.h"

/* Builds the clusters of every mesh that has none (all of them after an import; none, normally,
 * after a cache read) and, with `lod` (imports: what the cache then stores), the LOD DAG of every
 * mesh that has none; on failure destroys the scene. */
static gdr_status build_clusters(const char *path, gdr_scene **scene, int lod, int no_progress, gdr_error *err)
{
    gdr_error build_err;
    gdr_lod_options lod_options = {.no_progress = no_progress};
    if ((lod ? gdr_scene_build_lod(*scene, &lod_options, NULL, &build_err)
             : gdr_scene_build_clusters(*scene, NULL, &build_err)) == GDR_OK)
        return GDR_OK;
    gdr_scene_destroy(*scene);
    *scene = NULL;
    return gdr_error_set(err, build_err.status, "%s: %s", path, build_err.message);
}

/* Stores the textures in block formats (the same for a render through the cache or without it);
 * on failure destroys the scene. */
static gdr_status compress_textures(const char *path, gdr_scene **scene, gdr_error *err)
{
    gdr_error compress_err;
    if (gdr_scene_compress_textures(*scene, NULL, &compress_err) == GDR_OK)
        return GDR_OK;
    gdr_scene_destroy(*scene);
    *scene = NULL;
    return gdr_error_set(err, compress_err.status, "%s: %s", path, compress_err.message);
}

gdr_status gdr_import_file(const char *path, const gdr_import_options *options, gdr_scene **out,
                           gdr_import_result *result, gdr_error *err)
{
    gdr_status status;
    if (gdr_io_has_extension(path, ".gltf") || gdr_io_has_extension(path, ".glb")) {
        status = gdr_import_gltf(path, options, out, result, err);
    } else if (gdr_io_has_extension(path, ".obj")) {
        status = gdr_import_obj(path, options, out, result, err);
    } else {
        *out = NULL;
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: unknown file type (.gltf, .glb, .obj or .gdrc)", path);
    }
    if (status == GDR_OK)
        status = build_clusters(path, out, 1, options && options->no_progress, err);
    return status == GDR_OK ? compress_textures(path, out, err) : status;
}

/* $XDG_CACHE_HOME/gdr or ~/.cache/gdr, created when missing; 0 when there is none. */
static int fallback_cache_dir(char *out, size_t size)
{
    const char *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    char parent[PATH_MAX];
    if (xdg && xdg[0] == '/')
        snprintf(parent, sizeof parent, "%s", xdg);
    else if (home && home[0] == '/')
        snprintf(parent, sizeof parent, "%s/.cache", home);
    else
        return 0;
    mkdir(parent, 0755);
    int n = snprintf(out, size, "%s/gdr", parent);
    if (n <= 0 || (size_t)n >= size)
        return 0;
    return mkdir(out, 0755) == 0 || errno == EEXIST;
}

static void warn(const gdr_load_options *o, const char *format, ...) __attribute__((format(printf, 2, 3)));
static void warn(const gdr_load_options *o, const char *format, ...)
{
    char message[GDR_ERROR_MESSAGE_MAX + 128];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    if (o->warning)
        o->warning(o->warning_user, message);
    else
        fprintf(stderr, "gdr: warning: %s\n", message);
}

/* After a cache read: clusters for a cache that had none, and the PVS handed out (or freed). */
static gdr_status finish_cache_read(const char *path, gdr_scene **out, gdr_pvs *pvs, gdr_pvs **out_pvs,
                                    gdr_error *err)
{
    gdr_status status = gdr_io_clean_unclustered_meshes(*out, path, err);
    if (status != GDR_OK) {
        gdr_scene_destroy(*out);
        *out = NULL;
    } else {
        status = build_clusters(path, out, 0, 1, err);
    }
    if (status == GDR_OK && out_pvs)
        *out_pvs = pvs;
    else
        cache_pvs_destroy(pvs);
    return status;
}

gdr_status gdr_scene_load_file(const char *path, const gdr_load_options *options, gdr_scene **out, gdr_pvs **out_pvs,
                               gdr_error *err)
{
    static const gdr_load_options defaults = {0};
    if (!options)
        options = &defaults;
    *out = NULL;
    if (out_pvs)
        *out_pvs = NULL;
    const char *build_options = gdr_cache_build_options();
    gdr_pvs *pvs = NULL;
    if (options->geometry_in_pages) {
        if (!gdr_io_has_extension(path, ".gdrc"))
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: streaming reads a .gdrc cache with geometry "
                                 "pages (gdr build SCENE -o FILE.gdrc --pages), not a source file", path);
        return gdr_cache_read_for_streaming(path, build_options, out, out_pvs, NULL, err);
    }
    if (gdr_io_has_extension(path, ".gdrc")) {
        gdr_status status = gdr_cache_read(path, build_options, out, out_pvs ? &pvs : NULL, err);
        return status == GDR_OK ? finish_cache_read(path, out, pvs, out_pvs, err) : status;
    }
    gdr_import_options import = {.warning = options->warning, .warning_user = options->warning_user,
                                 .no_progress = options->no_progress, .budget = options->budget,
                                 .allow_outside_files = options->allow_outside_files};
    if (options->no_cache) {
        import.sources = options->sources;
        return gdr_import_file(path, &import, out, NULL, err);
    }

    /* Candidates: the given cache_dir, or next to the source then the per-user folder. */
    char candidates[2][PATH_MAX], fallback[PATH_MAX];
    int count = 0;
    if (options->cache_dir) {
        mkdir(options->cache_dir, 0755);
        count += gdr_cache_path_for(path, options->cache_dir, candidates[count], PATH_MAX) != 0;
    } else {
        count += gdr_cache_path_for(path, NULL, candidates[count], PATH_MAX) != 0;
        if (fallback_cache_dir(fallback, sizeof fallback))
            count += gdr_cache_path_for(path, fallback, candidates[count], PATH_MAX) != 0;
    }
    for (int i = 0; i < count; i++) {
        if (access(candidates[i], F_OK) != 0)
            continue;
        gdr_error cache_err;
        gdr_status read = gdr_io_cache_read_for(candidates[i], path, build_options, out, out_pvs ? &pvs : NULL,
                                                &cache_err);
        if (read == GDR_OK)
            return finish_cache_read(candidates[i], out, pvs, out_pvs, err);
        if (read != GDR_ERROR_STALE) /* a stale cache is rebuilt without a word; anything else is said */
            warn(options, "%s; rebuilding it", cache_err.message);
    }

    gdr_source_list sources = {0};
    import.sources = &sources;
    gdr_status status = gdr_import_file(path, &import, out, NULL, err);
    if (status == GDR_OK) {
        gdr_cache_write_options write = {.source = {build_options, &sources}};
        int written = 0;
        gdr_error write_err = {0};
        for (int i = 0; i < count && !written; i++)
            written = gdr_cache_write(candidates[i], *out, &write, &write_err) == GDR_OK;
        if (!written && count)
            warn(options, "cache not written: %s", write_err.message);
    }
    if (status == GDR_OK && options->sources) /* the caller's, as gdr_load_options.sources asks */
        *options->sources = sources;
    else
        gdr_source_list_free(&sources);
    return status;
}
