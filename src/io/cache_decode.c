/* Per-mesh decoding on a thread pool. A streamed open of a billion source triangles decodes and
 * checks about 23 million cluster records and their hierarchies; each mesh's records lie at an
 * offset known before decoding (from the counts) and go to the mesh's own arrays, so meshes decode
 * independently. The file is refused with the first failure in mesh order, the one a decode in
 * order stops at: the message does not depend on the threads. */
#include "io/cache_decode.h"

#include <stdatomic.h>
#include <stdbool.h>
#include <stdlib.h>

#include "gdr/thread_pool.h"

/* Below this many records a decode takes well under a millisecond: threads would cost more. */
#define DECODE_PARALLEL_MIN_WORK 65536u

static _Atomic uint32_t decode_threads; /* 0: one per processor */

void cache_set_decode_threads(uint32_t threads) { atomic_store(&decode_threads, threads); }

static uint32_t thread_count(void)
{
    uint32_t set = atomic_load(&decode_threads);
    if (set)
        return set > GDR_THREAD_POOL_MAX_THREADS ? GDR_THREAD_POOL_MAX_THREADS : set;
    return gdr_processor_count();
}

typedef struct decode_job {
    cache_mesh_decode_fn *fn;
    void *user;
    gdr_status *status; /* per mesh */
    gdr_error *errors;  /* per mesh */
} decode_job;

static void decode_task(void *user, uint32_t mesh, uint32_t worker)
{
    (void)worker;
    decode_job *job = user;
    job->status[mesh] = job->fn(job->user, mesh, &job->errors[mesh]);
}

static gdr_status decode_in_order(uint32_t count, cache_mesh_decode_fn *fn, void *user, gdr_error *err)
{
    for (uint32_t m = 0; m < count; m++) {
        gdr_status status = fn(user, m, err);
        if (status != GDR_OK)
            return status;
    }
    return GDR_OK;
}

gdr_status cache_decode_meshes(uint32_t count, uint64_t work, cache_mesh_decode_fn *fn, void *user, gdr_error *err)
{
    uint32_t threads = thread_count();
    if (threads > count)
        threads = count;
    bool forced = atomic_load(&decode_threads) > 1; /* tests: threads however small the work */
    if (threads < 2 || (work < DECODE_PARALLEL_MIN_WORK && !forced))
        return decode_in_order(count, fn, user, err);
    decode_job job = {fn, user, calloc(count, sizeof *job.status), calloc(count, sizeof *job.errors)};
    gdr_thread_pool *pool = NULL;
    gdr_error ignored = {0};
    if (!job.status || !job.errors || gdr_thread_pool_create(threads, &pool, &ignored) != GDR_OK) {
        free(job.status); /* no threads: decoded in order instead, the same result */
        free(job.errors);
        return decode_in_order(count, fn, user, err);
    }
    gdr_thread_pool_run(pool, count, decode_task, &job);
    gdr_thread_pool_destroy(pool);
    gdr_status status = GDR_OK;
    for (uint32_t m = 0; m < count && status == GDR_OK; m++)
        if ((status = job.status[m]) != GDR_OK && err)
            *err = job.errors[m];
    free(job.status);
    free(job.errors);
    return status;
}
