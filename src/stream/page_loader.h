/* The page loader: threads that read, check and decode the pages the residency planned
 * (docs/STREAMING.md), so that file reads and decoding never stall the frame. Results come back
 * in the order the loads were submitted (only the completed prefix), so that what a frame
 * applies never depends on which page happened to finish first or on the thread count; collect
 * with wait_all makes the whole sequence deterministic. */
#ifndef GDR_STREAM_PAGE_LOADER_H
#define GDR_STREAM_PAGE_LOADER_H

#include "gdr/paged_cache.h"
#include "stream/residency.h"

typedef struct gdr_page_result {
    gdr_stream_load load;
    gdr_status status; /* GDR_OK: `page` holds the decoded page; else `error` says why */
    gdr_page page;
    gdr_error error;
} gdr_page_result;

typedef struct gdr_page_loader gdr_page_loader;

/* Decoding, not reading, limits a worker (docs/STREAMING.md): a large machine's cores all help. */
#define GDR_PAGE_LOADER_MAX_THREADS 32

/* `threads` workers (0: one per processor but one, at most GDR_PAGE_LOADER_MAX_THREADS). */
gdr_status gdr_page_loader_create(gdr_paged_cache *cache, uint32_t threads, gdr_page_loader **out, gdr_error *err);
/* Waits for the pages being decoded, drops the rest. */
void gdr_page_loader_destroy(gdr_page_loader *loader);
/* Queues loads (copied) behind the ones before. Out of memory: GDR_ERROR_OUT_OF_MEMORY, none queued. */
gdr_status gdr_page_loader_submit(gdr_page_loader *loader, const gdr_stream_load *loads, uint32_t count,
                                  gdr_error *err);
/* Moves up to `capacity` finished results, oldest first, into `out` (the caller frees each page
 * with gdr_page_free); stops at the first unfinished load unless wait_all, which waits for it.
 * Returns how many. */
uint32_t gdr_page_loader_collect(gdr_page_loader *loader, int wait_all, gdr_page_result *out, uint32_t capacity);
/* What the loader did since it was created: the pages read (checked or not), their bytes in the
 * file and decoded, and the seconds at least one worker was busy (bytes_read / busy_s: its
 * throughput while it had work); and now: loads waiting for a worker, pages being read. */
typedef struct gdr_page_loader_stats {
    uint64_t bytes_read, bytes_decoded, pages_read;
    double busy_s;
    uint32_t queued, reading, threads;
} gdr_page_loader_stats;
gdr_page_loader_stats gdr_page_loader_get_stats(gdr_page_loader *loader);
/* Loads submitted and not yet collected. */
uint32_t gdr_page_loader_pending(gdr_page_loader *loader);

#endif
