/* What the program asks of the culling module's precomputed visibility (gdr/cull.h): cli_pvs.c; in
 * a build without the module (gdr/config.h: GDR_HAVE_CULL 0) cli_pvs_absent.c stands in, and the
 * options that need it are refused first (cli_needs_cull). */
#ifndef GDR_CLI_PVS_H
#define GDR_CLI_PVS_H

#include <stdint.h>

#include "gdr/io.h"

/* The bake (docs/CULLING.md) on a pool of every processor, its report printed; 0: the default cell
 * size and samples. */
gdr_status cli_pvs_bake(const gdr_scene *scene, float cell_size, uint32_t samples, gdr_pvs **out, gdr_error *err);
/* gdr build: "pvs: kept from INPUT (...)" for a .gdrc input's PVS carried over. */
void cli_pvs_print_kept(const char *input, const gdr_pvs *pvs);
/* gdr info: the "pvs:" line for the PVS a scene was loaded with (NULL: none). */
void cli_pvs_print_info(const gdr_pvs *pvs);
/* Frees a PVS the library returned (NULL: nothing). */
void cli_pvs_destroy(gdr_pvs *pvs);

#endif
