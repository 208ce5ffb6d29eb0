/* The DAG build's sort of id lists (src/geometry/lod_sort.h): sorted and each value once, as qsort
 * and dropping repeats give, for short and long lists, few and many repeats, values that share
 * their high bits (the digits the sort skips) and values that use all 32 bits. */
#include <stdint.h>
#include <stdlib.h>

#include "geometry/lod_sort.h"
#include "test_util.h"

static int compare_u32(const void *x, const void *y)
{
    uint32_t a = *(const uint32_t *)x, b = *(const uint32_t *)y;
    return a < b ? -1 : a > b;
}

/* A deterministic 32-bit generator (xorshift). */
static uint32_t next_random(uint32_t *state)
{
    uint32_t x = *state;
    x ^= x << 13, x ^= x >> 17, x ^= x << 5;
    return *state = x;
}

/* n values of random bits under `mask` plus `base`, sorted both ways: the same values, the same
 * count. */
static void check_list(size_t n, uint32_t base, uint32_t mask, uint32_t seed)
{
    uint32_t *v = malloc((n + 1) * sizeof *v), *expected = malloc((n + 1) * sizeof *v),
             *scratch = malloc((n + 1) * sizeof *v);
    CHECK(v && expected && scratch);
    if (!v || !expected || !scratch)
        goto done;
    for (size_t i = 0; i < n; i++)
        v[i] = expected[i] = base + (next_random(&seed) & mask);
    qsort(expected, n, sizeof *expected, compare_u32);
    size_t unique = 0;
    for (size_t i = 0; i < n; i++)
        if (i == 0 || expected[i] != expected[unique - 1])
            expected[unique++] = expected[i];
    size_t got = lod_sort_unique_u32(v, n, scratch);
    CHECK_MSG(got == unique, "n %zu base %u mask %x: %zu distinct values, expected %zu", n, base, mask, got, unique);
    int same = got == unique;
    for (size_t i = 0; same && i < got; i++)
        same = v[i] == expected[i];
    CHECK_MSG(same, "n %zu base %u mask %x: not the sorted distinct values", n, base, mask);
done:
    free(v);
    free(expected);
    free(scratch);
}

int main(void)
{
    static const size_t sizes[] = {0, 1, 2, 47, 48, 49, 1000, 65536, 300000};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        size_t n = sizes[k];
        check_list(n, 0, UINT32_MAX, 1u + (uint32_t)k);            /* all 32 bits, few repeats */
        check_list(n, 0, 0x3fffffffu, 7u + (uint32_t)k);           /* triangle references: 30 bits */
        check_list(n, 0x12340000u, 0xffffu, 11u + (uint32_t)k);    /* shared high digits */
        check_list(n, 5u, 0x3fu, 13u + (uint32_t)k);               /* many repeats */
        check_list(n, 0x80000000u, 0x801ff800u, 17u + (uint32_t)k); /* only middle and top digits vary */
        check_list(n, 42u, 0, 19u + (uint32_t)k);                   /* one value */
    }
    return test_finish("test_lod_sort");
}
