#include "core/progress.h"

#include <stdio.h>
#include <time.h>
#include <unistd.h>

double gdr_now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

void gdr_progress_begin(gdr_progress *p, const char *label, uint64_t total, int disabled)
{
    *p = (gdr_progress){.label = label, .total = total ? total : 1, .start = gdr_now_seconds(), .last_permille = -1};
    p->enabled = !disabled && isatty(STDERR_FILENO);
}

void gdr_progress_update(gdr_progress *p, uint64_t done)
{
    if (!p->enabled)
        return;
    double elapsed = gdr_now_seconds() - p->start;
    if (!p->drawn && elapsed < 0.3)
        return;
    int permille = (int)(done >= p->total ? 1000 : done * 1000 / p->total);
    if (permille == p->last_permille)
        return;
    p->last_permille = permille;
    p->drawn = 1;
    enum { WIDTH = 32 };
    char bar[WIDTH + 1];
    int filled = permille * WIDTH / 1000;
    for (int i = 0; i < WIDTH; i++)
        bar[i] = i < filled ? '#' : '.';
    bar[WIDTH] = 0;
    fprintf(stderr, "\r%-12s [%s] %5.1f%%  %.1f s", p->label, bar, permille / 10.0, elapsed);
    fflush(stderr);
}

void gdr_progress_end(gdr_progress *p)
{
    if (p->enabled && p->drawn) {
        p->last_permille = -1;
        gdr_progress_update(p, p->total);
        fputc('\n', stderr);
    }
}
