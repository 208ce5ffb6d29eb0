/* Which geometry pages are resident in a GPU page pool of fixed size, and which to load and evict
 * next (docs/STREAMING.md). The pool is `budget_bytes` cut into slots of the scene's largest
 * decoded page; each resident page holds one slot. Three rules keep every frame's LOD cut valid
 * and bounded:
 *  - closure: a page becomes resident only after the pages holding the parents (in the DAG) of
 *    its groups; so along every DAG path the resident groups are a prefix from the root, and the
 *    streaming cut rule (a group that is absent counts as passing) draws exactly one cluster per
 *    path: never a hole, never a crack;
 *  - a page is evicted only when no resident page holds a child of its groups, it is not pinned
 *    (every mesh's page 0, with its root group, is resident from the start and never leaves), and
 *    it was not used by the latest frame's cut; of those, the one unused for longest goes first;
 *  - the pages loaded in one frame hold at most `upload_budget_bytes` decoded bytes (at least one
 *    page a frame, so that a page larger than the budget still loads).
 * Single-threaded: the caller owns it (the loader thread only reads and decodes pages). */
#ifndef GDR_STREAM_RESIDENCY_H
#define GDR_STREAM_RESIDENCY_H

#include <stdint.h>

#include "gdr/core.h"
#include "gdr/paged_cache.h"
#include "gdr/thread_pool.h"

/* A group the GPU wanted and found absent; larger priority first (e.g. its projected error). */
typedef struct gdr_stream_request {
    uint32_t mesh, group;
    float priority;
} gdr_stream_request;

/* A page to load into `slot` (decode it, upload it, then gdr_residency_loaded). */
typedef struct gdr_stream_load {
    uint32_t mesh, page, slot;
} gdr_stream_load;

typedef struct gdr_residency_stats {
    uint64_t resident_bytes;     /* slots held, in bytes */
    uint32_t resident_pages;
    uint32_t pinned_pages;
    uint32_t requests;           /* distinct groups asked for this frame */
    uint32_t loads;              /* pages planned for loading this frame */
    uint64_t load_bytes;         /* their decoded bytes */
    uint32_t evictions;          /* this frame */
    uint32_t deferred;           /* requests left for later frames (upload budget or no free slot) */
    uint32_t frames_since_change; /* frames since a page last became resident or left */
    uint64_t evicted_in_use;     /* debug counter: evictions of a pinned page, a page the latest cut
                                    used or one with a resident child; must stay 0 */
} gdr_residency_stats;

typedef struct gdr_residency_desc {
    const gdr_paged_cache *cache;
    uint64_t budget_bytes;        /* the pool: at least every mesh's page 0 */
    uint64_t upload_budget_bytes; /* decoded bytes loaded per frame at most (0: no limit) */
    gdr_thread_pool *pool;        /* threads for the page graph's creation (NULL: this thread); the
                                     same graph for any pool */
} gdr_residency_desc;

typedef struct gdr_residency gdr_residency;

/* Fails (GDR_ERROR_CAPACITY, naming the sizes) when the budget cannot hold the pinned pages. The
 * pinned pages are the first frame's loads (gdr_residency_plan with no requests returns them,
 * without the upload budget: the first frame needs them). */
gdr_status gdr_residency_create(const gdr_residency_desc *desc, gdr_residency **out, gdr_error *err);
void gdr_residency_destroy(gdr_residency *res);

/* Frame `frame`'s cut used this page (the GPU's page-use read-back): its LRU stamp; the pages of
 * the latest frame marked are never evicted. */
void gdr_residency_mark_used(gdr_residency *res, uint32_t frame, uint32_t mesh, uint32_t page);

/* Plans frame `frame`: turns the requests into page loads (closure first, by priority, within the
 * upload budget and the pool), evicting what the rules allow. Writes at most `capacity` loads to
 * `loads`, their count to *count. The planned pages count as resident from now on for the
 * closure; the caller must call gdr_residency_loaded (or _failed) for each before the GPU may see
 * them. */
void gdr_residency_plan(gdr_residency *res, uint32_t frame, const gdr_stream_request *requests,
                        uint32_t request_count, gdr_stream_load *loads, uint32_t capacity, uint32_t *count);
/* A planned page arrived in its slot (the GPU may now use it), or could not be read (damaged:
 * it stays absent and is never planned again; its slot is freed). */
void gdr_residency_loaded(gdr_residency *res, uint32_t mesh, uint32_t page);
void gdr_residency_failed(gdr_residency *res, uint32_t mesh, uint32_t page);

/* The pages the cut of frame `frame` needs resident: those holding the groups it drew (marked with
 * gdr_residency_mark_used for that frame) or asked for, those holding their groups' ancestors in
 * the DAG (the closure), and the pinned pages. Walks those pages only. */
uint32_t gdr_residency_count_wanted(gdr_residency *res, uint32_t frame, const gdr_stream_request *requests,
                                    uint32_t request_count);

/* Whether group `group` of mesh `mesh` is resident (its page arrived). */
int gdr_residency_group_resident(const gdr_residency *res, uint32_t mesh, uint32_t group);
/* The slot of a resident page, or UINT32_MAX. */
uint32_t gdr_residency_page_slot(const gdr_residency *res, uint32_t mesh, uint32_t page);
/* The slot of a page planned and not yet arrived, or UINT32_MAX. */
uint32_t gdr_residency_planned_slot(const gdr_residency *res, uint32_t mesh, uint32_t page);
uint32_t gdr_residency_slot_bytes(const gdr_residency *res);
uint32_t gdr_residency_slot_count(const gdr_residency *res);
gdr_residency_stats gdr_residency_get_stats(const gdr_residency *res);

/* The decoded size of a page in the pool: vertices, their cluster vertex list entries, triangles. */
uint64_t gdr_page_pool_bytes(const gdr_page_info *page);

#endif
