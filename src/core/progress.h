/* A progress bar on stderr for long builds (import, cache writing, LOD DAG), drawn only on a
 * terminal and only once the work has taken 0.3 s. Not thread-safe: one thread updates a bar. */
#ifndef GDR_CORE_PROGRESS_H
#define GDR_CORE_PROGRESS_H

#include <stdint.h>

typedef struct gdr_progress {
    const char *label;
    uint64_t total;
    double start;
    int enabled, drawn, last_permille;
} gdr_progress;

void gdr_progress_begin(gdr_progress *p, const char *label, uint64_t total, int disabled);
void gdr_progress_update(gdr_progress *p, uint64_t done);
void gdr_progress_end(gdr_progress *p);

/* Seconds on the monotonic clock. */
double gdr_now_seconds(void);

#endif
