/* gdr bench --plot FILE.svg: GPU ms per pass of the benchmark's rows, drawn by gnuplot (Debian's
 * gnuplot-nox) against scene size or, along a camera path, against the frame. */
#include "bench_plot.h"

#include "gdr/io.h"

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

/* A legend title fit for a data file's quoted column header: the rows may come from a results file
 * made elsewhere, so only letters, digits and a few punctuation marks are kept (no quote, backslash,
 * newline, dollar or at sign); anything else becomes '?'. */
static void legend_title(const char *run, const char *pass, char *out, size_t size)
{
    snprintf(out, size, "%.40s: %.40s", run, pass);
    for (char *c = out; *c; c++) {
        bool plain = (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
                     strchr(" _.:,+-()/", *c) != NULL;
        if (!plain)
            *c = '?';
    }
}

/* The distinct runs of the rows, in order of first appearance (at most PLOT_MAX_SERIES). */
static int distinct_runs(const cJSON *rows, char runs[][64])
{
    int run_count = 0;
    for (const cJSON *row = rows->child; row; row = row->next) {
        char label[64];
        run_label(row, label, sizeof label);
        int known = 0;
        for (int r = 0; r < run_count; r++)
            known |= strcmp(runs[r], label) == 0;
        if (!known && run_count < PLOT_MAX_SERIES)
            snprintf(runs[run_count++], 64, "%s", label);
    }
    return run_count;
}

/* One series' data file: its legend title as a quoted column header, then "x ms" lines. */
static bool write_series(const char *file, const cJSON *rows, const char *x_key, const char *run, const char *pass)
{
    FILE *f = fopen(file, "w");
    if (!f)
        return false;
    char title[96];
    legend_title(run, pass, title, sizeof title);
    fprintf(f, "\"%s\" \"ms\"\n", title);
    for (const cJSON *row = rows->child; row; row = row->next) {
        char label[64];
        run_label(row, label, sizeof label);
        const cJSON *x = cJSON_GetObjectItem(row, x_key);
        const cJSON *ms = cJSON_GetObjectItem(cJSON_GetObjectItem(row, "gpu_ms"), pass);
        if (strcmp(label, run) == 0 && cJSON_IsNumber(x) && cJSON_IsNumber(ms))
            fprintf(f, "%.17g %.9g\n", x->valuedouble, ms->valuedouble);
    }
    bool ok = !ferror(f);
    return fclose(f) == 0 && ok;
}

/* One data file per (run, pass) in `dir`, named series0.dat, series1.dat, ...; returns how many, or
 * -1 when one could not be written. */
static int write_series_files(const char *dir, const cJSON *rows, const char *x_key)
{
    char runs[PLOT_MAX_SERIES][64];
    int run_count = distinct_runs(rows, runs), series = 0;
    const cJSON *passes = cJSON_GetObjectItem(cJSON_GetArrayItem(rows, 0), "gpu_ms");
    for (int r = 0; r < run_count; r++) {
        for (const cJSON *pass = passes ? passes->child : NULL; pass && series < PLOT_MAX_SERIES; pass = pass->next) {
            char file[96];
            snprintf(file, sizeof file, "%s/series%d.dat", dir, series);
            if (!pass->string || !write_series(file, rows, x_key, runs[r], pass->string))
                return -1;
            series++;
        }
    }
    return series;
}

/* The script holds no text from the rows: every title and number reaches gnuplot as data, from the
 * series files, whose first line is the legend title (`title columnheader`). */
static gdr_status write_script(const char *dir, int series, bool along_path, gdr_error *err)
{
    char script[96];
    snprintf(script, sizeof script, "%s/plot.gp", dir);
    FILE *f = fopen(script, "w");
    if (!f)
        return gdr_error_set(err, GDR_ERROR_IO, "--plot: cannot write %s", script);
    fprintf(f, "set terminal svg size 960,600 dynamic noenhanced background rgb 'white'\nset output '%s/plot.svg'\n",
            dir);
    fprintf(f, "set title 'GPU ms per pass%s'\nset xlabel '%s'\nset ylabel 'GPU ms'\nset key outside right\n"
               "set grid\n%s",
            along_path ? " along the camera path" : " against scene size", along_path ? "frame" : "instances",
            along_path ? "" : "set logscale x\n");
    fprintf(f, "plot for [i=0:%d] sprintf('%s/series%%d.dat', i) using 1:2 with linespoints title columnheader(1)\n",
            series - 1, dir);
    bool ok = !ferror(f);
    return fclose(f) == 0 && ok ? GDR_OK : gdr_error_set(err, GDR_ERROR_IO, "--plot: cannot write %s", script);
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

static gdr_status copy_out(const char *from, const char *to, gdr_error *err)
{
    char *data;
    size_t size;
    gdr_status status = gdr_read_file(from, (size_t)1 << 30, &data, &size, err);
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
    /* A regular file only: a FIFO is refused at once, never waited on. */
    gdr_status status = gdr_read_file(json_path, (size_t)256 << 20, &text, &size, err);
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
    int series = write_series_files(dir, rows, along_path ? "frame" : "instances_total");
    gdr_status status = GDR_OK;
    if (series < 0)
        status = gdr_error_set(err, GDR_ERROR_IO, "--plot: cannot write the data files in %s", dir);
    else if (series == 0)
        status = gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "--plot: no GPU timings to plot");
    if (status == GDR_OK)
        status = write_script(dir, series, along_path, err);
    char script[96], svg[96];
    snprintf(script, sizeof script, "%s/plot.gp", dir);
    snprintf(svg, sizeof svg, "%s/plot.svg", dir);
    if (status == GDR_OK)
        status = run_gnuplot(script, err);
    if (status == GDR_OK)
        status = copy_out(svg, path, err);
    remove(script);
    remove(svg);
    for (int s = 0; s < PLOT_MAX_SERIES; s++) { /* those written, also when one failed */
        char file[96];
        snprintf(file, sizeof file, "%s/series%d.dat", dir, s);
        remove(file);
    }
    rmdir(dir);
    return status;
}
