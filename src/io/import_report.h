/* An import's report (gdr_import_report, gdr/io.h): its warnings, kept and replayed. */
#ifndef GDR_IO_IMPORT_REPORT_H
#define GDR_IO_IMPORT_REPORT_H

#include <stddef.h>
#include <stdio.h>

#include "gdr/io.h"

/* Keeps a warning (its first GDR_REPORT_MAX_WARNING_BYTES bytes; beyond GDR_REPORT_MAX_WARNINGS
 * warnings only the total grows). */
gdr_status gdr_io_report_add(gdr_import_report *report, const char *message, size_t length, gdr_error *err);

/* Says the kept warnings again through fn (NULL: "gdr: warning: ..." on stderr), then how many were
 * not kept, if any. */
void gdr_io_report_replay(const gdr_import_report *report, gdr_warning_fn fn, void *user);

/* The warnings of the import of `source` (the path as given, which starts its messages) with that
 * path and its folder replaced by markers, so that a cache read for the same file by another
 * spelling, or copied with its folder, says them as an import from there would. *out: a copy. */
gdr_status gdr_io_report_template(const gdr_import_report *report, const char *source, gdr_import_report *out,
                                  gdr_error *err);
/* A loader's warning through the load's sink (gdr_load_options.warning), else "gdr: warning: ..."
 * on stderr. */
void gdr_io_load_warn(const gdr_load_options *o, const char *format, ...) __attribute__((format(printf, 2, 3)));

/* An import's warning sink (gdr_import_options.warning; user: a gdr_io_report_collector): each
 * warning is kept in the report (the one a cache keeps) and said through the load's sink. */
typedef struct gdr_io_report_collector {
    const gdr_load_options *options;
    gdr_import_report *report;
} gdr_io_report_collector;
void gdr_io_report_collect(void *user, const char *message);

/* The markers replaced by `source` (the path as given now) and its folder; NULL: "(its source)". */
gdr_status gdr_io_report_untemplate(gdr_import_report *report, const char *source, gdr_error *err);

#endif
