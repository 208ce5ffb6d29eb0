#include <stdio.h>

#include "cli_args.h"
#include "cli_warnings.h"

void cli_warning(void *user, const char *message)
{
    cli_warnings *w = user;
    w->count++;
    fprintf(stderr, "gdr: %s: %s\n", w->strict ? "error" : "warning", message);
}

int cli_strict_check(const cli_warnings *w, const char *scene)
{
    if (!w->strict || w->count == 0)
        return 0;
    fprintf(stderr, "gdr: --strict: %s loaded with %u warning(s), each an error (exit status %d)\n", scene, w->count,
            GDR_EXIT_STRICT);
    return GDR_EXIT_STRICT;
}

int cli_camera_index_refused(const char *command, uint32_t index, const gdr_scene *scene,
                             const gdr_import_report *report)
{
    if (report && report->file_cameras > scene->camera_count)
        fprintf(stderr, "gdr %s: --camera-index %u: the file has %u camera(s), of which %u can be used (the "
                "warnings say why the others were left out)\n", command, index, report->file_cameras,
                scene->camera_count);
    else
        fprintf(stderr, "gdr %s: --camera-index %u: the scene has %u camera(s)\n", command, index,
                scene->camera_count);
    return 2;
}

bool cli_parse_cache_max(const char *option, const char *text, uint64_t *out)
{
    uint32_t mib;
    if (!cli_parse_u32(option, text, 1, 1u << 24, &mib))
        return false;
    *out = (uint64_t)mib << 20;
    return true;
}
