/* Cache folders: the per-user one ($XDG_CACHE_HOME/gdr, else ~/.cache/gdr) or one given with
 * --cache-dir. gdr only ever lists, touches or removes the caches it wrote there: regular files of
 * this user named NAME-<16 hex digits>.gdrc (gdr_cache_path_for) that start with the cache's magic. */
#define _XOPEN_SOURCE 700
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/cache_internal.h"
#include "io/io_internal.h"

size_t gdr_cache_default_dir(char *out, size_t out_size)
{
    const char *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    int n;
    if (xdg && xdg[0] == '/') /* the XDG rule: a relative value is ignored */
        n = snprintf(out, out_size, "%s/gdr", xdg);
    else if (home && home[0] == '/')
        n = snprintf(out, out_size, "%s/.cache/gdr", home);
    else
        return 0;
    return n > 0 && (size_t)n < out_size ? (size_t)n : 0;
}

gdr_status gdr_io_cache_dir_prepare(const char *dir, gdr_error *err)
{
    char parent[PATH_MAX];
    gdr_io_dirname(dir, parent, sizeof parent);
    if (parent[0] && mkdir(parent, 0700) != 0 && errno != EEXIST)
        return gdr_error_set(err, GDR_ERROR_IO, "cache folder %s: cannot create its parent: %s", dir, strerror(errno));
    if (mkdir(dir, 0700) != 0 && errno != EEXIST)
        return gdr_error_set(err, GDR_ERROR_IO, "cache folder %s: cannot create it: %s", dir, strerror(errno));
    struct stat st;
    if (stat(dir, &st) != 0)
        return gdr_error_set(err, GDR_ERROR_IO, "cache folder %s: %s", dir, strerror(errno));
    if (!S_ISDIR(st.st_mode))
        return gdr_error_set(err, GDR_ERROR_NOT_A_FILE, "cache folder %s: not a folder", dir);
    /* Another user who can write here could plant a cache, which would then be rendered as the scene. */
    if (st.st_uid != geteuid() || (st.st_mode & 022))
        return gdr_error_set(err, GDR_ERROR_IO, "cache folder %s: %s; caches are neither read nor written there",
                             dir, st.st_uid != geteuid() ? "belongs to another user" : "others may write to it");
    return GDR_OK;
}

void gdr_io_cache_touch(const char *path)
{
    utimensat(AT_FDCWD, path, NULL, 0); /* best effort: a cache that cannot be touched ages sooner */
}

uint64_t gdr_io_cache_limit(uint64_t max_bytes)
{
    if (max_bytes)
        return max_bytes;
    const char *text = getenv("GDR_CACHE_MAX_MIB");
    char *end;
    errno = 0;
    unsigned long long mib = text ? strtoull(text, &end, 10) : 0;
    if (text && !errno && end != text && !*end && text[0] != '-' && mib > 0 && mib < (1ull << 40))
        return mib << 20;
    return GDR_CACHE_DEFAULT_MAX_BYTES;
}

/* NAME-<16 lowercase hex digits>.gdrc, as gdr_cache_path_for names caches in a folder. */
static int cache_name(const char *name)
{
    size_t n = strlen(name);
    if (n < 23 || strcmp(name + n - 5, ".gdrc") != 0 || name[n - 22] != '-')
        return 0;
    for (size_t i = n - 21; i < n - 5; i++)
        if (!((name[i] >= '0' && name[i] <= '9') || (name[i] >= 'a' && name[i] <= 'f')))
            return 0;
    return 1;
}

typedef struct cache_file {
    char *path;
    uint64_t size;
    int64_t used_ns;
} cache_file;

/* A regular file of this user (not a link) that starts with the cache's magic. */
static int is_gdr_cache(const char *path, struct stat *st)
{
    if (lstat(path, st) != 0 || !S_ISREG(st->st_mode) || st->st_uid != geteuid())
        return 0;
    int fd = open(path, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    char magic[8];
    int ok = fd >= 0 && gdr_io_pread_exact(fd, magic, 8, 0) == 8 && memcmp(magic, CACHE_MAGIC, 8) == 0;
    if (fd >= 0)
        close(fd);
    return ok;
}

static int compare_use(const void *a, const void *b)
{
    const cache_file *x = a, *y = b;
    if (x->used_ns != y->used_ns)
        return x->used_ns < y->used_ns ? -1 : 1;
    return strcmp(x->path, y->path);
}

static void free_files(cache_file *files, size_t count)
{
    for (size_t i = 0; i < count; i++)
        free(files[i].path);
    free(files);
}

/* The caches gdr wrote in dir, least recently used first. */
static gdr_status list_files(const char *dir, cache_file **out, size_t *out_count, gdr_error *err)
{
    *out = NULL;
    *out_count = 0;
    DIR *d = opendir(dir);
    if (!d)
        return errno == ENOENT ? GDR_OK
                               : gdr_error_set(err, GDR_ERROR_IO, "cache folder %s: %s", dir, strerror(errno));
    cache_file *files = NULL;
    size_t count = 0, capacity = 0;
    gdr_status status = GDR_OK;
    for (struct dirent *e; status == GDR_OK && (e = readdir(d));) {
        char path[PATH_MAX];
        struct stat st;
        if (!cache_name(e->d_name) || snprintf(path, sizeof path, "%s/%s", dir, e->d_name) >= (int)sizeof path ||
            !is_gdr_cache(path, &st))
            continue;
        if (count == capacity) {
            capacity = capacity ? capacity * 2 : 16;
            cache_file *grown = realloc(files, capacity * sizeof *grown);
            if (!grown) {
                status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "cache folder %s: out of memory", dir);
                break;
            }
            files = grown;
        }
        files[count].path = strdup(path);
        files[count].size = (uint64_t)st.st_size;
        files[count].used_ns = (int64_t)st.st_mtim.tv_sec * 1000000000ll + st.st_mtim.tv_nsec;
        if (!files[count++].path)
            status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "cache folder %s: out of memory", dir);
    }
    closedir(d);
    if (status != GDR_OK) {
        free_files(files, count);
        return status;
    }
    if (count)
        qsort(files, count, sizeof *files, compare_use);
    *out = files;
    *out_count = count;
    return GDR_OK;
}

uint32_t gdr_io_cache_evict(const char *dir, uint64_t max_bytes, const char *keep)
{
    cache_file *files;
    size_t count;
    gdr_error err;
    if (list_files(dir, &files, &count, &err) != GDR_OK)
        return 0;
    uint64_t total = 0;
    for (size_t i = 0; i < count; i++)
        total += files[i].size;
    uint32_t removed = 0;
    char kept[PATH_MAX] = "";
    if (keep && !realpath(keep, kept))
        kept[0] = 0;
    for (size_t i = 0; i < count && total > max_bytes; i++) {
        char resolved[PATH_MAX];
        if (kept[0] && realpath(files[i].path, resolved) && strcmp(resolved, kept) == 0)
            continue;
        /* Another gdr may have removed it first: either way it is gone. */
        if (unlink(files[i].path) == 0 || errno == ENOENT) {
            total -= files[i].size;
            removed++;
        }
    }
    free_files(files, count);
    return removed;
}

/* The folder a listing or a clearing is about: dir, else the per-user one. */
static gdr_status which_dir(const char *dir, char *out, size_t size, gdr_error *err)
{
    if (dir) {
        snprintf(out, size, "%s", dir);
        return GDR_OK;
    }
    if (!gdr_cache_default_dir(out, size))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "no cache folder: neither XDG_CACHE_HOME nor HOME is "
                             "an absolute path");
    return GDR_OK;
}

gdr_status gdr_cache_list(const char *dir, gdr_cache_entry_fn fn, void *user, gdr_error *err)
{
    char folder[PATH_MAX];
    cache_file *files;
    size_t count;
    gdr_status status = which_dir(dir, folder, sizeof folder, err);
    if (status == GDR_OK)
        status = list_files(folder, &files, &count, err);
    if (status != GDR_OK)
        return status;
    for (size_t i = 0; i < count; i++) {
        char source[PATH_MAX];
        gdr_error source_err;
        if (gdr_io_cache_recorded_source(files[i].path, source, sizeof source, &source_err) != GDR_OK)
            source[0] = 0;
        gdr_cache_entry entry = {files[i].path, source, files[i].size, files[i].used_ns};
        fn(user, &entry);
    }
    free_files(files, count);
    return GDR_OK;
}

gdr_status gdr_cache_clear(const char *dir, uint32_t *removed, uint64_t *bytes, gdr_error *err)
{
    char folder[PATH_MAX];
    cache_file *files;
    size_t count;
    if (removed)
        *removed = 0;
    if (bytes)
        *bytes = 0;
    gdr_status status = which_dir(dir, folder, sizeof folder, err);
    if (status == GDR_OK)
        status = list_files(folder, &files, &count, err);
    if (status != GDR_OK)
        return status;
    for (size_t i = 0; i < count && status == GDR_OK; i++) {
        if (unlink(files[i].path) != 0 && errno != ENOENT) {
            status = gdr_error_set(err, GDR_ERROR_IO, "%s: cannot remove: %s", files[i].path, strerror(errno));
        } else {
            if (removed)
                (*removed)++;
            if (bytes)
                *bytes += files[i].size;
        }
    }
    free_files(files, count);
    return status;
}
