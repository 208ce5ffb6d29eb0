/* The one definition of a material's sound values, shared by everything that makes or reads one:
 * gdr_scene_add_material (so every importer and the API), the cache writer and the cache reader.
 * A value an importer cannot hold (a factor of 1e300 is +inf as a float) is refused where it is
 * read, never written into a cache that the reader would then refuse. */
#include <math.h>
#include <stddef.h>

#include "gdr/scene.h"

static int finite_floats(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

static int texture_ref_sound(const gdr_texture_ref *t)
{
    const float transform[5] = {t->offset.x, t->offset.y, t->scale.x, t->scale.y, t->rotation};
    return t->sampler < GDR_SAMPLER_STATES && finite_floats(transform, 5);
}

const char *gdr_material_problem(const gdr_material *m)
{
    const float factors[5] = {m->metallic_factor, m->roughness_factor, m->normal_scale, m->occlusion_strength,
                              m->alpha_cutoff};
    static const char *const factor_problems[5] = {"metallic factor is not finite", "roughness factor is not finite",
                                                   "normal scale is not finite", "occlusion strength is not finite",
                                                   "alpha cutoff is not finite"};
    if (!finite_floats(&m->base_color.x, 4))
        return "base colour factor is not finite";
    if (!finite_floats(&m->emissive.x, 3))
        return "emissive factor (times its strength) is not finite";
    for (int k = 0; k < 5; k++)
        if (!isfinite(factors[k]))
            return factor_problems[k];
    const gdr_texture_ref *refs[5] = {&m->base_color_texture, &m->metallic_roughness_texture, &m->normal_texture,
                                      &m->occlusion_texture, &m->emissive_texture};
    for (int k = 0; k < 5; k++)
        if (!texture_ref_sound(refs[k]))
            return "a texture's sampler state or transform is out of range";
    if (m->alpha_mode > GDR_ALPHA_BLEND)
        return "alpha mode is not OPAQUE, MASK or BLEND";
    if (m->double_sided > 1)
        return "double-sided is neither 0 nor 1";
    return NULL;
}
