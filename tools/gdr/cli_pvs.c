/* The program's precomputed visibility over the culling module (cli_pvs.h). */
#include <stdio.h>
#include <time.h>

#include "cli_pvs.h"
#include "gdr/cull.h"
#include "gdr/thread_pool.h"

gdr_status cli_pvs_bake(const gdr_scene *scene, float cell_size, uint32_t samples, gdr_pvs **out, gdr_error *err)
{
    gdr_thread_pool *pool = NULL;
    gdr_status status = gdr_thread_pool_create(0, &pool, err);
    if (status != GDR_OK)
        return status;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    gdr_pvs_bake_desc desc = {.scene = scene, .pool = pool, .cell_size = cell_size, .samples_per_cell = samples};
    gdr_pvs_bake_report report;
    status = gdr_pvs_bake(&desc, out, &report, err);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (status == GDR_OK)
        printf("pvs: %ux%ux%u cells, %u baked (%u touched by geometry), %u objects, %llu samples, %zu bytes "
               "compressed from %zu, %.0f ms on %u threads\n",
               report.grid[0], report.grid[1], report.grid[2], report.cells_baked, report.cells_occupied,
               gdr_pvs_object_count(*out), (unsigned long long)report.samples_used, report.compressed_bytes,
               report.uncompressed_bytes,
               (double)(t1.tv_sec - t0.tv_sec) * 1e3 + (double)(t1.tv_nsec - t0.tv_nsec) * 1e-6,
               gdr_thread_pool_thread_count(pool));
    gdr_thread_pool_destroy(pool);
    return status;
}

void cli_pvs_print_kept(const char *input, const gdr_pvs *pvs)
{
    printf("pvs: kept from %s (%u cells, %u objects)\n", input, gdr_pvs_cell_count(pvs), gdr_pvs_object_count(pvs));
}

void cli_pvs_print_info(const gdr_pvs *pvs)
{
    if (pvs)
        printf("pvs:         %u cells, %u objects (%zu bytes)\n", gdr_pvs_cell_count(pvs), gdr_pvs_object_count(pvs),
               gdr_pvs_serialized_size(pvs));
    else
        printf("pvs:         none\n");
}

void cli_pvs_destroy(gdr_pvs *pvs) { gdr_pvs_destroy(pvs); }
