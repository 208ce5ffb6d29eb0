/* File reading, file identities for the cache, warnings and base64. */
#define _XOPEN_SOURCE 700 /* realpath */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <xxhash.h>

#include "io/io_internal.h"

uint64_t gdr_io_max_file_size = GDR_IO_MAX_FILE_SIZE;

uint64_t gdr_io_hash(const void *data, size_t size)
{
    return (uint64_t)XXH3_64bits(data, size);
}

int gdr_io_stat(const char *path, uint64_t *size, int64_t *mtime_ns)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return -1;
    *size = (uint64_t)st.st_size;
    *mtime_ns = (int64_t)st.st_mtim.tv_sec * 1000000000ll + st.st_mtim.tv_nsec;
    return 0;
}

gdr_status gdr_io_source_add(gdr_source_list *list, const char *path, uint64_t size, int64_t mtime_ns,
                             uint64_t hash, gdr_error *err)
{
    if (list->count == list->capacity) {
        uint32_t capacity = list->capacity ? list->capacity * 2 : 8;
        gdr_source_file *grown = realloc(list->files, sizeof *grown * capacity);
        if (!grown)
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
        list->files = grown;
        list->capacity = capacity;
    }
    size_t length = strlen(path);
    char *copy = malloc(length + 1);
    if (!copy)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    memcpy(copy, path, length + 1);
    list->files[list->count++] = (gdr_source_file){copy, size, mtime_ns, hash, GDR_SOURCE_READ};
    return GDR_OK;
}

void gdr_io_absolute_path(const char *path, char *out, size_t out_size)
{
    char resolved[PATH_MAX], dir[PATH_MAX];
    if (realpath(path, resolved)) {
        snprintf(out, out_size, "%s", resolved);
        return;
    }
    /* Nothing there: its folder resolved, with the last part as written. */
    gdr_io_dirname(path, dir, sizeof dir);
    const char *base = path + strlen(dir);
    if (realpath(dir[0] ? dir : ".", resolved)) {
        snprintf(out, out_size, "%s%s%s", resolved, strcmp(resolved, "/") ? "/" : "", base);
        return;
    }
    char cwd[PATH_MAX];
    if (path[0] != '/' && getcwd(cwd, sizeof cwd))
        snprintf(out, out_size, "%s/%s", cwd, path);
    else
        snprintf(out, out_size, "%s", path);
}

gdr_status gdr_io_source_add_looked_for(gdr_source_list *list, const char *path, gdr_error *err)
{
    if (!list)
        return GDR_OK;
    char absolute[PATH_MAX];
    gdr_io_absolute_path(path, absolute, sizeof absolute);
    uint64_t size = 0;
    int64_t mtime = 0;
    int exists = gdr_io_stat(absolute, &size, &mtime) == 0;
    gdr_status status = gdr_io_source_add(list, absolute, exists ? size : 0, exists ? mtime : 0, 0, err);
    if (status == GDR_OK)
        list->files[list->count - 1].state = exists ? GDR_SOURCE_UNREAD : GDR_SOURCE_ABSENT;
    return status;
}

/* The length of a UTF-8 sequence at s (n bytes left) that encodes a printable code point (U+00A0
 * and up, not a surrogate), or 0. */
static size_t printable_utf8(const unsigned char *s, size_t n)
{
    size_t length = s[0] >= 0xf0 && s[0] <= 0xf4 ? 4 : s[0] >= 0xe0 ? 3 : s[0] >= 0xc2 && s[0] < 0xe0 ? 2 : 0;
    if (length == 0 || length > n || (s[0] >= 0xe0 && s[0] < 0xf0 && length != 3))
        return 0;
    uint32_t cp = s[0] & (0x7f >> length);
    for (size_t i = 1; i < length; i++) {
        if ((s[i] & 0xc0) != 0x80)
            return 0;
        cp = cp << 6 | (s[i] & 0x3f);
    }
    int shortest = (length == 2 && cp >= 0x80) || (length == 3 && cp >= 0x800) || (length == 4 && cp >= 0x10000);
    return shortest && cp >= 0xa0 && cp <= 0x10ffff && !(cp >= 0xd800 && cp <= 0xdfff) ? length : 0;
}

size_t gdr_io_escape_text(const char *text, size_t length, char *out, size_t out_size)
{
    const unsigned char *s = (const unsigned char *)text;
    size_t n = 0;
    for (size_t i = 0; i < length && out_size;) {
        size_t utf8 = s[i] >= 0x80 ? printable_utf8(s + i, length - i) : 0;
        size_t need = utf8 ? utf8 : s[i] >= 0x20 && s[i] < 0x7f ? 1 : 4;
        if (n + need >= out_size)
            break;
        if (utf8)
            memcpy(out + n, s + i, utf8);
        else if (need == 1)
            out[n] = (char)s[i];
        else
            snprintf(out + n, 5, "\\x%02x", s[i]);
        n += need;
        i += utf8 ? utf8 : 1;
    }
    if (out_size)
        out[n] = 0;
    return n;
}

void gdr_source_list_free(gdr_source_list *list)
{
    if (!list)
        return;
    for (uint32_t i = 0; i < list->count; i++)
        free(list->files[i].path);
    free(list->files);
    *list = (gdr_source_list){0};
}

gdr_status gdr_io_open_regular(const char *path, int *out_fd, gdr_error *err)
{
    *out_fd = -1;
    /* O_NONBLOCK: opening a FIFO without a writer, or some devices, would otherwise wait forever
     * before fstat could refuse them. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0)
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    int flags = fcntl(fd, F_GETFL);
    if (fstat(fd, &st) != 0 || flags < 0) {
        int error = errno;
        close(fd);
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot stat: %s", path, strerror(error));
    }
    if (!S_ISREG(st.st_mode)) {
        close(fd);
        return gdr_error_set(err, GDR_ERROR_NOT_A_FILE, "%s: not a regular file", path);
    }
    if (fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
        int error = errno;
        close(fd);
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot open: %s", path, strerror(error));
    }
    *out_fd = fd;
    return GDR_OK;
}

size_t gdr_io_pread_exact(int fd, void *dst, size_t size, uint64_t offset)
{
    size_t done = 0;
    while (done < size) {
        ssize_t n = pread(fd, (uint8_t *)dst + done, size - done, (off_t)(offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            if (n == 0)
                errno = 0;
            break;
        }
        done += (size_t)n;
    }
    return done;
}

/* The `size` bytes of the open regular file `fd` (closed here) into a malloc'ed buffer with one NUL
 * byte after them. */
static gdr_status read_open_file(const char *path, int fd, size_t size, char **out, gdr_error *err)
{
    char *data = malloc(size + 1);
    if (!data) {
        close(fd);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory reading %zu bytes", path, size);
    }
    size_t got = gdr_io_pread_exact(fd, data, size, 0);
    int read_errno = errno;
    close(fd);
    if (got != size) {
        free(data);
        return gdr_error_set(err, GDR_ERROR_IO, "%s: read %zu of %zu bytes%s%s", path, got, size,
                             read_errno ? ": " : "", read_errno ? strerror(read_errno) : "");
    }
    data[size] = 0;
    *out = data;
    return GDR_OK;
}

gdr_status gdr_io_read_file(const char *path, uint8_t **out_data, size_t *out_size, gdr_source_list *sources,
                            gdr_error *err)
{
    *out_data = NULL;
    *out_size = 0;
    int fd;
    gdr_status opened = gdr_io_open_regular(path, &fd, err);
    if (opened != GDR_OK)
        return opened;
    struct stat st;
    if (fstat(fd, &st) != 0) {
        close(fd);
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot stat: %s", path, strerror(errno));
    }
    if ((uint64_t)st.st_size > gdr_io_max_file_size) {
        close(fd);
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: %llu bytes is larger than the %llu byte limit",
                             path, (unsigned long long)st.st_size, (unsigned long long)gdr_io_max_file_size);
    }
    size_t size = (size_t)st.st_size;
    char *text;
    gdr_status status = read_open_file(path, fd, size, &text, err);
    if (status != GDR_OK)
        return status;
    uint8_t *data = (uint8_t *)text;
    if (sources) {
        /* Absolute, so the cache can be checked from any working directory. */
        char absolute[PATH_MAX];
        status = gdr_io_source_add(sources, realpath(path, absolute) ? absolute : path, size,
                                   (int64_t)st.st_mtim.tv_sec * 1000000000ll + st.st_mtim.tv_nsec,
                                   gdr_io_hash(data, size), err);
        if (status != GDR_OK) {
            free(data);
            return status;
        }
    }
    *out_data = data;
    *out_size = size;
    return GDR_OK;
}

void gdr_io_warn(gdr_io_warnings *w, const char *format, ...)
{
    char message[GDR_ERROR_MESSAGE_MAX];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    w->count++;
    /* Text from the file (names, URIs) may hold control characters: escaped, never sent to a terminal. */
    char safe[GDR_ERROR_MESSAGE_MAX];
    gdr_io_escape_text(message, strlen(message), safe, sizeof safe);
    memcpy(message, safe, sizeof safe);
    if (w->fn)
        w->fn(w->user, message);
    else
        fprintf(stderr, "gdr: warning: %s\n", message);
}

static int base64_value(unsigned char c)
{
    if (c >= 'A' && c <= 'Z')
        return c - 'A';
    if (c >= 'a' && c <= 'z')
        return c - 'a' + 26;
    if (c >= '0' && c <= '9')
        return c - '0' + 52;
    if (c == '+' || c == '-')
        return 62;
    if (c == '/' || c == '_')
        return 63;
    return -1;
}

size_t gdr_base64_decode(uint8_t *out, const char *in, size_t length)
{
    while (length > 0 && in[length - 1] == '=')
        length--;
    size_t written = 0;
    uint32_t accumulator = 0;
    int bits = 0;
    for (size_t i = 0; i < length; i++) {
        int v = base64_value((unsigned char)in[i]);
        if (v < 0)
            return SIZE_MAX;
        accumulator = (accumulator << 6) | (uint32_t)v;
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out[written++] = (uint8_t)(accumulator >> bits);
        }
    }
    return written;
}

void gdr_io_dirname(const char *path, char *out, size_t out_size)
{
    const char *slash = strrchr(path, '/');
    size_t length = slash ? (size_t)(slash - path) + 1 : 0;
    if (length >= out_size)
        length = 0;
    memcpy(out, path, length);
    out[length] = 0;
}

int gdr_io_has_extension(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n >= e && strcasecmp(path + n - e, ext) == 0;
}

gdr_status gdr_read_file(const char *path, size_t max_size, char **out, size_t *out_size, gdr_error *err)
{
    *out = NULL;
    *out_size = 0;
    int fd;
    gdr_status status = gdr_io_open_regular(path, &fd, err);
    if (status != GDR_OK)
        return status;
    struct stat st;
    if (fstat(fd, &st) != 0 || (uint64_t)st.st_size > max_size) {
        close(fd);
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "%s: larger than %zu bytes", path, max_size);
    }
    status = read_open_file(path, fd, (size_t)st.st_size, out, err);
    if (status == GDR_OK)
        *out_size = (size_t)st.st_size;
    return status;
}
