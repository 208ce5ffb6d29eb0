/* Heap accounting by wrapping the allocator (heap_count.h). */
#define _GNU_SOURCE
#include "heap_count.h"

#include <malloc.h>
#include <stdatomic.h>
#include <stddef.h>

extern void *__libc_malloc(size_t size);
extern void *__libc_calloc(size_t count, size_t size);
extern void *__libc_realloc(void *p, size_t size);
extern void __libc_free(void *p);

static atomic_llong in_use, peak;

static void heap_add(long long bytes)
{
    long long now = atomic_fetch_add(&in_use, bytes) + bytes;
    long long p = atomic_load(&peak);
    while (now > p && !atomic_compare_exchange_weak(&peak, &p, now)) {
    }
}

void *malloc(size_t size)
{
    void *p = __libc_malloc(size);
    if (p)
        heap_add((long long)malloc_usable_size(p));
    return p;
}

void *calloc(size_t count, size_t size)
{
    void *p = __libc_calloc(count, size);
    if (p)
        heap_add((long long)malloc_usable_size(p));
    return p;
}

void *realloc(void *old, size_t size)
{
    long long before = old ? (long long)malloc_usable_size(old) : 0;
    void *p = __libc_realloc(old, size);
    if (p)
        heap_add((long long)malloc_usable_size(p) - before);
    else if (size == 0 && old)
        heap_add(-before);
    return p;
}

void free(void *p)
{
    if (p)
        heap_add(-(long long)malloc_usable_size(p));
    __libc_free(p);
}

long long heap_in_use(void) { return atomic_load(&in_use); }

long long heap_peak_reset(void)
{
    long long now = atomic_load(&in_use);
    atomic_store(&peak, now);
    return now;
}

long long heap_peak(void) { return atomic_load(&peak); }
