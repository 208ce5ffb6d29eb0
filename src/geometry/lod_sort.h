/* Sorting in the DAG build: lists of 32-bit ids (triangle references, position ids), each value
 * kept once, and records by a 64-bit key (the cluster graph's edges). */
#ifndef GDR_LOD_SORT_H
#define GDR_LOD_SORT_H

#include <stddef.h>
#include <stdint.h>

/* Sorts v[0 .. n) ascending and drops repeated values; returns how many distinct values are left
 * in front. `scratch` must hold n values (its contents are overwritten). The same result as qsort
 * followed by dropping repeats, in time linear in n (a least-significant-digit radix sort). */
size_t lod_sort_unique_u32(uint32_t *v, size_t n, uint32_t *scratch);

/* A 64-bit key with a payload. */
typedef struct key_record {
    uint64_t key;
    uint32_t value;
    uint32_t pad;
} key_record;

/* Sorts a[0 .. n) by key, stably (least-significant-digit radix over bytes; byte positions where
 * every key agrees are skipped). tmp must hold n records. */
void lod_sort_key_records(key_record *a, key_record *tmp, size_t n);

#endif
