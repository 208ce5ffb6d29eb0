/* The processed-scene cache (.gdrc): see docs/CACHE_FORMAT.md. Little-endian, a 64-byte header,
 * a table of checksummed sections; the reader trusts nothing in the file. */
#define _XOPEN_SOURCE 700 /* realpath */
#include <assert.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/output_file.h"
#include "io/cache_internal.h"
#include "io/import_report.h"
#include "io/io_internal.h"

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the cache reader and writer assume a little-endian host"
#endif


const char *gdr_cache_build_options(void)
{
    /* Bump when the importers' or the geometry processing's output for the same input changes. */
    return "import=1;meshlets=3;lod=11";
}

/* --- writing --------------------------------------------------------------------------------- */

/* Where the serialised file goes: whole in memory, written at the end (a device or FIFO, written in
 * place, cannot seek back to its header), or section by section into the temporary file, its header
 * and table written last, so that memory holds one section at a time and a cache of pages may grow
 * past what memory holds. */
typedef struct cache_sink {
    FILE *file;
    bool seekable;    /* written section by section; else all in memory until the end */
    uint64_t flushed; /* bytes written before w->data[0]: a multiple of 8 */
    int failed;
    gdr_progress progress; /* sections written */
} cache_sink;

/* The buffer's whole 8-byte words into the file; the rest stays (alignment is counted from it). */
static void flush_sections(writer *w, cache_sink *sink)
{
    if (!sink->seekable || w->failed)
        return;
    size_t n = w->size & ~(size_t)7;
    if (n && fwrite(w->data, 1, n, sink->file) != n)
        sink->failed = 1;
    memmove(w->data, w->data + n, w->size - n);
    w->size -= n;
    sink->flushed += n;
}

/* Every section whose description says it is present, in table order: one table entry each, its
 * checksum taken while its bytes are in memory. */
static void write_sections(writer *w, cache_sink *sink, const cache_write_input *in, section_entry *entries,
                           uint32_t *count)
{
    uint32_t n = 0;
    for (uint32_t k = 0; k < CACHE_SECTION_COUNT && !sink->failed; k++) {
        const cache_section *sec = &gdr_cache_sections[k];
        if (sec->present && !sec->present(in))
            continue;
        put_align(w, 8);
        size_t start = w->size;
        entries[n] = (section_entry){sec->id, sec->flags, sink->flushed + start, 0, 0};
        sec->write(w, in);
        entries[n].size = w->size - start;
        entries[n].checksum = w->failed ? 0 : gdr_io_hash(w->data + start, (size_t)entries[n].size);
        n++;
        flush_sections(w, sink);
        gdr_progress_update(&sink->progress, n);
    }
    *count = n;
}

static void store_u32(uint8_t *p, uint32_t v) { memcpy(p, &v, 4); }
static void store_u64(uint8_t *p, uint64_t v) { memcpy(p, &v, 8); }

/* The writer refuses what the reader would refuse, before serialising: a scene read for streaming
 * (its meshes have no arrays to write), a file over the reader's size limit (counted here from the raw arrays alone, a lower bound of the file), and textures
 * larger than it reads (the TEXR section's check). A cache that cannot be read back is never
 * written. */
static gdr_status check_reader_limits(const char *path, const gdr_scene *s, bool paged, gdr_error *err)
{
    if (s->geometry_in_pages)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: the scene was read for streaming and holds no "
                             "geometry: nothing written", path);
    uint64_t bytes = CACHE_HEADER_SIZE;
    for (uint32_t i = 0; i < s->texture_count; i++)
        bytes += gdr_texture_format_level_offset(s->textures[i].format, s->textures[i].width, s->textures[i].height, 1);
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh *m = &s->meshes[i];
        bytes += (uint64_t)m->vertex_count * 32 + (uint64_t)m->index_count * 4 + (uint64_t)m->clusters.vertex_count * 4 +
                 m->clusters.triangle_byte_count;
    }
    if (bytes > gdr_io_max_file_size && !paged)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "%s: the scene needs at least %llu bytes, more than the %llu a "
                             "cache may hold (the reader's limit)", path, (unsigned long long)bytes,
                             (unsigned long long)gdr_io_max_file_size);
    return GDR_OK;
}

void cache_put_header(uint8_t *head, const section_entry *entries, uint32_t count, uint64_t size, uint32_t flags)
{
    memset(head, 0, CACHE_HEADER_SIZE);
    uint8_t *table = head + CACHE_HEADER_SIZE;
    for (uint32_t i = 0; i < count; i++) {
        uint8_t *e = table + i * CACHE_ENTRY_SIZE;
        store_u32(e, entries[i].id);
        store_u32(e + 4, entries[i].flags);
        store_u64(e + 8, entries[i].offset);
        store_u64(e + 16, entries[i].size);
        store_u64(e + 24, entries[i].checksum);
    }
    memcpy(head, CACHE_MAGIC, 8);
    store_u32(head + 8, GDR_CACHE_FORMAT_VERSION);
    store_u32(head + 12, CACHE_HEADER_SIZE);
    store_u32(head + 16, count);
    store_u32(head + 20, flags);
    store_u64(head + 24, size);
    store_u64(head + 32, gdr_io_hash(table, (size_t)count * CACHE_ENTRY_SIZE));
    store_u64(head + 40, gdr_io_hash(head, 40));
}

/* Writes what is left in the buffer (in memory: the whole file, its header in place), then, section
 * by section, the header and table at the start of the file. */
static int finish_file(writer *w, cache_sink *sink, const uint8_t *head, size_t head_size)
{
    if (!sink->seekable) {
        memcpy(w->data, head, head_size);
        return fwrite(w->data, 1, w->size, sink->file) == w->size;
    }
    return fwrite(w->data, 1, w->size, sink->file) == w->size && fseek(sink->file, 0, SEEK_SET) == 0 &&
           fwrite(head, 1, head_size, sink->file) == head_size && fseek(sink->file, 0, SEEK_END) == 0;
}

/* The file: its sections (into the sink as they are made), then its header. A file over the whole
 * reader's limit is refused unless it has pages (`paged`), which the streaming reader reads with
 * positioned reads at 64-bit offsets. */
static gdr_status serialise(const char *path, const cache_write_input *in, uint32_t expected, cache_sink *sink,
                            bool paged, uint64_t *size, gdr_error *err)
{
    section_entry entries[CACHE_SECTION_COUNT];
    uint32_t count = 0;
    size_t head_size = CACHE_HEADER_SIZE + (size_t)expected * CACHE_ENTRY_SIZE;
    writer w = {0};
    uint8_t *head = calloc(1, head_size);
    put_space(&w, head_size); /* the header and table, written last */
    if (w.data)
        memset(w.data, 0, w.size);
    write_sections(&w, sink, in, entries, &count);
    assert(w.failed || sink->failed || count == expected);
    *size = sink->flushed + w.size;
    gdr_status status = GDR_OK;
    if (w.failed || !head)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory serialising the scene", path);
    else if (*size > gdr_io_max_file_size && !paged)
        status = gdr_error_set(err, GDR_ERROR_CAPACITY, "%s: %llu bytes, more than the %llu a cache without pages may "
                               "hold (the whole reader's limit)", path, (unsigned long long)*size,
                               (unsigned long long)gdr_io_max_file_size);
    if (status == GDR_OK) {
        cache_put_header(head, entries, count, *size, in->pages_only ? CACHE_FLAG_PAGES_ONLY : 0);
        if (sink->failed || !finish_file(&w, sink, head, head_size))
            status = gdr_error_set(err, GDR_ERROR_IO, "%s: write failed: %s", path, strerror(errno));
    }
    free(head);
    free(w.data);
    return status;
}

gdr_status gdr_cache_write(const char *path, const gdr_scene *scene, const gdr_cache_write_options *options,
                           gdr_error *err)
{
    static const gdr_cache_write_options defaults = {0};
    if (!options)
        options = &defaults;
    gdr_status limits = check_reader_limits(path, scene, options->page_bytes != 0, err);
    if (limits != GDR_OK)
        return limits;
    /* The table has exactly one entry per section: no byte of the file lies outside a checksum. */
    cache_write_input in = cache_write_input_of(scene, options);
    uint32_t expected = 0;
    for (uint32_t k = 0; k < CACHE_SECTION_COUNT; k++) {
        const cache_section *sec = &gdr_cache_sections[k];
        if (sec->present && !sec->present(&in))
            continue;
        gdr_status status = sec->check ? sec->check(&in, path, err) : GDR_OK;
        if (status != GDR_OK)
            return status;
        expected++;
    }
    /* A temporary file in the same folder, then rename: readers see the old file or the new one
     * (core/output_file.h: links followed, devices and FIFOs written directly). */
    gdr_output_file out;
    gdr_status status = gdr_output_open(path, &out, err);
    if (status != GDR_OK)
        return status;
    cache_sink sink = {.file = out.file, .seekable = out.temporary != NULL};
    uint64_t size = 0;
    gdr_progress_begin(&sink.progress, "write cache", expected, 0);
    status = serialise(path, &in, expected, &sink, options->page_bytes != 0, &size, err);
    gdr_progress_end(&sink.progress);
    return gdr_output_close(&out, status == GDR_OK, path, err) == GDR_OK ? status : err->status;
}

/* --- reading --------------------------------------------------------------------------------- */

typedef struct byte_range {
    uint64_t offset, length;
    uint32_t id;
} byte_range;

static int compare_ranges(const void *a, const void *b)
{
    const byte_range *x = a, *y = b;
    return x->offset < y->offset ? -1 : x->offset > y->offset;
}

/* Every byte after the table must belong to a section or be zero alignment padding (under 8 bytes
 * before each section and at the end): no byte of the file escapes the checksums. */
static gdr_status check_coverage(const char *name, const uint8_t *data, size_t size, uint64_t table_end,
                                 byte_range *ranges, uint32_t count, gdr_error *err)
{
    qsort(ranges, count, sizeof *ranges, compare_ranges);
    uint64_t cursor = table_end;
    char after[32] = "the section table"; /* what the bytes at cursor follow */
    for (uint32_t i = 0; i <= count; i++) {
        uint64_t next = i < count ? ranges[i].offset : size;
        if (next < cursor)
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: corrupted: sections overlap at offset %llu (after %s)",
                                 name, (unsigned long long)next, after);
        if (next - cursor >= 8)
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: corrupted: %llu bytes at offset %llu, after %s, lie "
                                 "outside every section", name, (unsigned long long)(next - cursor),
                                 (unsigned long long)cursor, after);
        for (uint64_t at = cursor; at < next; at++)
            if (data[at] != 0)
                return gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: corrupted: padding byte at offset %llu, after %s, is "
                                     "not zero", name, (unsigned long long)at, after);
        if (i < count) {
            char text[5];
            fourcc_text(ranges[i].id, text);
            snprintf(after, sizeof after, "section '%s'", text);
        }
        if (i < count)
            cursor = ranges[i].offset + ranges[i].length;
    }
    return GDR_OK;
}

/* Where the container's bytes come from: the whole file in memory, or the open file, each section
 * read with a positioned read when it is needed (the read for streaming leaves the geometry there). */
typedef struct container_source {
    const char *name;
    const uint8_t *data; /* the whole file, or NULL: read from fd */
    int fd;
    uint64_t size;
    int paged;           /* sections marked in_pages are not read */
    uint8_t *owned[CACHE_SECTION_COUNT]; /* sections read from fd, freed with the view */
    uint64_t bytes_read;
} container_source;

/* Exactly `length` bytes at `offset` of the source into dst. */
static gdr_status source_read(container_source *src, void *dst, uint64_t length, uint64_t offset, gdr_error *err)
{
    if (src->data) {
        memcpy(dst, src->data + offset, (size_t)length);
        return GDR_OK;
    }
    size_t done = gdr_io_pread_exact(src->fd, dst, (size_t)length, offset);
    if (done < length)
        return gdr_error_set(err, GDR_ERROR_IO, "%s: %s at offset %llu", src->name,
                             errno ? strerror(errno) : "the file ends", (unsigned long long)(offset + done));
    src->bytes_read += length;
    return GDR_OK;
}

/* Section `known` (an index of gdr_cache_sections, or -1 for one this build does not know) into
 * v, its checksum checked; with the whole file every section's checksum is checked, read from the
 * file only the known ones the read needs. */
static gdr_status fetch_section(container_source *src, int known, uint64_t offset, uint64_t length,
                                uint64_t checksum, cache_view *v, gdr_error *err)
{
    char text[5];
    fourcc_text(known >= 0 ? gdr_cache_sections[known].id : 0, text);
    const uint8_t *bytes = src->data ? src->data + offset : NULL;
    if (!src->data) {
        if (known < 0 || (src->paged && gdr_cache_sections[known].in_pages))
            return GDR_OK;
        if (!(src->owned[known] = malloc(length ? (size_t)length : 1)))
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: section '%s': out of memory for %llu bytes",
                                 src->name, text, (unsigned long long)length);
        gdr_status status = source_read(src, src->owned[known], length, offset, err);
        if (status != GDR_OK)
            return status;
        bytes = src->owned[known];
    }
    if (checksum != gdr_io_hash(bytes, (size_t)length))
        return gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: corrupted: section '%s' checksum mismatch", src->name, text);
    if (known >= 0)
        v->sections[known] = (reader){bytes, (size_t)length, 0, 0};
    return GDR_OK;
}

gdr_status cache_parse_header(const char *name, const uint8_t *h, uint64_t size, uint32_t *out_count,
                               uint64_t *out_table_hash, uint32_t *out_flags, gdr_error *err)
{
    if (memcmp(h, CACHE_MAGIC, 8) != 0)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: not a gdr cache (bad magic)", name);
    reader r = {h, CACHE_HEADER_SIZE, 8, 0};
    uint32_t version = get_u32(&r), header_size = get_u32(&r), count = get_u32(&r), flags = get_u32(&r);
    uint64_t file_size = get_u64(&r), table_hash = get_u64(&r), header_hash = get_u64(&r);
    if (version != GDR_CACHE_FORMAT_VERSION)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: cache format version %u, this build reads %u; rebuild it",
                             name, version, GDR_CACHE_FORMAT_VERSION);
    if (header_hash != gdr_io_hash(h, 40))
        return gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: corrupted: header checksum mismatch", name);
    if (header_size != CACHE_HEADER_SIZE)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: header size %u, expected %u", name, header_size,
                             CACHE_HEADER_SIZE);
    if (file_size != size)
        return gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: truncated or extended: %llu bytes, the header says %llu", name,
                             (unsigned long long)size, (unsigned long long)file_size);
    if (count > CACHE_MAX_SECTIONS || CACHE_HEADER_SIZE + (uint64_t)count * CACHE_ENTRY_SIZE > size)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section table (%u entries) does not fit", name, count);
    for (unsigned i = 48; i < CACHE_HEADER_SIZE; i++)
        if (h[i] != 0)
            return gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: corrupted: reserved header byte %u is not zero", name, i);
    if (flags & ~CACHE_FLAG_PAGES_ONLY)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: header flags 0x%x: unknown to this build (it knows 0x%x)", name,
                             flags, CACHE_FLAG_PAGES_ONLY);
    *out_count = count;
    *out_table_hash = table_hash;
    if (out_flags)
        *out_flags = flags;
    return GDR_OK;
}

/* One table entry: where it lies, whether this build knows it, its bytes. */
static gdr_status parse_entry(container_source *src, const uint8_t *e, uint64_t table_end, uint32_t i,
                              byte_range *range, cache_view *v, gdr_error *err)
{
    reader t = {e, CACHE_ENTRY_SIZE, 0, 0};
    uint32_t id = get_u32(&t), flags = get_u32(&t);
    uint64_t offset = get_u64(&t), length = get_u64(&t), checksum = get_u64(&t);
    char text[5];
    fourcc_text(id, text);
    if (offset < table_end || offset > src->size || length > src->size - offset)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section %u '%s' (offset %llu, %llu bytes) lies outside "
                             "the file", src->name, i, text, (unsigned long long)offset, (unsigned long long)length);
    *range = (byte_range){offset, length, id};
    int known = -1;
    for (int k = 0; k < CACHE_SECTION_COUNT; k++)
        if (gdr_cache_sections[k].id == id)
            known = k;
    if (known >= 0 && v->present[known])
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section '%s' appears twice", src->name, text);
    gdr_status status = fetch_section(src, known, offset, length, checksum, v, err);
    if (status != GDR_OK)
        return status;
    if (known < 0 && (flags & CACHE_SECTION_REQUIRED))
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: requires section '%s', unknown to this build",
                             src->name, text);
    if (known >= 0)
        v->present[known] = 1; /* an unknown optional section belongs to a later version: skipped */
    return GDR_OK;
}

/* Every required section is there; the whole geometry exactly when the header does not say that the
 * pages hold it alone, and then the pages. */
static gdr_status check_sections_present(const char *name, const cache_view *v, gdr_error *err)
{
    int pages_only = (v->flags & CACHE_FLAG_PAGES_ONLY) != 0;
    char text[5];
    if (pages_only && !v->present[CACHE_PAGES])
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: its header says its geometry is in its pages alone, and it "
                             "has no section 'PAGE'", name);
    for (int k = 0; k < CACHE_SECTION_COUNT; k++) {
        const cache_section *sec = &gdr_cache_sections[k];
        fourcc_text(sec->id, text);
        if (sec->whole_geometry && pages_only && v->present[k])
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section '%s' in a cache whose header says its geometry is "
                                 "in its pages alone", name, text);
        if (!v->present[k] && !sec->optional && !(sec->whole_geometry && pages_only))
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section '%s' is missing", name, text);
    }
    return GDR_OK;
}

/* Header, table and the sections the read needs into v. With the whole file, every byte after the
 * table is accounted for (check_coverage); read from the file, only the sections read are checked. */
static gdr_status parse_container(container_source *src, cache_view *v, gdr_error *err)
{
    memset(v, 0, sizeof *v);
    const char *name = src->name;
    uint8_t h[CACHE_HEADER_SIZE];
    if (src->size < CACHE_HEADER_SIZE)
        return gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: truncated: %llu bytes, shorter than the header", name,
                             (unsigned long long)src->size);
    uint32_t count = 0;
    uint64_t table_hash = 0;
    gdr_status status = source_read(src, h, CACHE_HEADER_SIZE, 0, err);
    if (status == GDR_OK)
        status = cache_parse_header(name, h, src->size, &count, &table_hash, &v->flags, err);
    uint8_t *table = status == GDR_OK ? malloc((size_t)count * CACHE_ENTRY_SIZE + 1) : NULL;
    if (status == GDR_OK && !table)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory for the section table", name);
    if (status == GDR_OK)
        status = source_read(src, table, (uint64_t)count * CACHE_ENTRY_SIZE, CACHE_HEADER_SIZE, err);
    if (status == GDR_OK && table_hash != gdr_io_hash(table, (size_t)count * CACHE_ENTRY_SIZE))
        status = gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: corrupted: section table checksum mismatch", name);
    uint64_t table_end = CACHE_HEADER_SIZE + (uint64_t)count * CACHE_ENTRY_SIZE;
    byte_range ranges[CACHE_MAX_SECTIONS];
    for (uint32_t i = 0; i < count && status == GDR_OK; i++)
        status = parse_entry(src, table + (size_t)i * CACHE_ENTRY_SIZE, table_end, i, &ranges[i], v, err);
    free(table);
    if (status == GDR_OK && src->data)
        status = check_coverage(name, src->data, (size_t)src->size, table_end, ranges, count, err);
    if (status == GDR_OK)
        status = check_sections_present(name, v, err);
    v->data = src->data;
    v->size = (size_t)src->size;
    return status;
}

static void source_free(container_source *src)
{
    for (int k = 0; k < CACHE_SECTION_COUNT; k++)
        free(src->owned[k]);
}

static gdr_status read_report(const char *name, cache_view *v, gdr_import_report *out, gdr_error *err);

gdr_status gdr_cache_read_memory(const void *data, size_t size, const char *name, gdr_scene **out, gdr_pvs **out_pvs,
                                 gdr_error *err)
{
    *out = NULL;
    if (out_pvs)
        *out_pvs = NULL;
    cache_view v;
    container_source src = {.name = name ? name : "(memory)", .data = data, .size = size};
    gdr_status status = parse_container(&src, &v, err);
    gdr_import_report report = {0};
    if (status == GDR_OK)
        status = read_report(src.name, &v, &report, err); /* checked, then dropped */
    gdr_import_report_free(&report);
    if (status != GDR_OK)
        return status;
    return gdr_cache_read_sections(src.name, &v, 0, out, out_pvs, err);
}

/* Section 'REPT': the import's warnings, each checked against the limits before it is kept and kept
 * with its control characters escaped (the text is the file's, and is printed on every run). */
static gdr_status read_report(const char *name, cache_view *v, gdr_import_report *out, gdr_error *err)
{
    reader r = v->sections[CACHE_REPORT];
    uint32_t cameras = get_u32(&r), total = get_u32(&r), kept = get_u32(&r);
    if (r.failed)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'REPT' is truncated (%zu bytes)", name, r.size);
    if (kept > GDR_REPORT_MAX_WARNINGS || kept > total || (kept < total && kept < GDR_REPORT_MAX_WARNINGS) ||
        kept > (r.size - r.at) / 4)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'REPT': %u warnings kept of %u (at most %u, all of "
                             "them below that, 4 bytes each at least)", name, kept, total, GDR_REPORT_MAX_WARNINGS);
    for (uint32_t i = 0; i < kept; i++) {
        uint32_t length;
        const char *text = get_string(&r, &length);
        if (r.failed || length > GDR_REPORT_MAX_WARNING_BYTES) {
            gdr_import_report_free(out);
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'REPT': warning %u: %s", name, i,
                                 r.failed ? "runs past the section's end" : "longer than the 511 bytes a warning may be");
        }
        char safe[4 * GDR_REPORT_MAX_WARNING_BYTES + 1];
        size_t n = gdr_io_escape_text(text, length, safe, sizeof safe);
        gdr_status status = gdr_io_report_add(out, safe, n, err);
        if (status != GDR_OK) {
            gdr_import_report_free(out);
            return status;
        }
    }
    if (r.at != r.size) {
        gdr_import_report_free(out);
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'REPT' has %zu bytes left over", name, r.size - r.at);
    }
    out->warning_total = total;
    out->file_cameras = cameras;
    return GDR_OK;
}

/* One entry of section 'SRCE': a file the scene was built from, as it was then. */
/* A file as it is now: its identity (device and inode) and, once looked at, its contents' hash. */
typedef struct source_now {
    int exists, hashed, unreadable;
    uint64_t size, hash;
    int64_t mtime;
    uint64_t device, inode;
} source_now;

typedef struct source_entry {
    char *path;    /* where to look for it now (malloc'ed) */
    uint32_t state; /* gdr_source_state: what the import found there */
    uint64_t size, mtime, hash;
    uint64_t key;  /* hash of the path, to stat each spelling once */
    int moved;     /* its folder moved with the source: the mtime says nothing, compare contents */
    source_now now;
} source_entry;

static int compare_entries(const void *a, const void *b)
{
    const source_entry *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return strcmp(x->path, y->path);
}

/* Orders entries by the file they name (missing ones first): spellings of one file are adjacent. */
static int compare_files(const void *a, const void *b)
{
    const source_now *x = &((const source_entry *)a)->now, *y = &((const source_entry *)b)->now;
    if (x->exists != y->exists)
        return x->exists < y->exists ? -1 : 1;
    if (x->device != y->device)
        return x->device < y->device ? -1 : 1;
    if (x->inode != y->inode)
        return x->inode < y->inode ? -1 : 1;
    return 0;
}

static source_now stat_now(const char *path)
{
    struct stat st;
    source_now now = {0};
    if (stat(path, &st) != 0)
        return now;
    now.exists = 1;
    now.size = (uint64_t)st.st_size;
    now.mtime = (int64_t)st.st_mtim.tv_sec * 1000000000ll + st.st_mtim.tv_nsec;
    now.device = (uint64_t)st.st_dev;
    now.inode = (uint64_t)st.st_ino;
    return now;
}

static void free_entries(source_entry *entries, uint32_t count)
{
    for (uint32_t i = 0; entries && i < count; i++)
        free(entries[i].path);
    free(entries);
}

/* The entries of 'SRCE' after the build options. When the cache is read for `source` (the file it
 * would be rebuilt from) and the first entry (the source it was built from) names another path,
 * the source's folder has moved or been copied: entries under the old folder are looked for under
 * the new one. */
static gdr_status read_entries(const char *name, reader *r, const char *source, source_entry **out,
                               uint32_t *out_count, gdr_error *err)
{
    uint32_t files = get_u32(r);
    if (r->failed || files > (r->size - r->at) / 33) /* each entry is at least 33 bytes */
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'SRCE' is malformed", name);
    source_entry *entries = calloc((size_t)files + 1, sizeof *entries);
    if (!entries)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    char old_dir[PATH_MAX] = "", new_dir[PATH_MAX] = "", absolute[PATH_MAX];
    for (uint32_t i = 0; i < files; i++) {
        uint32_t length;
        const char *path = get_string(r, &length);
        source_entry *e = &entries[i];
        e->state = get_u32(r);
        e->size = get_u64(r), e->mtime = get_u64(r), e->hash = get_u64(r);
        if (r->failed || length == 0 || length >= PATH_MAX || memchr(path, 0, length) || e->state > GDR_SOURCE_UNREAD ||
            (i == 0 && e->state != GDR_SOURCE_READ)) {
            free_entries(entries, files);
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'SRCE' is malformed", name);
        }
        size_t old_length = strlen(old_dir);
        if (i == 0 && source && realpath(source, absolute) && (strlen(absolute) != length ||
                                                               memcmp(absolute, path, length) != 0)) {
            char recorded[PATH_MAX];
            snprintf(recorded, sizeof recorded, "%.*s", (int)length, path);
            gdr_io_dirname(recorded, old_dir, sizeof old_dir);
            gdr_io_dirname(absolute, new_dir, sizeof new_dir);
            old_length = strlen(old_dir);
            e->path = strdup(absolute);
            e->moved = 1;
        } else if (old_length && length > old_length && memcmp(path, old_dir, old_length) == 0) {
            size_t n = strlen(new_dir) + (length - old_length) + 1;
            if ((e->path = malloc(n)))
                snprintf(e->path, n, "%s%.*s", new_dir, (int)(length - old_length), path + old_length);
            e->moved = 1;
        } else if ((e->path = malloc((size_t)length + 1))) {
            memcpy(e->path, path, length);
            e->path[length] = 0;
        }
        if (!e->path) {
            free_entries(entries, files);
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
        }
        e->key = gdr_io_hash(e->path, strlen(e->path));
    }
    *out = entries;
    *out_count = files;
    return GDR_OK;
}

/* A recorded path for a message: it comes from the file, so control characters are escaped. */
static const char *shown(const char *path, char out[PATH_MAX])
{
    gdr_io_escape_text(path, strlen(path), out, PATH_MAX);
    return out;
}

/* Hashes the file now, once (now->hashed or now->unreadable afterwards). */
static void hash_now(const char *path, source_now *now)
{
    if (now->hashed || now->unreadable)
        return;
    uint8_t *contents;
    size_t contents_size;
    gdr_error read_err;
    if (gdr_io_read_file(path, &contents, &contents_size, NULL, &read_err) == GDR_OK) {
        now->hash = gdr_io_hash(contents, contents_size);
        now->hashed = 1;
        free(contents);
    } else {
        now->unreadable = 1;
    }
}

/* Compares one entry with the file now (contents hashed at most once per file): the import would
 * find the same thing there, or the cache is stale. A file that was read must be there with the same
 * contents (a touched file with the same contents stays valid); a path where nothing was found must
 * still be empty; something that was there but not read must be unchanged (size and time). */
static gdr_status check_entry(const char *name, const source_entry *e, source_now *now, gdr_error *err)
{
    char text[PATH_MAX];
    if (e->state == GDR_SOURCE_ABSENT)
        return now->exists ? gdr_error_set(err, GDR_ERROR_STALE, "%s: stale: %s was not there when the cache was "
                                           "built", name, shown(e->path, text))
                           : GDR_OK;
    if (!now->exists)
        return gdr_error_set(err, GDR_ERROR_STALE, "%s: stale: %s is gone", name, shown(e->path, text));
    if (now->size != e->size)
        return gdr_error_set(err, GDR_ERROR_STALE, "%s: stale: %s changed size (%llu -> %llu bytes)", name,
                             shown(e->path, text), (unsigned long long)e->size, (unsigned long long)now->size);
    if (e->state == GDR_SOURCE_UNREAD)
        return (uint64_t)now->mtime == e->mtime && !e->moved
                   ? GDR_OK
                   : gdr_error_set(err, GDR_ERROR_STALE, "%s: stale: %s changed", name, shown(e->path, text));
    if ((uint64_t)now->mtime == e->mtime && !e->moved)
        return GDR_OK;
    hash_now(e->path, now);
    if (!now->hashed)
        return gdr_error_set(err, GDR_ERROR_STALE, "%s: stale: %s can no longer be read", name, shown(e->path, text));
    if (now->hash != e->hash)
        return gdr_error_set(err, GDR_ERROR_STALE, "%s: stale: %s changed since the cache was built", name,
                             shown(e->path, text));
    return GDR_OK;
}

/* Compares the SRCE section with the build options and, when the cache is read for `source` (the
 * file it stands for), with the files on disk: the cache must record the source as its first entry,
 * with the same contents, and no other recorded file that exists may differ. Without `source` the
 * cache is read as it stands: no recorded file is opened. */
static gdr_status check_fresh(const char *name, cache_view *v, const char *build_options, const char *source,
                              gdr_error *err)
{
    if (!v->present[CACHE_SOURCE])
        return source ? gdr_error_set(err, GDR_ERROR_STALE, "%s: stale: it does not record the source it "
                                      "was built from", name)
                      : GDR_OK;
    reader r = v->sections[CACHE_SOURCE];
    uint32_t length;
    const char *options = get_string(&r, &length);
    if (r.failed)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'SRCE' is truncated", name);
    if (build_options && (strlen(build_options) != length || memcmp(options, build_options, length) != 0))
        return gdr_error_set(err, GDR_ERROR_STALE, "%s: stale: built with options '%.*s', now '%s'", name,
                             (int)(length > 64 ? 64 : length), options, build_options);
    source_entry *entries = NULL;
    uint32_t count = 0;
    gdr_status status = read_entries(name, &r, source, &entries, &count, err);
    if (status != GDR_OK || !source) {
        /* Read as it stands: the recorded sources are never opened (whether a file named there
         * exists, or has given contents, must not change the outcome). */
        free_entries(entries, count);
        return status;
    }
    if (source && count == 0)
        status = gdr_error_set(err, GDR_ERROR_STALE, "%s: stale: it does not record the source it was "
                               "built from", name);
    if (source && status == GDR_OK) {
        /* The source itself must be there, with the contents the cache was built from. */
        source_now now = {0};
        now.exists = gdr_io_stat(entries[0].path, &now.size, &now.mtime) == 0;
        char text[PATH_MAX];
        if (!now.exists)
            status = gdr_error_set(err, GDR_ERROR_STALE, "%s: stale: its source %s is not there", name,
                                   shown(entries[0].path, text));
        else
            status = check_entry(name, &entries[0], &now, err);
    }
    /* Every file once, however often and however spelled (`//dir/./f`) the list names it: each
     * spelling is looked up once, then entries naming one device and inode share one hash. */
    qsort(entries, count, sizeof *entries, compare_entries);
    for (uint32_t i = 0; i < count && status == GDR_OK; i++)
        entries[i].now = i > 0 && compare_entries(&entries[i - 1], &entries[i]) == 0 ? entries[i - 1].now
                                                                                      : stat_now(entries[i].path);
    qsort(entries, count, sizeof *entries, compare_files);
    source_now shared = {0};
    for (uint32_t i = 0; i < count && status == GDR_OK; i++) {
        if (i == 0 || compare_files(&entries[i - 1], &entries[i]) != 0)
            shared = entries[i].now;
        status = check_entry(name, &entries[i], &shared, err);
    }
    free_entries(entries, count);
    return status;
}

gdr_status gdr_cache_read(const char *path, const char *build_options, gdr_scene **out, gdr_pvs **out_pvs,
                          gdr_error *err)
{
    return gdr_io_cache_read_for(path, NULL, build_options, out, out_pvs, NULL, err);
}

gdr_status gdr_io_cache_read_for(const char *path, const char *source, const char *build_options, gdr_scene **out,
                                 gdr_pvs **out_pvs, gdr_import_report *out_report, gdr_error *err)
{
    *out = NULL;
    if (out_pvs)
        *out_pvs = NULL;
    uint8_t *data;
    size_t size;
    gdr_status status = gdr_io_read_file(path, &data, &size, NULL, err);
    if (status != GDR_OK)
        return status;
    cache_view v;
    container_source src = {.name = path, .data = data, .size = size};
    status = parse_container(&src, &v, err);
    if (status == GDR_OK)
        status = check_fresh(path, &v, build_options, source, err);
    gdr_import_report report = {0};
    if (status == GDR_OK)
        status = read_report(path, &v, &report, err);
    if (status == GDR_OK)
        status = gdr_cache_read_sections(path, &v, 0, out, out_pvs, err);
    if (status == GDR_OK && out_report)
        *out_report = report;
    else
        gdr_import_report_free(&report);
    free(data);
    return status;
}

gdr_status gdr_cache_read_for_streaming(const char *path, const char *build_options, gdr_scene **out,
                                        gdr_pvs **out_pvs, uint64_t *out_bytes_read, gdr_error *err)
{
    return gdr_io_cache_read_for_streaming(path, NULL, build_options, out, out_pvs, NULL, out_bytes_read, err);
}

gdr_status gdr_io_cache_read_for_streaming(const char *path, const char *source, const char *build_options,
                                           gdr_scene **out, gdr_pvs **out_pvs, gdr_import_report *out_report,
                                           uint64_t *out_bytes_read, gdr_error *err)
{
    *out = NULL;
    if (out_pvs)
        *out_pvs = NULL;
    if (out_bytes_read)
        *out_bytes_read = 0;
    container_source src = {.name = path, .paged = 1};
    gdr_status status = gdr_io_open_regular(path, &src.fd, err);
    if (status != GDR_OK)
        return status;
    struct stat st;
    if (fstat(src.fd, &st) != 0) {
        close(src.fd);
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot stat: %s", path, strerror(errno));
    }
    src.size = (uint64_t)st.st_size;
    cache_view v;
    status = parse_container(&src, &v, err);
    if (status == GDR_OK && !v.present[CACHE_PAGES])
        status = gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: has no geometry pages to stream; build it with "
                               "pages (gdr build --pages)", path);
    if (status == GDR_OK)
        status = check_fresh(path, &v, build_options, source, err);
    gdr_import_report report = {0};
    if (status == GDR_OK)
        status = read_report(path, &v, &report, err);
    if (status == GDR_OK)
        status = gdr_cache_read_sections(path, &v, 1, out, out_pvs, err);
    if (status == GDR_OK && out_report)
        *out_report = report;
    else
        gdr_import_report_free(&report);
    close(src.fd);
    source_free(&src);
    if (out_bytes_read)
        *out_bytes_read = src.bytes_read;
    return status;
}

size_t gdr_cache_path_for(const char *source_path, const char *cache_dir, char *out, size_t out_size)
{
    int n;
    if (!cache_dir || strcmp(cache_dir, ".") == 0) {
        n = snprintf(out, out_size, "%s.gdrc", source_path);
    } else {
        char absolute[PATH_MAX];
        const char *key = realpath(source_path, absolute) ? absolute : source_path;
        const char *base = strrchr(source_path, '/');
        base = base ? base + 1 : source_path;
        n = snprintf(out, out_size, "%s/%.64s-%016llx.gdrc", cache_dir, base,
                     (unsigned long long)gdr_io_hash(key, strlen(key)));
    }
    return n > 0 && (size_t)n < out_size ? (size_t)n : 0;
}

/* The 'SRCE' section of an open cache (header, table and that section only, each checksum checked),
 * at most 16 MiB; *out is malloc'ed. */
static gdr_status read_source_section(const char *path, int fd, uint64_t size, uint8_t **out, size_t *out_size,
                                      gdr_error *err)
{
    uint8_t h[CACHE_HEADER_SIZE];
    uint32_t count;
    uint64_t table_hash;
    if (size < CACHE_HEADER_SIZE || gdr_io_pread_exact(fd, h, CACHE_HEADER_SIZE, 0) != CACHE_HEADER_SIZE)
        return gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: truncated", path);
    gdr_status status = cache_parse_header(path, h, size, &count, &table_hash, NULL, err);
    if (status != GDR_OK)
        return status;
    uint8_t *table = malloc((size_t)count * CACHE_ENTRY_SIZE + 1);
    if (!table)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    size_t table_size = (size_t)count * CACHE_ENTRY_SIZE;
    if (gdr_io_pread_exact(fd, table, table_size, CACHE_HEADER_SIZE) != table_size ||
        gdr_io_hash(table, table_size) != table_hash) {
        free(table);
        return gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: corrupted: section table", path);
    }
    status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: records no source", path);
    for (uint32_t i = 0; i < count; i++) {
        reader t = {table + (size_t)i * CACHE_ENTRY_SIZE, CACHE_ENTRY_SIZE, 0, 0};
        uint32_t id = get_u32(&t);
        (void)get_u32(&t);
        uint64_t offset = get_u64(&t), length = get_u64(&t), checksum = get_u64(&t);
        if (id != gdr_cache_sections[CACHE_SOURCE].id)
            continue;
        uint8_t *bytes = offset <= size && length <= size - offset && length <= (16u << 20) ? malloc(length + 1) : NULL;
        if (!bytes || gdr_io_pread_exact(fd, bytes, length, offset) != length || gdr_io_hash(bytes, length) != checksum) {
            free(bytes);
            status = gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: section 'SRCE' is damaged", path);
            break;
        }
        *out = bytes;
        *out_size = length;
        status = GDR_OK;
        break;
    }
    free(table);
    return status;
}

gdr_status gdr_io_cache_recorded_source(const char *path, char *out, size_t out_size, gdr_error *err)
{
    out[0] = 0;
    int fd;
    gdr_status status = gdr_io_open_regular(path, &fd, err);
    if (status != GDR_OK)
        return status;
    struct stat st;
    uint8_t *bytes = NULL;
    size_t size = 0;
    status = fstat(fd, &st) == 0 ? read_source_section(path, fd, (uint64_t)st.st_size, &bytes, &size, err)
                                 : gdr_error_set(err, GDR_ERROR_IO, "%s: cannot stat", path);
    close(fd);
    if (status != GDR_OK)
        return status;
    reader r = {bytes, size, 0, 0};
    uint32_t length;
    (void)get_string(&r, &length); /* the build options */
    uint32_t files = get_u32(&r);
    const char *first = files ? get_string(&r, &length) : NULL;
    if (r.failed || !first)
        status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'SRCE' is malformed", path);
    else
        gdr_io_escape_text(first, length, out, out_size);
    free(bytes);
    return status;
}
