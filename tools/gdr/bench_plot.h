/* Plots of gdr bench's rows (gnuplot) and its runs along a camera path. */
#ifndef GDR_BENCH_PLOT_H
#define GDR_BENCH_PLOT_H

#include <stdbool.h>

#include <cjson/cJSON.h>

#include "camera_path.h"
#include "gdr/gdr.h"

/* Writes an SVG of GPU ms per pass: one line per run (pipeline, LOD threshold, occlusion) and pass,
 * against instances_total, or against `frame` when along_path. Needs gnuplot. */
gdr_status bench_plot_svg(const char *path, const cJSON *rows, bool along_path, gdr_error *err);

/* The plot of rows a gdr bench --json run wrote (against the frame where the rows have "frame"). */
gdr_status bench_plot_from_json(const char *json_path, const char *svg_path, gdr_error *err);

/* Renders one frame per pose of the path (after 3 untimed frames at its first pose), printing a
 * line per frame and adding a JSON row per frame ("frame", "gpu_ms" per pass, "gpu_ms_per_frame",
 * "cpu_ms_per_frame", the counts) to rows. */
gdr_status bench_run_path(gdr_renderer *renderer, gdr_frame_desc *frame, const camera_path *path, cJSON *rows,
                          gdr_error *err);

#endif
