/* A small fixed-size pthread pool that runs "parallel for" jobs: task_count independent tasks,
 * handed out one at a time through an atomic counter, with the calling thread working too.
 *
 * Contract:
 *  - gdr_thread_pool_run blocks until every task of the job has returned;
 *  - the caller is worker 0, so a pool of N threads starts N - 1 extra threads, and a pool of 1
 *    (or a NULL pool) runs every task on the calling thread, in order;
 *  - jobs from different threads on one pool are serialised (one job at a time);
 *  - a task must not call gdr_thread_pool_run on the same pool (it would deadlock).
 * Which worker runs which task is not deterministic: code that must give the same result for any
 * thread count writes each task's output to its own place, indexed by task_index. */
#ifndef GDR_THREAD_POOL_H
#define GDR_THREAD_POOL_H

#include <stdint.h>

#include "gdr/core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct gdr_thread_pool gdr_thread_pool;

/* worker_index is in [0, gdr_thread_pool_thread_count(pool)). */
typedef void gdr_task_fn(void *user, uint32_t task_index, uint32_t worker_index);

#define GDR_THREAD_POOL_MAX_THREADS 256

/* thread_count: total workers including the caller, in [1, GDR_THREAD_POOL_MAX_THREADS];
 * 0 picks the number of online processors. */
GDR_API gdr_status gdr_thread_pool_create(uint32_t thread_count, gdr_thread_pool **out, gdr_error *err);
GDR_API void gdr_thread_pool_destroy(gdr_thread_pool *pool);
/* The online processors, at least 1, at most GDR_THREAD_POOL_MAX_THREADS. */
GDR_API uint32_t gdr_processor_count(void);
/* A pool of one thread per processor where `worth_it` (the caller's work is large enough to gain from
 * threads) and the machine has more than one; NULL otherwise, or where the pool cannot be made: the
 * functions that take a pool then run on the calling thread. */
GDR_API gdr_thread_pool *gdr_thread_pool_create_if(int worth_it);
/* 1 for a NULL pool. */
GDR_API uint32_t gdr_thread_pool_thread_count(const gdr_thread_pool *pool);
/* Runs fn(user, i, worker) for every i in [0, task_count); pool may be NULL. */
GDR_API void gdr_thread_pool_run(gdr_thread_pool *pool, uint32_t task_count, gdr_task_fn *fn, void *user);

#ifdef __cplusplus
}
#endif
#endif
