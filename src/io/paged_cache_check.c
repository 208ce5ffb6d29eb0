/* A paged cache against the scene read from the same file (gdr_paged_cache_check_scene): the check
 * streaming makes before it sizes anything from the pages, here without a GPU so that the fuzzer
 * reaches it through the same path as the streaming open. */
#include <stdint.h>

#include "gdr/paged_cache.h"

gdr_status gdr_paged_cache_check_scene(const gdr_paged_cache *cache, const gdr_scene *scene, const char *path,
                                       gdr_error *err)
{
    if (gdr_paged_cache_mesh_count(cache) != scene->mesh_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: %u meshes, the scene has %u: not its cache", path,
                             gdr_paged_cache_mesh_count(cache), scene->mesh_count);
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const gdr_mesh_clusters *c = &scene->meshes[m].clusters;
        const gdr_paged_mesh *pm = gdr_paged_cache_mesh(cache, m);
        if (pm->group_count != c->group_count || (c->cluster_count > 0 && c->group_count == 0))
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: mesh %u has %u LOD groups, the scene's %u "
                                 "(streaming needs every mesh's LOD DAG)", path, m, pm->group_count, c->group_count);
        for (uint32_t p = 0; p < pm->page_count; p++) {
            const gdr_page_info *info = &pm->pages[p];
            uint64_t clusters = 0;
            for (uint32_t k = info->first; k < info->first + info->group_count; k++)
                clusters += c->groups[pm->page_groups[k]].cluster_count;
            if (clusters != info->cluster_count)
                return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: mesh %u page %u holds %u clusters, the "
                                     "scene's groups %llu: not its cache", path, m, p, info->cluster_count,
                                     (unsigned long long)clusters);
        }
    }
    return GDR_OK;
}
