/* Sorting the DAG build's lists of 32-bit ids (triangle references, position ids) and keeping each
 * value once. */
#ifndef GDR_LOD_SORT_H
#define GDR_LOD_SORT_H

#include <stddef.h>
#include <stdint.h>

/* Sorts v[0 .. n) ascending and drops repeated values; returns how many distinct values are left
 * in front. `scratch` must hold n values (its contents are overwritten). The same result as qsort
 * followed by dropping repeats, in time linear in n (a least-significant-digit radix sort). */
size_t lod_sort_unique_u32(uint32_t *v, size_t n, uint32_t *scratch);

#endif
