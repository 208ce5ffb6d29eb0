#include "gdr/thread_pool.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

struct gdr_thread_pool {
    uint32_t thread_count;
    pthread_t *threads;
    pthread_mutex_t run_lock; /* one job at a time */
    pthread_mutex_t lock;
    pthread_cond_t wake;      /* workers wait here for a new generation */
    pthread_cond_t done;      /* the caller waits here for busy_workers == 0 */
    uint64_t generation;      /* bumped for each job; guarded by lock */
    uint32_t busy_workers;    /* extra workers still inside the current job; guarded by lock */
    int quit;
    /* the current job */
    gdr_task_fn *fn;
    void *user;
    uint32_t task_count;
    atomic_uint next_task;
};

typedef struct worker_start {
    gdr_thread_pool *pool;
    uint32_t index;
} worker_start;

static void run_tasks(gdr_thread_pool *pool, uint32_t worker_index)
{
    for (;;) {
        uint32_t task = atomic_fetch_add_explicit(&pool->next_task, 1, memory_order_relaxed);
        if (task >= pool->task_count)
            return;
        pool->fn(pool->user, task, worker_index);
    }
}

static void *worker_main(void *arg)
{
    worker_start start = *(worker_start *)arg;
    free(arg);
    gdr_thread_pool *pool = start.pool;
    uint64_t seen = 0;
    pthread_mutex_lock(&pool->lock);
    for (;;) {
        while (!pool->quit && pool->generation == seen)
            pthread_cond_wait(&pool->wake, &pool->lock);
        if (pool->quit)
            break;
        seen = pool->generation;
        pthread_mutex_unlock(&pool->lock);
        run_tasks(pool, start.index);
        pthread_mutex_lock(&pool->lock);
        if (--pool->busy_workers == 0)
            pthread_cond_signal(&pool->done);
    }
    pthread_mutex_unlock(&pool->lock);
    return NULL;
}

uint32_t gdr_processor_count(void)
{
    long online = sysconf(_SC_NPROCESSORS_ONLN);
    return online < 1 ? 1 : online > GDR_THREAD_POOL_MAX_THREADS ? GDR_THREAD_POOL_MAX_THREADS : (uint32_t)online;
}

gdr_thread_pool *gdr_thread_pool_create_if(int worth_it)
{
    gdr_thread_pool *pool = NULL;
    gdr_error ignored = {0};
    if (worth_it && gdr_processor_count() > 1)
        (void)gdr_thread_pool_create(0, &pool, &ignored);
    return pool;
}

gdr_status gdr_thread_pool_create(uint32_t thread_count, gdr_thread_pool **out, gdr_error *err)
{
    *out = NULL;
    if (thread_count == 0)
        thread_count = gdr_processor_count();
    if (thread_count > GDR_THREAD_POOL_MAX_THREADS)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "thread pool: %u threads exceeds %u",
                             thread_count, GDR_THREAD_POOL_MAX_THREADS);
    gdr_thread_pool *pool = calloc(1, sizeof(*pool));
    if (!pool)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "thread pool: out of memory");
    pool->thread_count = 1;
    pthread_mutex_init(&pool->run_lock, NULL);
    pthread_mutex_init(&pool->lock, NULL);
    pthread_cond_init(&pool->wake, NULL);
    pthread_cond_init(&pool->done, NULL);
    atomic_init(&pool->next_task, 0);
    if (thread_count > 1) {
        pool->threads = calloc(thread_count - 1, sizeof(pthread_t));
        if (!pool->threads) {
            gdr_thread_pool_destroy(pool);
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "thread pool: out of memory");
        }
    }
    for (uint32_t i = 1; i < thread_count; i++) {
        worker_start *start = malloc(sizeof(*start));
        if (!start) {
            gdr_thread_pool_destroy(pool);
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "thread pool: out of memory");
        }
        *start = (worker_start){pool, i};
        if (pthread_create(&pool->threads[i - 1], NULL, worker_main, start) != 0) {
            free(start);
            gdr_thread_pool_destroy(pool);
            return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "thread pool: pthread_create failed for thread %u", i);
        }
        pool->thread_count = i + 1;
    }
    *out = pool;
    return GDR_OK;
}

void gdr_thread_pool_destroy(gdr_thread_pool *pool)
{
    if (!pool)
        return;
    pthread_mutex_lock(&pool->lock);
    pool->quit = 1;
    pthread_cond_broadcast(&pool->wake);
    pthread_mutex_unlock(&pool->lock);
    for (uint32_t i = 1; i < pool->thread_count; i++)
        pthread_join(pool->threads[i - 1], NULL);
    pthread_cond_destroy(&pool->done);
    pthread_cond_destroy(&pool->wake);
    pthread_mutex_destroy(&pool->lock);
    pthread_mutex_destroy(&pool->run_lock);
    free(pool->threads);
    free(pool);
}

uint32_t gdr_thread_pool_thread_count(const gdr_thread_pool *pool)
{
    return pool ? pool->thread_count : 1;
}

void gdr_thread_pool_run(gdr_thread_pool *pool, uint32_t task_count, gdr_task_fn *fn, void *user)
{
    if (task_count == 0)
        return;
    if (!pool || pool->thread_count == 1 || task_count == 1) {
        for (uint32_t i = 0; i < task_count; i++)
            fn(user, i, 0);
        return;
    }
    pthread_mutex_lock(&pool->run_lock);
    pthread_mutex_lock(&pool->lock);
    pool->fn = fn;
    pool->user = user;
    pool->task_count = task_count;
    atomic_store_explicit(&pool->next_task, 0, memory_order_relaxed);
    pool->busy_workers = pool->thread_count - 1;
    pool->generation++;
    pthread_cond_broadcast(&pool->wake);
    pthread_mutex_unlock(&pool->lock);

    run_tasks(pool, 0);

    pthread_mutex_lock(&pool->lock);
    while (pool->busy_workers != 0)
        pthread_cond_wait(&pool->done, &pool->lock);
    pthread_mutex_unlock(&pool->lock);
    pthread_mutex_unlock(&pool->run_lock);
}
