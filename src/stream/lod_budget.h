/* A cut that fits the pool (docs/STREAMING.md, "A cut that fits the pool"): the factor by which a
 * streamed frame's LOD threshold is raised so that the pages its cut needs fit the page pool.
 *
 * Observations come from frames read back two frames late. Only those drawn at the current factor
 * count (the others describe a cut that is no longer asked for), so the factor changes at most
 * once per round trip and never chases its own lag. The rule, global with hysteresis:
 *  - over: the observed cut needs more pages than the pool has slots. The factor rises by the
 *    square root of the excess (a cut's clusters fall with the square of the threshold), at least
 *    10% and at most 4x a step. If that cut came from a lowering still on trial, the factor goes
 *    back to where it was before the lowering instead, and the next lowering may take only half
 *    that step (in log scale): a binary search that ends when the step falls below 5%;
 *  - settled: nothing requested, every page of the cut resident. A lowering on trial has
 *    succeeded. If the factor is above 1, it falls to where the same model predicts that the cut
 *    fills 90% of the pool, by at most the step allowed (2x at first), and only by 5% or more;
 *  - the step allowed goes back to 2x when a settled cut needs less than three quarters of the
 *    pages it needed when a lowering last failed (the view got lighter: the camera moved back),
 *    or when the factor had to rise for a cut that was not on trial (the view got heavier);
 *  - every group resident (the whole scene fits): the factor is 1.
 * Between these, while pages are loading and the cut fits, nothing changes: a lagging upload
 * budget does not raise the threshold, since the cut over resident groups already draws the best
 * geometry there is and requests are served by priority. With a still camera the factor changes a
 * bounded number of times and then stays: no lowering is tried twice from the same cut. */
#ifndef GDR_STREAM_LOD_BUDGET_H
#define GDR_STREAM_LOD_BUDGET_H

#include <stdbool.h>
#include <stdint.h>

#define GDR_LOD_BUDGET_MAX_SCALE 65536.0f

typedef struct gdr_lod_budget {
    float scale;          /* >= 1: the factor on the frame's LOD threshold */
    float step_limit;     /* the largest factor one lowering may divide by */
    float trial_from;     /* a lowering on trial: the factor before it (0: none) */
    float trial_to;
    uint32_t trial_wanted; /* pages the cut needed before that lowering */
    uint32_t failed_wanted; /* pages the cut needed where a lowering last failed (0: none) */
    uint32_t changes;     /* times the factor changed */
} gdr_lod_budget;

/* One frame read back. */
typedef struct gdr_lod_budget_observation {
    float scale;          /* the factor that frame was drawn with */
    bool known;           /* its cut was read back (some group was absent when it was drawn) */
    bool all_resident;    /* no group is absent now */
    uint32_t wanted;      /* pages its cut needs: those it drew and asked for, with their ancestors' */
    uint32_t requests;    /* the groups it asked for */
    uint32_t capacity;    /* the pool's slots */
    uint32_t pinned;      /* pages always resident (they scale with nothing) */
} gdr_lod_budget_observation;

void gdr_lod_budget_init(gdr_lod_budget *b);
/* Applies one observation; returns true when the factor changed. */
bool gdr_lod_budget_update(gdr_lod_budget *b, const gdr_lod_budget_observation *o);

#endif
