/* libFuzzer target: one geometry page of the scene cache (section 'PAGE', cache_pages.c), decoded
 * against an index entry made from the page's own header, so that the decoder (zstd frame,
 * cluster records, meshoptimizer's vertex and index streams, the triangle checks) sees every
 * mutation. Input: u16 clusters in the first of two groups (0: one group), u8 flags (bit 0:
 * compute the checksum the index would hold; else a wrong one, which must be refused), u8 unused,
 * u32 the clusters' vertex count in all (the index's; the header holds the page's shared ones),
 * then the page's bytes. A page that decodes must hold what its index entry says, every triangle
 * inside its cluster. The seed corpus/pages/page0.bin is page 0 of
 * `gdr build unique-field:meshes=1,triangles=1000 -o p.gdrc --pages=4` behind the prefix 0 0 1 0 and its vertex count,
 * written with float vertices; page0_quantized.bin the same page now that --pages quantizes them. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/paged_cache.h"
#include "io/cache_pages.h"
#include "io/io_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 8 + CACHE_PAGE_HEADER)
        return 0;
    const uint8_t *bytes = data + 8;
    size_t stored = size - 8;
    uint32_t h[8], expanded;
    memcpy(h, bytes, sizeof h);
    memcpy(&expanded, data + 4, 4);
    uint64_t clusters = h[3], vertices = expanded, triangles = h[5];
    /* What the index parser would have refused already. */
    if (clusters == 0 || vertices < clusters || vertices > clusters * GDR_CLUSTER_MAX_VERTICES ||
        triangles < clusters || triangles > clusters * GDR_CLUSTER_MAX_TRIANGLES ||
        clusters * CACHE_PAGE_CLUSTER_RECORD + vertices * sizeof(gdr_page_vertex) + triangles * 3 > CACHE_PAGE_MAX_RAW)
        return 0;
    uint32_t split = (uint32_t)(data[0] | data[1] << 8) % (uint32_t)clusters;
    gdr_page_group groups[2] = {{.error = INFINITY, .cluster_count = split ? split : (uint32_t)clusters},
                                {.error = 1.0f, .depth = 0, .cluster_count = (uint32_t)clusters - split}};
    uint32_t order[2] = {0, 1};
    gdr_page_info info = {.stored_size = (uint32_t)stored, .group_count = split ? 2u : 1u,
                          .cluster_count = (uint32_t)clusters, .vertex_count = (uint32_t)vertices,
                          .triangle_count = (uint32_t)triangles};
    int fix = data[2] & 1;
    info.checksum = gdr_io_hash(bytes, stored) ^ (fix ? 0u : 1u);
    /* Refined groups may name any group of the mesh: the index's count is what they are checked against. */
    gdr_paged_mesh pm = {.group_count = 1u << 16, .page_count = 1, .groups = groups, .page_groups = order, .pages = &info};
    gdr_page page;
    gdr_error err = {0};
    gdr_status status = cache_page_decode("fuzz.gdrc", 0, 0, &pm, bytes, stored, &page, &err);
    if (!fix && status == GDR_OK)
        abort(); /* a wrong checksum must be refused */
    if (status != GDR_OK) {
        if (getenv("FUZZ_PAGES_VERBOSE"))
            fprintf(stderr, "%s\n", err.message);
        return 0;
    }
    if (page.cluster_count != clusters || page.vertex_count != vertices)
        abort();
    for (uint32_t c = 0; c < page.cluster_count; c++) {
        const gdr_page_cluster *pc = &page.clusters[c];
        if (pc->vertex_offset + pc->vertex_count > page.vertex_count ||
            pc->triangle_offset + 3 * pc->triangle_count > page.triangle_byte_count)
            abort();
        for (uint32_t i = 0; i < 3 * pc->triangle_count; i++)
            if (page.triangles[pc->triangle_offset + i] >= pc->vertex_count)
                abort();
    }
    gdr_page_free(&page);
    return 0;
}
