/* Output files: links followed, regular files replaced atomically, devices and FIFOs written in
 * place (output_file.h). */
#define _XOPEN_SOURCE 700 /* realpath, fsync */
#include "core/output_file.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The process id of a temporary file of `base` ("BASE.tmp.PID"), or 0 when `name` is not one. */
static long temporary_pid(const char *name, const char *base)
{
    size_t length = strlen(base);
    if (strncmp(name, base, length) != 0 || strncmp(name + length, ".tmp.", 5) != 0)
        return 0;
    const char *digits = name + length + 5;
    char *end;
    errno = 0;
    long pid = strtol(digits, &end, 10);
    return digits[0] >= '1' && digits[0] <= '9' && !*end && !errno && pid > 0 ? pid : 0;
}

/* Removes the temporary files of `target` ("TARGET.tmp.PID") that writers killed by a signal left
 * behind: those whose process no longer runs (one still running, or of another user, is kept). */
static void remove_stale_temporaries(const char *target)
{
    const char *slash = strrchr(target, '/');
    char folder[PATH_MAX];
    if (!slash)
        snprintf(folder, sizeof folder, ".");
    else
        snprintf(folder, sizeof folder, "%.*s", slash == target ? 1 : (int)(slash - target), target);
    const char *base = slash ? slash + 1 : target;
    DIR *d = opendir(folder);
    if (!d)
        return;
    for (struct dirent *e; (e = readdir(d));) {
        long pid = temporary_pid(e->d_name, base);
        struct stat st;
        if (pid == 0 || (pid_t)pid == getpid())
            continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) /* running (perhaps as another user) */
            continue;
        if (fstatat(dirfd(d), e->d_name, &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISREG(st.st_mode))
            unlinkat(dirfd(d), e->d_name, 0);
    }
    closedir(d);
}

/* A device, FIFO or socket: opened for writing as it is (no O_CREAT, no O_TRUNC). */
static gdr_status open_direct(const char *path, gdr_output_file *out, gdr_error *err)
{
    int fd = open(path, O_WRONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0)
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot write: %s", path,
                             errno == ENXIO ? "a FIFO with no reader" : strerror(errno));
    int flags = fcntl(fd, F_GETFL);
    if (flags < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0 || !(out->file = fdopen(fd, "wb"))) {
        close(fd);
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot write: %s", path, strerror(errno));
    }
    return GDR_OK;
}

/* The file a chain of symbolic links ends at, which need not exist yet (its folder must). */
static bool resolve_link(const char *path, char *out)
{
    char current[PATH_MAX], next[PATH_MAX];
    snprintf(current, sizeof current, "%s", path);
    for (int hops = 0; hops < 16; hops++) {
        struct stat st;
        if (lstat(current, &st) != 0 || !S_ISLNK(st.st_mode))
            break;
        ssize_t n = readlink(current, next, sizeof next - 1);
        if (n <= 0)
            return false;
        next[n] = 0;
        if (next[0] != '/') { /* relative to the link's folder */
            const char *slash = strrchr(current, '/');
            int length = slash ? (int)(slash - current) + 1 : 0;
            char joined[PATH_MAX];
            if (snprintf(joined, sizeof joined, "%.*s%s", length, current, next) >= (int)sizeof joined)
                return false;
            snprintf(next, sizeof next, "%s", joined);
        }
        snprintf(current, sizeof current, "%s", next);
    }
    if (realpath(current, out))
        return true;
    /* Not there yet: its folder resolved, its name kept. */
    char folder[PATH_MAX], resolved[PATH_MAX];
    const char *slash = strrchr(current, '/');
    snprintf(folder, sizeof folder, "%.*s", slash ? (int)(slash - current) + (slash == current) : 1,
             slash ? current : ".");
    if (errno != ENOENT || !realpath(folder, resolved))
        return false;
    return snprintf(out, PATH_MAX, "%s/%s", resolved, slash ? slash + 1 : current) < PATH_MAX;
}

/* N when the path, or a link on the way from it, names this process's descriptor N (/dev/stdout,
 * /dev/fd/N, /proc/self/fd/N); -1 otherwise. */
static int own_descriptor(const char *path)
{
    char current[PATH_MAX], next[PATH_MAX];
    snprintf(current, sizeof current, "%s", path);
    for (int hops = 0; hops < 16; hops++) {
        if (strcmp(current, "/dev/stdout") == 0)
            return 1;
        if (strcmp(current, "/dev/stderr") == 0)
            return 2;
        const char *number = strncmp(current, "/dev/fd/", 8) == 0 ? current + 8
                             : strncmp(current, "/proc/self/fd/", 14) == 0 ? current + 14 : NULL;
        if (number && number[0] >= '0' && number[0] <= '9' && strspn(number, "0123456789") == strlen(number))
            return atoi(number);
        ssize_t n = readlink(current, next, sizeof next - 1);
        if (n <= 0 || next[0] != '/')
            return -1;
        next[n] = 0;
        snprintf(current, sizeof current, "%s", next);
    }
    return -1;
}

gdr_status gdr_output_open(const char *path, gdr_output_file *out, gdr_error *err)
{
    *out = (gdr_output_file){0};
    struct stat st;
    /* The process's own output (gdr ... --stats /dev/stdout > file): written through the descriptor
     * it has, after what is buffered for it, never replacing the file behind it. */
    int own = own_descriptor(path);
    if (own >= 0) {
        fflush(own == 1 ? stdout : own == 2 ? stderr : NULL);
        int fd = dup(own);
        if (fd < 0 || !(out->file = fdopen(fd, "wb"))) {
            if (fd >= 0)
                close(fd);
            return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot write: %s", path, strerror(errno));
        }
        if (!(out->target = strdup(path))) {
            fclose(out->file);
            out->file = NULL;
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
        }
        return GDR_OK;
    }
    /* What the path names, links followed: a device, FIFO or socket is written where it is (through
     * the path itself, so that /dev/stdout reaches a pipe). */
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return gdr_error_set(err, GDR_ERROR_NOT_A_FILE, "%s: is a directory", path);
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        if (!(out->target = strdup(path)))
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
        gdr_status status = open_direct(path, out, err);
        if (status != GDR_OK)
            free(out->target), out->target = NULL;
        return status;
    }
    /* A regular file, or none yet: replaced atomically, at the end of any chain of links. */
    char resolved[PATH_MAX];
    const char *target = path;
    if (lstat(path, &st) == 0 && S_ISLNK(st.st_mode)) {
        if (!resolve_link(path, resolved))
            return gdr_error_set(err, GDR_ERROR_IO, "%s: a symbolic link whose target cannot be written: %s", path,
                                 strerror(errno));
        target = resolved;
    }
    out->target = strdup(target);
    if (!out->target)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    size_t length = strlen(target) + 32;
    out->temporary = malloc(length);
    if (!out->temporary) {
        free(out->target), out->target = NULL;
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    remove_stale_temporaries(target);
    snprintf(out->temporary, length, "%s.tmp.%ld", target, (long)getpid());
    int fd = open(out->temporary, O_WRONLY | O_CREAT | O_TRUNC | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0 && errno == EEXIST && unlink(out->temporary) == 0) /* left by a crashed run of this pid */
        fd = open(out->temporary, O_WRONLY | O_CREAT | O_TRUNC | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0 || !(out->file = fdopen(fd, "wb"))) {
        gdr_status status = gdr_error_set(err, GDR_ERROR_IO, "%s: cannot create: %s", out->temporary, strerror(errno));
        if (fd >= 0)
            close(fd), unlink(out->temporary);
        free(out->temporary), free(out->target);
        *out = (gdr_output_file){0};
        return status;
    }
    return GDR_OK;
}

gdr_status gdr_output_close(gdr_output_file *out, bool ok, const char *path, gdr_error *err)
{
    gdr_status status = GDR_OK;
    int saved = errno;
    if (ok && (fflush(out->file) != 0 || (out->temporary && fsync(fileno(out->file)) != 0)))
        ok = false, saved = errno;
    if (fclose(out->file) != 0 && ok)
        ok = false, saved = errno;
    if (ok && out->temporary && rename(out->temporary, out->target) != 0)
        ok = false, saved = errno;
    if (!ok) {
        if (out->temporary)
            unlink(out->temporary);
        status = gdr_error_set(err, GDR_ERROR_IO, "%s: cannot write (%s)", path, strerror(saved));
    }
    free(out->temporary);
    free(out->target);
    *out = (gdr_output_file){0};
    return status;
}
