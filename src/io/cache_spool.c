/* Spools of the scene cache's sections written in parts (cache_spool.h). */
#define _GNU_SOURCE /* copy_file_range */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <xxhash.h>

#include "io/cache_spool.h"
#include "io/io_internal.h"

#define SPOOL_CHUNK (4u << 20) /* bytes read back at a time */

/* A file removed at once in `folder`: mkstemp, then unlink. -1 on failure. */
static int unnamed_file(const char *folder)
{
    char name[PATH_MAX];
    if (snprintf(name, sizeof name, "%s/.gdr-spool-XXXXXX", folder) >= (int)sizeof name)
        return -1;
    int fd = mkstemp(name);
    if (fd >= 0)
        unlink(name);
    return fd;
}

gdr_status cache_spool_open(cache_spool *spool, const char *output, gdr_error *err)
{
    *spool = (cache_spool){.fd = -1};
    char folder[PATH_MAX];
    gdr_io_dirname(output, folder, sizeof folder);
    spool->fd = unnamed_file(folder[0] ? folder : ".");
    if (spool->fd < 0) {
        const char *tmp = getenv("TMPDIR");
        spool->fd = unnamed_file(tmp && tmp[0] == '/' ? tmp : "/tmp");
    }
    if (spool->fd < 0)
        return gdr_error_set(err, GDR_ERROR_IO, "%s: no temporary file beside it or in the temporary folder: %s",
                             output, strerror(errno));
    XXH3_state_t *state = XXH3_createState();
    if (!state || XXH3_64bits_reset(state) != XXH_OK) {
        XXH3_freeState(state);
        cache_spool_close(spool);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", output);
    }
    spool->hash = state;
    return GDR_OK;
}

int cache_write_all(int fd, const void *data, size_t n)
{
    const uint8_t *p = data;
    while (n > 0) {
        ssize_t done = write(fd, p, n);
        if (done < 0 && errno == EINTR)
            continue;
        if (done <= 0)
            return 0;
        p += done;
        n -= (size_t)done;
    }
    return 1;
}

int cache_spool_append(cache_spool *spool, const void *data, size_t n)
{
    if (n == 0)
        return 1;
    if (!cache_write_all(spool->fd, data, n))
        return 0;
    XXH3_64bits_update(spool->hash, data, n);
    spool->size += n;
    return 1;
}

uint64_t cache_spool_digest(const cache_spool *spool) { return (uint64_t)XXH3_64bits_digest(spool->hash); }

int cache_spool_hash_into(const cache_spool *spool, void *hash)
{
    uint8_t *buffer = malloc(SPOOL_CHUNK);
    int ok = buffer != NULL;
    for (uint64_t at = 0; ok && at < spool->size;) {
        size_t n = spool->size - at < SPOOL_CHUNK ? (size_t)(spool->size - at) : SPOOL_CHUNK;
        ok = gdr_io_pread_exact(spool->fd, buffer, n, at) == n;
        if (ok)
            XXH3_64bits_update(hash, buffer, n);
        at += n;
    }
    free(buffer);
    return ok;
}

/* Gives the disk blocks of bytes [from, to) of the spool back (they are in the output now), so that
 * the disk holds each byte once, in the spool or in the file, and the spools' copy needs no room of
 * its own. Where the file system cannot, the blocks go when the spool is closed. */
static void release(const cache_spool *spool, uint64_t from, uint64_t to)
{
    if (to > from)
        (void)fallocate(spool->fd, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, (off_t)from, (off_t)(to - from));
}

/* The copy through a buffer, from byte `at` on (where copy_file_range cannot go on). */
static int copy_by_reading(const cache_spool *spool, uint64_t at, int fd)
{
    uint8_t *buffer = malloc(SPOOL_CHUNK);
    int ok = buffer != NULL;
    while (ok && at < spool->size) {
        size_t n = spool->size - at < SPOOL_CHUNK ? (size_t)(spool->size - at) : SPOOL_CHUNK;
        ok = gdr_io_pread_exact(spool->fd, buffer, n, at) == n && cache_write_all(fd, buffer, n);
        if (ok)
            release(spool, at, at + n);
        at += n;
    }
    free(buffer);
    return ok;
}

int cache_spool_copy(const cache_spool *spool, int fd)
{
    /* In the kernel where it can (no copy through user memory), else through a buffer; 64 MiB at a
     * time, each given back once copied. */
    loff_t at = 0;
    while ((uint64_t)at < spool->size) {
        size_t n = spool->size - (uint64_t)at < (64u << 20) ? (size_t)(spool->size - (uint64_t)at) : (64u << 20);
        loff_t from = at;
        ssize_t done = copy_file_range(spool->fd, &at, fd, NULL, n, 0);
        if (done < 0 && errno == EINTR)
            continue;
        if (done <= 0)
            return copy_by_reading(spool, (uint64_t)at, fd);
        release(spool, (uint64_t)from, (uint64_t)at);
    }
    return 1;
}

void cache_spool_close(cache_spool *spool)
{
    if (spool->fd >= 0)
        close(spool->fd);
    XXH3_freeState(spool->hash);
    *spool = (cache_spool){.fd = -1};
}
