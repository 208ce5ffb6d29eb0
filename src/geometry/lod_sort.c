/* Sorting for the DAG build (lod_sort.h).
 *
 * The error measurement collects the level-0 triangles around a group's samples or corners (each
 * listed once per corner it has there) and needs them sorted and each once; qsort's comparisons
 * through a function pointer cost 3% of a build's instructions. A radix sort over 11-bit digits
 * takes at most three passes over the list, and passes over digits that every value shares (the
 * high digits of a small mesh's ids) are skipped. */
#include "geometry/lod_sort.h"

#include <string.h>

#define DIGIT_BITS 11
#define DIGITS (1u << DIGIT_BITS)

/* Below this many values an insertion sort costs less than clearing the digit counts. */
#define SMALL_LIST 48

static void insertion_sort(uint32_t *v, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        uint32_t x = v[i];
        size_t j = i;
        for (; j > 0 && v[j - 1] > x; j--)
            v[j] = v[j - 1];
        v[j] = x;
    }
}

/* One stable counting pass over the digit at `shift`, from `from` into `to`. */
static void radix_pass(const uint32_t *from, uint32_t *to, size_t n, unsigned shift)
{
    size_t count[DIGITS];
    memset(count, 0, sizeof count);
    for (size_t i = 0; i < n; i++)
        count[from[i] >> shift & (DIGITS - 1)]++;
    size_t sum = 0;
    for (uint32_t d = 0; d < DIGITS; d++) {
        size_t c = count[d];
        count[d] = sum;
        sum += c;
    }
    for (size_t i = 0; i < n; i++)
        to[count[from[i] >> shift & (DIGITS - 1)]++] = from[i];
}

static size_t drop_repeats(uint32_t *v, size_t n)
{
    size_t unique = 0;
    for (size_t i = 0; i < n; i++)
        if (i == 0 || v[i] != v[unique - 1])
            v[unique++] = v[i];
    return unique;
}

size_t lod_sort_unique_u32(uint32_t *v, size_t n, uint32_t *scratch)
{
    if (n < SMALL_LIST) {
        insertion_sort(v, n);
        return drop_repeats(v, n);
    }
    uint32_t all = 0, any = 0; /* the bits every value has, and the bits some value has */
    all = ~all;
    for (size_t i = 0; i < n; i++)
        all &= v[i], any |= v[i];
    uint32_t varying = all ^ any; /* bits that differ between some two values */
    uint32_t *from = v, *to = scratch;
    for (unsigned shift = 0; shift < 32; shift += DIGIT_BITS) {
        if (!(varying >> shift & (DIGITS - 1)))
            continue; /* every value has the same digit here: the order is that of the last pass */
        radix_pass(from, to, n, shift);
        uint32_t *t = from;
        from = to;
        to = t;
    }
    if (from != v)
        memcpy(v, from, n * sizeof *v);
    return drop_repeats(v, n);
}

void lod_sort_key_records(key_record *a, key_record *tmp, size_t n)
{
    for (int shift = 0; shift < 64; shift += 8) {
        size_t count[256] = {0};
        for (size_t i = 0; i < n; i++)
            count[(a[i].key >> shift) & 255]++;
        if (n == 0 || count[(a[0].key >> shift) & 255] == n)
            continue;
        size_t sum = 0;
        for (int d = 0; d < 256; d++) {
            size_t c = count[d];
            count[d] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++)
            tmp[count[(a[i].key >> shift) & 255]++] = a[i];
        memcpy(a, tmp, n * sizeof *a);
    }
}
