/* An import's report (gdr_import_report): its warnings and cameras, kept in the cache (section
 * 'REPT') so that a cached run says what the import said. */
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
