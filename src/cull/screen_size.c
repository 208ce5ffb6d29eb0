/* Screen-size culling: the projected size of the bounding sphere, about its diameter over the
 * viewport height (UE5's screen size: max(P00, P11) * r / distance). */
#include <math.h>

#include "cull/cull_internal.h"

float cull_screen_size(float screen_scale, float radius, float center_distance)
{
    if (center_distance <= radius)
        return INFINITY; /* the camera is inside the sphere: it covers the screen */
    return screen_scale * radius / center_distance;
}

bool cull_screen_size_visible(float size, float view_min, const gdr_cull_object *o)
{
    if (o->min_screen_size > 0.0f && size < o->min_screen_size)
        return false;
    if (view_min > 0.0f && size < view_min)
        return false;
    return !(o->max_screen_size > 0.0f && size >= o->max_screen_size);
}
