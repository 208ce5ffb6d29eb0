/* Distance culling with minimum and maximum draw distances and a fade band (UE5's
 * MinDrawDistance / MaxDrawDistance / FadeRadius, written with plain distances). */
#include <math.h>

#include "cull/cull_internal.h"

bool cull_distance_visible(const cull_distance_params *p, const gdr_cull_object *o, float center_distance,
                           bool *fading)
{
    float closest = center_distance, farthest = center_distance;
    if (p->to_sphere_edge) {
        /* Huge objects (a wall, a river) stay while any part of their sphere is in range. */
        closest = fmaxf(center_distance - o->radius, 0.0f);
        farthest = center_distance + o->radius;
    }
    float max_distance = o->max_draw_distance * p->scale;
    float min_distance = o->min_draw_distance * p->scale;
    bool has_max = o->max_draw_distance > 0.0f, has_min = o->min_draw_distance > 0.0f;
    if (has_max && closest > max_distance)
        return false;
    if (has_min && farthest < min_distance)
        return false;
    *fading = p->fade_range > 0.0f && ((has_max && closest > max_distance - p->fade_range) ||
                                       (has_min && farthest < min_distance + p->fade_range));
    return true;
}
