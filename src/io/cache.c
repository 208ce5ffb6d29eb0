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
#include "gdr/cull.h"
#include "io/io_internal.h"

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the cache reader and writer assume a little-endian host"
#endif

#define CACHE_MAGIC "GDRCACHE"
#define CACHE_HEADER_SIZE 64u
#define CACHE_ENTRY_SIZE 32u
#define CACHE_MAX_SECTIONS 1024u
#define CACHE_SECTION_REQUIRED 1u
#define CACHE_MAX_TEXTURE_SIDE 32768u

#define FOURCC(a, b, c, d) ((uint32_t)(a) | (uint32_t)(b) << 8 | (uint32_t)(c) << 16 | (uint32_t)(d) << 24)
enum {
    SEC_SOURCE = FOURCC('S', 'R', 'C', 'E'),
    SEC_SCENE = FOURCC('S', 'C', 'N', 'E'),
    SEC_MESHES = FOURCC('M', 'E', 'S', 'H'),
    SEC_GEOMETRY = FOURCC('G', 'E', 'O', 'M'),
    SEC_MATERIALS = FOURCC('M', 'A', 'T', 'L'),
    SEC_INSTANCES = FOURCC('I', 'N', 'S', 'T'),
    SEC_CAMERAS = FOURCC('C', 'A', 'M', 'R'),
    SEC_TEXTURES = FOURCC('T', 'E', 'X', 'R'),
    SEC_PIXELS = FOURCC('T', 'X', 'P', 'X'),
    SEC_CLUSTERS = FOURCC('C', 'L', 'U', 'S'),
    SEC_CLUSTER_DATA = FOURCC('C', 'L', 'D', 'T'),
    SEC_PVS = FOURCC('P', 'V', 'I', 'S'), /* optional: the precomputed-visibility blob */
};

enum { MESH_RECORD = 64 + 8 + 16, MATERIAL_RECORD = 64 + 16 + 12 + 12 + 8, INSTANCE_RECORD = 64 + 8 + 16,
       CAMERA_RECORD = 64 + 12 + 16 + 16, TEXTURE_RECORD = 64 + 12, CLUSTERS_RECORD = 6 * 4,
       CLUSTER_RECORD = 4 * 4 + 16 + 12 + 12 + 4 + 3 * 4, GROUP_RECORD = 16 + 4 + 3 * 4 };

const char *gdr_cache_build_options(void)
{
    /* Bump when the importers' or the geometry processing's output for the same input changes. */
    return "import=1;meshlets=1;lod=1";
}

/* --- writing --------------------------------------------------------------------------------- */

typedef struct writer {
    uint8_t *data;
    size_t size, capacity;
    int failed;
} writer;

static void put(writer *w, const void *bytes, size_t n)
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

static void put_u32(writer *w, uint32_t v) { put(w, &v, 4); }
static void put_u64(writer *w, uint64_t v) { put(w, &v, 8); }
static void put_f32s(writer *w, const float *v, size_t n) { put(w, v, 4 * n); }
static void put_name(writer *w, const char *name)
{
    char buffer[GDR_NAME_MAX] = {0};
    snprintf(buffer, sizeof buffer, "%s", name);
    put(w, buffer, sizeof buffer);
}
static void put_string(writer *w, const char *s)
{
    uint32_t n = s ? (uint32_t)strlen(s) : 0;
    put_u32(w, n);
    put(w, s, n);
}
static void align8(writer *w)
{
    static const uint8_t zeros[8] = {0};
    put(w, zeros, (8 - w->size % 8) % 8);
}
/* n bytes at the end, for the caller to fill; NULL when out of memory. */
static uint8_t *put_space(writer *w, size_t n)
{
    put(w, NULL, n);
    return w->failed ? NULL : w->data + w->size - n;
}
static void align4(writer *w)
{
    static const uint8_t zeros[4] = {0};
    put(w, zeros, (4 - w->size % 4) % 4);
}

typedef struct section_entry {
    uint32_t id, flags;
    uint64_t offset, size, checksum;
} section_entry;

static void write_sections(writer *w, const gdr_scene *s, const gdr_cache_source *source, const gdr_pvs *pvs,
                           section_entry *entries, uint32_t *count)
{
    uint32_t n = 0;
#define BEGIN(sid, sflags) do { align8(w); entries[n] = (section_entry){sid, sflags, w->size, 0, 0}; } while (0)
#define END() do { entries[n].size = w->size - entries[n].offset; n++; } while (0)
    BEGIN(SEC_SOURCE, 0);
    put_string(w, source && source->build_options ? source->build_options : "");
    uint32_t files = source && source->files ? source->files->count : 0;
    put_u32(w, files);
    for (uint32_t i = 0; i < files; i++) {
        const gdr_source_file *f = &source->files->files[i];
        put_string(w, f->path);
        put_u64(w, f->size);
        put_u64(w, (uint64_t)f->mtime_ns);
        put_u64(w, f->hash);
    }
    END();

    BEGIN(SEC_SCENE, CACHE_SECTION_REQUIRED);
    put_u32(w, s->mesh_count);
    put_u32(w, s->material_count);
    put_u32(w, s->instance_count);
    put_u32(w, s->camera_count);
    put_u32(w, s->texture_count);
    put_string(w, s->extensions);
    END();

    BEGIN(SEC_MESHES, CACHE_SECTION_REQUIRED);
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh *m = &s->meshes[i];
        put_name(w, m->name);
        put_u32(w, m->vertex_count);
        put_u32(w, m->index_count);
        put_f32s(w, &m->bounds.x, 4);
    }
    END();

    BEGIN(SEC_GEOMETRY, CACHE_SECTION_REQUIRED);
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh *m = &s->meshes[i];
        put(w, m->positions, sizeof(gdr_vec3) * m->vertex_count);
        put(w, m->normals, sizeof(gdr_vec3) * m->vertex_count);
        put(w, m->uvs, sizeof(gdr_vec2) * m->vertex_count);
        put(w, m->indices, sizeof(uint32_t) * m->index_count);
    }
    END();

    BEGIN(SEC_MATERIALS, CACHE_SECTION_REQUIRED);
    for (uint32_t i = 0; i < s->material_count; i++) {
        const gdr_material *m = &s->materials[i];
        put_name(w, m->name);
        put_f32s(w, &m->base_color.x, 4);
        put_u32(w, m->base_color_texture);
        put_u32(w, m->normal_texture);
        put_u32(w, m->metallic_roughness_texture);
        put_f32s(w, (const float[3]){m->metallic_factor, m->roughness_factor, m->alpha_cutoff}, 3);
        put_u32(w, m->alpha_mode);
        put_u32(w, m->double_sided);
    }
    END();

    BEGIN(SEC_INSTANCES, CACHE_SECTION_REQUIRED);
    for (uint32_t i = 0; i < s->instance_count; i++) {
        const gdr_instance *inst = &s->instances[i];
        put_f32s(w, inst->transform.m, 16);
        put_u32(w, inst->mesh);
        put_u32(w, inst->material);
        put_f32s(w, &inst->color.x, 4);
    }
    END();

    BEGIN(SEC_CAMERAS, CACHE_SECTION_REQUIRED);
    for (uint32_t i = 0; i < s->camera_count; i++) {
        const gdr_camera *cam = &s->cameras[i];
        put_name(w, cam->name);
        put_f32s(w, &cam->position.x, 3);
        put_f32s(w, &cam->rotation.x, 4);
        put_f32s(w, (const float[4]){cam->yfov, cam->znear, cam->zfar, cam->aspect}, 4);
    }
    END();

    BEGIN(SEC_TEXTURES, CACHE_SECTION_REQUIRED);
    for (uint32_t i = 0; i < s->texture_count; i++) {
        put_name(w, s->textures[i].name);
        put_u32(w, s->textures[i].width);
        put_u32(w, s->textures[i].height);
        put_u32(w, s->textures[i].srgb);
    }
    END();

    BEGIN(SEC_PIXELS, CACHE_SECTION_REQUIRED);
    for (uint32_t i = 0; i < s->texture_count; i++)
        put(w, s->textures[i].rgba, (size_t)s->textures[i].width * s->textures[i].height * 4);
    END();

    BEGIN(SEC_CLUSTERS, CACHE_SECTION_REQUIRED);
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh_clusters *c = &s->meshes[i].clusters;
        put_u32(w, c->cluster_count);
        put_u32(w, c->level0_cluster_count);
        put_u32(w, c->vertex_count);
        put_u32(w, c->triangle_byte_count);
        put_u32(w, c->group_count);
        put_u32(w, c->dag_depth);
    }
    END();

    BEGIN(SEC_CLUSTER_DATA, CACHE_SECTION_REQUIRED);
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh_clusters *c = &s->meshes[i].clusters;
        for (uint32_t k = 0; k < c->cluster_count; k++) {
            const gdr_cluster *cl = &c->clusters[k];
            put_u32(w, cl->vertex_offset);
            put_u32(w, cl->triangle_offset);
            put_u32(w, cl->vertex_count);
            put_u32(w, cl->triangle_count);
            put_f32s(w, &cl->sphere.x, 4);
            put_f32s(w, &cl->cone_apex.x, 3);
            put_f32s(w, &cl->cone_axis.x, 3);
            put_f32s(w, &cl->cone_cutoff, 1);
            put_u32(w, cl->group);
            put_u32(w, cl->refined_group);
            put_u32(w, cl->reserved);
        }
        for (uint32_t k = 0; k < c->group_count; k++) {
            const gdr_cluster_group *g = &c->groups[k];
            put_f32s(w, &g->sphere.x, 4);
            put_f32s(w, &g->error, 1);
            put_u32(w, g->depth);
            put_u32(w, g->first_cluster);
            put_u32(w, g->cluster_count);
        }
        put(w, c->vertices, sizeof(uint32_t) * c->vertex_count);
        put(w, c->triangles, c->triangle_byte_count);
        align4(w);
    }
    END();

    if (pvs) {
        /* optional: readers of version 2 that predate it skip it */
        BEGIN(SEC_PVS, 0);
        size_t size = gdr_pvs_serialized_size(pvs);
        uint8_t *blob = put_space(w, size);
        if (blob && gdr_pvs_serialize(pvs, blob, size, NULL) != GDR_OK)
            w->failed = 1;
        END();
    }
#undef BEGIN
#undef END
    *count = n;
}

static void store_u32(uint8_t *p, uint32_t v) { memcpy(p, &v, 4); }
static void store_u64(uint8_t *p, uint64_t v) { memcpy(p, &v, 8); }

/* The writer refuses what the reader would refuse (the file size, a texture's sides), before
 * allocating for it: a cache that cannot be read back is never written. */
static gdr_status check_reader_limits(const char *path, const gdr_scene *s, gdr_error *err)
{
    uint64_t bytes = CACHE_HEADER_SIZE + (uint64_t)s->instance_count * INSTANCE_RECORD;
    for (uint32_t i = 0; i < s->texture_count; i++) {
        const gdr_texture *t = &s->textures[i];
        if (t->width == 0 || t->height == 0 || t->width > CACHE_MAX_TEXTURE_SIDE || t->height > CACHE_MAX_TEXTURE_SIDE)
            return gdr_error_set(err, GDR_ERROR_CAPACITY, "%s: texture %u is %ux%u; a cache holds at most %ux%u", path,
                                 i, t->width, t->height, CACHE_MAX_TEXTURE_SIDE, CACHE_MAX_TEXTURE_SIDE);
        bytes += TEXTURE_RECORD + (uint64_t)t->width * t->height * 4;
    }
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh *m = &s->meshes[i];
        bytes += MESH_RECORD + (uint64_t)m->vertex_count * 32 + (uint64_t)m->index_count * 4 +
                 (uint64_t)m->clusters.cluster_count * CLUSTER_RECORD + (uint64_t)m->clusters.vertex_count * 4 +
                 m->clusters.triangle_byte_count;
    }
    if (bytes > GDR_IO_MAX_FILE_SIZE)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "%s: the scene needs at least %llu bytes, more than the %llu a "
                             "cache may hold (the reader's limit)", path, (unsigned long long)bytes,
                             (unsigned long long)GDR_IO_MAX_FILE_SIZE);
    return GDR_OK;
}

gdr_status gdr_cache_write(const char *path, const gdr_scene *scene, const gdr_cache_source *source, gdr_error *err)
{
    return gdr_cache_write_ex(path, scene, source, NULL, err);
}

gdr_status gdr_cache_write_ex(const char *path, const gdr_scene *scene, const gdr_cache_source *source,
                              const gdr_pvs *pvs, gdr_error *err)
{
    enum { BASE_SECTIONS = 11, MAX_SECTIONS = BASE_SECTIONS + 1 };
    if (pvs && gdr_pvs_object_count(pvs) != scene->instance_count)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "%s: the precomputed visibility was baked for %u objects, the scene has %u instances",
                             path, gdr_pvs_object_count(pvs), scene->instance_count);
    gdr_status limits = check_reader_limits(path, scene, err);
    if (limits != GDR_OK)
        return limits;
    /* The table has exactly one entry per section: no byte of the file lies outside a checksum. */
    uint32_t expected = BASE_SECTIONS + (pvs ? 1u : 0u);
    section_entry entries[MAX_SECTIONS];
    uint32_t count = 0;
    writer w = {0};
    put_space(&w, CACHE_HEADER_SIZE + (size_t)expected * CACHE_ENTRY_SIZE); /* header and table, below */
    if (w.data)
        memset(w.data, 0, w.size);
    write_sections(&w, scene, source, pvs, entries, &count);
    assert(w.failed || count == expected);
    if (w.failed) {
        free(w.data);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory serialising the scene", path);
    }
    if (w.size > GDR_IO_MAX_FILE_SIZE) {
        free(w.data);
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "%s: %zu bytes, more than the %llu a cache may hold (the "
                             "reader's limit)", path, w.size, (unsigned long long)GDR_IO_MAX_FILE_SIZE);
    }
    uint8_t *table = w.data + CACHE_HEADER_SIZE;
    for (uint32_t i = 0; i < count; i++) {
        entries[i].checksum = gdr_io_hash(w.data + entries[i].offset, entries[i].size);
        uint8_t *e = table + i * CACHE_ENTRY_SIZE;
        store_u32(e, entries[i].id);
        store_u32(e + 4, entries[i].flags);
        store_u64(e + 8, entries[i].offset);
        store_u64(e + 16, entries[i].size);
        store_u64(e + 24, entries[i].checksum);
    }
    memcpy(w.data, CACHE_MAGIC, 8);
    store_u32(w.data + 8, GDR_CACHE_FORMAT_VERSION);
    store_u32(w.data + 12, CACHE_HEADER_SIZE);
    store_u32(w.data + 16, count);
    store_u32(w.data + 20, 0);
    store_u64(w.data + 24, w.size);
    store_u64(w.data + 32, gdr_io_hash(table, (size_t)count * CACHE_ENTRY_SIZE));
    store_u64(w.data + 40, gdr_io_hash(w.data, 40));

    /* A temporary file in the same folder, then rename: readers see the old file or the new one
     * (core/output_file.h: links followed, devices and FIFOs written directly). */
    gdr_output_file out;
    gdr_status status = gdr_output_open(path, &out, err);
    if (status == GDR_OK) {
        gdr_progress progress;
        gdr_progress_begin(&progress, "write cache", w.size, 0);
        size_t done = 0;
        while (done < w.size) {
            size_t chunk = w.size - done < (16u << 20) ? w.size - done : (16u << 20);
            if (fwrite(w.data + done, 1, chunk, out.file) != chunk)
                break;
            done += chunk;
            gdr_progress_update(&progress, done);
        }
        gdr_progress_end(&progress);
        status = gdr_output_close(&out, done == w.size, path, err);
    }
    free(w.data);
    return status;
}

/* --- reading --------------------------------------------------------------------------------- */

typedef struct reader {
    const uint8_t *data;
    size_t size, at;
    int failed;
} reader;

static const uint8_t *take(reader *r, size_t n)
{
    if (r->failed || n > r->size - r->at) {
        r->failed = 1;
        return NULL;
    }
    const uint8_t *p = r->data + r->at;
    r->at += n;
    return p;
}
static uint32_t get_u32(reader *r)
{
    uint32_t v = 0;
    const uint8_t *p = take(r, 4);
    if (p)
        memcpy(&v, p, 4);
    return v;
}
static uint64_t get_u64(reader *r)
{
    uint64_t v = 0;
    const uint8_t *p = take(r, 8);
    if (p)
        memcpy(&v, p, 8);
    return v;
}
static void get_f32s(reader *r, float *out, size_t n)
{
    const uint8_t *p = take(r, 4 * n);
    if (p)
        memcpy(out, p, 4 * n);
    else
        memset(out, 0, 4 * n);
}
static void get_name(reader *r, char *out)
{
    const uint8_t *p = take(r, GDR_NAME_MAX);
    if (p)
        memcpy(out, p, GDR_NAME_MAX);
    else
        out[0] = 0;
    out[GDR_NAME_MAX - 1] = 0;
}
/* A length-prefixed string: points into the data (not NUL-terminated). */
static const char *get_string(reader *r, uint32_t *length)
{
    *length = get_u32(r);
    return (const char *)take(r, *length);
}

enum { K_SOURCE, K_SCENE, K_MESHES, K_GEOMETRY, K_MATERIALS, K_INSTANCES, K_CAMERAS, K_TEXTURES, K_PIXELS,
       K_CLUSTERS, K_CLUSTER_DATA, K_PVS, K_COUNT };
static const uint32_t known_ids[K_COUNT] = {SEC_SOURCE, SEC_SCENE, SEC_MESHES, SEC_GEOMETRY, SEC_MATERIALS,
                                            SEC_INSTANCES, SEC_CAMERAS, SEC_TEXTURES, SEC_PIXELS, SEC_CLUSTERS,
                                            SEC_CLUSTER_DATA, SEC_PVS};
/* Sections a file may leave out. */
static int optional_section(int k) { return k == K_SOURCE || k == K_PVS; }

typedef struct cache_view {
    const uint8_t *data;
    size_t size;
    reader sections[K_COUNT]; /* by the order of the known ids above */
    int present[K_COUNT];
} cache_view;

static void fourcc_text(uint32_t id, char out[5])
{
    for (int i = 0; i < 4; i++) {
        char ch = (char)(id >> (8 * i));
        out[i] = ch >= 32 && ch < 127 ? ch : '?';
    }
    out[4] = 0;
}

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
                return gdr_error_set(err, GDR_ERROR_PARSE, "%s: corrupted: padding byte at offset %llu, after %s, is "
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

static gdr_status parse_container(const char *name, const uint8_t *data, size_t size, cache_view *v, gdr_error *err)
{
    memset(v, 0, sizeof *v);
    if (size < CACHE_HEADER_SIZE)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: truncated: %zu bytes, shorter than the header", name, size);
    if (memcmp(data, CACHE_MAGIC, 8) != 0)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: not a gdr cache (bad magic)", name);
    reader h = {data, CACHE_HEADER_SIZE, 8, 0};
    uint32_t version = get_u32(&h), header_size = get_u32(&h), count = get_u32(&h);
    (void)get_u32(&h);
    uint64_t file_size = get_u64(&h), table_hash = get_u64(&h), header_hash = get_u64(&h);
    if (version != GDR_CACHE_FORMAT_VERSION)
        return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: cache format version %u, this build reads %u; rebuild it",
                             name, version, GDR_CACHE_FORMAT_VERSION);
    if (header_hash != gdr_io_hash(data, 40))
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: corrupted: header checksum mismatch", name);
    if (header_size != CACHE_HEADER_SIZE)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: header size %u, expected %u", name, header_size,
                             CACHE_HEADER_SIZE);
    if (file_size != size)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: truncated or extended: %zu bytes, the header says %llu", name,
                             size, (unsigned long long)file_size);
    if (count > CACHE_MAX_SECTIONS || CACHE_HEADER_SIZE + (uint64_t)count * CACHE_ENTRY_SIZE > size)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section table (%u entries) does not fit", name, count);
    const uint8_t *table = data + CACHE_HEADER_SIZE;
    if (table_hash != gdr_io_hash(table, (size_t)count * CACHE_ENTRY_SIZE))
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: corrupted: section table checksum mismatch", name);
    for (unsigned i = 48; i < CACHE_HEADER_SIZE; i++)
        if (data[i] != 0)
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: corrupted: reserved header byte %u is not zero", name, i);
    uint64_t table_end = CACHE_HEADER_SIZE + (uint64_t)count * CACHE_ENTRY_SIZE;
    byte_range ranges[CACHE_MAX_SECTIONS];
    reader t = {table, (size_t)count * CACHE_ENTRY_SIZE, 0, 0};
    for (uint32_t i = 0; i < count; i++) {
        uint32_t id = get_u32(&t), flags = get_u32(&t);
        uint64_t offset = get_u64(&t), length = get_u64(&t), checksum = get_u64(&t);
        char text[5];
        fourcc_text(id, text);
        if (offset < table_end || offset > size || length > size - offset)
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section %u '%s' (offset %llu, %llu bytes) lies outside "
                                 "the file", name, i, text, (unsigned long long)offset, (unsigned long long)length);
        ranges[i] = (byte_range){offset, length, id};
        if (checksum != gdr_io_hash(data + offset, (size_t)length))
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: corrupted: section '%s' checksum mismatch", name, text);
        int known = -1;
        for (int k = 0; k < K_COUNT; k++)
            if (known_ids[k] == id)
                known = k;
        if (known < 0) {
            if (flags & CACHE_SECTION_REQUIRED)
                return gdr_error_set(err, GDR_ERROR_UNSUPPORTED, "%s: requires section '%s', unknown to this build",
                                     name, text);
            continue; /* an optional section of a later version */
        }
        if (v->present[known])
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section '%s' appears twice", name, text);
        v->present[known] = 1;
        v->sections[known] = (reader){data + offset, (size_t)length, 0, 0};
    }
    gdr_status coverage = check_coverage(name, data, size, table_end, ranges, count, err);
    if (coverage != GDR_OK)
        return coverage;
    for (int k = 0; k < K_COUNT; k++)
        if (!v->present[k] && !optional_section(k)) {
            char text[5];
            fourcc_text(known_ids[k], text);
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section '%s' is missing", name, text);
        }
    v->data = data;
    v->size = size;
    return GDR_OK;
}

static int all_finite(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

#define BAD(...) do { status = gdr_error_set(err, GDR_ERROR_PARSE, __VA_ARGS__); goto done; } while (0)

/* --- clusters: CLUS (per mesh counts) and CLDT (per mesh arrays) ------------------------------ */

static int bad_sphere(const gdr_vec4 *sphere) { return !all_finite(&sphere->x, 4) || !(sphere->w >= 0.0f); }

/* Reads the arrays of one mesh's clusters (counts already set in c, arrays allocated) and checks
 * every offset, count and index against the limits, the arrays and the mesh. */
static gdr_status read_mesh_clusters(const char *name, reader *r, uint32_t m, const gdr_mesh *mesh,
                                     gdr_mesh_clusters *c, gdr_error *err)
{
#define CLDT(fmt, ...) gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'CLDT': mesh %u" fmt, name, m, __VA_ARGS__)
    for (uint32_t k = 0; k < c->cluster_count; k++) {
        gdr_cluster *cl = &c->clusters[k];
        cl->vertex_offset = get_u32(r);
        cl->triangle_offset = get_u32(r);
        cl->vertex_count = get_u32(r);
        cl->triangle_count = get_u32(r);
        get_f32s(r, &cl->sphere.x, 4);
        get_f32s(r, &cl->cone_apex.x, 3);
        get_f32s(r, &cl->cone_axis.x, 3);
        get_f32s(r, &cl->cone_cutoff, 1);
        cl->group = get_u32(r);
        cl->refined_group = get_u32(r);
        cl->reserved = get_u32(r);
        if (cl->vertex_count < 1 || cl->vertex_count > GDR_CLUSTER_MAX_VERTICES || cl->triangle_count < 1 ||
            cl->triangle_count > GDR_CLUSTER_MAX_TRIANGLES)
            return CLDT(" cluster %u: %u vertices and %u triangles (1 to %u and %u)", k, cl->vertex_count,
                        cl->triangle_count, GDR_CLUSTER_MAX_VERTICES, GDR_CLUSTER_MAX_TRIANGLES);
        if ((uint64_t)cl->vertex_offset + cl->vertex_count > c->vertex_count)
            return CLDT(" cluster %u: vertices %u..%u lie outside the mesh's %u cluster vertices", k,
                        cl->vertex_offset, cl->vertex_offset + (cl->vertex_count - 1), c->vertex_count);
        if (cl->triangle_offset % 4 != 0 || (uint64_t)cl->triangle_offset + 3ull * cl->triangle_count >
                                                c->triangle_byte_count)
            return CLDT(" cluster %u: triangle bytes at %u (%u triangles) are unaligned or lie outside the mesh's %u",
                        k, cl->triangle_offset, cl->triangle_count, c->triangle_byte_count);
        if (bad_sphere(&cl->sphere) || !all_finite(&cl->cone_apex.x, 3) || !all_finite(&cl->cone_axis.x, 3) ||
            !all_finite(&cl->cone_cutoff, 1))
            return CLDT(" cluster %u: bounds are not finite (or a negative radius)", k);
        if ((cl->group != GDR_NO_INDEX && cl->group >= c->group_count) ||
            (cl->refined_group != GDR_NO_INDEX && cl->refined_group >= c->group_count))
            return CLDT(" cluster %u: group %u / refined group %u does not exist (%u groups)", k, cl->group,
                        cl->refined_group, c->group_count);
    }
    for (uint32_t k = 0; k < c->group_count; k++) {
        gdr_cluster_group *g = &c->groups[k];
        get_f32s(r, &g->sphere.x, 4);
        get_f32s(r, &g->error, 1);
        g->depth = get_u32(r);
        g->first_cluster = get_u32(r);
        g->cluster_count = get_u32(r);
        if (bad_sphere(&g->sphere) || isnan(g->error))
            return CLDT(" group %u: sphere or error is not a number", k);
        if ((uint64_t)g->first_cluster + g->cluster_count > c->cluster_count)
            return CLDT(" group %u: clusters %u (+%u) lie outside the mesh's %u", k, g->first_cluster,
                        g->cluster_count, c->cluster_count);
    }
    const uint8_t *vertices = take(r, sizeof(uint32_t) * (size_t)c->vertex_count);
    const uint8_t *triangles = take(r, c->triangle_byte_count);
    take(r, (4 - c->triangle_byte_count % 4) % 4);
    if (r->failed) /* the caller checked the sizes: only a programming error gets here */
        return CLDT(" %s", "runs past the section");
    memcpy(c->vertices, vertices, sizeof(uint32_t) * (size_t)c->vertex_count);
    memcpy(c->triangles, triangles, c->triangle_byte_count);
    for (uint32_t k = 0; k < c->vertex_count; k++)
        if (c->vertices[k] >= mesh->vertex_count)
            return CLDT(" cluster vertex %u: mesh vertex %u does not exist (%u vertices)", k, c->vertices[k],
                        mesh->vertex_count);
    uint64_t level0_triangles = 0;
    for (uint32_t k = 0; k < c->cluster_count; k++) {
        const gdr_cluster *cl = &c->clusters[k];
        const uint8_t *local = c->triangles + cl->triangle_offset;
        for (uint32_t t = 0; t < 3 * cl->triangle_count; t++)
            if (local[t] >= cl->vertex_count)
                return CLDT(" cluster %u triangle %u: local vertex %u, the cluster has %u", k, t / 3, local[t],
                            cl->vertex_count);
        if (k < c->level0_cluster_count)
            level0_triangles += cl->triangle_count;
    }
    if (level0_triangles != mesh->index_count / 3)
        return CLDT(": level-0 clusters hold %llu triangles, the mesh %u", (unsigned long long)level0_triangles,
                    mesh->index_count / 3);
#undef CLDT
    return GDR_OK;
}

static gdr_status read_clusters(const char *name, cache_view *v, gdr_scene *s, gdr_error *err)
{
    reader *counts = &v->sections[K_CLUSTERS], *data = &v->sections[K_CLUSTER_DATA];
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        gdr_mesh *mesh = &s->meshes[m];
        uint32_t cluster_count = get_u32(counts), level0 = get_u32(counts), vertex_count = get_u32(counts);
        uint32_t triangle_bytes = get_u32(counts), group_count = get_u32(counts), dag_depth = get_u32(counts);
        if (level0 > cluster_count || (cluster_count == 0 && (vertex_count || triangle_bytes || group_count ||
                                                              dag_depth)) ||
            (cluster_count > 0 && (level0 == 0 || mesh->index_count == 0)))
            return gdr_error_set(err, GDR_ERROR_PARSE,
                                 "%s: section 'CLUS': mesh %u: %u clusters (%u of level 0) for %u indices, %u cluster "
                                 "vertices, %u triangle bytes, %u groups: inconsistent", name, m, cluster_count,
                                 level0, mesh->index_count, vertex_count, triangle_bytes, group_count);
        uint64_t need = (uint64_t)cluster_count * CLUSTER_RECORD + (uint64_t)group_count * GROUP_RECORD +
                        (uint64_t)vertex_count * 4 + ((uint64_t)triangle_bytes + 3) / 4 * 4;
        if (need > data->size - data->at)
            return gdr_error_set(err, GDR_ERROR_PARSE,
                                 "%s: section 'CLDT': mesh %u: %u clusters, %u groups, %u vertices and %u triangle "
                                 "bytes run past the section", name, m, cluster_count, group_count, vertex_count,
                                 triangle_bytes);
        if (cluster_count == 0)
            continue;
        gdr_mesh_clusters *c = &mesh->clusters; /* owned by the scene from here: freed with it */
        c->clusters = malloc(sizeof(gdr_cluster) * (size_t)cluster_count);
        c->vertices = malloc(sizeof(uint32_t) * (size_t)vertex_count + 1);
        c->triangles = malloc((size_t)triangle_bytes + 1);
        c->groups = group_count ? malloc(sizeof(gdr_cluster_group) * (size_t)group_count) : NULL;
        if (!c->clusters || !c->vertices || !c->triangles || (group_count && !c->groups))
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: mesh %u: out of memory for %u clusters", name, m,
                                 cluster_count);
        c->cluster_count = cluster_count;
        c->level0_cluster_count = level0;
        c->vertex_count = vertex_count;
        c->triangle_byte_count = triangle_bytes;
        c->group_count = group_count;
        c->dag_depth = dag_depth;
        gdr_status status = read_mesh_clusters(name, data, m, mesh, c, err);
        if (status != GDR_OK)
            return status;
    }
    if (data->at != data->size)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'CLDT' has %zu bytes left over", name,
                             data->size - data->at);
    return GDR_OK;
}

static gdr_status build_scene(const char *name, cache_view *v, gdr_scene **out, gdr_error *err)
{
    gdr_scene *s = NULL;
    gdr_status status = gdr_scene_create(&s, err);
    if (status != GDR_OK)
        return status;
    reader *sc = &v->sections[K_SCENE];
    uint32_t mesh_count = get_u32(sc), material_count = get_u32(sc), instance_count = get_u32(sc);
    uint32_t camera_count = get_u32(sc), texture_count = get_u32(sc), ext_length;
    const char *ext = get_string(sc, &ext_length);
    if (sc->failed || sc->at != sc->size)
        BAD("%s: section 'SCNE' has the wrong size", name);
    if (ext_length) {
        char *copy = malloc(ext_length + 1);
        if (!copy)
            BAD("%s: out of memory", name);
        memcpy(copy, ext, ext_length);
        copy[ext_length] = 0;
        status = gdr_scene_set_extensions(s, copy, err);
        free(copy);
        if (status != GDR_OK)
            goto done;
    }
    struct { int k; uint32_t count, record; const char *id; } sizes[] = {
        {K_MESHES, mesh_count, MESH_RECORD, "MESH"},       {K_MATERIALS, material_count, MATERIAL_RECORD, "MATL"},
        {K_INSTANCES, instance_count, INSTANCE_RECORD, "INST"}, {K_CAMERAS, camera_count, CAMERA_RECORD, "CAMR"},
        {K_TEXTURES, texture_count, TEXTURE_RECORD, "TEXR"}, {K_CLUSTERS, mesh_count, CLUSTERS_RECORD, "CLUS"},
    };
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++)
        if (v->sections[sizes[i].k].size != (uint64_t)sizes[i].count * sizes[i].record)
            BAD("%s: section '%s' holds %zu bytes, %u records need %llu", name, sizes[i].id,
                v->sections[sizes[i].k].size, sizes[i].count, (unsigned long long)sizes[i].count * sizes[i].record);

    reader *tr = &v->sections[K_TEXTURES], *px = &v->sections[K_PIXELS];
    for (uint32_t i = 0; i < texture_count; i++) {
        char tname[GDR_NAME_MAX];
        get_name(tr, tname);
        uint32_t width = get_u32(tr), height = get_u32(tr), srgb = get_u32(tr);
        if (width == 0 || height == 0 || width > CACHE_MAX_TEXTURE_SIDE || height > CACHE_MAX_TEXTURE_SIDE ||
            srgb > 1)
            BAD("%s: texture %u: size %ux%u or flags are out of range", name, i, width, height);
        const uint8_t *pixels = take(px, (size_t)width * height * 4);
        if (!pixels)
            BAD("%s: texture %u: pixel data runs past section 'TXPX'", name, i);
        status = gdr_scene_add_texture(s, tname, width, height, pixels, srgb, NULL, err);
        if (status != GDR_OK)
            goto done;
    }
    if (px->at != px->size)
        BAD("%s: section 'TXPX' has %zu bytes left over", name, px->size - px->at);

    reader *mr = &v->sections[K_MESHES], *geo = &v->sections[K_GEOMETRY];
    for (uint32_t i = 0; i < mesh_count; i++) {
        char mname[GDR_NAME_MAX];
        get_name(mr, mname);
        uint32_t vertex_count = get_u32(mr), index_count = get_u32(mr);
        gdr_vec4 bounds;
        get_f32s(mr, &bounds.x, 4);
        uint64_t need = (uint64_t)vertex_count * 32 + (uint64_t)index_count * 4;
        if (need > geo->size - geo->at)
            BAD("%s: mesh %u: %u vertices and %u indices run past section 'GEOM'", name, i, vertex_count, index_count);
        const void *positions = take(geo, (size_t)vertex_count * 12), *normals = take(geo, (size_t)vertex_count * 12);
        const void *uvs = take(geo, (size_t)vertex_count * 8), *indices = take(geo, (size_t)index_count * 4);
        /* Copies are needed anyway; aligned ones let gdr_scene_add_mesh read them as arrays. */
        gdr_vec3 *p = malloc((size_t)vertex_count * 12 + 1), *n = malloc((size_t)vertex_count * 12 + 1);
        gdr_vec2 *t = malloc((size_t)vertex_count * 8 + 1);
        uint32_t *idx = malloc((size_t)index_count * 4 + 1);
        if (p && n && t && idx) {
            memcpy(p, positions, (size_t)vertex_count * 12);
            memcpy(n, normals, (size_t)vertex_count * 12);
            memcpy(t, uvs, (size_t)vertex_count * 8);
            memcpy(idx, indices, (size_t)index_count * 4);
            if (!all_finite((const float *)n, (size_t)vertex_count * 3) ||
                !all_finite((const float *)t, (size_t)vertex_count * 2) || !all_finite(&bounds.x, 4))
                status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: mesh %u: normals, uvs or bounds are not finite", name,
                                       i);
            else
                status = gdr_scene_add_mesh(s, mname, p, n, t, vertex_count, idx, index_count, NULL, err);
        } else {
            status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
        }
        free(p);
        free(n);
        free(t);
        free(idx);
        if (status != GDR_OK)
            goto done;
        s->meshes[s->mesh_count - 1].bounds = bounds;
    }
    if (geo->at != geo->size)
        BAD("%s: section 'GEOM' has %zu bytes left over", name, geo->size - geo->at);
    status = read_clusters(name, v, s, err);
    if (status != GDR_OK)
        goto done;

    reader *ma = &v->sections[K_MATERIALS];
    for (uint32_t i = 0; i < material_count; i++) {
        gdr_material m;
        float factors[3];
        get_name(ma, m.name);
        get_f32s(ma, &m.base_color.x, 4);
        m.base_color_texture = get_u32(ma);
        m.normal_texture = get_u32(ma);
        m.metallic_roughness_texture = get_u32(ma);
        get_f32s(ma, factors, 3);
        m.metallic_factor = factors[0];
        m.roughness_factor = factors[1];
        m.alpha_cutoff = factors[2];
        m.alpha_mode = get_u32(ma);
        m.double_sided = get_u32(ma);
        uint32_t textures[3] = {m.base_color_texture, m.normal_texture, m.metallic_roughness_texture};
        for (int k = 0; k < 3; k++)
            if (textures[k] != GDR_NO_INDEX && textures[k] >= texture_count)
                BAD("%s: material %u: texture %u does not exist (%u textures)", name, i, textures[k], texture_count);
        if (!all_finite(&m.base_color.x, 4) || !all_finite(factors, 3) || m.alpha_mode > GDR_ALPHA_BLEND ||
            m.double_sided > 1)
            BAD("%s: material %u: values out of range", name, i);
        status = gdr_scene_add_material(s, &m, NULL, err);
        if (status != GDR_OK)
            goto done;
    }

    reader *in = &v->sections[K_INSTANCES];
    for (uint32_t i = 0; i < instance_count; i++) {
        gdr_instance inst;
        get_f32s(in, inst.transform.m, 16);
        inst.mesh = get_u32(in);
        inst.material = get_u32(in);
        get_f32s(in, &inst.color.x, 4);
        if (!all_finite(&inst.color.x, 4))
            BAD("%s: instance %u: colour is not finite", name, i);
        status = gdr_scene_add_instance(s, &inst, err);
        if (status != GDR_OK)
            goto done;
    }

    reader *ca = &v->sections[K_CAMERAS];
    for (uint32_t i = 0; i < camera_count; i++) {
        gdr_camera cam;
        float lens[4];
        get_name(ca, cam.name);
        get_f32s(ca, &cam.position.x, 3);
        get_f32s(ca, &cam.rotation.x, 4);
        get_f32s(ca, lens, 4);
        cam.yfov = lens[0];
        cam.znear = lens[1];
        cam.zfar = lens[2];
        cam.aspect = lens[3];
        if (!all_finite(&cam.position.x, 3) || !all_finite(&cam.rotation.x, 4) || !all_finite(lens, 4))
            BAD("%s: camera %u: values are not finite", name, i);
        status = gdr_scene_add_camera(s, &cam, err);
        if (status != GDR_OK)
            goto done;
    }
done:
    if (status != GDR_OK) {
        gdr_scene_destroy(s);
        return status;
    }
    *out = s;
    return GDR_OK;
}

/* PVIS: the precomputed-visibility blob (gdr_pvs_load checks all of it), baked for this scene's
 * instances. Checked whether or not the caller wants it (out may be NULL), like every section. */
static gdr_status read_pvs(const char *name, const cache_view *v, const gdr_scene *scene, gdr_pvs **out,
                           gdr_error *err)
{
    if (!v->present[K_PVS])
        return GDR_OK;
    const reader *r = &v->sections[K_PVS];
    gdr_pvs *pvs = NULL;
    gdr_error pvs_err = {0};
    gdr_status status = gdr_pvs_load(r->data, r->size, &pvs, &pvs_err);
    if (status != GDR_OK)
        return gdr_error_set(err, status, "%s: section 'PVIS' (%zu bytes at offset %zu): %s", name, r->size,
                             (size_t)(r->data - v->data), pvs_err.message);
    if (gdr_pvs_object_count(pvs) != scene->instance_count) {
        status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'PVIS': baked for %u objects, the scene has %u "
                               "instances", name, gdr_pvs_object_count(pvs), scene->instance_count);
        gdr_pvs_destroy(pvs);
        return status;
    }
    if (out)
        *out = pvs;
    else
        gdr_pvs_destroy(pvs);
    return GDR_OK;
}

/* The scene, then the optional sections that refer to it. */
static gdr_status build_all(const char *name, cache_view *v, gdr_scene **out, gdr_pvs **out_pvs, gdr_error *err)
{
    gdr_status status = build_scene(name, v, out, err);
    if (status == GDR_OK && (status = read_pvs(name, v, *out, out_pvs, err)) != GDR_OK) {
        gdr_scene_destroy(*out);
        *out = NULL;
    }
    return status;
}

gdr_status gdr_cache_read_memory(const void *data, size_t size, const char *name, gdr_scene **out, gdr_error *err)
{
    return gdr_cache_read_memory_ex(data, size, name, out, NULL, err);
}

gdr_status gdr_cache_read_memory_ex(const void *data, size_t size, const char *name, gdr_scene **out,
                                    gdr_pvs **out_pvs, gdr_error *err)
{
    *out = NULL;
    if (out_pvs)
        *out_pvs = NULL;
    cache_view v;
    gdr_status status = parse_container(name ? name : "(memory)", data, size, &v, err);
    if (status != GDR_OK)
        return status;
    return build_all(name ? name : "(memory)", &v, out, out_pvs, err);
}

/* One entry of section 'SRCE': a file the scene was built from, as it was then. */
typedef struct source_entry {
    char *path;    /* where to look for it now (malloc'ed) */
    uint64_t size, mtime, hash;
    uint64_t key;  /* hash of the path, to check each path once */
    int moved;     /* its folder moved with the source: the mtime says nothing, compare contents */
} source_entry;

/* A file as it is now: looked at once however many entries name it. */
typedef struct source_now {
    int exists, hashed, unreadable;
    uint64_t size, hash;
    int64_t mtime;
} source_now;

static int compare_entries(const void *a, const void *b)
{
    const source_entry *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return strcmp(x->path, y->path);
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
    if (r->failed || files > (r->size - r->at) / 28) /* each entry is at least 28 bytes */
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'SRCE' is malformed", name);
    source_entry *entries = calloc((size_t)files + 1, sizeof *entries);
    if (!entries)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    char old_dir[PATH_MAX] = "", new_dir[PATH_MAX] = "", absolute[PATH_MAX];
    for (uint32_t i = 0; i < files; i++) {
        uint32_t length;
        const char *path = get_string(r, &length);
        source_entry *e = &entries[i];
        e->size = get_u64(r), e->mtime = get_u64(r), e->hash = get_u64(r);
        if (r->failed || length == 0 || length >= PATH_MAX || memchr(path, 0, length)) {
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

/* Compares one entry with the file now (stat once, contents hashed at most once per path). */
static gdr_status check_entry(const char *name, const source_entry *e, source_now *now, gdr_error *err)
{
    if (!now->exists)
        return GDR_OK; /* the file is not here: the cache stands alone */
    if (now->size != e->size)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: stale: %s changed size (%llu -> %llu bytes)", name,
                             e->path, (unsigned long long)e->size, (unsigned long long)now->size);
    if ((uint64_t)now->mtime == e->mtime && !e->moved)
        return GDR_OK;
    if (!now->hashed && !now->unreadable) {
        uint8_t *contents;
        size_t contents_size;
        gdr_error read_err;
        if (gdr_io_read_file(e->path, &contents, &contents_size, NULL, &read_err) == GDR_OK) {
            now->hash = gdr_io_hash(contents, contents_size);
            now->hashed = 1;
            free(contents);
        } else {
            now->unreadable = 1;
        }
    }
    if (now->hashed && now->hash != e->hash)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: stale: %s changed since the cache was built", name,
                             e->path);
    return GDR_OK;
}

/* Compares the SRCE section with the build options and the files on disk. With `source` (the file
 * the cache stands for), the cache must record it as its first entry, with the same contents. */
static gdr_status check_fresh(const char *name, cache_view *v, const char *build_options, const char *source,
                              gdr_error *err)
{
    if (!v->present[K_SOURCE])
        return source ? gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: stale: it does not record the source it "
                                      "was built from", name)
                      : GDR_OK;
    reader r = v->sections[K_SOURCE];
    uint32_t length;
    const char *options = get_string(&r, &length);
    if (r.failed)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'SRCE' is truncated", name);
    if (build_options && (strlen(build_options) != length || memcmp(options, build_options, length) != 0))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: stale: built with options '%.*s', now '%s'", name,
                             (int)(length > 64 ? 64 : length), options, build_options);
    source_entry *entries = NULL;
    uint32_t count = 0;
    gdr_status status = read_entries(name, &r, source, &entries, &count, err);
    if (status != GDR_OK)
        return status;
    if (source && count == 0)
        status = gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: stale: it does not record the source it was "
                               "built from", name);
    if (source && status == GDR_OK) {
        /* The source itself must be there, with the contents the cache was built from. */
        source_now now = {0};
        now.exists = gdr_io_stat(entries[0].path, &now.size, &now.mtime) == 0;
        if (!now.exists)
            status = gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: stale: its source %s is not there", name,
                                   entries[0].path);
        else
            status = check_entry(name, &entries[0], &now, err);
    }
    /* Every other path once, however often the list names it. */
    qsort(entries, count, sizeof *entries, compare_entries);
    source_now now = {0};
    for (uint32_t i = 0; i < count && status == GDR_OK; i++) {
        if (i == 0 || compare_entries(&entries[i - 1], &entries[i]) != 0) {
            now = (source_now){0};
            now.exists = gdr_io_stat(entries[i].path, &now.size, &now.mtime) == 0;
        }
        status = check_entry(name, &entries[i], &now, err);
    }
    free_entries(entries, count);
    return status;
}

gdr_status gdr_cache_read(const char *path, const char *build_options, gdr_scene **out, gdr_error *err)
{
    return gdr_cache_read_ex(path, build_options, out, NULL, err);
}

gdr_status gdr_cache_read_ex(const char *path, const char *build_options, gdr_scene **out, gdr_pvs **out_pvs,
                             gdr_error *err)
{
    return gdr_io_cache_read_for(path, NULL, build_options, out, out_pvs, err);
}

gdr_status gdr_io_cache_read_for(const char *path, const char *source, const char *build_options, gdr_scene **out,
                                 gdr_pvs **out_pvs, gdr_error *err)
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
    status = parse_container(path, data, size, &v, err);
    if (status == GDR_OK)
        status = check_fresh(path, &v, build_options, source, err);
    if (status == GDR_OK)
        status = build_all(path, &v, out, out_pvs, err);
    free(data);
    return status;
}

size_t gdr_cache_path_for(const char *source_path, const char *cache_dir, char *out, size_t out_size)
{
    int n;
    if (!cache_dir) {
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
