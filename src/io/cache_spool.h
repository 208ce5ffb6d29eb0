/* A section of the scene cache being written in parts (cache_meshes.c): its bytes in an unnamed
 * temporary file beside the output, their XXH3 taken as they arrive, copied into the output once
 * every part is there. Not part of the public API. */
#ifndef GDR_IO_CACHE_SPOOL_H
#define GDR_IO_CACHE_SPOOL_H

#include <stddef.h>
#include <stdint.h>

#include "gdr/core.h"

typedef struct cache_spool {
    int fd;        /* -1: not open */
    uint64_t size; /* bytes appended */
    void *hash;    /* XXH3 state over those bytes */
} cache_spool;

/* An empty spool in the folder of `output` (a file there that is removed at once, so that nothing
 * is left behind whatever happens), or in the temporary folder when that folder takes none. */
gdr_status cache_spool_open(cache_spool *spool, const char *output, gdr_error *err);
/* Appends n bytes; 0 when the write fails (errno says why). */
int cache_spool_append(cache_spool *spool, const void *data, size_t n);
/* XXH3-64 of every byte appended. */
uint64_t cache_spool_digest(const cache_spool *spool);
/* Feeds every byte appended to `hash` (an XXH3 state) by reading the file back; 0 on a read failure. */
int cache_spool_hash_into(const cache_spool *spool, void *hash);
/* Writes every byte appended to `fd` at its position; 0 on failure (errno says why). */
int cache_spool_copy(const cache_spool *spool, int fd);
void cache_spool_close(cache_spool *spool);

/* Writes exactly n bytes to fd (again after EINTR and short writes); 0 on failure. */
int cache_write_all(int fd, const void *data, size_t n);

#endif
