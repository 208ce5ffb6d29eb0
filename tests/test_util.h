/* A minimal test harness: CHECK records a failure and continues; main returns test_failures(). */
#ifndef GDR_TEST_UTIL_H
#define GDR_TEST_UTIL_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "gdr/core.h"

static int test_failure_count;

#define CHECK(cond)                                                                    \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);   \
            test_failure_count++;                                                      \
        }                                                                              \
    } while (0)

/* CHECK with a printf-style message saying what was found. */
#define CHECK_MSG(cond, ...)                                                           \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "%s:%d: ", __FILE__, __LINE__);                            \
            fprintf(stderr, __VA_ARGS__);                                              \
            fprintf(stderr, "\n");                                                     \
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

/* The error `err` (a gdr_error) holds the status `code`; on a mismatch, says both and the message. */
#define CHECK_STATUS(err, code) check_status_(&(err), (code), __FILE__, __LINE__)

/* `call` returns the status `code` and fills `err` (a gdr_error) with it. */
#define CHECK_FAILS(call, err, code)                                                                   \
    do {                                                                                               \
        gdr_status check_returned_ = (call);                                                           \
        if (check_returned_ != (code)) {                                                               \
            fprintf(stderr, "%s:%d: CHECK_FAILS: %s returned %s, expected %s: %s\n", __FILE__, __LINE__, \
                    #call, gdr_status_name(check_returned_), gdr_status_name(code), (err).message);       \
            test_failure_count++;                                                                      \
        } else {                                                                                       \
            check_status_(&(err), (code), __FILE__, __LINE__);                                         \
        }                                                                                              \
    } while (0)

/* The message of `err` names `place` (a file, a line, a JSON path, a section): what errors
 * promise to say (docs/SECURITY.md). What went wrong is the status's to say, not the wording's. */
#define CHECK_NAMES(err, place) check_names_(&(err), (place), __FILE__, __LINE__)

static inline void check_status_(const gdr_error *err, gdr_status code, const char *file, int line)
{
    if (err->status != code) {
        fprintf(stderr, "%s:%d: CHECK_STATUS failed: %s, expected %s: %s\n", file, line, gdr_status_name(err->status),
                gdr_status_name(code), err->message);
        test_failure_count++;
    }
}

static inline void check_names_(const gdr_error *err, const char *place, const char *file, int line)
{
    if (!strstr(err->message, place)) {
        fprintf(stderr, "%s:%d: CHECK_NAMES failed: '%s' not in: %s\n", file, line, place, err->message);
        test_failure_count++;
    }
}

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

/* A deterministic value in [0, 1) from an index (an integer hash), for inputs made per element. */
static inline float test_hash_unit(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return (float)(x >> 8) / 16777216.0f;
}

static inline float test_random_range(unsigned *state, float lo, float hi)
{
    return lo + (hi - lo) * test_random(state);
}

#endif
