/* The scene cache's two halves (docs/CACHE_FORMAT.md): the container (cache.c: header, section
 * table, checksums, coverage, staleness, the file) and the sections (cache_sections.c: one
 * description per section saying how it is written and read). Not part of the public API. */
#ifndef GDR_IO_CACHE_INTERNAL_H
#define GDR_IO_CACHE_INTERNAL_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/io.h"

#define CACHE_MAGIC "GDRCACHE"
#define CACHE_HEADER_SIZE 64u
#define CACHE_ENTRY_SIZE 32u
#define CACHE_MAX_SECTIONS 1024u
#define CACHE_SECTION_REQUIRED 1u /* table flag: a reader that does not know the section must refuse the file */
#define CACHE_FLAG_PAGES_ONLY 1u  /* header flag: the geometry is in section 'PAGE' alone (no GEOM, VCOL, CLGM) */
#define CACHE_MAX_TEXTURE_SIDE 32768u /* the largest texture side the reader accepts (and the writer writes) */

/* --- writing: a growing buffer; `failed` once memory ran out ---------------------------------- */

typedef struct writer {
    uint8_t *data;
    size_t size, capacity;
    int failed;
} writer;

static inline void put(writer *w, const void *bytes, size_t n)
{
    if (w->failed)
        return;
    if (w->size + n > w->capacity) {
        size_t capacity = w->capacity ? w->capacity : 4096;
        while (capacity < w->size + n)
            capacity *= 2;
        uint8_t *grown = realloc(w->data, capacity);
        if (!grown) {
            w->failed = 1;
            return;
        }
        w->data = grown;
        w->capacity = capacity;
    }
    if (n && bytes)
        memcpy(w->data + w->size, bytes, n);
    w->size += n;
}

static inline void put_u32(writer *w, uint32_t v) { put(w, &v, 4); }
static inline void put_u64(writer *w, uint64_t v) { put(w, &v, 8); }
static inline void put_f32s(writer *w, const float *v, size_t n) { put(w, v, 4 * n); }
static inline void put_name(writer *w, const char *name)
{
    char buffer[GDR_NAME_MAX] = {0};
    snprintf(buffer, sizeof buffer, "%s", name);
    put(w, buffer, sizeof buffer);
}
static inline void put_string(writer *w, const char *s)
{
    uint32_t n = s ? (uint32_t)strlen(s) : 0;
    put_u32(w, n);
    put(w, s, n);
}
/* Zero bytes up to a multiple of `alignment` (a power of two up to 8). */
static inline void put_align(writer *w, size_t alignment)
{
    static const uint8_t zeros[8] = {0};
    put(w, zeros, (alignment - w->size % alignment) % alignment);
}
/* n bytes at the end, for the caller to fill; NULL when out of memory. */
static inline uint8_t *put_space(writer *w, size_t n)
{
    put(w, NULL, n);
    return w->failed ? NULL : w->data + w->size - n;
}

/* --- reading: a bounded cursor; `failed` once a read ran past the end ------------------------- */

typedef struct reader {
    const uint8_t *data;
    size_t size, at;
    int failed;
} reader;

static inline const uint8_t *take(reader *r, size_t n)
{
    if (r->failed || n > r->size - r->at) {
        r->failed = 1;
        return NULL;
    }
    const uint8_t *p = r->data + r->at;
    r->at += n;
    return p;
}
static inline uint32_t get_u32(reader *r)
{
    uint32_t v = 0;
    const uint8_t *p = take(r, 4);
    if (p)
        memcpy(&v, p, 4);
    return v;
}
static inline uint64_t get_u64(reader *r)
{
    uint64_t v = 0;
    const uint8_t *p = take(r, 8);
    if (p)
        memcpy(&v, p, 8);
    return v;
}
static inline void get_f32s(reader *r, float *out, size_t n)
{
    const uint8_t *p = take(r, 4 * n);
    if (p)
        memcpy(out, p, 4 * n);
    else
        memset(out, 0, 4 * n);
}
static inline void get_name(reader *r, char *out)
{
    const uint8_t *p = take(r, GDR_NAME_MAX);
    if (p)
        memcpy(out, p, GDR_NAME_MAX);
    else
        out[0] = 0;
    out[GDR_NAME_MAX - 1] = 0;
}
/* A length-prefixed string: points into the data (not NUL-terminated). */
static inline const char *get_string(reader *r, uint32_t *length)
{
    *length = get_u32(r);
    return (const char *)take(r, *length);
}

/* One record of section 'INST' (docs/CACHE_FORMAT.md), as the whole-file and the paged reader
 * read it; CACHE_INSTANCE_RECORD bytes. The caller checks the values. */
#define CACHE_INSTANCE_RECORD (64u + 8u + 16u + 8u)
static inline void cache_get_instance(reader *r, gdr_instance *inst)
{
    get_f32s(r, inst->transform.m, 16);
    inst->mesh = get_u32(r);
    inst->material = get_u32(r);
    get_f32s(r, &inst->color.x, 4);
    get_f32s(r, &inst->min_screen_size, 1);
    get_f32s(r, &inst->max_screen_size, 1);
}

/* A section id as text for messages ('?' for bytes that are not printable). */
static inline void fourcc_text(uint32_t id, char out[5])
{
    for (int i = 0; i < 4; i++) {
        char ch = (char)(id >> (8 * i));
        out[i] = ch >= 32 && ch < 127 ? ch : '?';
    }
    out[4] = 0;
}

/* --- the sections ------------------------------------------------------------------------------ */

/* Every section this build knows, in the order they are written and read (a section may use what
 * the ones before it read). */
enum {
    CACHE_SOURCE, CACHE_REPORT, CACHE_SCENE, CACHE_TEXTURES, CACHE_PIXELS, CACHE_MESHES, CACHE_GEOMETRY, CACHE_COLORS, CACHE_CLUSTERS,
    CACHE_CLUSTER_GROUPS, CACHE_CLUSTER_DATA, CACHE_CLUSTER_GEOMETRY, CACHE_HIERARCHY, CACHE_MATERIALS, CACHE_INSTANCES, CACHE_CAMERAS, CACHE_PVS,
    CACHE_PAGES, CACHE_SECTION_COUNT
};

/* What a file is written from. */
typedef struct cache_write_input {
    const gdr_scene *scene;
    const gdr_cache_source *source;
    const gdr_import_report *report; /* NULL: a report with no warnings */
    const gdr_pvs *pvs; /* NULL: no PVIS section */
    uint32_t page_bytes; /* 0: no PAGE section */
    int pages_only;      /* the pages hold the only copy of the geometry: GEOM, VCOL, CLGM left out */
} cache_write_input;

/* The input of a write with these options: a cache with pages keeps its geometry in them alone
 * unless asked for the whole geometry too. */
static inline cache_write_input cache_write_input_of(const gdr_scene *scene, const gdr_cache_write_options *o)
{
    return (cache_write_input){scene, &o->source, o->report, o->pvs, o->page_bytes,
                               o->page_bytes != 0 && !o->whole_geometry};
}

typedef struct cache_read_state cache_read_state; /* cache_sections.c */

/* One entry of the section table. */
typedef struct section_entry {
    uint32_t id, flags;
    uint64_t offset, size, checksum;
} section_entry;

/* The header and section table (`count` entries) of a file of `size` bytes into `head`
 * (CACHE_HEADER_SIZE + count * CACHE_ENTRY_SIZE bytes); `flags`: CACHE_FLAG_PAGES_ONLY or 0. */
void cache_put_header(uint8_t *head, const section_entry *entries, uint32_t count, uint64_t size, uint32_t flags);

/* One section: its id and flags, and how it is written and read. */
typedef struct cache_section {
    uint32_t id;    /* four ASCII characters, the first in the lowest byte */
    uint32_t flags; /* CACHE_SECTION_REQUIRED */
    int optional;   /* a file may leave it out */
    int (*present)(const cache_write_input *in); /* NULL: always written */
    /* What the input must satisfy to be written (NULL: anything); refuses naming `path`. */
    gdr_status (*check)(const cache_write_input *in, const char *path, gdr_error *err);
    void (*write)(writer *w, const cache_write_input *in);
    /* Reads and checks the whole section into the scene being built; NULL: the container reads it
     * (SRCE, for staleness; REPT, the import's report). */
    gdr_status (*read)(cache_read_state *st, reader *r, gdr_error *err);
    int in_pages; /* geometry the pages hold too: a read for streaming leaves it in the file */
    int whole_geometry; /* the whole geometry (GEOM, VCOL, CLGM): in every file but one whose geometry is
                           in its pages alone (CACHE_FLAG_PAGES_ONLY), which must not have it */
} cache_section;

extern const cache_section gdr_cache_sections[CACHE_SECTION_COUNT];

/* The sections of a file whose container was checked (every known section's bytes, by index). */
typedef struct cache_view {
    const uint8_t *data;
    size_t size;
    reader sections[CACHE_SECTION_COUNT];
    int present[CACHE_SECTION_COUNT];
    uint32_t flags; /* the header's: CACHE_FLAG_PAGES_ONLY or 0 */
} cache_view;

/* The checks of the header's CACHE_HEADER_SIZE bytes `h` of a file of `size` bytes (magic, version,
 * checksum, size, flags, reserved bytes; the table fits): the whole-file, the streaming and the
 * paged readers share them. Out: the table's entry count and checksum, the flags (may be NULL). */
gdr_status cache_parse_header(const char *name, const uint8_t *h, uint64_t size, uint32_t *out_count,
                              uint64_t *out_table_hash, uint32_t *out_flags, gdr_error *err);

/* Builds the scene (and the PVS when out_pvs is not NULL) from the sections, each read and checked
 * by its description, in table order. With `paged`, the sections marked in_pages are not read (their
 * readers are not given their bytes) and the scene's meshes hold no geometry (geometry_in_pages).
 * On failure nothing is returned. */
gdr_status gdr_cache_read_sections(const char *name, cache_view *v, int paged, gdr_scene **out, gdr_pvs **out_pvs,
                                   gdr_error *err);

#endif
