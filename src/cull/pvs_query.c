/* Precomputed visibility lookups (placeholder until the bake lands). */
#include "cull/cull_internal.h"

uint32_t gdr_pvs_object_count(const gdr_pvs *pvs) { (void)pvs; return 0; }
const gdr_pvs *gdr_pvs_cache_pvs(const gdr_pvs_cache *cache) { (void)cache; return NULL; }
const uint32_t *gdr_pvs_lookup(gdr_pvs_cache *cache, gdr_vec3 point) { (void)cache; (void)point; return NULL; }
