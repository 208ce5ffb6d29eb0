/* Streaming from a source file or a built-in scene (loaders.h, gdr_load_options.geometry_in_pages):
 * the scene is read for streaming from its paged cache, which is built first (imported or made,
 * quantized, written with pages: what gdr build --pages writes) where no fresh one is found. The
 * paged cache sits beside the loader's own cache for the source, as FILE.pages.gdrc, so that it
 * follows wherever the loader puts its caches and never replaces the cache of the whole scene. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/output_file.h"
#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "io/import_report.h"
#include "io/io_internal.h"
#include "io/loaders.h"

/* FILE.gdrc -> FILE.pages.gdrc; 0 when it does not fit. */
static int paged_name(const char *candidate, char *out, size_t size)
{
    size_t n = strlen(candidate);
    if (n < 5 || strcmp(candidate + n - 5, ".gdrc") != 0)
        return 0;
    int written = snprintf(out, size, "%.*s.pages.gdrc", (int)(n - 5), candidate);
    return written > 0 && (size_t)written < size;
}

/* The first of `paths` where a file can be written (made and removed again); -1 when none. */
static int writable_path(char (*paths)[PATH_MAX], int count, gdr_error *err)
{
    for (int i = 0; i < count; i++) {
        gdr_output_file probe;
        if (gdr_output_open(paths[i], &probe, err) == GDR_OK) {
            gdr_output_close(&probe, false, paths[i], &(gdr_error){0});
            return i;
        }
    }
    return -1;
}

/* Builds the scene and writes it, mesh by mesh (paged_build.c), to the first of `paths` that takes
 * it; its index, or -1. */
static int write_paged(const char *spec, const gdr_load_options *o, bool builtin, const char *build_options,
                       char (*paths)[PATH_MAX], int count, gdr_error *err)
{
    gdr_source_list sources = {0};
    gdr_import_report report = {0}, kept = {0};
    gdr_error write_err = {0};
    int written = writable_path(paths, count, &write_err);
    if (written < 0) {
        gdr_error_set(err, GDR_ERROR_IO, "%s: streaming needs its paged cache, which could not be written: %s",
                      spec, count ? write_err.message : "no cache folder (give one: --cache-dir DIR)");
        return -1;
    }
    gdr_io_paged_source src;
    gdr_status status = gdr_io_paged_source_open(spec, o, builtin, &src, &sources, &report, err);
    if (status == GDR_OK)
        status = gdr_io_report_template(&report, spec, &kept, err);
    if (status == GDR_OK) {
        gdr_cache_write_options write = {.source = {build_options, &sources}, .page_bytes = GDR_PAGE_BYTES_DEFAULT,
                                         .report = &kept};
        if (gdr_io_paged_source_write(&src, paths[written], &write, 0, o->no_progress, &write_err) != GDR_OK)
            status = gdr_error_set(err, write_err.status, "%s: streaming needs its paged cache, which could not be "
                                   "written: %s", spec, write_err.message);
    }
    gdr_io_paged_source_close(&src);
    gdr_source_list_free(&sources);
    gdr_import_report_free(&report);
    gdr_import_report_free(&kept);
    return status == GDR_OK ? written : -1;
}

/* A built-in scene's cache file: in cache_dir, else in the per-user cache folder (created and
 * checked as for any cache). */
static int builtin_candidate(const char *spec, const gdr_load_options *o, char *out)
{
    char folder[PATH_MAX];
    if (o->cache_dir && strcmp(o->cache_dir, ".") != 0)
        snprintf(folder, sizeof folder, "%s", o->cache_dir);
    else if (!gdr_cache_default_dir(folder, sizeof folder))
        return 0;
    gdr_error dir_err;
    if (gdr_io_cache_dir_prepare(folder, &dir_err) != GDR_OK) {
        gdr_io_load_warn(o, "%s", dir_err.message);
        return 0;
    }
    return gdr_cache_path_for(spec, folder, out, PATH_MAX) != 0;
}

/* Reads the paged cache for streaming; its kept warnings handed to `report` and, with `replay`,
 * said again (not when they were just said while it was built). */
static gdr_status read_paged(const char *path, const char *spec, const char *source, const char *build_options,
                             const gdr_load_options *o, int replay, gdr_scene **out, gdr_pvs **out_pvs,
                             gdr_import_report *report, gdr_error *err)
{
    gdr_import_report cached = {0};
    gdr_status status = gdr_io_cache_read_for_streaming(path, source, build_options, out, out_pvs, &cached, NULL, err);
    if (status != GDR_OK)
        return status;
    gdr_error ignored;
    gdr_io_report_untemplate(&cached, spec, &ignored); /* out of memory: said with its markers */
    if (replay)
        gdr_io_report_replay(&cached, o->warning, o->warning_user);
    if (report) {
        gdr_import_report_free(report);
        *report = cached;
        report->cache_path = strdup(path);
        report->cache_state = GDR_CACHE_READ;
    } else {
        gdr_import_report_free(&cached);
    }
    if (o->cache_path && o->cache_path_size &&
        snprintf(o->cache_path, o->cache_path_size, "%s", path) >= (int)o->cache_path_size)
        o->cache_path[0] = '\0';
    return status;
}

gdr_status gdr_io_load_paged(const char *spec, const gdr_load_options *o, char (*candidates)[PATH_MAX], int count,
                             gdr_scene **out, gdr_pvs **out_pvs, gdr_import_report *report, gdr_error *err)
{
    *out = NULL;
    bool builtin = candidates == NULL;
    char own[1][PATH_MAX], paths[2][PATH_MAX];
    /* The options gdr build writes, so that the paged cache also reads as a plain .gdrc; a built-in
     * scene has no source file to compare with: its specification names its cache file. */
    const char *build_options = gdr_cache_build_options();
    if (builtin) {
        count = builtin_candidate(spec, o, own[0]);
        candidates = own;
    }
    int n = 0;
    for (int i = 0; i < count && n < 2; i++)
        n += paged_name(candidates[i], paths[n], PATH_MAX);
    const char *source = builtin ? NULL : spec;
    for (int i = 0; i < n; i++) {
        if (access(paths[i], F_OK) != 0)
            continue;
        gdr_error read_err;
        gdr_status read = read_paged(paths[i], spec, source, build_options, o, 1, out, out_pvs, report, &read_err);
        if (read == GDR_OK) {
            gdr_io_cache_touch(paths[i]);
            return GDR_OK;
        }
        if (read != GDR_ERROR_STALE)
            gdr_io_load_warn(o, "%s; rebuilding it", read_err.message);
    }
    int written = write_paged(spec, o, builtin, build_options, paths, n, err);
    if (written < 0)
        return err->status;
    return read_paged(paths[written], spec, source, build_options, o, 0, out, out_pvs, report, err);
}
