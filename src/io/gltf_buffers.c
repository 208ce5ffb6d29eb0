/* glTF buffers, buffer views (including EXT_meshopt_compression) and accessors, every offset
 * and length checked against what is really there before it is used. */
#define _XOPEN_SOURCE 700 /* realpath, strdup */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>

#include "io/gltf_internal.h"

gdr_status gltf_fail(gltf_ctx *c, gdr_status status, const char *format, ...)
{
    char message[GDR_ERROR_MESSAGE_MAX];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    return gdr_error_set(c->err, status, "%s: %s", c->name, message);
}

/* --- JSON helpers ---------------------------------------------------------------------------- */

gdr_status gltf_get_uint(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, int required,
                         uint32_t max, uint32_t *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) {
        if (required)
            return gltf_fail(c, GDR_ERROR_PARSE, "%s.%s: required but missing", place, key);
        return GDR_OK;
    }
    double v = item->valuedouble;
    if (!cJSON_IsNumber(item) || !(v >= 0.0) || v > (double)max || floor(v) != v)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.%s: expected an integer in [0, %u]", place, key, max);
    *out = (uint32_t)v;
    return GDR_OK;
}

gdr_status gltf_get_number(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, double *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item)
        return GDR_OK;
    if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble))
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.%s: expected a finite number", place, key);
    *out = item->valuedouble;
    return GDR_OK;
}

/* A number that becomes a float: finite, and finite once rounded to 32 bits (1e300 would be +inf). */
static int fits_float(double v)
{
    return isfinite(v) && fabs(v) <= GLTF_MAX_FLOAT;
}

gdr_status gltf_get_float(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, float *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item)
        return GDR_OK;
    if (!cJSON_IsNumber(item) || !fits_float(item->valuedouble))
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.%s: expected a finite number of at most %g in magnitude (a 32-bit "
                         "float)", place, key, GLTF_MAX_FLOAT);
    *out = (float)item->valuedouble;
    return GDR_OK;
}

gdr_status gltf_get_string(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, const char **out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item)
        return GDR_OK;
    if (!cJSON_IsString(item) || !item->valuestring)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.%s: expected a string", place, key);
    *out = item->valuestring;
    return GDR_OK;
}

gdr_status gltf_get_object(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, int required,
                           const cJSON **out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) {
        if (required)
            return gltf_fail(c, GDR_ERROR_PARSE, "%s.%s: required but missing", place, key);
        return GDR_OK;
    }
    if (!cJSON_IsObject(item))
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.%s: expected an object", place, key);
    *out = item;
    return GDR_OK;
}

gdr_status gltf_get_array(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, const cJSON **out,
                          uint32_t *count)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    *count = 0;
    if (!item)
        return GDR_OK;
    if (!cJSON_IsArray(item))
        return gltf_fail(c, GDR_ERROR_PARSE, "%s%s%s: expected an array", place, place[0] ? "." : "", key);
    int n = cJSON_GetArraySize(item);
    *out = item;
    *count = n > 0 ? (uint32_t)n : 0;
    return GDR_OK;
}

gdr_status gltf_get_floats(gltf_ctx *c, const cJSON *obj, const char *key, const char *place, uint32_t n,
                           float *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item)
        return GDR_OK;
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != (int)n)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.%s: expected an array of %u numbers", place, key, n);
    uint32_t i = 0;
    float values[16];
    for (const cJSON *e = item->child; e && i < n; e = e->next, i++) {
        if (!cJSON_IsNumber(e) || !fits_float(e->valuedouble))
            return gltf_fail(c, GDR_ERROR_PARSE, "%s.%s[%u]: expected a finite number of at most %g in magnitude (a "
                             "32-bit float)", place, key, i, GLTF_MAX_FLOAT);
        values[i] = (float)e->valuedouble;
    }
    memcpy(out, values, sizeof(float) * n);
    return GDR_OK;
}

const cJSON *gltf_extension(const cJSON *obj, const char *name)
{
    const cJSON *extensions = cJSON_GetObjectItemCaseSensitive(obj, "extensions");
    const cJSON *ext = cJSON_IsObject(extensions) ? cJSON_GetObjectItemCaseSensitive(extensions, name) : NULL;
    return cJSON_IsObject(ext) ? ext : NULL;
}

/* --- URIs and buffers ------------------------------------------------------------------------ */

static int hex_value(char ch)
{
    if (ch >= '0' && ch <= '9')
        return ch - '0';
    if (ch >= 'a' && ch <= 'f')
        return ch - 'a' + 10;
    if (ch >= 'A' && ch <= 'F')
        return ch - 'A' + 10;
    return -1;
}

/* An external file must lie inside the scene's folder: the URI (percent-decoded, `path` is the
 * folder joined with it) is relative, has no '..' part, and resolves (symlinks followed) to a path
 * under the folder's own resolved path; *path becomes that resolved path, which is what is opened.
 * Hostile scenes otherwise read any file the user can (its bytes would end up in the cache). */
static gdr_status confine_to_folder(gltf_ctx *c, const char *place, const char *uri, char **path)
{
    const char *relative = *path + strlen(c->base_dir);
    int escapes = relative[0] == '/';
    for (const char *part = relative; *part && !escapes; part = strchr(part, '/') ? strchr(part, '/') + 1 : "")
        escapes = strncmp(part, "..", 2) == 0 && (part[2] == '/' || part[2] == 0);
    if (escapes)
        return gltf_fail(c, GDR_ERROR_OUTSIDE_FOLDER, "%s.uri: '%.64s' leaves the scene's folder (absolute or '..'); "
                         "allow it with --allow-outside-files", place, uri);
    char folder[PATH_MAX], resolved[PATH_MAX];
    if (!realpath(c->base_dir[0] ? c->base_dir : ".", folder))
        return gltf_fail(c, GDR_ERROR_IO, "%s.uri: the scene's folder cannot be resolved: %s", place, strerror(errno));
    if (!realpath(*path, resolved))
        return GDR_OK; /* nothing there to read: opening it says so */
    size_t length = strlen(folder);
    if (strcmp(resolved, folder) == 0)
        return gltf_fail(c, GDR_ERROR_NOT_A_FILE, "%s.uri: '%.64s' names the scene's folder, not a file", place, uri);
    int inside = strncmp(resolved, folder, length) == 0 && (resolved[length] == '/' || strcmp(folder, "/") == 0);
    if (!inside)
        return gltf_fail(c, GDR_ERROR_OUTSIDE_FOLDER, "%s.uri: '%.64s' resolves outside the scene's folder (a symbolic "
                         "link); allow it with --allow-outside-files", place, uri);
    char *copy = strdup(resolved);
    if (!copy)
        return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "%s.uri: out of memory", place);
    free(*path);
    *path = copy;
    return GDR_OK;
}

gdr_status gltf_load_uri(gltf_ctx *c, const char *uri, const char *place, uint8_t **out, size_t *size)
{
    *out = NULL;
    *size = 0;
    if (strncmp(uri, "data:", 5) == 0) {
        const char *comma = strchr(uri, ',');
        const char *base64 = strstr(uri, ";base64,");
        if (!comma || base64 != comma - 7)
            return gltf_fail(c, GDR_ERROR_UNSUPPORTED, "%s.uri: only base64 data: URIs are supported", place);
        size_t length = strlen(comma + 1);
        gdr_status status = gdr_io_budget_take(&c->budget, GDR_BUDGET_DECODED_BYTES, gdr_base64_decoded_max(length),
                                               c->name, place, c->err);
        if (status != GDR_OK)
            return status;
        uint8_t *data = malloc(gdr_base64_decoded_max(length) + 1);
        if (!data)
            return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "%s.uri: out of memory", place);
        size_t n = gdr_base64_decode(data, comma + 1, length);
        if (n == SIZE_MAX) {
            free(data);
            return gltf_fail(c, GDR_ERROR_PARSE, "%s.uri: invalid base64 data", place);
        }
        *out = data;
        *size = n;
        return GDR_OK;
    }
    if (uri[0] == 0)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.uri: empty: it names no file", place);
    const char *colon = strchr(uri, ':'), *slash = strchr(uri, '/');
    if (colon && (!slash || colon < slash))
        return gltf_fail(c, GDR_ERROR_UNSUPPORTED, "%s.uri: '%.64s' has a URI scheme; only relative paths and "
                         "data: URIs are supported", place, uri);
    if (!c->base_dir)
        return gltf_fail(c, GDR_ERROR_UNSUPPORTED, "%s.uri: external file '%.64s' cannot be resolved here", place,
                         uri);
    size_t dir_length = strlen(c->base_dir), uri_length = strlen(uri);
    char *path = malloc(dir_length + uri_length + 1);
    if (!path)
        return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "%s.uri: out of memory", place);
    memcpy(path, c->base_dir, dir_length);
    size_t n = dir_length;
    for (size_t i = 0; i < uri_length; i++) {
        int hi, lo;
        if (uri[i] == '%' && i + 2 < uri_length + 1 && (hi = hex_value(uri[i + 1])) >= 0 &&
            (lo = hex_value(uri[i + 2])) >= 0 && (hi | lo) != 0) {
            path[n++] = (char)(hi * 16 + lo);
            i += 2;
        } else {
            path[n++] = uri[i];
        }
    }
    path[n] = 0;
    gdr_error file_err;
    gdr_status status = c->allow_outside_files ? GDR_OK : confine_to_folder(c, place, uri, &path);
    int confined = status == GDR_OK; /* else confine_to_folder said why in c->err */
    if (confined)
        status = gdr_io_read_file(path, out, size, c->sources, &file_err);
    if (status != GDR_OK) {
        /* Looked for and not read: recorded too, so that a cache built without it is rebuilt once the
         * file appears or changes. */
        gdr_error record_err;
        gdr_status recorded = gdr_io_source_add_looked_for(c->sources, path, &record_err);
        free(path);
        if (recorded != GDR_OK)
            return gltf_fail(c, recorded, "%s.uri: %s", place, record_err.message);
        return confined ? gltf_fail(c, status, "%s.uri: %s", place, file_err.message) : status;
    }
    free(path);
    return GDR_OK;
}

gdr_status gltf_buffer_get(gltf_ctx *c, uint32_t index, const char *place, const uint8_t **data, size_t *size)
{
    if (index >= c->buffer_count)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: buffer %u does not exist (%u buffers)", place, index,
                         c->buffer_count);
    gltf_buffer *b = &c->buffers[index];
    if (b->state == 0) {
        char here[48];
        snprintf(here, sizeof here, "buffers[%u]", index);
        const cJSON *json = c->buffer_at[index];
        uint32_t byte_length = 0;
        const char *uri = NULL;
        gdr_status status = gltf_get_uint(c, json, "byteLength", here, 1, UINT32_MAX, &byte_length);
        if (status == GDR_OK)
            status = gltf_get_string(c, json, "uri", here, &uri);
        if (status != GDR_OK)
            return status;
        const uint8_t *bytes;
        size_t available;
        if (uri) {
            status = gltf_load_uri(c, uri, here, &b->owned, &available);
            if (status != GDR_OK)
                return status;
            bytes = b->owned;
        } else if (index == 0 && c->is_glb && c->glb_bin) {
            bytes = c->glb_bin;
            available = c->glb_bin_size;
        } else {
            const cJSON *meshopt = gltf_extension(json, "EXT_meshopt_compression");
            if (meshopt && cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(meshopt, "fallback")))
                return gltf_fail(c, GDR_ERROR_PARSE, "%s: %s is an EXT_meshopt_compression fallback without data",
                                 place, here);
            return gltf_fail(c, GDR_ERROR_PARSE, "%s: has no uri%s, so its data is not usable", here,
                             c->is_glb ? " and is not the GLB binary chunk" : "");
        }
        if (available < byte_length) {
            /* An image's failure is only a warning: the buffer may be asked for again. */
            free(b->owned);
            b->owned = NULL;
            return gltf_fail(c, GDR_ERROR_PARSE, "%s.byteLength: %u, but only %zu bytes are there", here,
                             byte_length, available);
        }
        b->data = bytes;
        b->size = byte_length;
        b->state = 1;
    }
    *data = b->data;
    *size = b->size;
    return GDR_OK;
}

/* Decodes an EXT_meshopt_compression view into v->owned. */
static gdr_status decode_meshopt(gltf_ctx *c, const cJSON *ext, const char *place, uint32_t byte_length,
                                 gltf_view *v)
{
    char here[128];
    snprintf(here, sizeof here, "%s.extensions.EXT_meshopt_compression", place);
    uint32_t buffer = 0, offset = 0, length = 0, stride = 0, count = 0;
    const char *mode = NULL, *filter = "NONE";
    gdr_status status = gltf_get_uint(c, ext, "buffer", here, 1, UINT32_MAX, &buffer);
    if (status == GDR_OK)
        status = gltf_get_uint(c, ext, "byteOffset", here, 0, UINT32_MAX, &offset);
    if (status == GDR_OK)
        status = gltf_get_uint(c, ext, "byteLength", here, 1, UINT32_MAX, &length);
    if (status == GDR_OK)
        status = gltf_get_uint(c, ext, "byteStride", here, 1, 256, &stride);
    if (status == GDR_OK)
        status = gltf_get_uint(c, ext, "count", here, 1, UINT32_MAX, &count);
    if (status == GDR_OK)
        status = gltf_get_string(c, ext, "mode", here, &mode);
    if (status == GDR_OK)
        status = gltf_get_string(c, ext, "filter", here, &filter);
    if (status != GDR_OK)
        return status;
    if (!mode)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.mode: required but missing", here);
    const uint8_t *data;
    size_t size;
    status = gltf_buffer_get(c, buffer, here, &data, &size);
    if (status != GDR_OK)
        return status;
    if ((uint64_t)offset + length > size)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.byteLength: %u bytes at offset %u exceed buffer %u length %zu",
                         here, length, offset, buffer, size);
    uint64_t decoded = (uint64_t)count * stride;
    status = gdr_io_budget_take(&c->budget, GDR_BUDGET_DECODED_BYTES, decoded, c->name, here, c->err);
    if (status != GDR_OK)
        return status;
    if (decoded != byte_length)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: count %u x byteStride %u differs from the bufferView "
                         "byteLength %u", here, count, stride, byte_length);
    /* No meshopt stream expands more than 64x; a larger claim is a lie we need not allocate for. */
    if (decoded > (1ull << 30) || decoded > (uint64_t)length * 128 + 4096)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: %llu decoded bytes from %u compressed ones is implausible", here,
                         (unsigned long long)decoded, length);
    v->owned = malloc(decoded ? (size_t)decoded : 1);
    if (!v->owned)
        return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", here);
    const unsigned char *source = data + offset;
    int result;
    if (strcmp(mode, "ATTRIBUTES") == 0) {
        if (stride % 4 != 0)
            return gltf_fail(c, GDR_ERROR_PARSE, "%s.byteStride: %u is not a multiple of 4 (ATTRIBUTES)", here,
                             stride);
        result = meshopt_decodeVertexBuffer(v->owned, count, stride, source, length);
        if (result == 0 && strcmp(filter, "NONE") != 0) {
            if (strcmp(filter, "OCTAHEDRAL") == 0 && (stride == 4 || stride == 8))
                meshopt_decodeFilterOct(v->owned, count, stride);
            else if (strcmp(filter, "QUATERNION") == 0 && stride == 8)
                meshopt_decodeFilterQuat(v->owned, count, stride);
            else if (strcmp(filter, "EXPONENTIAL") == 0)
                meshopt_decodeFilterExp(v->owned, count, stride);
            else
                return gltf_fail(c, GDR_ERROR_PARSE, "%s.filter: '%.32s' with byteStride %u is not supported", here,
                                 filter, stride);
        }
    } else if (strcmp(mode, "TRIANGLES") == 0 || strcmp(mode, "INDICES") == 0) {
        if (stride != 2 && stride != 4)
            return gltf_fail(c, GDR_ERROR_PARSE, "%s.byteStride: %u must be 2 or 4 for %s", here, stride, mode);
        if (strcmp(filter, "NONE") != 0)
            return gltf_fail(c, GDR_ERROR_PARSE, "%s.filter: must be NONE for %s", here, mode);
        if (mode[0] == 'T') {
            if (count % 3 != 0)
                return gltf_fail(c, GDR_ERROR_PARSE, "%s.count: %u is not a multiple of 3 (TRIANGLES)", here, count);
            result = meshopt_decodeIndexBuffer(v->owned, count, stride, source, length);
        } else {
            result = meshopt_decodeIndexSequence(v->owned, count, stride, source, length);
        }
    } else {
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.mode: '%.32s' is not ATTRIBUTES, TRIANGLES or INDICES", here, mode);
    }
    if (result != 0)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: meshopt decoding failed (error %d)", here, result);
    v->data = v->owned;
    v->length = (size_t)decoded;
    return GDR_OK;
}

gdr_status gltf_view_get(gltf_ctx *c, uint32_t index, const char *place, const gltf_view **out)
{
    if (index >= c->view_count)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: bufferView %u does not exist (%u bufferViews)", place, index,
                         c->view_count);
    gltf_view *v = &c->views[index];
    if (v->state == 0) {
        char here[48];
        snprintf(here, sizeof here, "bufferViews[%u]", index);
        const cJSON *json = c->view_at[index];
        uint32_t buffer = 0, offset = 0, length = 0, stride = 0;
        gdr_status status = gltf_get_uint(c, json, "buffer", here, 1, UINT32_MAX, &buffer);
        if (status == GDR_OK)
            status = gltf_get_uint(c, json, "byteOffset", here, 0, UINT32_MAX, &offset);
        if (status == GDR_OK)
            status = gltf_get_uint(c, json, "byteLength", here, 1, UINT32_MAX, &length);
        if (status == GDR_OK)
            status = gltf_get_uint(c, json, "byteStride", here, 0, 252, &stride);
        if (status != GDR_OK)
            return status;
        if (cJSON_GetObjectItemCaseSensitive(json, "byteStride") && stride < 4)
            return gltf_fail(c, GDR_ERROR_PARSE, "%s.byteStride: %u is below 4", here, stride);
        v->stride = stride;
        const cJSON *meshopt = gltf_extension(json, "EXT_meshopt_compression");
        if (meshopt) {
            status = decode_meshopt(c, meshopt, here, length, v);
            if (status != GDR_OK)
                return status;
        } else {
            const uint8_t *data;
            size_t size;
            status = gltf_buffer_get(c, buffer, here, &data, &size);
            if (status != GDR_OK)
                return status;
            if ((uint64_t)offset + length > size)
                return gltf_fail(c, GDR_ERROR_PARSE, "%s.byteLength: %u bytes at offset %u exceed buffer %u length "
                                 "%zu", here, length, offset, buffer, size);
            v->data = data + offset;
            v->length = length;
        }
        v->state = 1;
    }
    *out = v;
    return GDR_OK;
}

void gltf_buffers_free(gltf_ctx *c)
{
    for (uint32_t i = 0; c->buffers && i < c->buffer_count; i++)
        free(c->buffers[i].owned);
    for (uint32_t i = 0; c->views && i < c->view_count; i++)
        free(c->views[i].owned);
    free(c->buffers);
    free(c->views);
    c->buffers = NULL;
    c->views = NULL;
}

/* --- accessors ------------------------------------------------------------------------------- */

static uint32_t component_size(uint32_t type)
{
    switch (type) {
    case 5120: case 5121: return 1; /* BYTE, UNSIGNED_BYTE */
    case 5122: case 5123: return 2; /* SHORT, UNSIGNED_SHORT */
    case 5125: case 5126: return 4; /* UNSIGNED_INT, FLOAT */
    default: return 0;
    }
}

static uint32_t type_components(const char *type)
{
    static const char *names[] = {"SCALAR", "VEC2", "VEC3", "VEC4"};
    for (uint32_t i = 0; i < 4; i++)
        if (strcmp(type, names[i]) == 0)
            return i + 1;
    return 0;
}

static double read_component(const uint8_t *p, uint32_t type, int normalized)
{
    switch (type) {
    case 5120: { int8_t v; memcpy(&v, p, 1); return normalized ? fmax(v / 127.0, -1.0) : v; }
    case 5121: { uint8_t v = *p; return normalized ? v / 255.0 : v; }
    case 5122: { int16_t v; memcpy(&v, p, 2); return normalized ? fmax(v / 32767.0, -1.0) : v; }
    case 5123: { uint16_t v; memcpy(&v, p, 2); return normalized ? v / 65535.0 : v; }
    case 5125: { uint32_t v; memcpy(&v, p, 4); return v; }
    default: { float v; memcpy(&v, p, 4); return v; }
    }
}

/* Where one accessor's elements are: data + i * stride. */
typedef struct accessor_source {
    gltf_accessor_info info;
    const uint8_t *data; /* NULL: no bufferView, all zeros */
    uint32_t stride, element_size;
    const cJSON *sparse;
} accessor_source;

static gdr_status locate_elements(gltf_ctx *c, const char *place, uint32_t view_index, uint32_t offset,
                                  uint32_t count, uint32_t element_size, int allow_stride, const uint8_t **data,
                                  uint32_t *stride)
{
    const gltf_view *view = NULL;
    gdr_status status = gltf_view_get(c, view_index, place, &view);
    if (status != GDR_OK)
        return status;
    uint32_t s = allow_stride && view->stride ? view->stride : element_size;
    if (s < element_size)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: bufferView %u byteStride %u is smaller than the element (%u bytes)",
                         place, view_index, s, element_size);
    uint64_t end = (uint64_t)offset + (uint64_t)s * (count - 1) + element_size;
    if (count == 0 || end > view->length)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.count: %u elements at offset %u exceed bufferView %u length %zu",
                         place, count, offset, view_index, view->length);
    *data = view->data + offset;
    *stride = s;
    return GDR_OK;
}

static gdr_status accessor_locate(gltf_ctx *c, uint32_t index, const char *use, accessor_source *src)
{
    if (index >= c->accessor_count)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: accessor %u does not exist (%u accessors)", use, index,
                         c->accessor_count);
    char here[48];
    snprintf(here, sizeof here, "accessors[%u]", index);
    const cJSON *json = c->accessor_at[index];
    uint32_t view = GDR_NO_INDEX, offset = 0, count = 0, ctype = 0;
    const char *type = NULL;
    const cJSON *normalized = cJSON_GetObjectItemCaseSensitive(json, "normalized");
    gdr_status status = gltf_get_uint(c, json, "bufferView", here, 0, UINT32_MAX - 1, &view);
    if (status == GDR_OK)
        status = gltf_get_uint(c, json, "byteOffset", here, 0, UINT32_MAX, &offset);
    if (status == GDR_OK)
        status = gltf_get_uint(c, json, "count", here, 1, UINT32_MAX, &count);
    if (status == GDR_OK)
        status = gltf_get_uint(c, json, "componentType", here, 1, UINT32_MAX, &ctype);
    if (status == GDR_OK)
        status = gltf_get_string(c, json, "type", here, &type);
    if (status == GDR_OK)
        status = gltf_get_object(c, json, "sparse", here, 0, &src->sparse);
    if (status != GDR_OK)
        return status;
    if (normalized && !cJSON_IsBool(normalized))
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.normalized: expected a boolean", here);
    if (!type)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.type: required but missing", here);
    if (count == 0)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.count: must be at least 1", here);
    uint32_t size = component_size(ctype);
    if (size == 0)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.componentType: %u is not a glTF component type", here, ctype);
    uint32_t components = type_components(type);
    if (components == 0)
        return gltf_fail(c, GDR_ERROR_UNSUPPORTED, "%s.type: '%.16s' is not usable for %s", here, type, use);
    src->info = (gltf_accessor_info){count, components, ctype, cJSON_IsTrue(normalized)};
    if (src->info.normalized && (ctype == 5125 || ctype == 5126))
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.normalized: not allowed with componentType %u", here, ctype);
    src->element_size = components * size;
    src->data = NULL;
    src->stride = src->element_size;
    if (view != GDR_NO_INDEX)
        return locate_elements(c, here, view, offset, count, src->element_size, 1, &src->data, &src->stride);
    if (!src->sparse && count > GDR_IO_MAX_UNBACKED_ELEMENTS)
        return gltf_fail(c, GDR_ERROR_UNSUPPORTED, "%s.count: %u zero elements without a bufferView exceed the "
                         "limit of %u", here, count, GDR_IO_MAX_UNBACKED_ELEMENTS);
    if (count > GDR_IO_MAX_UNBACKED_ELEMENTS)
        return gltf_fail(c, GDR_ERROR_UNSUPPORTED, "%s.count: %u sparse elements without a bufferView exceed the "
                         "limit of %u", here, count, GDR_IO_MAX_UNBACKED_ELEMENTS);
    return GDR_OK;
}

gdr_status gltf_accessor_info_get(gltf_ctx *c, uint32_t index, const char *use, gltf_accessor_info *info)
{
    accessor_source src = {0};
    gdr_status status = accessor_locate(c, index, use, &src);
    /* Elements no buffer backs are made from nothing: the caller allocates them next. */
    if (status == GDR_OK && !src.data)
        status = gdr_io_budget_take(&c->budget, GDR_BUDGET_DECODED_BYTES,
                                    (uint64_t)src.info.count * src.info.components * 4, c->name, use, c->err);
    if (status == GDR_OK)
        *info = src.info;
    return status;
}

/* Converts `count` elements starting at data (stride apart) into doubles-as-T via `store`. */
static void read_elements_float(const accessor_source *s, const uint8_t *data, uint32_t stride, uint32_t count,
                                uint32_t components, float *out)
{
    uint32_t n = s->info.components < components ? s->info.components : components;
    if (s->info.component_type == 5126 && n == s->info.components) {
        for (uint32_t i = 0; i < count; i++)
            memcpy(out + (size_t)i * components, data + (size_t)i * stride, sizeof(float) * n);
        return;
    }
    uint32_t size = component_size(s->info.component_type);
    for (uint32_t i = 0; i < count; i++)
        for (uint32_t k = 0; k < n; k++)
            out[(size_t)i * components + k] =
                (float)read_component(data + (size_t)i * stride + k * size, s->info.component_type, s->info.normalized);
}

/* Applies accessor.sparse: `apply(out, target element, values element)`. */
static gdr_status apply_sparse(gltf_ctx *c, uint32_t index, const accessor_source *s, uint32_t components,
                               float *out_float, uint32_t *out_uint)
{
    char here[64];
    snprintf(here, sizeof here, "accessors[%u].sparse", index);
    uint32_t count = 0, iview = 0, ioffset = 0, itype = 0, vview = 0, voffset = 0;
    const cJSON *indices = NULL, *values = NULL;
    gdr_status status = gltf_get_uint(c, s->sparse, "count", here, 1, s->info.count, &count);
    if (status == GDR_OK)
        status = gltf_get_object(c, s->sparse, "indices", here, 1, &indices);
    if (status == GDR_OK)
        status = gltf_get_object(c, s->sparse, "values", here, 1, &values);
    if (status != GDR_OK)
        return status;
    char iplace[80], vplace[80];
    snprintf(iplace, sizeof iplace, "%s.indices", here);
    snprintf(vplace, sizeof vplace, "%s.values", here);
    status = gltf_get_uint(c, indices, "bufferView", iplace, 1, UINT32_MAX, &iview);
    if (status == GDR_OK)
        status = gltf_get_uint(c, indices, "byteOffset", iplace, 0, UINT32_MAX, &ioffset);
    if (status == GDR_OK)
        status = gltf_get_uint(c, indices, "componentType", iplace, 1, UINT32_MAX, &itype);
    if (status == GDR_OK)
        status = gltf_get_uint(c, values, "bufferView", vplace, 1, UINT32_MAX, &vview);
    if (status == GDR_OK)
        status = gltf_get_uint(c, values, "byteOffset", vplace, 0, UINT32_MAX, &voffset);
    if (status != GDR_OK)
        return status;
    if (count == 0)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.count: must be at least 1", here);
    if (itype != 5121 && itype != 5123 && itype != 5125)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.componentType: %u is not an unsigned integer type", iplace, itype);
    const uint8_t *idata, *vdata;
    uint32_t istride, vstride;
    status = locate_elements(c, iplace, iview, ioffset, count, component_size(itype), 0, &idata, &istride);
    if (status == GDR_OK)
        status = locate_elements(c, vplace, vview, voffset, count, s->element_size, 0, &vdata, &vstride);
    if (status != GDR_OK)
        return status;
    uint64_t previous = 0;
    for (uint32_t i = 0; i < count; i++) {
        uint32_t target = (uint32_t)read_component(idata + (size_t)i * istride, itype, 0);
        if (target >= s->info.count || (i > 0 && target <= previous))
            return gltf_fail(c, GDR_ERROR_PARSE, "%s[%u]: index %u is out of range or not increasing", iplace, i,
                             target);
        previous = target;
        if (out_float) {
            read_elements_float(s, vdata + (size_t)i * vstride, vstride, 1, components,
                                out_float + (size_t)target * components);
        } else {
            out_uint[target] = (uint32_t)read_component(vdata + (size_t)i * vstride, s->info.component_type, 0);
        }
    }
    return GDR_OK;
}

gdr_status gltf_accessor_read_floats(gltf_ctx *c, uint32_t index, const char *use, uint32_t components,
                                     float *out)
{
    accessor_source s = {0};
    gdr_status status = accessor_locate(c, index, use, &s);
    if (status != GDR_OK)
        return status;
    memset(out, 0, sizeof(float) * components * (size_t)s.info.count);
    if (s.data)
        read_elements_float(&s, s.data, s.stride, s.info.count, components, out);
    return s.sparse ? apply_sparse(c, index, &s, components, out, NULL) : GDR_OK;
}

gdr_status gltf_accessor_read_uints(gltf_ctx *c, uint32_t index, const char *use, uint32_t *out)
{
    accessor_source s = {0};
    gdr_status status = accessor_locate(c, index, use, &s);
    if (status != GDR_OK)
        return status;
    if (s.info.components != 1 || (s.info.component_type != 5121 && s.info.component_type != 5123 &&
                                    s.info.component_type != 5125) || s.info.normalized)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: accessor %u must be a SCALAR of unsigned integers", use, index);
    memset(out, 0, sizeof(uint32_t) * (size_t)s.info.count);
    if (s.data) {
        uint32_t size = component_size(s.info.component_type);
        for (uint32_t i = 0; i < s.info.count; i++) {
            const uint8_t *p = s.data + (size_t)i * s.stride;
            if (size == 4)
                memcpy(&out[i], p, 4);
            else if (size == 2) {
                uint16_t v;
                memcpy(&v, p, 2);
                out[i] = v;
            } else {
                out[i] = *p;
            }
        }
    }
    return s.sparse ? apply_sparse(c, index, &s, 1, NULL, out) : GDR_OK;
}

/* An index member of a JSON object, or GDR_NO_INDEX when it is absent or not an index below `count`
 * (the conversion that reads it later says what is wrong). */
static uint32_t index_member(const cJSON *obj, const char *key, uint32_t count)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= 0.0) || v->valuedouble >= (double)count ||
        v->valuedouble != (double)(uint32_t)v->valuedouble)
        return GDR_NO_INDEX;
    return (uint32_t)v->valuedouble;
}

/* Marks the buffer behind bufferView `view`. */
static void mark_view(gltf_ctx *c, uint32_t view, uint8_t *marked)
{
    if (view == GDR_NO_INDEX)
        return;
    /* A compressed view reads the extension's buffer; its own may be a fallback without data. */
    const cJSON *meshopt = gltf_extension(c->view_at[view], "EXT_meshopt_compression");
    uint32_t buffer = index_member(meshopt ? meshopt : c->view_at[view], "buffer", c->buffer_count);
    if (buffer != GDR_NO_INDEX)
        marked[buffer] = 1;
}

static void mark_accessor(gltf_ctx *c, uint32_t accessor, uint8_t *marked)
{
    if (accessor == GDR_NO_INDEX)
        return;
    const cJSON *a = c->accessor_at[accessor];
    mark_view(c, index_member(a, "bufferView", c->view_count), marked);
    const cJSON *sparse = cJSON_GetObjectItemCaseSensitive(a, "sparse");
    if (!cJSON_IsObject(sparse))
        return;
    mark_view(c, index_member(cJSON_GetObjectItemCaseSensitive(sparse, "indices"), "bufferView", c->view_count),
              marked);
    mark_view(c, index_member(cJSON_GetObjectItemCaseSensitive(sparse, "values"), "bufferView", c->view_count),
              marked);
}

static void mark_mesh(gltf_ctx *c, uint32_t mesh, uint8_t *marked)
{
    const cJSON *prims = cJSON_GetObjectItemCaseSensitive(c->mesh_at[mesh], "primitives");
    for (const cJSON *prim = cJSON_IsArray(prims) ? prims->child : NULL; prim; prim = prim->next) {
        mark_accessor(c, index_member(prim, "indices", c->accessor_count), marked);
        const cJSON *attributes = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
        for (const cJSON *a = cJSON_IsObject(attributes) ? attributes->child : NULL; a; a = a->next)
            if (a->string)
                mark_accessor(c, index_member(attributes, a->string, c->accessor_count), marked);
    }
}

gdr_status gltf_load_mesh_buffers(gltf_ctx *c)
{
    uint8_t *meshes = calloc(c->mesh_count + 1, 1), *buffers = calloc(c->buffer_count + 1, 1);
    gdr_status status = meshes && buffers ? GDR_OK : gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
    for (uint32_t n = 0; n < c->node_count && status == GDR_OK; n++) {
        uint32_t mesh = index_member(c->node_at[n], "mesh", c->mesh_count);
        if (mesh != GDR_NO_INDEX && !meshes[mesh]) {
            meshes[mesh] = 1;
            mark_mesh(c, mesh, buffers);
        }
    }
    for (uint32_t b = 0; b < c->buffer_count && status == GDR_OK; b++) {
        const uint8_t *data;
        size_t size;
        if (buffers[b])
            status = gltf_buffer_get(c, b, "buffers", &data, &size);
    }
    free(meshes);
    free(buffers);
    return status;
}
