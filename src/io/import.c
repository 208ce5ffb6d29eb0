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
#include "io/import_report.h"
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

/* Where the cache of `path` goes: next to it for ".", else in cache_dir or the per-user folder
 * (*dir, created and checked). 0: no cache (no folder to be had; said when there is a reason). */
static int cache_location(const char *path, const gdr_load_options *options, char *dir, char *cache)
{
    dir[0] = 0;
    if (options->cache_dir && strcmp(options->cache_dir, ".") == 0)
        return gdr_cache_path_for(path, NULL, cache, PATH_MAX) != 0;
    if (options->cache_dir)
        snprintf(dir, PATH_MAX, "%s", options->cache_dir);
    else if (!gdr_cache_default_dir(dir, PATH_MAX))
        return 0; /* no HOME or XDG_CACHE_HOME: nowhere to keep one */
    gdr_error dir_err;
    if (gdr_io_cache_dir_prepare(dir, &dir_err) != GDR_OK) {
        gdr_io_load_warn(options, "%s", dir_err.message);
        return 0;
    }
    return gdr_cache_path_for(path, dir, cache, PATH_MAX) != 0;
}

/* The cache of `path` at `cache`, when it is there and fresh: the scene, its PVS and report, the
 * warnings said again; 0 when it must be (re)built. */
static int read_cached(const char *path, const char *cache, const gdr_load_options *options, gdr_scene **out,
                       gdr_pvs **out_pvs, gdr_import_report *report, gdr_status *status, gdr_error *err)
{
    if (access(cache, F_OK) != 0)
        return 0;
    gdr_error cache_err;
    gdr_pvs *pvs = NULL;
    gdr_import_report cached = {0};
    gdr_status read = gdr_io_cache_read_for(cache, path, gdr_cache_build_options(), out, out_pvs ? &pvs : NULL,
                                            &cached, &cache_err);
    if (read != GDR_OK) {
        /* Stale: rebuilt without a word; gone meanwhile (another gdr evicted it): the same; else said. */
        if (read != GDR_ERROR_STALE && access(cache, F_OK) == 0)
            gdr_io_load_warn(options, "%s; rebuilding it", cache_err.message);
        return 0;
    }
    gdr_io_cache_touch(cache); /* used now: the last to be evicted */
    gdr_error ignored;
    gdr_io_report_untemplate(&cached, path, &ignored); /* out of memory: said with its markers */
    gdr_io_report_replay(&cached, options->warning, options->warning_user);
    *report = cached;
    report->cache_path = strdup(cache);
    report->cache_state = GDR_CACHE_READ;
    *status = finish_cache_read(cache, out, pvs, out_pvs, err);
    return 1;
}

/* A .gdrc given directly: read as it stands, its import's warnings said again. */
static gdr_status load_cache_file(const char *path, gdr_scene **out, gdr_pvs **out_pvs,
                                  const gdr_load_options *options, gdr_import_report *report, gdr_error *err)
{
    gdr_pvs *pvs = NULL;
    gdr_status status = gdr_io_cache_read_for(path, NULL, gdr_cache_build_options(), out, out_pvs ? &pvs : NULL,
                                              report, err);
    if (status != GDR_OK)
        return status;
    gdr_error ignored;
    gdr_io_report_untemplate(report, NULL, &ignored);
    gdr_io_report_replay(report, options->warning, options->warning_user);
    return finish_cache_read(path, out, pvs, out_pvs, err);
}

/* Writes the cache of a fresh import, then keeps its folder within the size limit. */
static void write_cache(const char *path, const char *cache, const char *dir, const gdr_scene *scene,
                        const gdr_source_list *sources, const gdr_load_options *options, gdr_import_report *report)
{
    gdr_import_report kept;
    gdr_error write_err = {0};
    int written = gdr_io_report_template(report, path, &kept, &write_err) == GDR_OK;
    gdr_cache_write_options write = {.source = {gdr_cache_build_options(), sources}, .report = &kept};
    written = written && gdr_cache_write(cache, scene, &write, &write_err) == GDR_OK;
    gdr_import_report_free(&kept);
    report->cache_path = strdup(cache);
    report->cache_state = written ? GDR_CACHE_WRITTEN : GDR_CACHE_NOT_WRITTEN;
    if (!written)
        gdr_io_load_warn(options, "cache not written: %s", write_err.message);
    else if (dir[0])
        gdr_io_cache_evict(dir, gdr_io_cache_limit(options->cache_max_bytes), cache);
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
    gdr_import_report local = {0}, *report = options->report ? options->report : &local;
    *report = (gdr_import_report){0};
    gdr_status status;
    if (options->geometry_in_pages && gdr_io_has_extension(path, ".gdrc")) {
        if (options->cache_path && options->cache_path_size &&
            snprintf(options->cache_path, options->cache_path_size, "%s", path) >= (int)options->cache_path_size)
            options->cache_path[0] = '\0';
        status = gdr_io_cache_read_for_streaming(path, NULL, gdr_cache_build_options(), out, out_pvs, report, NULL,
                                                 err);
        gdr_error ignored;
        if (status == GDR_OK) {
            gdr_io_report_untemplate(report, NULL, &ignored); /* out of memory: said with its markers */
            gdr_io_report_replay(report, options->warning, options->warning_user);
        }
        gdr_import_report_free(&local);
        return status;
    }
    if (options->geometry_in_pages && options->no_cache)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: streaming reads a cache with geometry pages, "
                             "which no_cache (--no-cache) forbids", path);
    if (gdr_io_has_extension(path, ".gdrc")) {
        status = load_cache_file(path, out, out_pvs, options, report, err);
        gdr_import_report_free(&local);
        return status;
    }
    gdr_io_report_collector collector = {options, report};
    gdr_import_options import = {.warning = gdr_io_report_collect, .warning_user = &collector,
                                 .no_progress = options->no_progress, .budget = options->budget,
                                 .allow_outside_files = options->allow_outside_files};
    gdr_import_result result = {0};
    char dir[PATH_MAX], cache[1][PATH_MAX];
    int cached = !options->no_cache && cache_location(path, options, dir, cache[0]);
    if (options->geometry_in_pages) {
        status = gdr_io_load_paged(path, options, cache, cached, out, out_pvs, report, err);
        gdr_import_report_free(&local);
        return status;
    }
    if (cached && read_cached(path, cache[0], options, out, out_pvs, report, &status, err)) {
        gdr_import_report_free(&local);
        return status;
    }
    gdr_source_list sources = {0};
    import.sources = &sources;
    status = gdr_import_file(path, &import, out, &result, err);
    report->file_cameras = result.file_cameras;
    if (status == GDR_OK && cached)
        write_cache(path, cache[0], dir, *out, &sources, options, report);
    if (status == GDR_OK && options->sources) /* the caller's, as gdr_load_options.sources asks */
        *options->sources = sources;
    else
        gdr_source_list_free(&sources);
    gdr_import_report_free(&local);
    return status;
}
