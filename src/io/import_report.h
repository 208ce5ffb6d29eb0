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

#endif
