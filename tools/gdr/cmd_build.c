/* gdr build INPUT -o OUTPUT.gdrc [--pvs]: import a scene (or build the demo), optionally bake its
 * precomputed visibility, and write the cache. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "cli_args.h"
#include "cli_pvs.h"
#include "cli_warnings.h"
#include "commands.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"

static void build_usage(void)
{
    fputs("usage: gdr build INPUT -o OUTPUT.gdrc [--pvs] [--pvs-cell M] [--pvs-samples N] [--pages[=KIB]]\n"
          "                 [--whole-geometry] [--no-progress] [--strict] [--budget KEY=N,...] [--allow-outside-files] [--threads N]\n"
          "  INPUT: a .gltf, .glb or .obj file, a .gdrc cache, or a built-in scene: 'demo', 'lod-field',\n"
          "         'occlusion', 'unique-field' or 'rooms', each with optional ':key=value,...' (see gdr --help)\n"
          "  --strict: every warning of the import is an error: nothing is written, exit status 4\n"
          "  --pvs: bake precomputed visibility (every processor) into the cache; gdr render culls with it\n"
          "  --pvs-cell M: its cells' size in metres (default: the scene's largest side / 16; the rooms\n"
          "         scene wants 1: a cell touched by geometry gets no data)\n"
          "  --pvs-samples N: camera points per cell (default 8, at most 4096)\n"
          "  --pages[=KIB]: store the geometry in compressed pages of KIB kibibytes (default 128) alone,\n"
          "         read on demand for streaming (docs/CACHE_FORMAT.md, section 'PAGE'): the file is read\n"
          "         for streaming only (--geometry-budget); the vertices are\n"
          "         first moved onto a 16-bit grid per mesh (gdr_scene_quantize_vertices), which the pages\n"
          "         store as integers; a built-in scene is then built and written mesh by mesh, several\n"
          "         meshes at once (the unique field one mesh at a time: memory follows the meshes in flight)\n"
          "  --whole-geometry: with --pages, also keep the whole geometry beside the pages, so that the file\n"
          "         renders whole too (3.4 times larger on unique-field)\n"
          "  --threads N: threads of that build (default: one per processor; the file does not depend on it)\n",
          stderr);
}

/* The vertices onto their grids before the pages store them; reports the largest move. */
static gdr_status quantize(gdr_scene *scene, gdr_error *err)
{
    gdr_status status = gdr_scene_quantize_vertices(scene, err);
    float largest = 0.0f, relative = 0.0f;
    for (uint32_t m = 0; status == GDR_OK && m < scene->mesh_count; m++) {
        const gdr_mesh *mesh = &scene->meshes[m];
        largest = fmaxf(largest, mesh->quantization.max_displacement);
        if (mesh->bounds.w > 0.0f)
            relative = fmaxf(relative, mesh->quantization.max_displacement / mesh->bounds.w);
    }
    if (status == GDR_OK)
        printf("vertices: on a 16-bit grid per mesh, moved at most %g (%.2g of a mesh's radius)\n", largest, relative);
    return status;
}

/* A built-in scene with pages: built and written mesh by mesh (gdr_cache_build_paged). */
static int build_paged(const char *input, const char *output, uint32_t page_bytes, uint32_t threads, int no_progress,
                       int whole_geometry)
{
    gdr_error err = {0};
    gdr_paged_build_options options = {.page_bytes = page_bytes, .thread_count = threads, .no_progress = no_progress,
                                       .whole_geometry = whole_geometry};
    if (gdr_cache_build_paged(input, output, &options, &err) != GDR_OK)
        return cli_load_failed(input, &err);
    printf("%s: written mesh by mesh with pages of %u KiB\n", output, page_bytes / 1024);
    return 0;
}

int gdr_cmd_build(int argc, char **argv)
{
    const char *input = NULL, *output = NULL;
    int no_progress = 0, pvs_wanted = 0, allow_outside_files = 0, whole_geometry = 0;
    uint32_t page_bytes = 0, pvs_samples = 0, threads = 0;
    float pvs_cell = 0.0f;
    gdr_budget budget = {0};
    cli_warnings warnings = {0};
    for (int i = 1; i < argc; i++) {
        if ((strcmp(argv[i], "-o") == 0 || strcmp(argv[i], "--out") == 0) && i + 1 < argc) {
            output = argv[++i];
        } else if (strcmp(argv[i], "--no-progress") == 0) {
            no_progress = 1;
        } else if (strcmp(argv[i], "--strict") == 0) {
            warnings.strict = true;
        } else if (strcmp(argv[i], "--pvs") == 0) {
            if (!cli_needs_cull(argv[i]))
                return 2;
            pvs_wanted = 1;
        } else if (strcmp(argv[i], "--pvs-cell") == 0 && i + 1 < argc) {
            if (!cli_needs_cull(argv[i]) || !cli_parse_float(argv[i], argv[i + 1], 0.01f, 1e6f, &pvs_cell))
                return 2;
            pvs_wanted = 1;
            i++;
        } else if (strcmp(argv[i], "--pvs-samples") == 0 && i + 1 < argc) {
            if (!cli_needs_cull(argv[i]) || !cli_parse_u32(argv[i], argv[i + 1], 1, 4096, &pvs_samples))
                return 2;
            pvs_wanted = 1;
            i++;
        } else if (strcmp(argv[i], "--pages") == 0) {
            page_bytes = GDR_PAGE_BYTES_DEFAULT;
        } else if (strncmp(argv[i], "--pages=", 8) == 0) {
            char *end;
            unsigned long kib = strtoul(argv[i] + 8, &end, 10);
            if (*end || end == argv[i] + 8 || argv[i][8] == '-' || kib < GDR_PAGE_BYTES_MIN / 1024 ||
                kib > GDR_PAGE_BYTES_MAX / 1024) {
                fprintf(stderr, "gdr: build: --pages=%s: expected kibibytes in [%u, %u]\n", argv[i] + 8,
                        GDR_PAGE_BYTES_MIN / 1024, GDR_PAGE_BYTES_MAX / 1024);
                return 2;
            }
            page_bytes = (uint32_t)kib * 1024u;
        } else if (strcmp(argv[i], "--whole-geometry") == 0) {
            whole_geometry = 1;
        } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
            if (!cli_parse_u32(argv[i], argv[i + 1], 1, 256, &threads))
                return 2;
            i++;
        } else if (strcmp(argv[i], "--allow-outside-files") == 0) {
            allow_outside_files = 1;
        } else if (strcmp(argv[i], "--budget") == 0 && i + 1 < argc) {
            if (!cli_parse_budget(argv[i], argv[i + 1], &budget))
                return 2;
            i++;
        } else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            build_usage();
            return 0;
        } else if (argv[i][0] == '-' || input) {
            fprintf(stderr, "gdr: build: unexpected argument '%s'\n", argv[i]);
            build_usage();
            return 2;
        } else {
            input = argv[i];
        }
    }
    if (!input || !output) {
        build_usage();
        return 2;
    }
    if (whole_geometry && !page_bytes) {
        fputs("gdr: build: --whole-geometry is for a cache with --pages (one without pages holds it anyway)\n", stderr);
        return 2;
    }
    gdr_error err = {0};
    if (page_bytes && !pvs_wanted && gdr_scene_spec_is_builtin(input))
        return build_paged(input, output, page_bytes, threads, no_progress, whole_geometry);
    gdr_scene *scene = NULL;
    gdr_source_list sources = {0};
    gdr_status status;
    gdr_pvs *pvs = NULL; /* a .gdrc input's precomputed visibility is carried over unless rebaked */
    /* A .gdrc input's precomputed visibility is carried over unless rebaked; a source's files are
     * recorded in the cache written. */
    gdr_import_report report = {0}; /* the import's warnings, kept in the cache */
    gdr_load_options load = {.no_cache = 1, .no_progress = no_progress, .budget = budget,
                             .allow_outside_files = allow_outside_files, .pvs = &pvs, .sources = &sources,
                             .warning = cli_warning, .warning_user = &warnings, .report = &report};
    status = gdr_scene_load(input, &load, &scene, &err);
    int strict = status == GDR_OK ? cli_strict_check(&warnings, input) : 0;
    if (strict) {
        gdr_import_report_free(&report);
        cli_pvs_destroy(pvs);
        gdr_source_list_free(&sources);
        gdr_scene_destroy(scene);
        return strict;
    }
    if (status == GDR_OK && pvs && !pvs_wanted)
        cli_pvs_print_kept(input, pvs);
    if (status == GDR_OK && page_bytes)
        status = quantize(scene, &err);
    if (status == GDR_OK && pvs_wanted) {
        cli_pvs_destroy(pvs);
        pvs = NULL;
        status = cli_pvs_bake(scene, pvs_cell, pvs_samples, &pvs, &err); /* before writing: a failed bake leaves no file */
    }
    if (status == GDR_OK) {
        gdr_cache_write_options write = {.source = {gdr_cache_build_options(), &sources}, .pvs = pvs,
                                         .page_bytes = page_bytes, .whole_geometry = whole_geometry,
                                         .report = &report};
        status = gdr_cache_write(output, scene, &write, &err);
    }
    if (status == GDR_OK)
        printf("%s: %u meshes, %u instances, %llu triangles, %u materials, %u textures, %u cameras\n", output,
               scene->mesh_count, scene->instance_count, (unsigned long long)gdr_scene_triangle_count(scene),
               scene->material_count, scene->texture_count, scene->camera_count);
    int result = status == GDR_OK ? 0 : cli_load_failed(input, &err);
    cli_pvs_destroy(pvs);
    gdr_import_report_free(&report);
    gdr_source_list_free(&sources);
    gdr_scene_destroy(scene);
    return result;
}
