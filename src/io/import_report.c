/* An import's report (gdr_import_report): its warnings and cameras, kept in the cache (section
 * 'REPT') so that a cached run says what the import said. */
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "io/import_report.h"

void gdr_import_report_free(gdr_import_report *report)
{
    if (!report)
        return;
    for (uint32_t i = 0; i < report->warning_count; i++)
        free(report->warnings[i]);
    free(report->warnings);
    free(report->cache_path);
    *report = (gdr_import_report){0};
}

gdr_status gdr_io_report_add(gdr_import_report *report, const char *message, size_t length, gdr_error *err)
{
    report->warning_total++;
    if (report->warning_count >= GDR_REPORT_MAX_WARNINGS)
        return GDR_OK; /* counted, not kept: the replay says how many more there were */
    if (report->warning_count == report->warning_capacity) {
        uint32_t capacity = report->warning_capacity ? report->warning_capacity * 2 : 8;
        char **grown = realloc(report->warnings, sizeof *grown * capacity);
        if (!grown)
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "out of memory keeping a warning");
        report->warnings = grown;
        report->warning_capacity = capacity;
    }
    if (length > GDR_REPORT_MAX_WARNING_BYTES)
        length = GDR_REPORT_MAX_WARNING_BYTES;
    char *copy = malloc(length + 1);
    if (!copy)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "out of memory keeping a warning");
    memcpy(copy, message, length);
    copy[length] = 0;
    report->warnings[report->warning_count++] = copy;
    return GDR_OK;
}

void gdr_io_report_replay(const gdr_import_report *report, gdr_warning_fn fn, void *user)
{
    char more[96];
    for (uint32_t i = 0; i <= report->warning_count; i++) {
        const char *message = i < report->warning_count ? report->warnings[i] : NULL;
        if (!message && report->warning_total > report->warning_count) {
            snprintf(more, sizeof more, "%u more warnings were not kept",
                     report->warning_total - report->warning_count);
            message = more;
        }
        if (!message)
            continue;
        if (fn)
            fn(user, message);
        else
            fprintf(stderr, "gdr: warning: %s\n", message);
    }
}

#define SOURCE_MARK "${source}"
#define FOLDER_MARK "${folder}/"

/* `text` with every occurrence of `from` replaced by `to` (malloc'ed; NULL when out of memory). */
static char *replace_all(const char *text, const char *from, const char *to)
{
    size_t from_length = strlen(from), to_length = strlen(to), count = 0;
    for (const char *p = from_length ? strstr(text, from) : NULL; p; p = strstr(p + from_length, from))
        count++;
    size_t size = strlen(text) + count * to_length + 1;
    char *out = malloc(size), *o = out;
    if (!out)
        return NULL;
    for (const char *p = text; *p;) {
        if (from_length && strncmp(p, from, from_length) == 0) {
            memcpy(o, to, to_length);
            o += to_length;
            p += from_length;
        } else {
            *o++ = *p++;
        }
    }
    *o = 0;
    return out;
}

/* The source's folder as the import wrote it in messages ("box/" for "box/a.gltf"; "" for "a.gltf"). */
static void folder_of(const char *source, char *out, size_t size)
{
    const char *slash = strrchr(source, '/');
    size_t length = slash ? (size_t)(slash - source) + 1 : 0;
    if (length >= size)
        length = 0;
    memcpy(out, source, length);
    out[length] = 0;
}

/* Replaces each warning by a copy where `from_source`/`from_folder` became `to_source`/`to_folder`. */
static gdr_status rewrite(gdr_import_report *report, const char *from_source, const char *to_source,
                          const char *from_folder, const char *to_folder, gdr_error *err)
{
    for (uint32_t i = 0; i < report->warning_count; i++) {
        char *step = replace_all(report->warnings[i], from_source, to_source);
        char *done = step && from_folder[0] ? replace_all(step, from_folder, to_folder) : step;
        if (done != step)
            free(step);
        if (!done)
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "out of memory rewriting a warning");
        free(report->warnings[i]);
        report->warnings[i] = done;
    }
    return GDR_OK;
}

gdr_status gdr_io_report_template(const gdr_import_report *report, const char *source, gdr_import_report *out,
                                  gdr_error *err)
{
    *out = (gdr_import_report){.warning_total = report->warning_total, .file_cameras = report->file_cameras};
    for (uint32_t i = 0; i < report->warning_count; i++) {
        gdr_status status = gdr_io_report_add(out, report->warnings[i], strlen(report->warnings[i]), err);
        if (status != GDR_OK) {
            gdr_import_report_free(out);
            return status;
        }
    }
    out->warning_total = report->warning_total;
    char folder[4096];
    folder_of(source, folder, sizeof folder);
    gdr_status status = rewrite(out, source, SOURCE_MARK, folder, FOLDER_MARK, err);
    if (status != GDR_OK)
        gdr_import_report_free(out);
    return status;
}

gdr_status gdr_io_report_untemplate(gdr_import_report *report, const char *source, gdr_error *err)
{
    char folder[4096];
    folder_of(source ? source : "", folder, sizeof folder);
    return rewrite(report, SOURCE_MARK, source ? source : "(its source)", FOLDER_MARK, folder, err);
}

void gdr_io_load_warn(const gdr_load_options *o, const char *format, ...)
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

void gdr_io_report_collect(void *user, const char *message)
{
    gdr_io_report_collector *c = user;
    gdr_error ignored;
    gdr_io_report_add(c->report, message, strlen(message), &ignored); /* out of memory: said, not kept */
    if (c->options->warning)
        c->options->warning(c->options->warning_user, message);
    else
        fprintf(stderr, "gdr: warning: %s\n", message);
}
