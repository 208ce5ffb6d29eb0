/* Sphere and box against the frustum; validity of an object's bounds. */
#include <math.h>

#include "cull/cull_internal.h"

gdr_cull_outcome gdr_frustum_test_sphere(const gdr_frustum *frustum, gdr_vec3 center, float radius)
{
    int outside = 0, partly = 0;
    for (int i = 0; i < 8; i++) {
        float dist = frustum->px[i] * center.x + frustum->py[i] * center.y + frustum->pz[i] * center.z +
                     frustum->pd[i];
        outside |= dist < -radius;
        partly |= dist < radius;
    }
    return outside ? GDR_CULL_OUTSIDE : partly ? GDR_CULL_INTERSECTS : GDR_CULL_INSIDE;
}

gdr_cull_outcome gdr_frustum_test_box(const gdr_frustum *frustum, gdr_vec3 center, gdr_vec3 extent)
{
    return cull_box_classify(frustum, center, extent);
}

static bool finite3(gdr_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

bool cull_object_bounds_valid(const gdr_cull_object *o)
{
    if (!finite3(o->center) || !finite3(o->extent) || !isfinite(o->radius))
        return false;
    if (o->radius < 0.0f || o->extent.x < 0.0f || o->extent.y < 0.0f || o->extent.z < 0.0f)
        return false;
    /* empty: nothing to draw */
    return o->radius > 0.0f || o->extent.x > 0.0f || o->extent.y > 0.0f || o->extent.z > 0.0f;
}
