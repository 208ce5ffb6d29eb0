/* Page residency in a fixed pool of slots: closure, LRU eviction, per-frame upload budget
 * (residency.h, docs/STREAMING.md). */
#include "stream/residency.h"

#include <stdlib.h>
#include <string.h>

enum { PAGE_ABSENT, PAGE_PLANNED, PAGE_RESIDENT, PAGE_BROKEN };
/* page_state.requested while a frame is planned: asked for this frame, in the closure being
 * planned, or an ancestor of that closure (never evicted to make room for it). */
enum { MARK_NONE, MARK_REQUESTED, MARK_CLOSURE, MARK_PROTECTED };

typedef struct page_state {
    uint32_t slot;
    uint32_t last_used;  /* frame whose cut last used it (UINT32_MAX: never) */
    uint32_t dependents; /* planned or resident pages holding a child of its groups */
    uint32_t wanted_mark; /* the count of gdr_residency_count_wanted that last reached it */
    uint8_t state, pinned, requested;
} page_state;

/* Pages of all meshes in one array: mesh m's page p is page_base[m] + p. */
struct gdr_residency {
    const gdr_paged_cache *cache;
    uint32_t mesh_count, page_total;
    uint32_t *page_base;
    uint32_t *page_mesh;     /* the mesh of each global page */
    page_state *pages;
    uint32_t *parent_first;  /* page_total + 1: parent pages of page i are parents[parent_first[i] ..] */
    uint32_t *parents;
    uint32_t *child_first;   /* the reverse edges */
    uint32_t *children;
    uint32_t slot_bytes, slot_count, free_count;
    uint32_t *free_slots;
    uint64_t upload_budget;
    uint32_t frame, last_change, pinned_planned;
    uint32_t latest_use; /* the latest frame whose cut was marked (UINT32_MAX: none yet) */
    uint32_t *scratch;       /* 2 x page_total: a request's closure, its protected ancestors */
    /* Resident pages that are not pinned, least recently used first: lru_prev/next per page
     * (UINT32_MAX: none), so that finding a page to evict walks the pool, never the scene. */
    uint32_t *lru_prev, *lru_next;
    uint32_t lru_head, lru_tail;
    uint32_t wanted_mark;    /* counts of gdr_residency_count_wanted */
    gdr_residency_stats stats;
};

uint64_t gdr_page_pool_bytes(const gdr_page_info *page)
{
    /* As the pool holds it: each vertex (32 bytes) with its entry in the cluster vertex list (4
     * bytes), each cluster's triangles padded to 4 bytes. The clusters' records stay resident
     * outside the pool. */
    return (uint64_t)page->vertex_count * (sizeof(gdr_page_vertex) + 4u) +
           (((uint64_t)page->triangle_count * 3 + 3u * page->cluster_count) & ~(uint64_t)3);
}

static int compare_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* The distinct other pages holding parents of page p's groups (global indices), sorted. */
static uint32_t page_parents(const gdr_residency *res, uint32_t m, uint32_t p, uint32_t *out)
{
    const gdr_paged_mesh *pm = gdr_paged_cache_mesh(res->cache, m);
    const gdr_page_info *pi = &pm->pages[p];
    uint32_t n = 0;
    for (uint32_t k = pi->first; k < pi->first + pi->group_count; k++) {
        const gdr_page_group *g = &pm->groups[pm->page_groups[k]];
        for (uint32_t e = g->parent_first; e < g->parent_first + g->parent_count; e++)
            if (pm->groups[pm->parents[e]].page != p)
                out[n++] = res->page_base[m] + pm->groups[pm->parents[e]].page;
    }
    qsort(out, n, sizeof *out, compare_u32);
    uint32_t unique = 0;
    for (uint32_t i = 0; i < n; i++)
        if (i == 0 || out[i] != out[i - 1])
            out[unique++] = out[i];
    return unique;
}

/* One mesh's page parent lists, each page's written at the end of the one before, from the mesh's
 * share of `parents` (its parent edges bound its pages' lists); each page's count into
 * parent_first[page + 1]. A task per mesh: meshes write to disjoint places. */
typedef struct edge_job {
    gdr_residency *res;
    const uint64_t *mesh_edges; /* the mesh's share of parents starts here */
} edge_job;

static void mesh_page_parents(void *user, uint32_t m, uint32_t worker)
{
    (void)worker;
    const edge_job *job = user;
    gdr_residency *res = job->res;
    uint64_t at = job->mesh_edges[m];
    for (uint32_t p = 0; p < gdr_paged_cache_mesh(res->cache, m)->page_count; p++) {
        uint32_t n = page_parents(res, m, p, res->parents + at);
        res->parent_first[res->page_base[m] + p + 1] = n;
        at += n;
    }
}

/* The lists packed together in page order: parent_first from the counts, each mesh's lists moved
 * down from its share (shares only ever move towards the start, in order). */
static void pack_parents(gdr_residency *res, const uint64_t *mesh_edges)
{
    uint32_t n = 0;
    for (uint32_t m = 0; m < res->mesh_count; m++) {
        uint32_t first = res->page_base[m], pages = gdr_paged_cache_mesh(res->cache, m)->page_count, count = 0;
        for (uint32_t p = 0; p < pages; p++) {
            uint32_t c = res->parent_first[first + p + 1];
            res->parent_first[first + p] = n + count;
            count += c;
        }
        memmove(res->parents + n, res->parents + mesh_edges[m], sizeof *res->parents * count);
        n += count;
    }
    res->parent_first[res->page_total] = n;
}

/* Parent and child page lists of every page; the parents a task per mesh on `pool` (may be NULL). */
static int build_edges(gdr_residency *res, gdr_thread_pool *pool)
{
    uint64_t edges = 0;
    uint64_t *mesh_edges = malloc(sizeof *mesh_edges * ((size_t)res->mesh_count + 1));
    for (uint32_t m = 0; mesh_edges && m < res->mesh_count; m++) {
        mesh_edges[m] = edges;
        edges += gdr_paged_cache_mesh(res->cache, m)->parent_count;
    }
    res->parents = malloc(sizeof *res->parents * (edges ? edges : 1));
    res->children = malloc(sizeof *res->children * (edges ? edges : 1));
    res->parent_first = calloc((size_t)res->page_total + 1, sizeof *res->parent_first);
    res->child_first = calloc((size_t)res->page_total + 1, sizeof *res->child_first);
    if (!mesh_edges || !res->parents || !res->children || !res->parent_first || !res->child_first) {
        free(mesh_edges);
        return 0;
    }
    edge_job job = {res, mesh_edges};
    gdr_thread_pool_run(pool, res->mesh_count, mesh_page_parents, &job);
    pack_parents(res, mesh_edges);
    free(mesh_edges);
    uint32_t n = res->parent_first[res->page_total];
    for (uint32_t e = 0; e < n; e++)
        res->child_first[res->parents[e] + 1]++;
    for (uint32_t i = 0; i < res->page_total; i++)
        res->child_first[i + 1] += res->child_first[i];
    uint32_t *fill = res->scratch;
    memcpy(fill, res->child_first, sizeof *fill * res->page_total);
    for (uint32_t i = 0; i < res->page_total; i++)
        for (uint32_t e = res->parent_first[i]; e < res->parent_first[i + 1]; e++)
            res->children[fill[res->parents[e]]++] = i;
    return 1;
}

static gdr_status size_pool(gdr_residency *res, const gdr_residency_desc *desc, gdr_error *err)
{
    uint64_t largest = 0, pinned = 0;
    for (uint32_t m = 0; m < res->mesh_count; m++) {
        const gdr_paged_mesh *pm = gdr_paged_cache_mesh(res->cache, m);
        for (uint32_t p = 0; p < pm->page_count; p++) {
            uint64_t b = gdr_page_pool_bytes(&pm->pages[p]);
            largest = b > largest ? b : largest;
        }
        pinned += pm->page_count ? 1 : 0;
    }
    res->slot_bytes = (uint32_t)((largest + 255) & ~(uint64_t)255);
    uint64_t slots = res->slot_bytes ? desc->budget_bytes / res->slot_bytes : 0;
    if (slots < pinned || slots > UINT32_MAX)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "geometry budget of %llu bytes holds %llu pages of %u bytes; "
                             "the coarsest pages alone need %llu (or over 4G slots)",
                             (unsigned long long)desc->budget_bytes, (unsigned long long)slots, res->slot_bytes,
                             (unsigned long long)(pinned * res->slot_bytes));
    res->slot_count = (uint32_t)slots;
    res->free_slots = malloc(sizeof *res->free_slots * (slots ? slots : 1));
    if (!res->free_slots)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "page pool of %llu slots", (unsigned long long)slots);
    for (uint32_t s = 0; s < res->slot_count; s++)
        res->free_slots[s] = res->slot_count - 1 - s; /* slot 0 is handed out first */
    res->free_count = res->slot_count;
    return GDR_OK;
}

gdr_status gdr_residency_create(const gdr_residency_desc *desc, gdr_residency **out, gdr_error *err)
{
    *out = NULL;
    gdr_residency *res = calloc(1, sizeof *res);
    if (!res)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "residency");
    res->cache = desc->cache;
    res->mesh_count = gdr_paged_cache_mesh_count(desc->cache);
    res->upload_budget = desc->upload_budget_bytes;
    res->latest_use = UINT32_MAX;
    res->page_base = malloc(sizeof *res->page_base * ((size_t)res->mesh_count + 1));
    for (uint32_t m = 0; res->page_base && m < res->mesh_count; m++) {
        res->page_base[m] = res->page_total;
        res->page_total += gdr_paged_cache_mesh(desc->cache, m)->page_count;
    }
    res->pages = calloc(res->page_total ? res->page_total : 1, sizeof *res->pages);
    res->page_mesh = malloc(sizeof *res->page_mesh * (res->page_total ? res->page_total : 1));
    res->scratch = malloc(sizeof *res->scratch * 2 * ((size_t)res->page_total + 1));
    res->lru_prev = malloc(sizeof *res->lru_prev * ((size_t)res->page_total + 1));
    res->lru_next = malloc(sizeof *res->lru_next * ((size_t)res->page_total + 1));
    res->lru_head = res->lru_tail = UINT32_MAX;
    gdr_status status = GDR_OK;
    if (!res->page_base || !res->pages || !res->page_mesh || !res->scratch || !res->lru_prev || !res->lru_next ||
        !build_edges(res, desc->pool))
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "residency of %u pages", res->page_total);
    if (status == GDR_OK)
        status = size_pool(res, desc, err);
    if (status != GDR_OK) {
        gdr_residency_destroy(res);
        return status;
    }
    for (uint32_t m = 0; m < res->mesh_count; m++)
        for (uint32_t p = 0; p < gdr_paged_cache_mesh(desc->cache, m)->page_count; p++) {
            res->page_mesh[res->page_base[m] + p] = m;
            res->pages[res->page_base[m] + p] = (page_state){.slot = UINT32_MAX, .last_used = UINT32_MAX,
                                                             .pinned = p == 0};
        }
    *out = res;
    return GDR_OK;
}

void gdr_residency_destroy(gdr_residency *res)
{
    if (!res)
        return;
    free(res->page_base), free(res->page_mesh), free(res->pages), free(res->parent_first), free(res->parents);
    free(res->child_first), free(res->children), free(res->free_slots), free(res->scratch);
    free(res->lru_prev), free(res->lru_next);
    free(res);
}

/* --- planning ------------------------------------------------------------------------------------- */

static uint64_t page_bytes_of(const gdr_residency *res, uint32_t page)
{
    uint32_t m = res->page_mesh[page];
    return gdr_page_pool_bytes(&gdr_paged_cache_mesh(res->cache, m)->pages[page - res->page_base[m]]);
}

static void lru_unlink(gdr_residency *res, uint32_t page)
{
    uint32_t prev = res->lru_prev[page], next = res->lru_next[page];
    if (prev != UINT32_MAX)
        res->lru_next[prev] = next;
    else
        res->lru_head = next;
    if (next != UINT32_MAX)
        res->lru_prev[next] = prev;
    else
        res->lru_tail = prev;
}

/* Appends a page as the most recently used. */
static void lru_append(gdr_residency *res, uint32_t page)
{
    res->lru_prev[page] = res->lru_tail;
    res->lru_next[page] = UINT32_MAX;
    if (res->lru_tail != UINT32_MAX)
        res->lru_next[res->lru_tail] = page;
    else
        res->lru_head = page;
    res->lru_tail = page;
}

static void add_dependents(gdr_residency *res, uint32_t page, int delta)
{
    for (uint32_t e = res->parent_first[page]; e < res->parent_first[page + 1]; e++)
        res->pages[res->parents[e]].dependents += (uint32_t)delta;
}

static int used_by_latest_cut(const gdr_residency *res, const page_state *ps)
{
    return ps->last_used != UINT32_MAX && ps->last_used == res->latest_use;
}

/* Takes a planned or resident page out, its planned or resident children first (the closure). An
 * eviction (not `forced` by a damaged page) of a page in use is counted: it must never happen. */
static void remove_page(gdr_residency *res, uint32_t page, uint8_t new_state, int forced)
{
    page_state *ps = &res->pages[page];
    for (uint32_t e = res->child_first[page]; e < res->child_first[page + 1]; e++) {
        uint8_t s = res->pages[res->children[e]].state;
        if (s == PAGE_PLANNED || s == PAGE_RESIDENT)
            remove_page(res, res->children[e], PAGE_ABSENT, forced);
    }
    if (!forced && (ps->pinned || ps->dependents > 0 || used_by_latest_cut(res, ps)))
        res->stats.evicted_in_use++;
    if (ps->state == PAGE_RESIDENT && !ps->pinned)
        lru_unlink(res, page);
    add_dependents(res, page, -1);
    res->free_slots[res->free_count++] = ps->slot;
    ps->slot = UINT32_MAX;
    ps->state = new_state;
    res->last_change = res->frame;
}

/* The resident page unused for longest that may leave (not pinned, no planned or resident child, not
 * used by the latest cut, not an ancestor of the closure being planned): the first such in LRU
 * order. The walk passes only resident pages (the pool), never the whole scene. UINT32_MAX: none. */
static uint32_t eviction_candidate(const gdr_residency *res)
{
    for (uint32_t i = res->lru_head; i != UINT32_MAX; i = res->lru_next[i]) {
        const page_state *ps = &res->pages[i];
        if (ps->dependents == 0 && ps->requested != MARK_PROTECTED && !used_by_latest_cut(res, ps))
            return i;
    }
    return UINT32_MAX;
}

static int take_slot(gdr_residency *res, uint32_t *slot)
{
    if (res->free_count == 0) {
        uint32_t victim = eviction_candidate(res);
        if (victim == UINT32_MAX)
            return 0;
        remove_page(res, victim, PAGE_ABSENT, 0);
        res->stats.evictions++;
    }
    *slot = res->free_slots[--res->free_count];
    return 1;
}

static void plan_page(gdr_residency *res, uint32_t page, uint32_t slot, gdr_stream_load *loads, uint32_t *count)
{
    page_state *ps = &res->pages[page];
    ps->state = PAGE_PLANNED;
    ps->slot = slot;
    add_dependents(res, page, +1);
    uint32_t m = res->page_mesh[page];
    loads[(*count)++] = (gdr_stream_load){m, page - res->page_base[m], slot};
    res->stats.loads++;
    res->stats.load_bytes += page_bytes_of(res, page);
}

/* The absent pages page `page` needs (itself and, transitively, its parents' pages), ascending:
 * parents hold deeper groups, which come earlier in a mesh's page order; 0 if one is broken. The
 * resident parents met on the way are marked `protect` (and listed after the absent ones, *marked
 * of them) so that making room for the closure never evicts its own ancestors. */
static uint32_t closure(gdr_residency *res, uint32_t page, uint32_t *out, uint32_t *marked)
{
    uint32_t n = 0, top = 0, k = 0;
    uint32_t *protect = out + res->page_total; /* the scratch holds 2 x page_total */
    out[n++] = page;
    res->pages[page].requested = MARK_CLOSURE;
    int broken = 0;
    while (top < n) {
        uint32_t q = out[top++];
        for (uint32_t e = res->parent_first[q]; e < res->parent_first[q + 1]; e++) {
            page_state *ps = &res->pages[res->parents[e]];
            broken |= ps->state == PAGE_BROKEN;
            if (ps->requested == MARK_CLOSURE || ps->requested == MARK_PROTECTED)
                continue;
            if (ps->state == PAGE_ABSENT) {
                ps->requested = MARK_CLOSURE;
                out[n++] = res->parents[e];
            } else {
                ps->requested = MARK_PROTECTED;
                protect[k++] = res->parents[e];
            }
        }
    }
    for (uint32_t i = 0; i < n; i++)
        res->pages[out[i]].requested = MARK_NONE;
    res->pages[page].requested = MARK_REQUESTED;
    qsort(out, n, sizeof *out, compare_u32);
    *marked = k;
    return broken ? 0 : n;
}

static int compare_requests(const void *a, const void *b)
{
    const gdr_stream_request *x = a, *y = b;
    if (x->priority != y->priority)
        return x->priority > y->priority ? -1 : 1;
    if (x->mesh != y->mesh)
        return x->mesh < y->mesh ? -1 : 1;
    return x->group < y->group ? -1 : x->group > y->group;
}

/* One request: its closure's pages, in order, while the upload budget and the pool allow. */
static int plan_request(gdr_residency *res, uint32_t page, gdr_stream_load *loads, uint32_t capacity,
                        uint32_t *count)
{
    uint32_t marked = 0, n = closure(res, page, res->scratch, &marked);
    int room = 1;
    for (uint32_t i = 0; i < n && room; i++) {
        uint64_t bytes = page_bytes_of(res, res->scratch[i]);
        uint32_t slot;
        room = *count < capacity && !(res->upload_budget && res->stats.load_bytes > 0 &&
                                      res->stats.load_bytes + bytes > res->upload_budget);
        room = room && take_slot(res, &slot);
        if (room)
            plan_page(res, res->scratch[i], slot, loads, count);
    }
    for (uint32_t i = 0; i < marked; i++)
        res->pages[res->scratch[res->page_total + i]].requested = MARK_NONE;
    return room;
}

void gdr_residency_plan(gdr_residency *res, uint32_t frame, const gdr_stream_request *requests,
                        uint32_t request_count, gdr_stream_load *loads, uint32_t capacity, uint32_t *count)
{
    res->frame = frame;
    res->stats.requests = res->stats.loads = res->stats.evictions = res->stats.deferred = 0;
    res->stats.load_bytes = 0;
    *count = 0;
    for (uint32_t m = 0; !res->pinned_planned && m < res->mesh_count; m++)
        if (gdr_paged_cache_mesh(res->cache, m)->page_count && *count < capacity)
            plan_page(res, res->page_base[m], res->free_slots[--res->free_count], loads, count);
    res->pinned_planned = 1;
    res->stats.load_bytes = 0; /* the pinned pages are outside the upload budget */
    gdr_stream_request *sorted = malloc(sizeof *sorted * (request_count ? request_count : 1));
    if (!sorted)
        return; /* out of memory: nothing planned this frame, the GPU asks again */
    if (request_count)
        memcpy(sorted, requests, sizeof *sorted * request_count);
    qsort(sorted, request_count, sizeof *sorted, compare_requests);
    int room = 1;
    for (uint32_t i = 0; i < request_count; i++) {
        const gdr_paged_mesh *pm = sorted[i].mesh < res->mesh_count ? gdr_paged_cache_mesh(res->cache, sorted[i].mesh)
                                                                     : NULL;
        if (!pm || sorted[i].group >= pm->group_count)
            continue;
        uint32_t page = res->page_base[sorted[i].mesh] + pm->groups[sorted[i].group].page;
        if (res->pages[page].requested == MARK_REQUESTED)
            continue; /* another group of the same page, asked for this frame */
        res->pages[page].requested = MARK_REQUESTED;
        res->stats.requests++;
        if (res->pages[page].state != PAGE_ABSENT)
            continue;
        room = room && plan_request(res, page, loads, capacity, count);
        res->stats.deferred += !room || res->pages[page].state == PAGE_ABSENT;
    }
    for (uint32_t i = 0; i < request_count; i++)
        if (sorted[i].mesh < res->mesh_count && sorted[i].group < gdr_paged_cache_mesh(res->cache, sorted[i].mesh)->group_count)
            res->pages[res->page_base[sorted[i].mesh] +
                       gdr_paged_cache_mesh(res->cache, sorted[i].mesh)->groups[sorted[i].group].page].requested =
                MARK_NONE;
    free(sorted);
}

/* --- what a cut needs ---------------------------------------------------------------------------- */

/* Marks page `page` and the pages holding its groups' ancestors (not yet marked), pushing the new
 * ones on `stack`; counts the marked pages that are not pinned. */
static uint32_t mark_wanted(gdr_residency *res, uint32_t page, uint32_t *stack)
{
    uint32_t n = 0, top = 0;
    if (res->pages[page].wanted_mark == res->wanted_mark)
        return 0;
    res->pages[page].wanted_mark = res->wanted_mark;
    stack[top++] = page;
    while (top > 0) {
        uint32_t q = stack[--top];
        n += !res->pages[q].pinned;
        for (uint32_t e = res->parent_first[q]; e < res->parent_first[q + 1]; e++)
            if (res->pages[res->parents[e]].wanted_mark != res->wanted_mark) {
                res->pages[res->parents[e]].wanted_mark = res->wanted_mark;
                stack[top++] = res->parents[e];
            }
    }
    return n;
}

uint32_t gdr_residency_count_wanted(gdr_residency *res, uint32_t frame, const gdr_stream_request *requests,
                                    uint32_t request_count)
{
    if (++res->wanted_mark == 0) { /* wrapped: forget every old mark */
        for (uint32_t i = 0; i < res->page_total; i++)
            res->pages[i].wanted_mark = 0;
        res->wanted_mark = 1;
    }
    uint32_t *stack = res->scratch, wanted = 0;
    /* Pages a cut used move to the end of the LRU list: frame's pages are its tail. */
    for (uint32_t i = res->lru_tail; i != UINT32_MAX && res->pages[i].last_used == frame; i = res->lru_prev[i])
        wanted += mark_wanted(res, i, stack);
    for (uint32_t i = 0; i < request_count; i++) {
        uint32_t m = requests[i].mesh;
        const gdr_paged_mesh *pm = m < res->mesh_count ? gdr_paged_cache_mesh(res->cache, m) : NULL;
        if (pm && requests[i].group < pm->group_count)
            wanted += mark_wanted(res, res->page_base[m] + pm->groups[requests[i].group].page, stack);
    }
    for (uint32_t m = 0; m < res->mesh_count; m++)
        wanted += gdr_paged_cache_mesh(res->cache, m)->page_count ? 1 : 0;
    return wanted;
}

/* --- the rest ------------------------------------------------------------------------------------ */

void gdr_residency_mark_used(gdr_residency *res, uint32_t frame, uint32_t mesh, uint32_t page)
{
    if (mesh < res->mesh_count && page < gdr_paged_cache_mesh(res->cache, mesh)->page_count) {
        uint32_t global = res->page_base[mesh] + page;
        res->pages[global].last_used = frame;
        if (res->pages[global].state == PAGE_RESIDENT && !res->pages[global].pinned) {
            lru_unlink(res, global); /* now the most recently used */
            lru_append(res, global);
        }
        res->latest_use = res->latest_use == UINT32_MAX || frame > res->latest_use ? frame : res->latest_use;
    }
}

void gdr_residency_loaded(gdr_residency *res, uint32_t mesh, uint32_t page)
{
    page_state *ps = &res->pages[res->page_base[mesh] + page];
    if (ps->state == PAGE_PLANNED) {
        ps->state = PAGE_RESIDENT;
        res->last_change = res->frame;
        if (!ps->pinned)
            lru_append(res, res->page_base[mesh] + page);
    }
}

void gdr_residency_failed(gdr_residency *res, uint32_t mesh, uint32_t page)
{
    uint32_t global = res->page_base[mesh] + page;
    if (res->pages[global].state == PAGE_PLANNED || res->pages[global].state == PAGE_RESIDENT)
        remove_page(res, global, PAGE_BROKEN, 1);
}

int gdr_residency_group_resident(const gdr_residency *res, uint32_t mesh, uint32_t group)
{
    const gdr_paged_mesh *pm = gdr_paged_cache_mesh(res->cache, mesh);
    return res->pages[res->page_base[mesh] + pm->groups[group].page].state == PAGE_RESIDENT;
}

uint32_t gdr_residency_page_slot(const gdr_residency *res, uint32_t mesh, uint32_t page)
{
    const page_state *ps = &res->pages[res->page_base[mesh] + page];
    return ps->state == PAGE_RESIDENT ? ps->slot : UINT32_MAX;
}

uint32_t gdr_residency_planned_slot(const gdr_residency *res, uint32_t mesh, uint32_t page)
{
    const page_state *ps = &res->pages[res->page_base[mesh] + page];
    return ps->state == PAGE_PLANNED ? ps->slot : UINT32_MAX;
}

uint32_t gdr_residency_slot_bytes(const gdr_residency *res) { return res->slot_bytes; }
uint32_t gdr_residency_slot_count(const gdr_residency *res) { return res->slot_count; }

gdr_residency_stats gdr_residency_get_stats(const gdr_residency *res)
{
    gdr_residency_stats s = res->stats;
    s.resident_pages = res->slot_count - res->free_count;
    s.resident_bytes = (uint64_t)s.resident_pages * res->slot_bytes;
    s.pinned_pages = 0;
    for (uint32_t m = 0; m < res->mesh_count; m++)
        s.pinned_pages += gdr_paged_cache_mesh(res->cache, m)->page_count ? 1 : 0;
    s.frames_since_change = res->frame - res->last_change;
    return s;
}
