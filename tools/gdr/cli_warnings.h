/* The import's warnings on the command line: counted, printed, and with --strict errors. */
#ifndef GDR_CLI_WARNINGS_H
#define GDR_CLI_WARNINGS_H

#include <stdbool.h>
#include <stdint.h>

#include "gdr/io.h"
#include "gdr/scene.h"

/* The exit status of a run whose scene loaded with warnings under --strict (render, build, info,
 * view): every warning is an error. */
#define GDR_EXIT_STRICT 4

typedef struct cli_warnings {
    unsigned count;
    bool strict;
} cli_warnings;

/* A gdr_warning_fn: "gdr: warning: MESSAGE" (with --strict "gdr: error: MESSAGE") on stderr. */
void cli_warning(void *user, const char *message);
/* After loading: with --strict and any warning, says so and returns GDR_EXIT_STRICT; else 0. */
int cli_strict_check(const cli_warnings *w, const char *scene);
/* "--camera-index N: the scene has M camera(s)", or, when the file places more cameras than gdr could
 * use, how many it has and how many can be used. Returns 2 (bad usage). */
int cli_camera_index_refused(const char *command, uint32_t index, const gdr_scene *scene,
                             const gdr_import_report *report);
/* --cache-max MIB: parsed into bytes; false after printing why not. */
bool cli_parse_cache_max(const char *option, const char *text, uint64_t *out);

#endif
