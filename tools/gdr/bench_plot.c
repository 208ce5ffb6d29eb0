/* gdr bench --plot FILE.svg: GPU ms per pass of the benchmark's rows, drawn by gnuplot (Debian's
 * gnuplot-nox) against scene size or, along a camera path, against the frame. */
#include "bench_plot.h"

#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

#define PLOT_MAX_SERIES 64

/* A row's run: pipeline, LOD threshold and occlusion culling (the things gdr bench runs side by side). */
static void run_label(const cJSON *row, char *out, size_t size)
{
    const cJSON *pipeline = cJSON_GetObjectItem(row, "pipeline"), *lod = cJSON_GetObjectItem(row, "lod_error_px"),
                *occlusion = cJSON_GetObjectItem(row, "occlusion_applied");
    snprintf(out, size, "%s lod %g%s", cJSON_IsString(pipeline) ? pipeline->valuestring : "?",
             cJSON_IsNumber(lod) ? lod->valuedouble : 0.0, cJSON_IsTrue(occlusion) ? " occl" : "");
}

/* One gnuplot data block per (run, pass): "x ms" lines; the blocks' titles in `titles`. */
static int write_blocks(FILE *f, const cJSON *rows, const char *x_key, char titles[][96])
{
    int series = 0;
    const cJSON *first = cJSON_GetArrayItem(rows, 0);
    const cJSON *passes = cJSON_GetObjectItem(first, "gpu_ms");
    char runs[PLOT_MAX_SERIES][64];
    int run_count = 0;
    for (const cJSON *row = rows->child; row; row = row->next) {
        char label[64];
        run_label(row, label, sizeof label);
        int known = 0;
        for (int r = 0; r < run_count; r++)
            known |= strcmp(runs[r], label) == 0;
        if (!known && run_count < PLOT_MAX_SERIES)
            snprintf(runs[run_count++], sizeof runs[0], "%s", label);
    }
    for (int r = 0; r < run_count; r++) {
        for (const cJSON *pass = passes ? passes->child : NULL; pass && series < PLOT_MAX_SERIES; pass = pass->next) {
            snprintf(titles[series++], 96, "%.40s: %.40s", runs[r], pass->string);
            fprintf(f, "$block%d << EOD\n", series - 1);
            for (const cJSON *row = rows->child; row; row = row->next) {
                char label[64];
                run_label(row, label, sizeof label);
                const cJSON *x = cJSON_GetObjectItem(row, x_key);
                const cJSON *ms = cJSON_GetObjectItem(cJSON_GetObjectItem(row, "gpu_ms"), pass->string);
                if (strcmp(label, runs[r]) == 0 && cJSON_IsNumber(x) && cJSON_IsNumber(ms))
                    fprintf(f, "%.17g %.9g\n", x->valuedouble, ms->valuedouble);
            }
            fprintf(f, "EOD\n");
        }
    }
    return series;
}

static gdr_status write_script(const char *script, const char *svg, const cJSON *rows, bool along_path,
                               gdr_error *err)
{
    FILE *f = fopen(script, "w");
    if (!f)
        return gdr_error_set(err, GDR_ERROR_IO, "--plot: cannot write %s", script);
    static char titles[PLOT_MAX_SERIES][96];
    int series = write_blocks(f, rows, along_path ? "frame" : "instances_total", titles);
    fprintf(f, "set terminal svg size 960,600 dynamic noenhanced background rgb 'white'\nset output '%s'\n", svg);
    fprintf(f, "set title 'GPU ms per pass%s'\nset xlabel '%s'\nset ylabel 'GPU ms'\nset key outside right\n"
               "set grid\n%s",
            along_path ? " along the camera path" : " against scene size", along_path ? "frame" : "instances",
            along_path ? "" : "set logscale x\n");
    for (int s = 0; s < series; s++)
        fprintf(f, "%s $block%d using 1:2 with linespoints title '%s'%s", s ? "    " : "plot", s, titles[s],
                s + 1 < series ? ", \\\n" : "\n");
    bool ok = series > 0 && !ferror(f);
    fclose(f);
    return ok ? GDR_OK : gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "--plot: no GPU timings to plot");
}

/* Runs gnuplot on the script; its messages go to stderr. */
static gdr_status run_gnuplot(const char *script, gdr_error *err)
{
    char *argv[] = {"gnuplot", (char *)script, NULL};
    pid_t pid;
    if (posix_spawnp(&pid, "gnuplot", NULL, NULL, argv, environ) != 0)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "--plot: cannot run gnuplot (Debian package gnuplot-nox)");
    int status = 0;
    if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "--plot: gnuplot failed (status %d)", status);
    return GDR_OK;
}

/* The whole file, at most `limit` bytes, NUL-terminated. */
static gdr_status read_all(const char *path, size_t limit, char **out, size_t *out_size, gdr_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot open", path);
    char *data = NULL;
    size_t size = 0, capacity = 0, got;
    char chunk[65536];
    gdr_status status = GDR_OK;
    while (status == GDR_OK && (got = fread(chunk, 1, sizeof chunk, f)) > 0) {
        if (size + got > limit) {
            status = gdr_error_set(err, GDR_ERROR_CAPACITY, "%s: larger than %zu bytes", path, limit);
            break;
        }
        if (size + got + 1 > capacity) {
            capacity = (size + got + 1) * 2;
            char *grown = realloc(data, capacity);
            if (!grown)
                status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
            else
                data = grown;
        }
        if (status == GDR_OK)
            memcpy(data + size, chunk, got), size += got;
    }
    if (status == GDR_OK && ferror(f))
        status = gdr_error_set(err, GDR_ERROR_IO, "%s: read error", path);
    fclose(f);
    if (status == GDR_OK && !data)
        data = calloc(1, 1);
    if (status != GDR_OK || !data) {
        free(data);
        return status != GDR_OK ? status : gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    data[size] = '\0';
    *out = data;
    *out_size = size;
    return GDR_OK;
}

static gdr_status copy_out(const char *from, const char *to, gdr_error *err)
{
    char *data;
    size_t size;
    gdr_status status = read_all(from, (size_t)1 << 30, &data, &size, err);
    if (status != GDR_OK)
        return status;
    status = gdr_write_file_atomic(to, data, size, err);
    free(data);
    return status;
}

gdr_status bench_plot_from_json(const char *json_path, const char *svg_path, gdr_error *err)
{
    char *text;
    size_t size;
    gdr_status status = read_all(json_path, (size_t)256 << 20, &text, &size, err);
    if (status != GDR_OK)
        return status;
    cJSON *rows = cJSON_ParseWithLength(text, size);
    free(text);
    if (!cJSON_IsArray(rows)) {
        cJSON_Delete(rows);
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: not the JSON array gdr bench --json writes", json_path);
    }
    bool along_path = cJSON_GetObjectItem(cJSON_GetArrayItem(rows, 0), "frame") != NULL;
    status = bench_plot_svg(svg_path, rows, along_path, err);
    cJSON_Delete(rows);
    return status;
}

gdr_status bench_plot_svg(const char *path, const cJSON *rows, bool along_path, gdr_error *err)
{
    if (cJSON_GetArraySize(rows) == 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "--plot: no rows to plot");
    char dir[] = "/tmp/gdr-plot-XXXXXX";
    if (!mkdtemp(dir))
        return gdr_error_set(err, GDR_ERROR_IO, "--plot: cannot make a temporary folder");
    char script[64], svg[64];
    snprintf(script, sizeof script, "%s/plot.gp", dir);
    snprintf(svg, sizeof svg, "%s/plot.svg", dir);
    gdr_status status = write_script(script, svg, rows, along_path, err);
    if (status == GDR_OK)
        status = run_gnuplot(script, err);
    if (status == GDR_OK)
        status = copy_out(svg, path, err);
    remove(script);
    remove(svg);
    rmdir(dir);
    return status;
}
