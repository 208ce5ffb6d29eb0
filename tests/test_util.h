/* A minimal test harness: CHECK records a failure and continues; main returns test_failures(). */
#ifndef GDR_TEST_UTIL_H
#define GDR_TEST_UTIL_H

#include <math.h>
#include <stdio.h>

static int test_failure_count;

#define CHECK(cond)                                                                    \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);   \
            test_failure_count++;                                                      \
        }                                                                              \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                                    \
    do {                                                                                         \
        double check_a_ = (a), check_b_ = (b);                                                   \
        if (!(fabs(check_a_ - check_b_) <= (tol))) {                                             \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.9g, %s = %.9g (tolerance %g)\n",  \
                    __FILE__, __LINE__, #a, check_a_, #b, check_b_, (double)(tol));              \
            test_failure_count++;                                                                \
        }                                                                                        \
    } while (0)

static inline int test_finish(const char *name)
{
    if (test_failure_count)
        fprintf(stderr, "%s: %d check(s) failed\n", name, test_failure_count);
    else
        printf("%s: all checks passed\n", name);
    return test_failure_count ? 1 : 0;
}

/* Deterministic pseudo-random numbers for tests (xorshift32). */
static inline float test_random(unsigned *state)
{
    unsigned x = *state;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *state = x;
    return (float)(x >> 8) / 16777216.0f;
}

static inline float test_random_range(unsigned *state, float lo, float hi)
{
    return lo + (hi - lo) * test_random(state);
}

#endif
