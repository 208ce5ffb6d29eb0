#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>

#include "gdr/thread_pool.h"
#include "test_util.h"

typedef struct job {
    uint32_t *hits;
    atomic_uint calls;
    uint32_t threads;
    atomic_int bad_worker;
} job;

static void count_task(void *user, uint32_t task, uint32_t worker)
{
    job *j = user;
    j->hits[task]++;
    atomic_fetch_add(&j->calls, 1);
    if (worker >= j->threads)
        atomic_store(&j->bad_worker, 1);
}

int main(void)
{
    uint32_t thread_counts[] = {1, 2, 3, 8};
    for (size_t c = 0; c < sizeof(thread_counts) / sizeof(thread_counts[0]); c++) {
        gdr_thread_pool *pool;
        gdr_error err;
        CHECK(gdr_thread_pool_create(thread_counts[c], &pool, &err) == GDR_OK);
        CHECK(gdr_thread_pool_thread_count(pool) == thread_counts[c]);
        for (uint32_t round = 0; round < 50; round++) {
            uint32_t tasks = round * 7 % 300;
            job j = {calloc(tasks + 1, sizeof(uint32_t)), 0, thread_counts[c], 0};
            gdr_thread_pool_run(pool, tasks, count_task, &j);
            CHECK(atomic_load(&j.calls) == tasks);
            for (uint32_t t = 0; t < tasks; t++)
                CHECK(j.hits[t] == 1);
            CHECK(atomic_load(&j.bad_worker) == 0);
            free(j.hits);
        }
        gdr_thread_pool_destroy(pool);
    }
    /* a NULL pool runs inline */
    job j = {calloc(10, sizeof(uint32_t)), 0, 1, 0};
    gdr_thread_pool_run(NULL, 10, count_task, &j);
    CHECK(atomic_load(&j.calls) == 10);
    free(j.hits);
    CHECK(gdr_thread_pool_thread_count(NULL) == 1);
    gdr_thread_pool *pool;
    gdr_error err;
    CHECK(gdr_thread_pool_create(100000, &pool, &err) == GDR_ERROR_INVALID_ARGUMENT);
    return test_finish("test_thread_pool");
}
