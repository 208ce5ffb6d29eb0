/* gdr info FILE: a summary of a scene (meshes, instances, triangles, materials, cameras, ...) and
 * of the precomputed visibility its cache holds. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "cli_args.h"
#include "commands.h"
#include "cli_pvs.h"
#include "cli_warnings.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "gdr/renderer.h"

#define INFO_USAGE                                                                                       \
    "usage: gdr info FILE|demo|lod-field|occlusion|unique-field|rooms[:...] [--no-cache] [--cache-dir DIR]\n"  \
    "       [--cache-max MIB] [--strict] [--budget KEY=N,...] [--allow-outside-files]\n"                \
    "       gdr info --passes\n"

/* How many meshes have their vertices on a grid (gdr build --pages), and the largest move. */
static void print_quantization(const gdr_scene *scene)
{
    uint32_t quantized = 0;
    float largest = 0.0f;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_vertex_quantization *q = &scene->meshes[m].quantization;
        quantized += q->enabled != 0;
        largest = q->enabled && q->max_displacement > largest ? q->max_displacement : largest;
    }
    if (quantized)
        printf("vertices:    %u of %u meshes on a grid (16-bit positions), moved at most %g\n", quantized,
               scene->mesh_count, largest);
    else
        printf("vertices:    floats\n");
}

/* The cache's size per source triangle (the LOD DAG's input), whole and its pages alone. */
static void print_cache_bytes(const char *path, uint64_t source_triangles)
{
    struct stat st;
    if (stat(path, &st) != 0 || source_triangles == 0)
        return;
    printf("cache:       %lld bytes, %.1f bytes per source triangle\n", (long long)st.st_size,
           (double)st.st_size / (double)source_triangles);
    gdr_paged_cache *paged = NULL;
    gdr_error err = {0};
    if (gdr_paged_cache_open(path, &paged, &err) != GDR_OK) {
        printf("pages:       none (%s)\n", err.message);
        return;
    }
    uint64_t pages = 0, groups = 0;
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(paged); m++) {
        pages += gdr_paged_cache_mesh(paged, m)->page_count;
        groups += gdr_paged_cache_mesh(paged, m)->group_count;
    }
    uint64_t bytes = gdr_paged_cache_page_bytes(paged);
    printf("pages:       %llu pages of %llu groups, %llu bytes, %.1f bytes per source triangle (opening read %llu)\n",
           (unsigned long long)pages, (unsigned long long)groups, (unsigned long long)bytes,
           (double)bytes / (double)source_triangles, (unsigned long long)gdr_paged_cache_bytes_read(paged));
    printf("geometry:    %s\n", gdr_paged_cache_pages_only(paged) ? "in the pages alone (read for streaming only)"
                                                                     : "whole, and in the pages");
    gdr_paged_cache_close(paged);
}

/* The triangles and vertices of every cluster of a scene read for streaming, whose clusters' records
 * are in its pages: the page index counts them (each page its groups' clusters'). */
static void count_paged_clusters(const char *path, uint64_t *triangles, uint64_t *vertices)
{
    gdr_paged_cache *paged = NULL;
    gdr_error err = {0};
    if (gdr_paged_cache_open(path, &paged, &err) != GDR_OK)
        return;
    for (uint32_t m = 0; m < gdr_paged_cache_mesh_count(paged); m++) {
        const gdr_paged_mesh *pm = gdr_paged_cache_mesh(paged, m);
        for (uint32_t p = 0; p < pm->page_count; p++) {
            *triangles += pm->pages[p].triangle_count;
            *vertices += pm->pages[p].vertex_count;
        }
    }
    gdr_paged_cache_close(paged);
}

/* Whether `input` is a .gdrc whose geometry is in its pages alone: then it is read as for streaming
 * (everything printed here comes from the records that read takes). */
static int cache_pages_only(const char *input)
{
    size_t length = strlen(input);
    gdr_paged_cache *paged = NULL;
    gdr_error err = {0};
    if (length <= 5 || strcmp(input + length - 5, ".gdrc") != 0 || gdr_paged_cache_open(input, &paged, &err) != GDR_OK)
        return 0;
    int only = gdr_paged_cache_pages_only(paged);
    gdr_paged_cache_close(paged);
    return only;
}

/* Where the scene's cache is: read, written, not written, or none. */
static void print_cache_location(const gdr_import_report *report, int no_cache, const char *input)
{
    static const char *const states[] = {"", "read", "written", "could not be written"};
    if (report->cache_path)
        printf("cached in:   %s (%s)\n", report->cache_path, states[report->cache_state & 3]);
    else if (gdr_scene_spec_is_builtin(input))
        printf("cached in:   none (a built-in scene)\n");
    else if (strlen(input) > 5 && strcmp(input + strlen(input) - 5, ".gdrc") == 0)
        printf("cached in:   %s itself\n", input);
    else
        printf("cached in:   none%s\n", no_cache ? " (--no-cache)" : " (no cache folder)");
}

/* The textures' count, then per format how many and the bytes their mip chains take (what the
 * cache stores and a device that samples the format holds). */
static void print_textures(const gdr_scene *scene)
{
    printf("textures:    %u\n", scene->texture_count);
    for (uint32_t f = 0; f < GDR_TEXTURE_FORMAT_COUNT; f++) {
        uint32_t count = 0;
        unsigned long long bytes = 0, texels = 0;
        for (uint32_t i = 0; i < scene->texture_count; i++) {
            const gdr_texture *t = &scene->textures[i];
            if (t->format != f)
                continue;
            count++;
            bytes += gdr_texture_format_level_offset(t->format, t->width, t->height, t->levels);
            texels += (unsigned long long)t->width * t->height;
        }
        if (count)
            printf("  %-7s    %u (%llu texels at level 0, %llu bytes with their mips)\n", gdr_texture_format_name(f),
                   count, texels, bytes);
    }
}

/* Parses gdr info's arguments into *options and *input: 0, or the exit status after the usage
 * (0 for --help). */
static int parse_info_options(int argc, char **argv, gdr_load_options *options, cli_warnings *warnings,
                              const char **input)
{
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        bool has_value = i + 1 < argc;
        if (strcmp(arg, "--no-cache") == 0)
            options->no_cache = 1;
        else if (strcmp(arg, "--cache-dir") == 0 && has_value)
            options->cache_dir = argv[++i];
        else if (strcmp(arg, "--cache-max") == 0 && has_value) {
            if (!cli_parse_cache_max(arg, argv[++i], &options->cache_max_bytes))
                return 2;
        } else if (strcmp(arg, "--strict") == 0)
            warnings->strict = true;
        else if (strcmp(arg, "--allow-outside-files") == 0)
            options->allow_outside_files = 1;
        else if (strcmp(arg, "--budget") == 0 && has_value) {
            if (!cli_parse_budget(arg, argv[++i], &options->budget))
                return 2;
        } else if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0 || arg[0] == '-' || *input) {
            fputs(INFO_USAGE, stderr);
            return strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0 ? -1 : 2;
        } else
            *input = arg;
    }
    if (!*input) {
        fputs(INFO_USAGE, stderr);
        return 2;
    }
    return 0;
}

/* The scene's geometry summed over its meshes. */
typedef struct geometry_totals {
    uint64_t vertices, unique_triangles, clusters, level0, cluster_triangles, cluster_vertices, nodes;
    uint32_t node_levels;
} geometry_totals;

static geometry_totals sum_geometry(const gdr_scene *scene, const char *input)
{
    geometry_totals t = {0};
    for (uint32_t i = 0; i < scene->mesh_count; i++) {
        const gdr_mesh_clusters *c = &scene->meshes[i].clusters;
        t.nodes += c->lod_node_count;
        t.node_levels = c->lod_node_levels > t.node_levels ? c->lod_node_levels : t.node_levels;
        t.vertices += scene->meshes[i].vertex_count;
        t.unique_triangles += scene->meshes[i].index_count / 3;
        t.clusters += c->cluster_count;
        t.level0 += c->level0_cluster_count;
        for (uint32_t k = 0; c->clusters && k < c->cluster_count; k++) {
            t.cluster_triangles += c->clusters[k].triangle_count;
            t.cluster_vertices += c->clusters[k].vertex_count;
        }
    }
    if (scene->geometry_in_pages) /* the records are in the pages */
        count_paged_clusters(input, &t.cluster_triangles, &t.cluster_vertices);
    return t;
}

static void print_geometry(const gdr_scene *scene, const char *input, const geometry_totals *t)
{
    printf("scene:       %s\n", input);
    printf("meshes:      %u (%llu vertices, %llu triangles)\n", scene->mesh_count, (unsigned long long)t->vertices,
           (unsigned long long)t->unique_triangles);
    printf("clusters:    %llu (%.1f triangles, %.1f vertices each on average", (unsigned long long)t->clusters,
           t->clusters ? (double)t->cluster_triangles / (double)t->clusters : 0.0,
           t->clusters ? (double)t->cluster_vertices / (double)t->clusters : 0.0);
    if (t->level0 != t->clusters)
        printf("; %llu at level 0", (unsigned long long)t->level0);
    printf(")\n");
    printf("lod nodes:   %llu (hierarchies of up to %u levels)\n", (unsigned long long)t->nodes, t->node_levels);
    printf("instances:   %u\n", scene->instance_count);
    printf("triangles:   %llu (over all instances)\n", (unsigned long long)gdr_scene_triangle_count(scene));
}

int gdr_cmd_info(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--passes") == 0) {
        gdr_describe_frame_passes(stdout); /* docs/PIPELINE.md, "The frame, pass by pass" */
        return fflush(stdout) == 0 && !ferror(stdout) ? 0 : 1;
    }
    const char *input = NULL;
    cli_warnings warnings = {0};
    gdr_import_report report = {0};
    gdr_pvs *pvs = NULL; /* a cache's precomputed visibility is described too */
    gdr_load_options options = {.warning = cli_warning, .warning_user = &warnings, .report = &report, .pvs = &pvs};
    int usage = parse_info_options(argc, argv, &options, &warnings, &input);
    if (usage)
        return usage < 0 ? 0 : usage;
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    options.geometry_in_pages = cache_pages_only(input);
    gdr_status status = gdr_scene_load(input, &options, &scene, &err);
    int strict = status == GDR_OK ? cli_strict_check(&warnings, input) : 0;
    if (status == GDR_OK && !strict) {
        geometry_totals totals = sum_geometry(scene, input);
        print_geometry(scene, input, &totals);
        printf("materials:   %u\n", scene->material_count);
        print_textures(scene);
        printf("cameras:     %u\n", scene->camera_count);
        printf("extensions:  %s\n", scene->extensions ? scene->extensions : "(none)");
        print_quantization(scene);
        cli_pvs_print_info(pvs);
        size_t length = strlen(input);
        if (length > 5 && strcmp(input + length - 5, ".gdrc") == 0)
            print_cache_bytes(input, totals.unique_triangles);
        print_cache_location(&report, options.no_cache, input);
        if (warnings.count)
            printf("warnings:    %u\n", warnings.count);
    }
    gdr_import_report_free(&report);
    cli_pvs_destroy(pvs);
    gdr_scene_destroy(scene);
    return status != GDR_OK ? cli_load_failed(input, &err) : strict;
}
