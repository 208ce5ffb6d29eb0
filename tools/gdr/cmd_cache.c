/* gdr cache list|clear [--cache-dir DIR]: the caches gdr keeps in a cache folder (the per-user one,
 * $XDG_CACHE_HOME/gdr or ~/.cache/gdr, by default). */
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "commands.h"
#include "gdr/io.h"

#define CACHE_USAGE                                                                                        \
    "usage: gdr cache list [--cache-dir DIR]    the caches gdr wrote there, least recently used first\n"  \
    "       gdr cache clear [--cache-dir DIR]   remove them (and nothing else)\n"                          \
    "  DIR: default the per-user folder ($XDG_CACHE_HOME/gdr, else ~/.cache/gdr); its size limit is\n"      \
    "  GDR_CACHE_MAX_MIB (default 4096) or --cache-max MIB of render, view and info\n"

typedef struct listing {
    unsigned count;
    unsigned long long bytes;
} listing;

static void print_entry(void *user, const gdr_cache_entry *e)
{
    listing *l = user;
    char when[32] = "?";
    time_t seconds = (time_t)(e->used_ns / 1000000000ll);
    struct tm tm;
    if (gmtime_r(&seconds, &tm))
        strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S", &tm);
    /* e->source comes from the file: its control characters are escaped already. */
    printf("%12llu  %s UTC  %s  (%s)\n", (unsigned long long)e->size, when, e->path,
           e->source[0] ? e->source : "source unknown");
    l->count++;
    l->bytes += e->size;
}

int gdr_cmd_cache(int argc, char **argv)
{
    const char *action = NULL, *dir = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--cache-dir") == 0 && i + 1 < argc) {
            dir = argv[++i];
        } else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            fputs(CACHE_USAGE, stdout);
            return 0;
        } else if (!action && (strcmp(argv[i], "list") == 0 || strcmp(argv[i], "clear") == 0)) {
            action = argv[i];
        } else {
            fprintf(stderr, "gdr cache: unexpected argument '%s'\n%s", argv[i], CACHE_USAGE);
            return 2;
        }
    }
    if (!action) {
        fputs(CACHE_USAGE, stderr);
        return 2;
    }
    gdr_error err = {0};
    char folder[4096];
    if (!dir && gdr_cache_default_dir(folder, sizeof folder))
        dir = folder;
    if (strcmp(action, "list") == 0) {
        listing l = {0};
        if (gdr_cache_list(dir, print_entry, &l, &err) != GDR_OK) {
            fprintf(stderr, "gdr: %s\n", err.message);
            return 1;
        }
        printf("%u cache(s), %llu bytes in %s\n", l.count, l.bytes, dir ? dir : "(no cache folder)");
        return 0;
    }
    uint32_t removed = 0;
    uint64_t bytes = 0;
    gdr_status status = gdr_cache_clear(dir, &removed, &bytes, &err);
    printf("removed %u cache(s), %llu bytes from %s\n", removed, (unsigned long long)bytes,
           dir ? dir : "(no cache folder)");
    if (status != GDR_OK) {
        fprintf(stderr, "gdr: %s\n", err.message);
        return 1;
    }
    return 0;
}
