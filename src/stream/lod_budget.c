/* The LOD threshold's factor that makes a streamed cut fit its pool (lod_budget.h). */
#include "stream/lod_budget.h"

#include <math.h>

#define STEP_LIMIT_START 2.0f
#define STEP_MIN 1.05f     /* a change smaller than this is not worth a round of loads */
#define FILL_TARGET 0.9f   /* a lowering aims at this share of the pool */
#define LIGHTER 0.75f      /* a cut this much lighter than where a lowering failed: try again */

void gdr_lod_budget_init(gdr_lod_budget *b)
{
    *b = (gdr_lod_budget){.scale = 1.0f, .step_limit = STEP_LIMIT_START};
}

static void set_scale(gdr_lod_budget *b, float scale)
{
    scale = scale < 1.0f ? 1.0f : scale > GDR_LOD_BUDGET_MAX_SCALE ? GDR_LOD_BUDGET_MAX_SCALE : scale;
    if (scale != b->scale)
        b->changes++;
    b->scale = scale;
}

/* The cut needs more than the pool: back from a failed lowering, else up by the model. */
static void raise_scale(gdr_lod_budget *b, const gdr_lod_budget_observation *o)
{
    if (b->trial_from > 0.0f) {
        b->step_limit = sqrtf(b->trial_from / b->trial_to);
        b->failed_wanted = b->trial_wanted;
        set_scale(b, b->trial_from);
        b->trial_from = 0.0f;
        return;
    }
    float room = o->capacity > o->pinned ? (float)(o->capacity - o->pinned) : 1.0f;
    float excess = (float)(o->wanted - o->pinned) / room; /* wanted > capacity >= pinned */
    float step = sqrtf(excess) * 1.05f;
    step = step < 1.1f ? 1.1f : step > 4.0f ? 4.0f : step;
    b->step_limit = STEP_LIMIT_START;
    set_scale(b, b->scale * step);
}

/* A lowering to `scale` (not below 1), on trial until a cut drawn with it is read back; none when it
 * would change the factor by less than STEP_MIN and not reach 1. */
static void start_trial(gdr_lod_budget *b, const gdr_lod_budget_observation *o, float scale)
{
    scale = scale < 1.0f ? 1.0f : scale;
    if (scale > 1.0f && b->scale / scale < STEP_MIN)
        return;
    b->trial_from = b->scale;
    b->trial_to = scale;
    b->trial_wanted = o->wanted;
    set_scale(b, scale);
}

/* The cut at this factor is resident and fits: lower it where the model says it still fits. */
static void lower_scale(gdr_lod_budget *b, const gdr_lod_budget_observation *o)
{
    b->trial_from = 0.0f; /* a lowering on trial has held */
    if (b->failed_wanted && (float)o->wanted < LIGHTER * (float)b->failed_wanted) {
        b->failed_wanted = 0;
        b->step_limit = STEP_LIMIT_START;
    }
    if (b->scale <= 1.0f || b->step_limit < STEP_MIN)
        return;
    float used = (float)o->wanted - (float)o->pinned;
    if (used <= 0.0f) { /* the cut is all in the pinned pages: no model, the largest step */
        start_trial(b, o, b->scale / b->step_limit);
        return;
    }
    /* The requested threshold where the model says its cut fits the whole pool, else a lower factor
     * whose cut fills FILL_TARGET of it. */
    float target = used * b->scale * b->scale <= (float)(o->capacity - o->pinned)
                       ? used * b->scale * b->scale
                       : FILL_TARGET * (float)o->capacity - (float)o->pinned;
    if (target <= used)
        return;
    float step = sqrtf(target / used);
    start_trial(b, o, b->scale / (step > b->step_limit ? b->step_limit : step));
}

bool gdr_lod_budget_update(gdr_lod_budget *b, const gdr_lod_budget_observation *o)
{
    uint32_t changes = b->changes;
    if (o->all_resident) {
        b->trial_from = 0.0f;
        set_scale(b, 1.0f);
    } else if (o->known && o->scale == b->scale) {
        if (o->wanted > o->capacity)
            raise_scale(b, o);
        else if (o->requests == 0)
            lower_scale(b, o);
    }
    return b->changes != changes;
}
