/* The program built against a library without the culling module (cli_pvs.h): the library returns
 * no PVS and reads none from a cache, and the options that would bake one are refused before any of
 * this is reached (cli_needs_cull). */
#include <stdio.h>

#include "cli_pvs.h"

gdr_status cli_pvs_bake(const gdr_scene *scene, float cell_size, uint32_t samples, gdr_pvs **out, gdr_error *err)
{
    (void)scene, (void)cell_size, (void)samples;
    *out = NULL;
    return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "pvs: built without the culling module (GDR_EXCLUDE_MODULES)");
}

void cli_pvs_print_kept(const char *input, const gdr_pvs *pvs) { (void)input, (void)pvs; }

/* A cache's PVIS section, if it has one, was skipped: say so rather than "none". */
void cli_pvs_print_info(const gdr_pvs *pvs)
{
    (void)pvs;
    printf("pvs:         not read: built without the culling module (GDR_EXCLUDE_MODULES)\n");
}

void cli_pvs_destroy(gdr_pvs *pvs) { (void)pvs; }
