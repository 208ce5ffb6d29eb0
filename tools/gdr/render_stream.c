/* gdr render and gdr view: the scene read and set, uploaded whole or streamed (docs/STREAMING.md). */
#include "gdr/gdr.h"
#include "gdr/io.h"
#include "render_options.h"

bool render_options_streamed(const render_options *o) { return o->geometry_budget_mib || o->upload_budget_mib; }

gdr_status render_options_load(render_options *o, gdr_scene **scene, gdr_error *err)
{
    o->paged_cache[0] = '\0';
    o->load.geometry_in_pages = render_options_streamed(o);
    o->load.cache_path = o->paged_cache;
    o->load.cache_path_size = sizeof o->paged_cache;
    return gdr_scene_load(o->scene, &o->load, scene, err);
}

gdr_status render_options_set_scene(gdr_renderer *renderer, const gdr_scene *scene, const render_options *o,
                                    gdr_paged_cache **paged, gdr_error *err)
{
    if (!render_options_streamed(o))
        return gdr_renderer_set_scene(renderer, scene, err);
    gdr_status status = gdr_paged_cache_open(o->paged_cache, paged, err);
    if (status != GDR_OK)
        return status;
    gdr_streaming_desc stream = {.cache = *paged,
                                 .geometry_budget_bytes = (uint64_t)o->geometry_budget_mib << 20,
                                 .upload_budget_bytes = (uint64_t)o->upload_budget_mib << 20};
    return gdr_renderer_set_scene_streamed(renderer, scene, &stream, err);
}
