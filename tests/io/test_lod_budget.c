/* The rule that fits a streamed cut to its pool (src/stream/lod_budget.c, docs/STREAMING.md), on
 * models of a cut: pages needed at factor s, read back two frames late, with pages arriving a few
 * frames after the factor changes. For cuts whose pages fall with the square of the factor (the
 * rule's model) and with its first power (a cut the model misjudges): the factor settles (no change
 * in the last 100 of 200 frames), the settled cut fits the pool, the factor is within 15% (square
 * model) or 40% (first power) of the least that fits, it changes a bounded number of times, and
 * when the view gets lighter (the camera moves back) it returns to 1. A pool that holds the pinned
 * pages alone drives the factor up until the cut needs only those. */
#include <math.h>

#include "stream/lod_budget.h"
#include "test_util.h"

#define LAG 2          /* frames between drawing and reading back */
#define ARRIVAL 3      /* frames a new cut's pages take to arrive */

typedef struct model {
    double k, power;   /* pages beyond the pinned at factor s: ceil(k / s^power) */
    uint32_t pinned, capacity;
} model;

static uint32_t pages(const model *m, float s)
{
    return m->pinned + (uint32_t)(m->k / pow(s, m->power));
}

/* Runs `frames` frames; returns the frame of the last change of the factor. */
static uint32_t run(gdr_lod_budget *b, const model *m, uint32_t frames, float *drawn_scales)
{
    uint32_t last_change = 0, stable_since = 0;
    for (uint32_t f = 0; f < frames; f++) {
        if (f >= LAG) {
            float s = drawn_scales[(f - LAG) % 8];
            uint32_t wanted = pages(m, s);
            /* The cut's pages arrive ARRIVAL frames after the factor last changed, where they fit;
             * until then the cut asks for them. */
            bool arrived = f - LAG >= stable_since + ARRIVAL && wanted <= m->capacity;
            gdr_lod_budget_observation o = {.scale = s, .known = true, .wanted = wanted,
                                            .requests = arrived ? 0 : 1, .capacity = m->capacity,
                                            .pinned = m->pinned};
            if (gdr_lod_budget_update(b, &o))
                last_change = f, stable_since = f;
        }
        drawn_scales[f % 8] = b->scale;
    }
    return last_change;
}

/* The least factor (to 0.1%) whose cut fits the pool. */
static float least_fitting(const model *m)
{
    float s = 1.0f;
    while (pages(m, s) > m->capacity && s < GDR_LOD_BUDGET_MAX_SCALE)
        s *= 1.001f;
    return s;
}

static void settles(double power, double k, uint32_t capacity, double tolerance, uint32_t max_changes)
{
    model m = {.k = k, .power = power, .pinned = 12, .capacity = capacity};
    gdr_lod_budget b;
    gdr_lod_budget_init(&b);
    float drawn[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    uint32_t last = run(&b, &m, 200, drawn);
    float best = least_fitting(&m);
    printf("pages ~ 1/s^%g, %g pages beyond the pinned, %u slots: factor %.3f (least fitting %.3f), %u changes, "
           "the last in frame %u\n", power, k, capacity, (double)b.scale, (double)best, b.changes, last);
    CHECK(last < 100);
    CHECK(pages(&m, b.scale) <= capacity);
    CHECK(b.scale <= best * (1.0 + tolerance) && b.scale >= best * 0.999f);
    CHECK(b.changes <= max_changes);
    /* The camera moves back: the cut needs a tenth of the pages; the factor returns to 1. */
    m.k = k / 10.0 < capacity - m.pinned ? k / 10.0 : (capacity - m.pinned) * 0.5;
    run(&b, &m, 100, drawn);
    printf("  lighter view: factor %.3f\n", (double)b.scale);
    CHECK(b.scale == 1.0f);
}

int main(void)
{
    for (int fraction = 2; fraction <= 8; fraction *= 2) {
        settles(2.0, 70.0, 12 + 70 / fraction, 0.15, 16);
        settles(1.0, 70.0, 12 + 70 / fraction, 0.40, 16);
    }
    settles(2.0, 5000.0, 40, 0.15, 24); /* far over: steps of up to x4 */

    /* Room for the pinned pages alone: the factor rises until the cut needs only those. */
    model m = {.k = 70.0, .power = 2.0, .pinned = 12, .capacity = 12};
    gdr_lod_budget b;
    gdr_lod_budget_init(&b);
    float drawn[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    run(&b, &m, 400, drawn);
    printf("room for the pinned pages alone: factor %.1f, %u pages\n", (double)b.scale, pages(&m, b.scale));
    CHECK(b.scale < GDR_LOD_BUDGET_MAX_SCALE && pages(&m, b.scale) <= m.capacity);

    /* Every group resident: the factor is 1 at once; observations of an older factor change nothing. */
    b.scale = 3.0f;
    gdr_lod_budget_observation stale = {.scale = 2.0f, .known = true, .wanted = 100, .capacity = 20, .pinned = 12};
    CHECK(!gdr_lod_budget_update(&b, &stale) && b.scale == 3.0f);
    gdr_lod_budget_observation all = {.scale = 3.0f, .all_resident = true, .capacity = 20, .pinned = 12};
    CHECK(gdr_lod_budget_update(&b, &all) && b.scale == 1.0f);
    return test_finish("test_lod_budget");
}
