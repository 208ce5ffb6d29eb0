/* The paged reader of the scene cache (gdr/paged_cache.h): the container, the instances and the
 * page index at the open, then one page at a time with positioned reads, each checked before it
 * is decoded. Nothing reads the whole file. */
#define _XOPEN_SOURCE 700 /* pread */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/cache_pages.h"
#include "io/io_internal.h"

#define FOURCC(a, b, c, d) ((uint32_t)(a) | (uint32_t)(b) << 8 | (uint32_t)(c) << 16 | (uint32_t)(d) << 24)

struct gdr_paged_cache {
    char *name;
    int fd;
    uint64_t file_size;
    _Atomic uint64_t bytes_read;
    uint32_t mesh_count, material_count, instance_count;
    gdr_instance *instances;
    gdr_paged_mesh *meshes;
    uint64_t page_section_size;
    uint32_t header_flags; /* CACHE_FLAG_PAGES_ONLY: the pages hold the only copy of the geometry */
};

typedef struct section_ref {
    uint64_t offset, size, checksum;
    int present;
} section_ref;

/* Exactly `size` bytes at `offset`, or an error naming what was being read. */
static gdr_status read_at(gdr_paged_cache *pc, void *dst, size_t size, uint64_t offset, const char *what,
                          gdr_error *err)
{
    size_t done = gdr_io_pread_exact(pc->fd, dst, size, offset);
    if (done < size)
        return gdr_error_set(err, GDR_ERROR_IO, "%s: %s: %s at offset %llu (%zu of %zu bytes)", pc->name, what,
                             errno ? strerror(errno) : "the file ends", (unsigned long long)(offset + done), done,
                             size);
    atomic_fetch_add(&pc->bytes_read, size);
    return GDR_OK;
}

static uint32_t load_u32(const uint8_t *p) { uint32_t v; memcpy(&v, p, 4); return v; }
static uint64_t load_u64(const uint8_t *p) { uint64_t v; memcpy(&v, p, 8); return v; }

/* Header and table: the whole-file reader's checks that need no section's bytes. */
static gdr_status read_table(gdr_paged_cache *pc, section_ref *scne, section_ref *inst, section_ref *page,
                             gdr_error *err)
{
    uint8_t h[CACHE_HEADER_SIZE];
    if (pc->file_size < CACHE_HEADER_SIZE)
        return gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: truncated: %llu bytes, shorter than the header", pc->name,
                             (unsigned long long)pc->file_size);
    uint32_t count = 0;
    uint64_t table_hash = 0;
    gdr_status status = read_at(pc, h, CACHE_HEADER_SIZE, 0, "header", err);
    if (status == GDR_OK)
        status = cache_parse_header(pc->name, h, pc->file_size, &count, &table_hash, &pc->header_flags, err);
    if (status != GDR_OK)
        return status;
    uint8_t *table = malloc((size_t)count * CACHE_ENTRY_SIZE + 1);
    if (!table)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: section table", pc->name);
    status = read_at(pc, table, (size_t)count * CACHE_ENTRY_SIZE, CACHE_HEADER_SIZE, "section table", err);
    if (status == GDR_OK && table_hash != gdr_io_hash(table, (size_t)count * CACHE_ENTRY_SIZE))
        status = gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: corrupted: section table checksum mismatch", pc->name);
    for (uint32_t i = 0; i < count && status == GDR_OK; i++) {
        const uint8_t *e = table + (size_t)i * CACHE_ENTRY_SIZE;
        uint32_t id = load_u32(e);
        section_ref ref = {load_u64(e + 8), load_u64(e + 16), load_u64(e + 24), 1};
        if (ref.offset > pc->file_size || ref.size > pc->file_size - ref.offset)
            status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: section %u lies outside the file", pc->name, i);
        section_ref *slot = id == FOURCC('S', 'C', 'N', 'E') ? scne : id == FOURCC('I', 'N', 'S', 'T') ? inst
                          : id == FOURCC('P', 'A', 'G', 'E') ? page : NULL;
        if (slot && slot->present)
            status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: a section appears twice", pc->name);
        else if (slot)
            *slot = ref;
    }
    free(table);
    return status;
}

/* A whole (small) section, its checksum checked. */
static gdr_status read_section(gdr_paged_cache *pc, const section_ref *ref, const char *id, size_t limit,
                               uint8_t **out, gdr_error *err)
{
    *out = NULL;
    if (!ref->present)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section '%s' is missing", pc->name, id);
    if (ref->size > limit)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section '%s' of %llu bytes, more than %zu", pc->name, id,
                             (unsigned long long)ref->size, limit);
    *out = malloc(ref->size ? ref->size : 1);
    if (!*out)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: section '%s'", pc->name, id);
    gdr_status status = read_at(pc, *out, (size_t)ref->size, ref->offset, id, err);
    if (status == GDR_OK && gdr_io_hash(*out, (size_t)ref->size) != ref->checksum)
        status = gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: corrupted: section '%s' checksum mismatch", pc->name, id);
    if (status != GDR_OK) {
        free(*out);
        *out = NULL;
    }
    return status;
}

/* The instances, checked as the whole-file reader checks them (gdr_scene_add_instance against the
 * counts of section 'SCNE', colours finite), into a scene that holds only them. */
static gdr_status parse_instances(gdr_paged_cache *pc, const uint8_t *data, uint64_t size, gdr_error *err)
{
    if (size != (uint64_t)pc->instance_count * CACHE_INSTANCE_RECORD)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'INST' holds %llu bytes, %u records need %llu",
                             pc->name, (unsigned long long)size, pc->instance_count,
                             (unsigned long long)pc->instance_count * CACHE_INSTANCE_RECORD);
    gdr_scene *holder;
    gdr_status status = gdr_scene_create(&holder, err);
    if (status != GDR_OK)
        return status;
    holder->mesh_count = pc->mesh_count; /* counts only: add_instance checks indices against them */
    holder->material_count = pc->material_count;
    reader r = {data, (size_t)size, 0, 0};
    for (uint32_t i = 0; i < pc->instance_count && status == GDR_OK; i++) {
        gdr_instance inst;
        cache_get_instance(&r, &inst);
        status = isfinite(inst.color.x) && isfinite(inst.color.y) && isfinite(inst.color.z) && isfinite(inst.color.w)
                     ? gdr_scene_add_instance(holder, &inst, err)
                     : gdr_error_set(err, GDR_ERROR_PARSE, "instance %u: colour is not finite", i);
    }
    if (status != GDR_OK) {
        char message[GDR_ERROR_MESSAGE_MAX];
        snprintf(message, sizeof message, "%s", err->message);
        gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'INST': %s", pc->name, message);
    } else {
        pc->instances = holder->instances;
        holder->instances = NULL;
    }
    holder->mesh_count = holder->material_count = holder->instance_count = 0;
    gdr_scene_destroy(holder);
    return status == GDR_OK ? GDR_OK : GDR_ERROR_PARSE;
}

/* The page section's header and index (its own checksum: the section's covers pages unread). */
static gdr_status read_page_index(gdr_paged_cache *pc, const section_ref *page, gdr_error *err)
{
    if (!page->present)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: has no geometry pages; write it with page_bytes "
                             "(gdr build --pages)", pc->name);
    uint8_t head[CACHE_PAGES_HEADER];
    uint32_t mesh_count;
    uint64_t index_size, index_hash;
    gdr_status status = page->size >= CACHE_PAGES_HEADER
                            ? read_at(pc, head, CACHE_PAGES_HEADER, page->offset, "section 'PAGE'", err)
                            : GDR_OK;
    if (status == GDR_OK)
        status = cache_pages_parse_header(pc->name, head, page->size, &mesh_count, &index_size, &index_hash, err);
    if (status == GDR_OK && mesh_count != pc->mesh_count)
        status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'PAGE': %u meshes, the scene has %u", pc->name,
                               mesh_count, pc->mesh_count);
    if (status != GDR_OK)
        return status;
    uint8_t *index = malloc(index_size ? index_size : 1);
    if (!index)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: page index of %llu bytes", pc->name,
                             (unsigned long long)index_size);
    status = read_at(pc, index, (size_t)index_size, page->offset + CACHE_PAGES_HEADER, "page index", err);
    if (status == GDR_OK && gdr_io_hash(index, (size_t)index_size) != index_hash)
        status = gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: section 'PAGE': index checksum mismatch", pc->name);
    if (status == GDR_OK)
        status = cache_pages_parse_index(pc->name, index, index_size, mesh_count, page->offset, page->size,
                                         &pc->meshes, err);
    free(index);
    pc->page_section_size = page->size;
    return status;
}

static gdr_status open_sections(gdr_paged_cache *pc, gdr_error *err)
{
    section_ref scne = {0}, inst = {0}, page = {0};
    gdr_status status = read_table(pc, &scne, &inst, &page, err);
    uint8_t *bytes = NULL;
    if (status == GDR_OK)
        status = read_section(pc, &scne, "SCNE", 1u << 20, &bytes, err);
    if (status == GDR_OK && scne.size < 20)
        status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'SCNE' is too short", pc->name);
    if (status == GDR_OK) {
        pc->mesh_count = load_u32(bytes);
        pc->material_count = load_u32(bytes + 4);
        pc->instance_count = load_u32(bytes + 8);
    }
    free(bytes);
    if (status == GDR_OK)
        status = read_section(pc, &inst, "INST", (size_t)GDR_DEFAULT_MAX_INSTANCES * CACHE_INSTANCE_RECORD, &bytes, err);
    if (status == GDR_OK)
        status = parse_instances(pc, bytes, inst.size, err);
    free(bytes);
    if (status == GDR_OK)
        status = read_page_index(pc, &page, err);
    return status;
}

gdr_status gdr_paged_cache_open(const char *path, gdr_paged_cache **out, gdr_error *err)
{
    *out = NULL;
    gdr_paged_cache *pc = calloc(1, sizeof *pc);
    if (!pc || !(pc->name = strdup(path))) {
        free(pc);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: paged cache", path);
    }
    struct stat st;
    pc->fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC); /* a FIFO must not block the open */
    int opened = pc->fd >= 0 && fstat(pc->fd, &st) == 0;
    if (!opened || !S_ISREG(st.st_mode)) {
        gdr_status status = opened ? gdr_error_set(err, GDR_ERROR_NOT_A_FILE, "%s: not a regular file", path)
                                   : gdr_error_set(err, GDR_ERROR_IO, "%s: %s", path, strerror(errno));
        gdr_paged_cache_close(pc);
        return status;
    }
    pc->file_size = (uint64_t)st.st_size;
    gdr_status status = open_sections(pc, err);
    if (status != GDR_OK) {
        gdr_paged_cache_close(pc);
        return status;
    }
    *out = pc;
    return GDR_OK;
}

void gdr_paged_cache_close(gdr_paged_cache *pc)
{
    if (!pc)
        return;
    if (pc->fd >= 0)
        close(pc->fd);
    cache_pages_free_index(pc->meshes, pc->mesh_count);
    free(pc->instances);
    free(pc->name);
    free(pc);
}

const char *gdr_paged_cache_path(const gdr_paged_cache *cache) { return cache->name; }

uint32_t gdr_paged_cache_mesh_count(const gdr_paged_cache *pc) { return pc->mesh_count; }
const gdr_paged_mesh *gdr_paged_cache_mesh(const gdr_paged_cache *pc, uint32_t mesh)
{
    return mesh < pc->mesh_count ? &pc->meshes[mesh] : NULL;
}
const gdr_instance *gdr_paged_cache_instances(const gdr_paged_cache *pc, uint32_t *count)
{
    *count = pc->instance_count;
    return pc->instances;
}
uint64_t gdr_paged_cache_bytes_read(const gdr_paged_cache *pc) { return atomic_load(&pc->bytes_read); }
uint64_t gdr_paged_cache_page_bytes(const gdr_paged_cache *pc) { return pc->page_section_size; }
int gdr_paged_cache_pages_only(const gdr_paged_cache *pc) { return (pc->header_flags & CACHE_FLAG_PAGES_ONLY) != 0; }

gdr_status gdr_paged_cache_read_page(gdr_paged_cache *pc, uint32_t mesh, uint32_t page, gdr_page *out,
                                     gdr_error *err)
{
    *out = (gdr_page){.mesh = mesh, .page = page};
    if (mesh >= pc->mesh_count || page >= pc->meshes[mesh].page_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: mesh %u page %u does not exist", pc->name, mesh,
                             page);
    const gdr_page_info *pi = &pc->meshes[mesh].pages[page];
    uint8_t *bytes = malloc(pi->stored_size);
    if (!bytes)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: mesh %u page %u", pc->name, mesh, page);
    char what[64];
    snprintf(what, sizeof what, "mesh %u page %u", mesh, page);
    gdr_status status = read_at(pc, bytes, pi->stored_size, pi->offset, what, err);
    if (status == GDR_OK)
        status = cache_page_decode(pc->name, mesh, page, &pc->meshes[mesh], bytes, pi->stored_size, out, err);
    free(bytes);
    return status;
}
