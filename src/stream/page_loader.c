/* The page loader (page_loader.h): a queue of loads, worker threads that each take the next load
 * and decode it, results handed back in submission order. */
#include "stream/page_loader.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gdr/thread_pool.h"

struct gdr_page_loader {
    gdr_paged_cache *cache;
    pthread_t threads[GDR_PAGE_LOADER_MAX_THREADS];
    uint32_t thread_count;
    pthread_mutex_t lock;
    pthread_cond_t work, done;
    gdr_page_result *jobs; /* [collected, submitted): queued, being decoded or finished */
    uint8_t *finished;
    uint32_t capacity, submitted, taken, collected;
    int quit;
    /* Throughput: the stored and decoded bytes of the pages read, and the time at least one worker
     * was reading or decoding (busy), which excludes the time the queue stood empty. */
    uint64_t bytes_read, bytes_decoded, pages_read;
    uint32_t busy_workers;
    double busy_since, busy_s;
};

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* A worker starts or ends a page (under the lock). */
static void busy_begin(gdr_page_loader *l)
{
    if (l->busy_workers++ == 0)
        l->busy_since = now_s();
}

static void busy_end(gdr_page_loader *l, const gdr_stream_load *load)
{
    const gdr_paged_mesh *pm = gdr_paged_cache_mesh(l->cache, load->mesh);
    if (pm && load->page < pm->page_count) {
        l->bytes_read += pm->pages[load->page].stored_size;
        l->bytes_decoded += gdr_page_pool_bytes(&pm->pages[load->page]);
        l->pages_read++;
    }
    if (--l->busy_workers == 0)
        l->busy_s += now_s() - l->busy_since;
}

static void *loader_main(void *user)
{
    gdr_page_loader *l = user;
    pthread_mutex_lock(&l->lock);
    for (;;) {
        while (!l->quit && l->taken == l->submitted)
            pthread_cond_wait(&l->work, &l->lock);
        if (l->quit)
            break;
        uint32_t index = l->taken++;
        gdr_stream_load load = l->jobs[index].load;
        busy_begin(l);
        pthread_mutex_unlock(&l->lock);
        gdr_page_result result = {.load = load};
        result.status = gdr_paged_cache_read_page(l->cache, load.mesh, load.page, &result.page, &result.error);
        pthread_mutex_lock(&l->lock);
        l->jobs[index] = result; /* the arrays may have moved meanwhile: index, not pointer */
        l->finished[index] = 1;
        busy_end(l, &load);
        pthread_cond_broadcast(&l->done);
    }
    pthread_mutex_unlock(&l->lock);
    return NULL;
}

/* 0: one per processor but the one the frames run on, at least one, at most the maximum. */
static uint32_t worker_count(uint32_t asked)
{
    uint32_t processors = gdr_processor_count();
    uint32_t n = asked ? asked : processors > 2 ? processors - 1 : 1u;
    return n < GDR_PAGE_LOADER_MAX_THREADS ? n : GDR_PAGE_LOADER_MAX_THREADS;
}

gdr_status gdr_page_loader_create(gdr_paged_cache *cache, uint32_t threads, gdr_page_loader **out, gdr_error *err)
{
    *out = NULL;
    gdr_page_loader *l = calloc(1, sizeof *l);
    if (!l)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "page loader");
    l->cache = cache;
    pthread_mutex_init(&l->lock, NULL);
    pthread_cond_init(&l->work, NULL);
    pthread_cond_init(&l->done, NULL);
    uint32_t wanted = worker_count(threads);
    while (l->thread_count < wanted && pthread_create(&l->threads[l->thread_count], NULL, loader_main, l) == 0)
        l->thread_count++;
    if (l->thread_count == 0) {
        gdr_page_loader_destroy(l);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "page loader: cannot start a thread");
    }
    *out = l;
    return GDR_OK;
}

void gdr_page_loader_destroy(gdr_page_loader *l)
{
    if (!l)
        return;
    pthread_mutex_lock(&l->lock);
    l->quit = 1;
    pthread_cond_broadcast(&l->work);
    pthread_mutex_unlock(&l->lock);
    for (uint32_t i = 0; i < l->thread_count; i++)
        pthread_join(l->threads[i], NULL);
    for (uint32_t i = l->collected; i < l->submitted; i++)
        if (l->finished[i])
            gdr_page_free(&l->jobs[i].page);
    pthread_mutex_destroy(&l->lock);
    pthread_cond_destroy(&l->work);
    pthread_cond_destroy(&l->done);
    free(l->jobs);
    free(l->finished);
    free(l);
}

/* Room for `count` more jobs: collected jobs are dropped from the front when none is in flight. */
static int reserve(gdr_page_loader *l, uint32_t count)
{
    if (l->collected == l->submitted)
        l->collected = l->submitted = l->taken = 0;
    if (l->submitted + count <= l->capacity)
        return 1;
    uint32_t capacity = l->capacity ? l->capacity : 64;
    while (capacity < l->submitted + count)
        capacity *= 2;
    gdr_page_result *jobs = realloc(l->jobs, sizeof *jobs * capacity);
    if (!jobs)
        return 0;
    l->jobs = jobs;
    uint8_t *finished = realloc(l->finished, capacity);
    if (!finished)
        return 0;
    l->finished = finished;
    l->capacity = capacity;
    return 1;
}

gdr_status gdr_page_loader_submit(gdr_page_loader *l, const gdr_stream_load *loads, uint32_t count, gdr_error *err)
{
    pthread_mutex_lock(&l->lock);
    if (!reserve(l, count)) {
        pthread_mutex_unlock(&l->lock);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "page loader: %u loads", count);
    }
    for (uint32_t i = 0; i < count; i++) {
        l->jobs[l->submitted + i] = (gdr_page_result){.load = loads[i]};
        l->finished[l->submitted + i] = 0;
    }
    l->submitted += count;
    pthread_cond_broadcast(&l->work);
    pthread_mutex_unlock(&l->lock);
    return GDR_OK;
}

uint32_t gdr_page_loader_collect(gdr_page_loader *l, int wait_all, gdr_page_result *out, uint32_t capacity)
{
    uint32_t n = 0;
    pthread_mutex_lock(&l->lock);
    while (n < capacity && l->collected < l->submitted) {
        if (!l->finished[l->collected]) {
            if (!wait_all)
                break;
            pthread_cond_wait(&l->done, &l->lock);
            continue;
        }
        out[n++] = l->jobs[l->collected++];
    }
    pthread_mutex_unlock(&l->lock);
    return n;
}

uint32_t gdr_page_loader_pending(gdr_page_loader *l)
{
    pthread_mutex_lock(&l->lock);
    uint32_t n = l->submitted - l->collected;
    pthread_mutex_unlock(&l->lock);
    return n;
}

gdr_page_loader_stats gdr_page_loader_get_stats(gdr_page_loader *l)
{
    pthread_mutex_lock(&l->lock);
    gdr_page_loader_stats st = {.bytes_read = l->bytes_read, .bytes_decoded = l->bytes_decoded,
                                .pages_read = l->pages_read, .busy_s = l->busy_s, .queued = l->submitted - l->taken,
                                .reading = l->busy_workers, .threads = l->thread_count};
    if (l->busy_workers)
        st.busy_s += now_s() - l->busy_since;
    pthread_mutex_unlock(&l->lock);
    return st;
}
