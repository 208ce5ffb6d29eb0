/* Exact heap accounting for the benchmarks: heap_count.c wraps malloc/calloc/realloc/free (glibc's
 * __libc_* entry points) in every library of the program (meshoptimizer and METIS included) and
 * tracks the bytes in use (malloc_usable_size) and their peak. Link it into one benchmark only. */
#ifndef GDR_BENCH_HEAP_COUNT_H
#define GDR_BENCH_HEAP_COUNT_H

/* Bytes in use now. */
long long heap_in_use(void);
/* Restarts the peak from what is in use now; returns that. */
long long heap_peak_reset(void);
/* The most bytes in use since the last reset. */
long long heap_peak(void);

#endif
