/* Wavefront OBJ import: v / vt / vn / f, fan-triangulated polygons, negative (relative)
 * indices, one mesh per group or object. Messages name file:line. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/io_internal.h"

typedef struct obj_corner {
    uint32_t v, vt, vn; /* 0-based; UINT32_MAX when absent (vt, vn) */
} obj_corner;

typedef struct float_array {
    float *data;
    size_t count, capacity; /* in floats */
} float_array;

/* The mesh being assembled: unique (v, vt, vn) corners and the triangle list. */
typedef struct obj_mesh {
    char name[GDR_NAME_MAX];
    obj_corner *corners;
    uint32_t corner_count, corner_capacity;
    uint32_t *indices;
    uint32_t index_count, index_capacity;
    uint32_t *table; /* open addressing: corner index + 1, 0 empty */
    uint32_t table_size;
    int missing_normal;
} obj_mesh;

typedef struct obj_ctx {
    const char *name;
    gdr_error *err;
    gdr_io_warnings warnings;
    gdr_scene *scene;
    float_array v, vt, vn;
    obj_mesh mesh;
    gdr_io_budget budget;
    uint32_t line;
    int warned_lines, warned_unknown;
} obj_ctx;

static gdr_status obj_fail(obj_ctx *c, gdr_status status, const char *format, ...)
    __attribute__((format(printf, 3, 4)));
static gdr_status obj_fail(obj_ctx *c, gdr_status status, const char *format, ...)
{
    char message[GDR_ERROR_MESSAGE_MAX];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    return gdr_error_set(c->err, status, "%s:%u: %s", c->name, c->line, message);
}

static int grow(void **array, size_t *capacity, size_t needed, size_t element)
{
    if (needed <= *capacity)
        return 1;
    size_t n = *capacity ? *capacity : 256;
    while (n < needed)
        n *= 2;
    void *grown = realloc(*array, n * element);
    if (!grown)
        return 0;
    *array = grown;
    *capacity = n;
    return 1;
}

static int grow32(void **array, uint32_t *capacity, size_t needed, size_t element)
{
    if (needed > UINT32_MAX / 2)
        return 0;
    size_t cap = *capacity;
    int ok = grow(array, &cap, needed, element);
    *capacity = (uint32_t)cap;
    return ok;
}

static const char *skip_space(const char *p, const char *end)
{
    while (p < end && (*p == ' ' || *p == '\t'))
        p++;
    return p;
}

/* Reads up to `n` floats after the keyword; requires at least `min`. */
static gdr_status parse_floats(obj_ctx *c, const char *p, const char *end, uint32_t min, uint32_t n,
                               float_array *out, const char *keyword)
{
    if (!grow((void **)&out->data, &out->capacity, out->count + n, sizeof(float)))
        return obj_fail(c, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
    float values[4] = {0, 0, 0, 0};
    uint32_t got = 0;
    while (got < n) {
        p = skip_space(p, end);
        if (p >= end)
            break;
        char buffer[64];
        size_t length = 0;
        while (p + length < end && p[length] != ' ' && p[length] != '\t')
            length++;
        if (length >= sizeof buffer)
            return obj_fail(c, GDR_ERROR_PARSE, "%s: number too long", keyword);
        memcpy(buffer, p, length);
        buffer[length] = 0;
        char *stop;
        errno = 0;
        float value = strtof(buffer, &stop);
        if (stop == buffer || *stop)
            return obj_fail(c, GDR_ERROR_PARSE, "%s: '%s' is not a number", keyword, buffer);
        if (!isfinite(value))
            return obj_fail(c, GDR_ERROR_PARSE, "%s: '%s' is not finite", keyword, buffer);
        if (out == &c->v && fabsf(value) > GDR_IO_MAX_COORDINATE)
            return obj_fail(c, GDR_ERROR_PARSE, "v: '%s' is beyond the %g limit on coordinates", buffer,
                            GDR_IO_MAX_COORDINATE);
        values[got++] = value;
        p += length;
    }
    if (got < min)
        return obj_fail(c, GDR_ERROR_PARSE, "%s: expected %u numbers, found %u", keyword, min, got);
    memcpy(out->data + out->count, values, sizeof(float) * n);
    out->count += n;
    return GDR_OK;
}

static uint32_t hash_corner(obj_corner k)
{
    uint32_t h = k.v * 0x9E3779B1u ^ (k.vt + 0x7F4A7C15u) * 0x85EBCA77u ^ (k.vn + 0x165667B1u) * 0xC2B2AE3Du;
    return h ^ (h >> 15);
}

static gdr_status corner_index(obj_ctx *c, obj_corner k, uint32_t *out)
{
    obj_mesh *m = &c->mesh;
    if ((uint64_t)(m->corner_count + 1) * 2 > m->table_size) {
        uint32_t size = m->table_size ? m->table_size * 2 : 64;
        if (size == 0 || size > (1u << 30))
            return obj_fail(c, GDR_ERROR_CAPACITY, "more than 2^29 distinct vertices in one group");
        uint32_t *table = calloc(size, sizeof(uint32_t));
        if (!table)
            return obj_fail(c, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
        for (uint32_t i = 0; i < m->corner_count; i++) {
            uint32_t slot = hash_corner(m->corners[i]) & (size - 1);
            while (table[slot])
                slot = (slot + 1) & (size - 1);
            table[slot] = i + 1;
        }
        free(m->table);
        m->table = table;
        m->table_size = size;
    }
    uint32_t slot = hash_corner(k) & (m->table_size - 1);
    while (m->table[slot]) {
        obj_corner e = m->corners[m->table[slot] - 1];
        if (e.v == k.v && e.vt == k.vt && e.vn == k.vn) {
            *out = m->table[slot] - 1;
            return GDR_OK;
        }
        slot = (slot + 1) & (m->table_size - 1);
    }
    if (!grow32((void **)&m->corners, &m->corner_capacity, (size_t)m->corner_count + 1, sizeof(obj_corner)))
        return obj_fail(c, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
    m->corners[m->corner_count] = k;
    m->table[slot] = ++m->corner_count;
    *out = m->corner_count - 1;
    return GDR_OK;
}

/* One index of a face corner: 1-based, or negative = relative to the end. */
static gdr_status resolve_index(obj_ctx *c, const char *text, size_t length, size_t count, const char *what,
                                uint32_t *out)
{
    char buffer[24];
    if (length == 0 || length >= sizeof buffer)
        return obj_fail(c, GDR_ERROR_PARSE, "f: bad %s index '%.*s'", what, (int)(length < 24 ? length : 24), text);
    memcpy(buffer, text, length);
    buffer[length] = 0;
    char *stop;
    errno = 0;
    long long v = strtoll(buffer, &stop, 10);
    if (*stop || errno)
        return obj_fail(c, GDR_ERROR_PARSE, "f: '%s' is not a %s index", buffer, what);
    long long resolved = v > 0 ? v - 1 : (long long)count + v;
    if (v == 0 || resolved < 0 || resolved >= (long long)count)
        return obj_fail(c, GDR_ERROR_PARSE, "f: %s index %lld is out of range (%zu defined so far)", what, v, count);
    *out = (uint32_t)resolved;
    return GDR_OK;
}

static gdr_status parse_face(obj_ctx *c, const char *p, const char *end)
{
    uint32_t first = 0, previous = 0, n = 0;
    while (1) {
        p = skip_space(p, end);
        if (p >= end)
            break;
        const char *token = p;
        while (p < end && *p != ' ' && *p != '\t')
            p++;
        const char *parts[3] = {token, NULL, NULL};
        size_t lengths[3] = {0, 0, 0};
        int part = 0;
        for (const char *q = token; q < p; q++) {
            if (*q == '/') {
                if (part == 2)
                    return obj_fail(c, GDR_ERROR_PARSE, "f: corner '%.*s' has more than 3 parts", (int)(p - token),
                                    token);
                parts[++part] = q + 1;
            } else {
                lengths[part]++;
            }
        }
        obj_corner k = {0, UINT32_MAX, UINT32_MAX};
        gdr_status status = resolve_index(c, parts[0], lengths[0], c->v.count / 3, "position", &k.v);
        if (status == GDR_OK && part >= 1 && lengths[1])
            status = resolve_index(c, parts[1], lengths[1], c->vt.count / 2, "texture coordinate", &k.vt);
        if (status == GDR_OK && part >= 2 && lengths[2])
            status = resolve_index(c, parts[2], lengths[2], c->vn.count / 3, "normal", &k.vn);
        if (status != GDR_OK)
            return status;
        if (k.vn == UINT32_MAX)
            c->mesh.missing_normal = 1;
        uint32_t index = 0;
        status = corner_index(c, k, &index);
        if (status != GDR_OK)
            return status;
        if (n == 0)
            first = index;
        else if (n >= 2) {
            obj_mesh *m = &c->mesh;
            status = gdr_io_budget_take(&c->budget, GDR_BUDGET_TRIANGLES, 1, c->name, "f", c->err);
            if (status != GDR_OK)
                return obj_fail(c, status, "%u triangles exceed the budget of %llu; raise it with --budget "
                                "triangles=N", (unsigned)(c->budget.used[GDR_BUDGET_TRIANGLES] + 1),
                                (unsigned long long)c->budget.limit[GDR_BUDGET_TRIANGLES]);
            if (!grow32((void **)&m->indices, &m->index_capacity, (size_t)m->index_count + 3, sizeof(uint32_t)))
                return obj_fail(c, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
            m->indices[m->index_count++] = first;
            m->indices[m->index_count++] = previous;
            m->indices[m->index_count++] = index;
        }
        previous = index;
        n++;
    }
    if (n < 3)
        gdr_io_warn(&c->warnings, "%s:%u: face with %u corners skipped", c->name, c->line, n);
    return GDR_OK;
}

/* Degenerate and duplicate faces dropped, over-shared vertices split (mesh_clean.c). */
static gdr_status clean_group(obj_ctx *c, gdr_vec3 **positions, gdr_vec3 **normals, gdr_vec2 **uvs,
                              uint32_t *vertex_count)
{
    obj_mesh *m = &c->mesh;
    uint32_t before = m->index_count / 3, degenerate, duplicate, added;
    gdr_status status = gdr_io_drop_bad_triangles(*positions, *vertex_count, m->indices, &m->index_count,
                                                  &degenerate, &duplicate);
    if (status == GDR_OK)
        status = gdr_io_split_shared_vertices(positions, normals, uvs, &(gdr_vec4 *){NULL}, vertex_count, m->indices,
                                              m->index_count, &added);
    if (status != GDR_OK)
        return obj_fail(c, status, "out of memory");
    /* Zero-area faces draw nothing and are common in real files: dropped silently. */
    if (duplicate || (degenerate && m->index_count == 0))
        gdr_io_warn(&c->warnings, "%s: group '%s' ending at line %u: %u of %u faces dropped (%u degenerate, %u "
                    "duplicate)", c->name, m->name[0] ? m->name : "obj", c->line, degenerate + duplicate, before,
                    degenerate, duplicate);
    return GDR_OK;
}

/* Turns the assembled group into a mesh and an instance; starts an empty one. */
static gdr_status flush_mesh(obj_ctx *c)
{
    obj_mesh *m = &c->mesh;
    gdr_status status = GDR_OK;
    if (m->index_count > 0) {
        size_t n = m->corner_count ? m->corner_count : 1;
        gdr_vec3 *positions = malloc(sizeof(gdr_vec3) * n);
        gdr_vec3 *normals = m->missing_normal ? NULL : malloc(sizeof(gdr_vec3) * n);
        gdr_vec2 *uvs = calloc(n, sizeof(gdr_vec2));
        if (!positions || !uvs || (!m->missing_normal && !normals)) {
            status = obj_fail(c, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
        } else {
            for (uint32_t i = 0; i < m->corner_count; i++) {
                obj_corner k = m->corners[i];
                memcpy(&positions[i], c->v.data + 3 * (size_t)k.v, sizeof(gdr_vec3));
                if (k.vt != UINT32_MAX)
                    memcpy(&uvs[i], c->vt.data + 2 * (size_t)k.vt, sizeof(gdr_vec2));
                if (normals) {
                    gdr_vec3 nv;
                    memcpy(&nv, c->vn.data + 3 * (size_t)k.vn, sizeof nv);
                    float length = gdr_vec3_length(nv);
                    normals[i] = length > 1e-12f ? gdr_vec3_scale(nv, 1.0f / length) : (gdr_vec3){0, 1, 0};
                }
            }
            uint32_t mesh_index, vertex_count = m->corner_count;
            status = clean_group(c, &positions, &normals, &uvs, &vertex_count);
            if (status == GDR_OK && m->index_count == 0)
                goto flushed;
            if (status == GDR_OK)
                status = gdr_io_budget_take(&c->budget, GDR_BUDGET_INSTANCES, 1, c->name, "g", c->err);
            if (status == GDR_OK)
                status = gdr_scene_add_mesh(c->scene, m->name[0] ? m->name : "obj", positions, normals, uvs,
                                            vertex_count, m->indices, m->index_count, &mesh_index, c->err);
            if (status == GDR_OK) {
                gdr_instance instance = {.transform = gdr_mat4_identity(), .mesh = mesh_index,
                                         .material = GDR_NO_INDEX, .color = {1, 1, 1, 1}};
                status = gdr_scene_add_instance(c->scene, &instance, c->err);
            }
        }
    flushed:
        free(positions);
        free(normals);
        free(uvs);
    }
    /* Emptying the corner table costs its size: a table much larger than the group it served is
     * dropped instead, so that many small groups after a large one stay linear. */
    if (m->table && m->table_size > 8 * (uint64_t)m->corner_count + 1024) {
        free(m->table);
        m->table = NULL;
        m->table_size = 0;
    } else if (m->table) {
        memset(m->table, 0, sizeof(uint32_t) * m->table_size);
    }
    m->corner_count = m->index_count = 0;
    m->missing_normal = 0;
    return status;
}

static gdr_status parse_line(obj_ctx *c, const char *p, const char *end)
{
    p = skip_space(p, end);
    while (end > p && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\r'))
        end--;
    if (p >= end || *p == '#')
        return GDR_OK;
    const char *keyword = p;
    while (p < end && *p != ' ' && *p != '\t')
        p++;
    size_t length = (size_t)(p - keyword);
#define IS(word) (length == sizeof(word) - 1 && memcmp(keyword, word, length) == 0)
    if (IS("v"))
        return parse_floats(c, p, end, 3, 3, &c->v, "v");
    if (IS("vt"))
        return parse_floats(c, p, end, 1, 2, &c->vt, "vt");
    if (IS("vn"))
        return parse_floats(c, p, end, 3, 3, &c->vn, "vn");
    if (IS("f"))
        return parse_face(c, p, end);
    if (IS("g") || IS("o")) {
        gdr_status status = flush_mesh(c);
        p = skip_space(p, end);
        snprintf(c->mesh.name, sizeof c->mesh.name, "%.*s", (int)(end - p), p);
        return status;
    }
    if (IS("l") || IS("p")) {
        if (!c->warned_lines++)
            gdr_io_warn(&c->warnings, "%s:%u: points and lines skipped: only faces are drawn", c->name, c->line);
        return GDR_OK;
    }
    if (IS("mtllib") || IS("usemtl") || IS("s") || IS("vp") || IS("cstype") || IS("deg") || IS("curv") ||
        IS("parm") || IS("end") || IS("surf") || IS("lod") || IS("shadow_obj") || IS("trace_obj"))
        return GDR_OK;
#undef IS
    if (!c->warned_unknown++)
        gdr_io_warn(&c->warnings, "%s:%u: statement '%.*s' ignored", c->name, c->line, (int)(length > 32 ? 32 : length),
                    keyword);
    return GDR_OK;
}

gdr_status gdr_import_obj_memory(const void *data, size_t size, const char *name, const gdr_import_options *options,
                                 gdr_scene **out, gdr_import_result *result, gdr_error *err)
{
    static const gdr_import_options defaults = {0};
    if (!options)
        options = &defaults;
    *out = NULL;
    gdr_error local_err;
    obj_ctx c = {.name = name ? name : "(memory)", .err = err ? err : &local_err,
                 .warnings = {options->warning, options->warning_user, 0}};
    gdr_io_budget_init(&c.budget, &options->budget);
    const char *text = data, *end = text + size;
    gdr_status status = gdr_scene_create(&c.scene, c.err);
    if (status == GDR_OK && size >= 2 && ((text[0] == '\xfe' && text[1] == '\xff') ||
                                          (text[0] == '\xff' && text[1] == '\xfe') || memchr(text, 0, size)))
        status = gdr_error_set(c.err, GDR_ERROR_UNSUPPORTED, "%s: not a text file (UTF-16 or binary); OBJ must be "
                               "ASCII or UTF-8", c.name);
    gdr_progress progress;
    gdr_progress_begin(&progress, "import", size, options->no_progress);
    for (const char *line = text; status == GDR_OK && line < end;) {
        const char *newline = memchr(line, '\n', (size_t)(end - line));
        const char *line_end = newline ? newline : end;
        c.line++;
        status = parse_line(&c, line, line_end);
        line = newline ? newline + 1 : end;
        if ((c.line & 0xffff) == 0)
            gdr_progress_update(&progress, (uint64_t)(line - text));
    }
    gdr_progress_end(&progress);
    if (status == GDR_OK)
        status = flush_mesh(&c);
    if (status == GDR_OK && c.scene->mesh_count == 0)
        gdr_io_warn(&c.warnings, "%s: no faces; the scene is empty", c.name);
    free(c.v.data);
    free(c.vt.data);
    free(c.vn.data);
    free(c.mesh.corners);
    free(c.mesh.indices);
    free(c.mesh.table);
    if (result)
        result->warning_count = c.warnings.count;
    if (status != GDR_OK) {
        gdr_scene_destroy(c.scene);
        return status;
    }
    *out = c.scene;
    return GDR_OK;
}

gdr_status gdr_import_obj(const char *path, const gdr_import_options *options, gdr_scene **out,
                          gdr_import_result *result, gdr_error *err)
{
    *out = NULL;
    uint8_t *data;
    size_t size;
    gdr_status status = gdr_io_read_file(path, &data, &size, options ? options->sources : NULL, err);
    if (status != GDR_OK)
        return status;
    status = gdr_import_obj_memory(data, size, path, options, out, result, err);
    free(data);
    return status;
}
