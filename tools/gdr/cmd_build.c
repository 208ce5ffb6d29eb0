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

/* The command line of gdr build. */
typedef struct build_options {
    const char *input, *output;
    int no_progress, pvs_wanted, allow_outside_files, whole_geometry, help;
    uint32_t page_bytes, pvs_samples, threads;
    float pvs_cell;
    gdr_budget budget;
    cli_warnings warnings;
} build_options;

/* --pages=KIB; false after printing why the size is refused. */
static bool parse_page_size(const char *kib_text, uint32_t *page_bytes)
{
    char *end;
    unsigned long kib = strtoul(kib_text, &end, 10);
    if (*end || end == kib_text || kib_text[0] == '-' || kib < GDR_PAGE_BYTES_MIN / 1024 ||
        kib > GDR_PAGE_BYTES_MAX / 1024) {
        fprintf(stderr, "gdr: build: --pages=%s: expected kibibytes in [%u, %u]\n", kib_text, GDR_PAGE_BYTES_MIN / 1024,
                GDR_PAGE_BYTES_MAX / 1024);
        return false;
    }
    *page_bytes = (uint32_t)kib * 1024u;
    return true;
}

/* The precomputed-visibility options at argv[*i] (advancing *i past a value): 1 taken, 0 not one of
 * them, -1 refused (printed why). */
static int parse_pvs_option(build_options *o, int argc, char **argv, int *i)
{
    const char *arg = argv[*i];
    bool has_value = *i + 1 < argc;
    bool ok;
    if (strcmp(arg, "--pvs") == 0)
        ok = cli_needs_cull(arg);
    else if (strcmp(arg, "--pvs-cell") == 0 && has_value)
        ok = cli_needs_cull(arg) && cli_parse_float(arg, argv[++*i], 0.01f, 1e6f, &o->pvs_cell);
    else if (strcmp(arg, "--pvs-samples") == 0 && has_value)
        ok = cli_needs_cull(arg) && cli_parse_u32(arg, argv[++*i], 1, 4096, &o->pvs_samples);
    else
        return 0;
    o->pvs_wanted = 1;
    return ok ? 1 : -1;
}

/* One argument (with its value) at argv[*i]: 1 taken, 0 not an option of gdr build, -1 refused. */
static int parse_build_option(build_options *o, int argc, char **argv, int *i)
{
    const char *arg = argv[*i];
    bool has_value = *i + 1 < argc;
    if ((strcmp(arg, "-o") == 0 || strcmp(arg, "--out") == 0) && has_value)
        o->output = argv[++*i];
    else if (strcmp(arg, "--no-progress") == 0)
        o->no_progress = 1;
    else if (strcmp(arg, "--strict") == 0)
        o->warnings.strict = true;
    else if (strcmp(arg, "--pages") == 0)
        o->page_bytes = GDR_PAGE_BYTES_DEFAULT;
    else if (strncmp(arg, "--pages=", 8) == 0)
        return parse_page_size(arg + 8, &o->page_bytes) ? 1 : -1;
    else if (strcmp(arg, "--whole-geometry") == 0)
        o->whole_geometry = 1;
    else if (strcmp(arg, "--threads") == 0 && has_value)
        return cli_parse_u32(arg, argv[++*i], 1, 256, &o->threads) ? 1 : -1;
    else if (strcmp(arg, "--allow-outside-files") == 0)
        o->allow_outside_files = 1;
    else if (strcmp(arg, "--budget") == 0 && has_value)
        return cli_parse_budget(arg, argv[++*i], &o->budget) ? 1 : -1;
    else if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0)
        o->help = 1;
    else
        return parse_pvs_option(o, argc, argv, i);
    return 1;
}

/* Parses the command line into *o: 0, or the exit status after printing why (2; 0 for --help). */
static int parse_build_options(int argc, char **argv, build_options *o)
{
    *o = (build_options){0};
    for (int i = 1; i < argc && !o->help; i++) {
        int taken = parse_build_option(o, argc, argv, &i);
        if (taken < 0)
            return 2;
        if (taken > 0)
            continue;
        if (argv[i][0] == '-' || o->input) {
            fprintf(stderr, "gdr: build: unexpected argument '%s'\n", argv[i]);
            build_usage();
            return 2;
        }
        o->input = argv[i];
    }
    if (o->help) {
        build_usage();
        return -1;
    }
    if (!o->input || !o->output) {
        build_usage();
        return 2;
    }
    if (o->whole_geometry && !o->page_bytes) {
        fputs("gdr: build: --whole-geometry is for a cache with --pages (one without pages holds it anyway)\n", stderr);
        return 2;
    }
    return 0;
}

/* The precomputed visibility baked into the cache (--pvs): before writing, so that a failed bake
 * leaves no file. Without --pvs, a .gdrc input's is carried over. */
static gdr_status bake_pvs(const build_options *o, gdr_scene *scene, gdr_pvs **pvs, gdr_error *err)
{
    if (!o->pvs_wanted)
        return GDR_OK;
    cli_pvs_destroy(*pvs);
    *pvs = NULL;
    return cli_pvs_bake(scene, o->pvs_cell, o->pvs_samples, pvs, err);
}

/* A scene from a file (or a built-in scene without pages): loaded whole, then written. A source's
 * files are recorded in the cache written, and the import's warnings kept in it. */
static int build_whole(build_options *o)
{
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_source_list sources = {0};
    gdr_pvs *pvs = NULL;
    gdr_import_report report = {0};
    gdr_load_options load = {.no_cache = 1, .no_progress = o->no_progress, .budget = o->budget,
                             .allow_outside_files = o->allow_outside_files, .pvs = &pvs, .sources = &sources,
                             .warning = cli_warning, .warning_user = &o->warnings, .report = &report};
    gdr_status status = gdr_scene_load(o->input, &load, &scene, &err);
    int strict = status == GDR_OK ? cli_strict_check(&o->warnings, o->input) : 0;
    if (!strict && status == GDR_OK && pvs && !o->pvs_wanted)
        cli_pvs_print_kept(o->input, pvs);
    if (!strict && status == GDR_OK && o->page_bytes)
        status = quantize(scene, &err);
    if (!strict && status == GDR_OK)
        status = bake_pvs(o, scene, &pvs, &err);
    if (!strict && status == GDR_OK) {
        gdr_cache_write_options write = {.source = {gdr_cache_build_options(), &sources}, .pvs = pvs,
                                         .page_bytes = o->page_bytes, .whole_geometry = o->whole_geometry,
                                         .report = &report};
        status = gdr_cache_write(o->output, scene, &write, &err);
    }
    if (!strict && status == GDR_OK)
        printf("%s: %u meshes, %u instances, %llu triangles, %u materials, %u textures, %u cameras\n", o->output,
               scene->mesh_count, scene->instance_count, (unsigned long long)gdr_scene_triangle_count(scene),
               scene->material_count, scene->texture_count, scene->camera_count);
    int result = strict ? strict : status == GDR_OK ? 0 : cli_load_failed(o->input, &err);
    cli_pvs_destroy(pvs);
    gdr_import_report_free(&report);
    gdr_source_list_free(&sources);
    gdr_scene_destroy(scene);
    return result;
}

int gdr_cmd_build(int argc, char **argv)
{
    build_options o;
    int usage = parse_build_options(argc, argv, &o);
    if (usage)
        return usage < 0 ? 0 : usage;
    if (o.page_bytes && !o.pvs_wanted && gdr_scene_spec_is_builtin(o.input))
        return build_paged(o.input, o.output, o.page_bytes, o.threads, o.no_progress, o.whole_geometry);
    return build_whole(&o);
}
