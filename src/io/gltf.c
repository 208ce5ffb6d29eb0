/* glTF 2.0 / GLB import: JSON (cJSON) -> flat scene. Buffers, views and accessors are in
 * gltf_buffers.c; this file walks the document: extensions, materials, textures, meshes, the
 * node tree and cameras. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/gltf_internal.h"

/* Extensions whose presence in extensionsRequired we can honour. */
static const char *const supported_required[] = {
    "KHR_mesh_quantization", "EXT_meshopt_compression", "EXT_mesh_gpu_instancing",
    "KHR_materials_emissive_strength", /* only changes emission, which gdr does not draw */
};

enum { GLB_MAGIC = 0x46546C67u, GLB_JSON = 0x4E4F534Au, GLB_BIN = 0x004E4942u };

static uint32_t read_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Splits a GLB container into its JSON text and binary chunk. */
static gdr_status parse_glb(gltf_ctx *c, const uint8_t *data, size_t size, const char **json, size_t *json_size)
{
    if (size < 20)
        return gltf_fail(c, GDR_ERROR_PARSE, "GLB: %zu bytes is shorter than the 20-byte header", size);
    uint32_t version = read_u32(data + 4), length = read_u32(data + 8);
    if (version != 2)
        return gltf_fail(c, GDR_ERROR_UNSUPPORTED, "GLB: container version %u (only 2 is supported)", version);
    if (length > size)
        return gltf_fail(c, GDR_ERROR_PARSE, "GLB: header length %u exceeds the file size %zu", length, size);
    size_t offset = 12;
    int chunk = 0;
    while (offset + 8 <= length) {
        uint32_t chunk_length = read_u32(data + offset), type = read_u32(data + offset + 4);
        offset += 8;
        if (chunk_length > length - offset)
            return gltf_fail(c, GDR_ERROR_PARSE, "GLB: chunk %d length %u exceeds the file", chunk, chunk_length);
        if (chunk == 0) {
            if (type != GLB_JSON)
                return gltf_fail(c, GDR_ERROR_PARSE, "GLB: the first chunk is not JSON (type 0x%08x)", type);
            *json = (const char *)data + offset;
            *json_size = chunk_length;
        } else if (chunk == 1 && type == GLB_BIN) {
            c->glb_bin = data + offset;
            c->glb_bin_size = chunk_length;
        }
        offset += chunk_length;
        offset = (offset + 3) & ~(size_t)3;
        chunk++;
    }
    if (chunk == 0)
        return gltf_fail(c, GDR_ERROR_PARSE, "GLB: no JSON chunk");
    return GDR_OK;
}

/* Schema rules that hold everywhere outside "extras": "extensions" is an object of objects,
 * "name" is a string. */
static gdr_status check_extension_objects(gltf_ctx *c, const cJSON *node, char *place, size_t length,
                                          size_t capacity)
{
    if (!cJSON_IsObject(node) && !cJSON_IsArray(node))
        return GDR_OK;
    int index = 0;
    for (const cJSON *child = node->child; child; child = child->next, index++) {
        size_t added;
        if (cJSON_IsArray(node))
            added = (size_t)snprintf(place + length, capacity - length, "[%d]", index);
        else if (child->string && strcmp(child->string, "extras") == 0)
            continue;
        else
            added = (size_t)snprintf(place + length, capacity - length, "%s%s", length ? "." : "",
                                     child->string ? child->string : "");
        size_t next = length + added < capacity ? length + added : capacity - 1;
        if (!cJSON_IsArray(node) && child->string && strcmp(child->string, "name") == 0 && !cJSON_IsString(child))
            return gltf_fail(c, GDR_ERROR_PARSE, "%s: expected a string", place);
        if (!cJSON_IsArray(node) && child->string && strcmp(child->string, "extensions") == 0) {
            if (!cJSON_IsObject(child))
                return gltf_fail(c, GDR_ERROR_PARSE, "%s: expected an object", place);
            for (const cJSON *ext = child->child; ext; ext = ext->next)
                if (!cJSON_IsObject(ext))
                    return gltf_fail(c, GDR_ERROR_PARSE, "%s.%s: expected an object", place,
                                     ext->string ? ext->string : "");
        }
        gdr_status status = check_extension_objects(c, child, place, next, capacity);
        if (status != GDR_OK)
            return status;
        place[length] = 0;
    }
    return GDR_OK;
}

/* Top-level arrays: present ones must be arrays of objects. Their elements are indexed once into
 * *items (cJSON_GetArrayItem walks the list: a lookup per reference would be quadratic). */
static gdr_status get_top_array(gltf_ctx *c, const char *key, cJSON **out, uint32_t *count, const cJSON ***items)
{
    const cJSON *array = NULL;
    gdr_status status = gltf_get_array(c, c->root, key, "", &array, count);
    if (status != GDR_OK)
        return status;
    *items = malloc(sizeof(const cJSON *) * ((size_t)*count + 1));
    if (!*items)
        return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", key);
    uint32_t i = 0;
    for (const cJSON *e = array ? array->child : NULL; e && i < *count; e = e->next, i++) {
        if (!cJSON_IsObject(e))
            return gltf_fail(c, GDR_ERROR_PARSE, "%s[%u]: expected an object", key, i);
        (*items)[i] = e;
    }
    *out = (cJSON *)array;
    return GDR_OK;
}

static gdr_status check_asset_and_extensions(gltf_ctx *c)
{
    const cJSON *asset = NULL;
    const char *version = NULL;
    gdr_status status = gltf_get_object(c, c->root, "asset", "(root)", 1, &asset);
    if (status == GDR_OK)
        status = gltf_get_string(c, asset, "version", "asset", &version);
    if (status != GDR_OK)
        return status;
    if (!version)
        return gltf_fail(c, GDR_ERROR_PARSE, "asset.version: required but missing");
    if (version[0] != '2' || version[1] != '.')
        return gltf_fail(c, GDR_ERROR_UNSUPPORTED, "asset.version: '%.16s' (only glTF 2.x is supported)", version);

    const cJSON *required = NULL, *used = NULL;
    uint32_t n_required, n_used;
    status = gltf_get_array(c, c->root, "extensionsRequired", "", &required, &n_required);
    if (status == GDR_OK)
        status = gltf_get_array(c, c->root, "extensionsUsed", "", &used, &n_used);
    if (status != GDR_OK)
        return status;
    uint32_t i = 0;
    for (const cJSON *e = required ? required->child : NULL; e; e = e->next, i++) {
        if (!cJSON_IsString(e))
            return gltf_fail(c, GDR_ERROR_PARSE, "extensionsRequired[%u]: expected a string", i);
        int ok = 0;
        for (size_t k = 0; k < sizeof supported_required / sizeof supported_required[0]; k++)
            ok |= strcmp(e->valuestring, supported_required[k]) == 0;
        if (!ok)
            return gltf_fail(c, GDR_ERROR_UNSUPPORTED, "extensionsRequired: %.64s is not supported", e->valuestring);
    }
    char list[1024] = "";
    size_t length = 0;
    i = 0;
    for (const cJSON *e = used ? used->child : NULL; e; e = e->next, i++) {
        if (!cJSON_IsString(e))
            return gltf_fail(c, GDR_ERROR_PARSE, "extensionsUsed[%u]: expected a string", i);
        int added = snprintf(list + length, sizeof list - length, "%s%s", length ? "," : "", e->valuestring);
        if (added < 0 || (size_t)added >= sizeof list - length)
            break;
        length += (size_t)added;
    }
    return gdr_scene_set_extensions(c->scene, length ? list : NULL, c->err);
}

/* --- materials and textures ------------------------------------------------------------------ */

/* "images[3] (textures/wood.png)", "images[3] 'albedo' (bufferView 5)": the index, the image's
 * name if it has one, and where its bytes are: its file (a URI), a data: URI or its buffer view;
 * characters that are not printable ASCII become '?'. */
static void image_place(uint32_t image, const char *uri, const char *name, uint32_t view, char *out, size_t size)
{
    char what[80], named[80] = "";
    if (uri && strncmp(uri, "data:", 5) == 0)
        snprintf(what, sizeof what, "a data: URI");
    else if (uri)
        snprintf(what, sizeof what, "%.*s%s", 64, uri, strlen(uri) > 64 ? "..." : "");
    else if (view != GDR_NO_INDEX)
        snprintf(what, sizeof what, "bufferView %u", view);
    else
        snprintf(what, sizeof what, "no data");
    if (name)
        snprintf(named, sizeof named, " '%.*s%s'", 48, name, strlen(name) > 48 ? "..." : "");
    for (char *p = what; *p; p++)
        if ((unsigned char)*p < 32 || (unsigned char)*p > 126)
            *p = '?';
    for (char *p = named; *p; p++)
        if ((unsigned char)*p < 32 || (unsigned char)*p > 126)
            *p = '?';
    snprintf(out, size, "images[%u]%s (%s)", image, named, what);
}

/* Decodes an image within the import's budgets: its pixels, and as decoded bytes its mip chain
 * (kept by the scene) plus, for the time of the decoding, the RGBA8 copy and the decoder's own
 * memory (gdr_io_image_info.work_bytes), given back once decoding is over (a failed image's chain
 * stays counted, as its pixels do). A budget overrun is returned in c->err (*refused); any other
 * failure in *image_err (the texture is left out). */
static gdr_status decode_image(gltf_ctx *c, const uint8_t *bytes, size_t size, const char *place, uint8_t **rgba,
                               gdr_io_image_info *info, uint64_t *transient, bool *refused, gdr_error *image_err)
{
    char label[GDR_ERROR_MESSAGE_MAX];
    snprintf(label, sizeof label, "%s: %s", c->name, place);
    *transient = 0;
    *refused = false;
    gdr_status status = gdr_io_image_probe(bytes, size, label, info, image_err);
    if (status != GDR_OK)
        return status;
    uint64_t pixels = (uint64_t)info->width * info->height;
    uint64_t kept = gdr_texture_level_offset(info->width, info->height,
                                             gdr_texture_level_count(info->width, info->height));
    if (gdr_io_budget_take(&c->budget, GDR_BUDGET_TEXTURE_PIXELS, pixels, c->name, place, c->err) != GDR_OK ||
        gdr_io_budget_take(&c->budget, GDR_BUDGET_DECODED_BYTES, kept + pixels * 4 + info->work_bytes, c->name,
                           place, c->err) != GDR_OK) {
        *refused = true; /* over a budget: refused, not left out, so that the user learns why */
        return c->err->status;
    }
    *transient = pixels * 4 + info->work_bytes;
    return gdr_io_image_decode(bytes, size, label, info, rgba, image_err);
}

static gdr_status load_image(gltf_ctx *c, uint32_t image, int srgb, uint32_t *out)
{
    *out = GDR_NO_INDEX;
    uint32_t *slot = &c->image_texture[2 * image + (srgb ? 1 : 0)];
    if (*slot == GLTF_IMAGE_FAILED)
        return GDR_OK;
    if (*slot != GDR_NO_INDEX) {
        *out = *slot;
        return GDR_OK;
    }
    char here[32], described[192]; /* "images[3]"; "images[3] 'albedo' (textures/wood.png)" */
    snprintf(here, sizeof here, "images[%u]", image);
    const cJSON *json = c->image_at[image];
    const char *uri = NULL, *name = NULL;
    uint32_t view_index = GDR_NO_INDEX;
    gdr_status status = gltf_get_string(c, json, "uri", here, &uri);
    if (status == GDR_OK)
        status = gltf_get_string(c, json, "name", here, &name);
    if (status == GDR_OK)
        status = gltf_get_uint(c, json, "bufferView", here, 0, UINT32_MAX - 1, &view_index);
    if (status != GDR_OK)
        return status;
    image_place(image, uri, name, view_index, described, sizeof described);
    uint8_t *owned = NULL;
    const uint8_t *bytes = NULL;
    size_t size = 0;
    gdr_error image_err = {0};
    gdr_error *saved = c->err;
    c->err = &image_err; /* image problems become warnings: the geometry is still worth drawing */
    if (uri) {
        status = gltf_load_uri(c, uri, here, &owned, &size);
        bytes = owned;
    } else if (view_index != GDR_NO_INDEX) {
        const gltf_view *view;
        status = gltf_view_get(c, view_index, here, &view);
        if (status == GDR_OK) {
            bytes = view->data;
            size = view->length;
        }
    } else {
        status = gltf_fail(c, GDR_ERROR_PARSE, "%s: neither uri nor bufferView", here);
    }
    c->err = saved;
    uint8_t *rgba = NULL;
    gdr_io_image_info info = {0};
    uint64_t transient = 0;
    bool refused = false;
    if (status == GDR_OK) {
        status = decode_image(c, bytes, size, described, &rgba, &info, &transient, &refused, &image_err);
        if (refused) {
            free(owned);
            return status;
        }
    }
    free(owned);
    if (status == GDR_OK) {
        char texture_name[GDR_NAME_MAX];
        snprintf(texture_name, sizeof texture_name, "%s",
                 name ? name : uri && strncmp(uri, "data:", 5) ? uri : here);
        status = gdr_scene_add_texture(c->scene, texture_name, info.width, info.height, rgba, (uint32_t)srgb, out,
                                       c->err);
        free(rgba);
        gdr_io_budget_give(&c->budget, GDR_BUDGET_DECODED_BYTES, transient);
        if (status != GDR_OK)
            return status;
        *slot = *out;
        return GDR_OK;
    }
    gdr_io_budget_give(&c->budget, GDR_BUDGET_DECODED_BYTES, transient);
    if (status == GDR_ERROR_OUT_OF_MEMORY)
        return gdr_error_set(c->err, status, "%s", image_err.message);
    gdr_io_warn(&c->warnings, "%s (texture left out)", image_err.message);
    *slot = GLTF_IMAGE_FAILED;
    return GDR_OK;
}

/* One of glTF's wrap modes (key of samplers[index]) as a GDR_SAMPLER_WRAP_*; a value glTF does not
 * define is repeat (glTF's default), with a warning. */
static gdr_status sampler_wrap(gltf_ctx *c, const cJSON *json, const char *key, const char *place, uint32_t *out)
{
    uint32_t mode = 10497;
    gdr_status status = gltf_get_uint(c, json, key, place, 0, UINT32_MAX, &mode);
    if (status != GDR_OK)
        return status;
    *out = mode == 33071 ? GDR_SAMPLER_WRAP_CLAMP : mode == 33648 ? GDR_SAMPLER_WRAP_MIRROR : GDR_SAMPLER_WRAP_REPEAT;
    if (mode != 10497 && mode != 33071 && mode != 33648)
        gdr_io_warn(&c->warnings, "%s: %s.%s: %u is not a wrap mode (10497, 33071 or 33648); repeat is used", c->name,
                    place, key, mode);
    return GDR_OK;
}

/* samplers[index] as GDR_SAMPLER_* bits; filters left out are linear (glTF leaves them to the
 * implementation), and so are values glTF does not define (with a warning). */
static gdr_status load_sampler(gltf_ctx *c, uint32_t index, uint32_t *out)
{
    *out = 0;
    if (index >= c->sampler_count)
        return gltf_fail(c, GDR_ERROR_PARSE, "samplers[%u] does not exist (%u samplers)", index, c->sampler_count);
    char place[32];
    snprintf(place, sizeof place, "samplers[%u]", index);
    const cJSON *json = c->sampler_at[index];
    uint32_t mag = 9729, min = 9987, wrap_s = 0, wrap_t = 0;
    gdr_status status = gltf_get_uint(c, json, "magFilter", place, 0, UINT32_MAX, &mag);
    if (status == GDR_OK)
        status = gltf_get_uint(c, json, "minFilter", place, 0, UINT32_MAX, &min);
    if (status == GDR_OK)
        status = sampler_wrap(c, json, "wrapS", place, &wrap_s);
    if (status == GDR_OK)
        status = sampler_wrap(c, json, "wrapT", place, &wrap_t);
    if (status != GDR_OK)
        return status;
    if (mag != 9728 && mag != 9729) {
        gdr_io_warn(&c->warnings, "%s: %s.magFilter: %u is not NEAREST (9728) or LINEAR (9729); linear is used",
                    c->name, place, mag);
        mag = 9729;
    }
    if (min != 9728 && min != 9729 && (min < 9984 || min > 9987)) {
        gdr_io_warn(&c->warnings, "%s: %s.minFilter: %u is not a glTF minification filter; trilinear is used", c->name,
                    place, min);
        min = 9987;
    }
    /* 9728/9729: no mips; 9984..9987: NEAREST_MIPMAP_NEAREST, LINEAR_MIPMAP_NEAREST,
     * NEAREST_MIPMAP_LINEAR, LINEAR_MIPMAP_LINEAR. */
    bool min_nearest = min == 9728 || min == 9984 || min == 9986;
    *out = wrap_s | wrap_t << 2 | (mag == 9728 ? GDR_SAMPLER_MAG_NEAREST : 0u) |
           (min_nearest ? GDR_SAMPLER_MIN_NEAREST : 0u) | (min < 9984 ? GDR_SAMPLER_MIP_NONE : 0u) |
           (min == 9984 || min == 9985 ? GDR_SAMPLER_MIP_NEAREST : 0u);
    return GDR_OK;
}

/* A textureInfo's KHR_texture_transform (offset, rotation, scale) into ref, and the texture
 * coordinate set it may name instead of the textureInfo's. */
static gdr_status texture_transform(gltf_ctx *c, const cJSON *info, const char *here, gdr_texture_ref *ref,
                                    uint32_t *texcoord)
{
    const cJSON *t = gltf_extension(info, "KHR_texture_transform");
    if (!t)
        return GDR_OK;
    char place[224];
    snprintf(place, sizeof place, "%s.extensions.KHR_texture_transform", here);
    gdr_status status = gltf_get_floats(c, t, "offset", place, 2, &ref->offset.x);
    if (status == GDR_OK)
        status = gltf_get_floats(c, t, "scale", place, 2, &ref->scale.x);
    if (status == GDR_OK)
        status = gltf_get_float(c, t, "rotation", place, &ref->rotation);
    if (status == GDR_OK)
        status = gltf_get_uint(c, t, "texCoord", place, 0, UINT32_MAX, texcoord);
    return status;
}

/* A textureInfo object ({"index": N, ...}) at place -> ref: the gdr texture (GDR_NO_INDEX when it
 * is absent, cannot be decoded or uses a texture coordinate set other than 0, the only one gdr
 * meshes carry: left out with a warning), its sampler's GDR_SAMPLER_* bits and its transform.
 * `factor_key` ("scale" of a normal texture, "strength" of an occlusion texture) goes to *factor. */
static gdr_status texture_ref(gltf_ctx *c, const cJSON *parent, const char *key, const char *place, int srgb,
                              const char *factor_key, float *factor, gdr_texture_ref *ref)
{
    uint32_t *out = &ref->texture, *out_sampler = &ref->sampler;
    *out = GDR_NO_INDEX;
    const cJSON *info = NULL;
    char here[160];
    snprintf(here, sizeof here, "%s.%s", place, key);
    uint32_t texture = 0, texcoord = 0;
    float value = factor ? *factor : 1.0f;
    gdr_status status = gltf_get_object(c, parent, key, place, 0, &info);
    if (status != GDR_OK || !info)
        return status;
    status = gltf_get_uint(c, info, "texCoord", here, 0, UINT32_MAX, &texcoord);
    if (status == GDR_OK && factor_key)
        status = gltf_get_float(c, info, factor_key, here, &value);
    if (status == GDR_OK)
        status = gltf_get_uint(c, info, "index", here, 1, UINT32_MAX, &texture);
    if (status == GDR_OK)
        status = texture_transform(c, info, here, ref, &texcoord);
    if (status != GDR_OK)
        return status;
    if (factor)
        *factor = value;
    if (texcoord != 0) {
        gdr_io_warn(&c->warnings, "%s: %s: texture coordinate set %u is not supported (meshes carry set 0); texture "
                    "left out", c->name, here, texcoord);
        return GDR_OK;
    }
    if (texture >= c->texture_count)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.index: texture %u does not exist (%u textures)", here, texture,
                         c->texture_count);
    char tplace[48];
    snprintf(tplace, sizeof tplace, "textures[%u]", texture);
    const cJSON *tjson = c->texture_at[texture];
    uint32_t source = GDR_NO_INDEX, sampler = GDR_NO_INDEX;
    status = gltf_get_uint(c, tjson, "source", tplace, 0, UINT32_MAX - 1, &source);
    if (status == GDR_OK)
        status = gltf_get_uint(c, tjson, "sampler", tplace, 0, UINT32_MAX - 1, &sampler);
    if (status == GDR_OK && sampler != GDR_NO_INDEX)
        status = load_sampler(c, sampler, out_sampler);
    if (status != GDR_OK)
        return status;
    if (source == GDR_NO_INDEX) {
        gdr_io_warn(&c->warnings, "%s: %s has no source image gdr can decode (texture left out)", c->name, tplace);
        return GDR_OK;
    }
    if (source >= c->image_count)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.source: image %u does not exist (%u images)", tplace, source,
                         c->image_count);
    return load_image(c, source, srgb, out);
}

/* KHR_materials_emissive_strength: the emissive factor times emissiveStrength (>= 0). */
static gdr_status emissive_strength(gltf_ctx *c, const cJSON *json, const char *here, gdr_vec3 *emissive)
{
    const cJSON *e = gltf_extension(json, "KHR_materials_emissive_strength");
    if (!e)
        return GDR_OK;
    char place[160];
    snprintf(place, sizeof place, "%s.extensions.KHR_materials_emissive_strength", here);
    double strength = 1.0;
    gdr_status status = gltf_get_number(c, e, "emissiveStrength", place, &strength);
    if (status != GDR_OK)
        return status;
    if (!(strength >= 0.0 && strength <= 1e6))
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.emissiveStrength: %g is not in [0, 1e6]", place, strength);
    *emissive = gdr_vec3_scale(*emissive, (float)strength);
    return GDR_OK;
}

static gdr_status load_material(gltf_ctx *c, uint32_t index)
{
    char here[48];
    snprintf(here, sizeof here, "materials[%u]", index);
    const cJSON *json = c->material_at[index];
    gdr_material m = gdr_material_default();
    const char *name = NULL, *alpha_mode = NULL;
    const cJSON *pbr = NULL, *double_sided = cJSON_GetObjectItemCaseSensitive(json, "doubleSided");
    gdr_status status = gltf_get_string(c, json, "name", here, &name);
    if (status == GDR_OK)
        status = gltf_get_string(c, json, "alphaMode", here, &alpha_mode);
    if (status == GDR_OK)
        status = gltf_get_float(c, json, "alphaCutoff", here, &m.alpha_cutoff);
    if (status == GDR_OK)
        status = gltf_get_object(c, json, "pbrMetallicRoughness", here, 0, &pbr);
    if (status == GDR_OK)
        status = gltf_get_floats(c, json, "emissiveFactor", here, 3, &m.emissive.x);
    if (status != GDR_OK)
        return status;
    if (double_sided && !cJSON_IsBool(double_sided))
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.doubleSided: expected a boolean", here);
    m.double_sided = cJSON_IsTrue(double_sided) ? 1u : 0u;
    if (alpha_mode) {
        if (strcmp(alpha_mode, "MASK") == 0)
            m.alpha_mode = GDR_ALPHA_MASK;
        else if (strcmp(alpha_mode, "BLEND") == 0)
            m.alpha_mode = GDR_ALPHA_BLEND;
        else if (strcmp(alpha_mode, "OPAQUE") != 0)
            return gltf_fail(c, GDR_ERROR_PARSE, "%s.alphaMode: '%.16s' is not OPAQUE, MASK or BLEND", here,
                             alpha_mode);
    }
    snprintf(m.name, sizeof m.name, "%s", name ? name : here);
    if (pbr) {
        char pplace[80];
        snprintf(pplace, sizeof pplace, "%s.pbrMetallicRoughness", here);
        status = gltf_get_floats(c, pbr, "baseColorFactor", pplace, 4, &m.base_color.x);
        if (status == GDR_OK)
            status = gltf_get_float(c, pbr, "metallicFactor", pplace, &m.metallic_factor);
        if (status == GDR_OK)
            status = gltf_get_float(c, pbr, "roughnessFactor", pplace, &m.roughness_factor);
        if (status == GDR_OK)
            status = texture_ref(c, pbr, "baseColorTexture", pplace, 1, NULL, NULL, &m.base_color_texture);
        if (status == GDR_OK)
            status = texture_ref(c, pbr, "metallicRoughnessTexture", pplace, 0, NULL, NULL, &m.metallic_roughness_texture);
        if (status != GDR_OK)
            return status;
    }
    status = texture_ref(c, json, "normalTexture", here, 0, "scale", &m.normal_scale, &m.normal_texture);
    if (status == GDR_OK)
        status = texture_ref(c, json, "occlusionTexture", here, 0, "strength", &m.occlusion_strength,
                             &m.occlusion_texture);
    if (status == GDR_OK)
        status = texture_ref(c, json, "emissiveTexture", here, 1, NULL, NULL, &m.emissive_texture);
    if (status == GDR_OK)
        status = emissive_strength(c, json, here, &m.emissive);
    if (status != GDR_OK)
        return status;
    /* The rule the cache reader applies (an emissive factor times its strength may overflow). */
    const char *problem = gdr_material_problem(&m);
    if (problem)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: %s", here, problem);
    return gdr_scene_add_material(c->scene, &m, NULL, c->err);
}

/* glTF's default material, for primitives without one: added to the scene the first time. */
static gdr_status default_material(gltf_ctx *c, uint32_t *out)
{
    if (!c->default_material_plus_one) {
        gdr_material m = gdr_material_default();
        snprintf(m.name, sizeof m.name, "default");
        uint32_t index = 0;
        gdr_status status = gdr_scene_add_material(c->scene, &m, &index, c->err);
        if (status != GDR_OK)
            return status;
        c->default_material_plus_one = index + 1;
    }
    *out = c->default_material_plus_one - 1;
    return GDR_OK;
}

/* --- meshes ---------------------------------------------------------------------------------- */

static gdr_status grow_prims(gltf_ctx *c, uint32_t extra)
{
    if ((uint64_t)c->prim_count + extra <= c->prim_capacity)
        return GDR_OK;
    uint64_t capacity = c->prim_capacity ? c->prim_capacity : 64;
    while (capacity < (uint64_t)c->prim_count + extra)
        capacity *= 2;
    if (capacity > UINT32_MAX)
        return gltf_fail(c, GDR_ERROR_CAPACITY, "too many primitives");
    uint32_t *a = realloc(c->prim_mesh, sizeof(uint32_t) * capacity);
    if (a)
        c->prim_mesh = a;
    uint32_t *b = a ? realloc(c->prim_material, sizeof(uint32_t) * capacity) : NULL;
    if (b)
        c->prim_material = b;
    if (!a || !b)
        return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
    c->prim_capacity = (uint32_t)capacity;
    return GDR_OK;
}

/* Topology -> triangle list. Returns the triangle index count written to out (sized 3 * n). */
static uint32_t triangulate(uint32_t mode, const uint32_t *in, uint32_t n, uint32_t *out)
{
    uint32_t written = 0;
    if (mode == 4) {
        memcpy(out, in, sizeof(uint32_t) * (n - n % 3));
        return n - n % 3;
    }
    for (uint32_t i = 0; i + 2 < n; i++) {
        uint32_t a, b, c;
        if (mode == 5) { /* strip: every other triangle flips to keep the winding */
            a = in[i];
            b = in[i + 1 + i % 2];
            c = in[i + 2 - i % 2];
        } else { /* fan */
            a = in[i + 1];
            b = in[i + 2];
            c = in[0];
        }
        if (a == b || b == c || a == c)
            continue;
        out[written++] = a;
        out[written++] = b;
        out[written++] = c;
    }
    return written;
}

typedef struct prim_arrays {
    gdr_vec3 *positions, *normals;
    gdr_vec2 *uvs;
    gdr_vec4 *colors;
    uint32_t *indices, *triangles;
} prim_arrays;

static void prim_arrays_free(prim_arrays *a)
{
    free(a->positions);
    free(a->normals);
    free(a->uvs);
    free(a->colors);
    free(a->indices);
    free(a->triangles);
}

/* Reads an attribute accessor that must have `count` elements of `components` components. */
static gdr_status read_attribute(gltf_ctx *c, const cJSON *attributes, const char *semantic, const char *place,
                                 uint32_t components, uint32_t *count, float **out)
{
    uint32_t accessor = GDR_NO_INDEX;
    char use[160];
    snprintf(use, sizeof use, "%s.attributes", place);
    gdr_status status = gltf_get_uint(c, attributes, semantic, use, 0, UINT32_MAX - 1, &accessor);
    if (status != GDR_OK || accessor == GDR_NO_INDEX)
        return status;
    snprintf(use, sizeof use, "%s.attributes.%s", place, semantic);
    gltf_accessor_info info;
    status = gltf_accessor_info_get(c, accessor, use, &info);
    if (status != GDR_OK)
        return status;
    if (info.components != components)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: accessor %u has %u components, expected %u", use, accessor,
                         info.components, components);
    if (*count != 0 && info.count != *count)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: accessor %u count %u differs from POSITION count %u", use,
                         accessor, info.count, *count);
    *out = malloc(sizeof(float) * components * (size_t)info.count);
    if (!*out)
        return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", use);
    *count = info.count;
    return gltf_accessor_read_floats(c, accessor, use, components, *out);
}

/* COLOR_0 (VEC3 or VEC4; float, or unsigned byte or short normalized) as RGBA, alpha 1 for VEC3;
 * values outside [0, 1] or not finite drop the colours with a warning. */
static gdr_status read_colors(gltf_ctx *c, const cJSON *attributes, const char *place, uint32_t vertex_count,
                              gdr_vec4 **out)
{
    uint32_t accessor = GDR_NO_INDEX;
    char use[160];
    snprintf(use, sizeof use, "%s.attributes", place);
    gdr_status status = gltf_get_uint(c, attributes, "COLOR_0", use, 0, UINT32_MAX - 1, &accessor);
    if (status != GDR_OK || accessor == GDR_NO_INDEX)
        return status;
    snprintf(use, sizeof use, "%s.attributes.COLOR_0", place);
    gltf_accessor_info info;
    status = gltf_accessor_info_get(c, accessor, use, &info);
    if (status != GDR_OK)
        return status;
    if (info.components != 3 && info.components != 4)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: accessor %u has %u components, expected 3 or 4", use, accessor,
                         info.components);
    if (info.count != vertex_count)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: accessor %u count %u differs from POSITION count %u", use, accessor,
                         info.count, vertex_count);
    float *values = malloc(sizeof(float) * info.components * (size_t)(vertex_count ? vertex_count : 1));
    *out = malloc(sizeof(gdr_vec4) * (vertex_count ? vertex_count : 1));
    if (!values || !*out) {
        free(values);
        return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", use);
    }
    status = gltf_accessor_read_floats(c, accessor, use, info.components, values);
    bool in_range = true;
    for (uint32_t v = 0; status == GDR_OK && v < vertex_count; v++) {
        float rgba[4] = {0, 0, 0, 1};
        for (uint32_t k = 0; k < info.components; k++) {
            rgba[k] = values[(size_t)v * info.components + k];
            in_range = in_range && rgba[k] >= 0.0f && rgba[k] <= 1.0f;
        }
        (*out)[v] = (gdr_vec4){rgba[0], rgba[1], rgba[2], rgba[3]};
    }
    free(values);
    if (status == GDR_OK && !in_range) {
        gdr_io_warn(&c->warnings, "%s: %s: values outside [0, 1] or not finite; vertex colours dropped", c->name, use);
        free(*out);
        *out = NULL;
    }
    return status;
}

/* The triangles `n` indices of topology `mode` make, from the budget, before anything is allocated
 * for them. */
static gdr_status take_triangles(gltf_ctx *c, uint32_t mode, uint32_t n, const char *place)
{
    uint64_t triangles = mode == 4 ? n / 3 : n > 2 ? n - 2 : 0;
    return gdr_io_budget_take(&c->budget, GDR_BUDGET_TRIANGLES, triangles, c->name, place, c->err);
}

/* Degenerate and duplicate triangles dropped, vertices shared by too many triangles split: what
 * meshlet building needs to stay linear (mesh_clean.c). */
static gdr_status clean_triangles(gltf_ctx *c, const char *place, prim_arrays *a, uint32_t *vertex_count,
                                  uint32_t *index_count)
{
    uint32_t before = *index_count / 3, degenerate, duplicate, added;
    gdr_status status = gdr_io_drop_bad_triangles(a->positions, *vertex_count, a->triangles, index_count,
                                                  &degenerate, &duplicate);
    if (status == GDR_OK)
        status = gdr_io_split_shared_vertices(&a->positions, &a->normals, &a->uvs, &a->colors, vertex_count, a->triangles,
                                              *index_count, &added);
    if (status != GDR_OK)
        return gltf_fail(c, status, "%s: out of memory", place);
    /* Zero-area triangles draw nothing and are common in real files: dropped silently. */
    if (duplicate || (degenerate && *index_count == 0))
        gdr_io_warn(&c->warnings, "%s: %s: %u of %u triangles dropped (%u degenerate, %u duplicate)%s", c->name,
                    place, degenerate + duplicate, before, degenerate, duplicate,
                    *index_count ? "" : "; no triangles left, skipped");
    return GDR_OK;
}

/* Normals unit length (any zero or non-finite one: all generated from the faces instead) and
 * finite texture coordinates (else dropped), with a warning each. */
static void check_normals_and_uvs(gltf_ctx *c, const char *place, prim_arrays *a, uint32_t vertex_count)
{
    if (a->normals) {
        uint32_t bad = 0;
        for (uint32_t v = 0; v < vertex_count; v++) {
            float length = gdr_vec3_length(a->normals[v]);
            if (!isfinite(length) || length < 1e-6f)
                bad++;
            else
                a->normals[v] = gdr_vec3_scale(a->normals[v], 1.0f / length);
        }
        if (bad) {
            gdr_io_warn(&c->warnings, "%s: %s.attributes.NORMAL: %u of %u normals are zero or not finite; "
                        "normals generated from the faces", c->name, place, bad, vertex_count);
            free(a->normals);
            a->normals = NULL;
        }
    }
    if (a->uvs) {
        for (uint32_t v = 0; v < vertex_count; v++)
            if (!isfinite(a->uvs[v].x) || !isfinite(a->uvs[v].y)) {
                gdr_io_warn(&c->warnings, "%s: %s.attributes.TEXCOORD_0: not finite; texture coordinates dropped",
                            c->name, place);
                free(a->uvs);
                a->uvs = NULL;
                break;
            }
    }
}

/* The primitive's indices (its accessor, or 0 .. vertex_count - 1 without one), each checked
 * against vertex_count; their triangles are taken from the budget before anything is allocated. */
static gdr_status read_indices(gltf_ctx *c, uint32_t accessor, uint32_t mode, uint32_t vertex_count,
                               const char *place, uint32_t **out, uint32_t *count)
{
    char use[160];
    snprintf(use, sizeof use, "%s.indices", place);
    uint32_t n = vertex_count;
    gltf_accessor_info info;
    gdr_status status = accessor == GDR_NO_INDEX ? GDR_OK : gltf_accessor_info_get(c, accessor, use, &info);
    if (status == GDR_OK && accessor != GDR_NO_INDEX)
        n = info.count;
    if (status == GDR_OK)
        status = take_triangles(c, mode, n, accessor == GDR_NO_INDEX ? place : use);
    if (status != GDR_OK)
        return status;
    uint32_t *indices = malloc(sizeof(uint32_t) * ((size_t)n ? n : 1));
    if (!indices)
        return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", use);
    *out = indices;
    *count = n;
    if (accessor == GDR_NO_INDEX) {
        for (uint32_t i = 0; i < n; i++)
            indices[i] = i;
        return GDR_OK;
    }
    status = gltf_accessor_read_uints(c, accessor, use, indices);
    for (uint32_t i = 0; i < n && status == GDR_OK; i++)
        if (indices[i] >= vertex_count)
            status = gltf_fail(c, GDR_ERROR_PARSE, "%s: index %u (at %u) is out of range (%u vertices)", use,
                               indices[i], i, vertex_count);
    return status;
}

/* The accessors a primitive's geometry is read from (gltf_geometry_key), each a checked index. */
static gdr_status geometry_key(gltf_ctx *c, const cJSON *attributes, const char *place, uint32_t mode,
                               uint32_t indices, gltf_geometry_key *key)
{
    static const char *const semantics[4] = {"POSITION", "NORMAL", "TEXCOORD_0", "COLOR_0"};
    char use[160];
    snprintf(use, sizeof use, "%s.attributes", place);
    key->values[0] = mode;
    key->values[1] = indices;
    gdr_status status = GDR_OK;
    for (int k = 0; k < 4 && status == GDR_OK; k++) {
        key->values[2 + k] = GDR_NO_INDEX;
        status = gltf_get_uint(c, attributes, semantics[k], use, 0, UINT32_MAX - 1, &key->values[2 + k]);
    }
    return status;
}

static gdr_status convert_geometry(gltf_ctx *c, const cJSON *attributes, const char *place, const char *mesh_name,
                                   uint32_t mode, uint32_t indices_accessor, uint32_t *out_mesh);

/* One primitive -> a gdr mesh (or GDR_NO_INDEX when it has no triangles): the mesh of an earlier
 * primitive that read the same accessors, else a new one. */
static gdr_status convert_primitive(gltf_ctx *c, const cJSON *prim, const char *place, const char *mesh_name,
                                    uint32_t *out_mesh, uint32_t *out_material)
{
    *out_mesh = *out_material = GDR_NO_INDEX;
    const cJSON *attributes = NULL;
    uint32_t mode = 4, indices_accessor = GDR_NO_INDEX, material = GDR_NO_INDEX;
    gdr_status status = gltf_get_object(c, prim, "attributes", place, 1, &attributes);
    if (status == GDR_OK)
        status = gltf_get_uint(c, prim, "mode", place, 0, 6, &mode);
    if (status == GDR_OK)
        status = gltf_get_uint(c, prim, "indices", place, 0, UINT32_MAX - 1, &indices_accessor);
    if (status == GDR_OK)
        status = gltf_get_uint(c, prim, "material", place, 0, UINT32_MAX - 1, &material);
    if (status != GDR_OK)
        return status;
    if (material != GDR_NO_INDEX && material >= c->material_count)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.material: material %u does not exist (%u materials)", place,
                         material, c->material_count);
    *out_material = material;
    static const char *const mode_names[] = {"points", "lines", "line loop", "line strip"};
    if (mode < 4) {
        gdr_io_warn(&c->warnings, "%s: %s: mode %u (%s) skipped: only triangles are drawn", c->name, place, mode,
                    mode_names[mode]);
        return GDR_OK;
    }
    if (!cJSON_GetObjectItemCaseSensitive(attributes, "POSITION")) {
        gdr_io_warn(&c->warnings, "%s: %s: no POSITION attribute; skipped", c->name, place);
        return GDR_OK;
    }
    if (gltf_extension(prim, "KHR_draco_mesh_compression"))
        return gltf_fail(c, GDR_ERROR_UNSUPPORTED, "%s: KHR_draco_mesh_compression is not supported", place);
    gltf_geometry_key key;
    status = geometry_key(c, attributes, place, mode, indices_accessor, &key);
    if (status != GDR_OK || gltf_shared_mesh_find(&c->shared, &key, out_mesh))
        return status;
    status = convert_geometry(c, attributes, place, mesh_name, mode, indices_accessor, out_mesh);
    if (status == GDR_OK && !gltf_shared_mesh_add(&c->shared, &key, *out_mesh))
        status = gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", place);
    return status;
}

/* The primitive's geometry, read, checked and cleaned, as a new gdr mesh (GDR_NO_INDEX when no
 * triangle is left). */
static gdr_status convert_geometry(gltf_ctx *c, const cJSON *attributes, const char *place, const char *mesh_name,
                                   uint32_t mode, uint32_t indices_accessor, uint32_t *out_mesh)
{
    gdr_status status;
    prim_arrays a = {0};
    uint32_t vertex_count = 0, n = 0, normal_count, uv_count;
    float *positions = NULL, *normals = NULL, *uvs = NULL;
    status = read_attribute(c, attributes, "POSITION", place, 3, &vertex_count, &positions);
    normal_count = uv_count = vertex_count;
    if (status == GDR_OK)
        status = read_attribute(c, attributes, "NORMAL", place, 3, &normal_count, &normals);
    if (status == GDR_OK)
        status = read_attribute(c, attributes, "TEXCOORD_0", place, 2, &uv_count, &uvs);
    if (status == GDR_OK)
        status = read_colors(c, attributes, place, vertex_count, &a.colors);
    a.positions = (gdr_vec3 *)positions;
    a.normals = (gdr_vec3 *)normals;
    a.uvs = (gdr_vec2 *)uvs;
    if (status != GDR_OK)
        goto done;
    char positions_place[120];
    snprintf(positions_place, sizeof positions_place, "%s.attributes.POSITION", place);
    status = gdr_io_check_positions(a.positions, vertex_count, c->name, positions_place, c->err);
    if (status != GDR_OK)
        goto done;
    check_normals_and_uvs(c, place, &a, vertex_count);
    status = read_indices(c, indices_accessor, mode, vertex_count, place, &a.indices, &n);
    if (status != GDR_OK)
        goto done;
    if (mode == 4 && n % 3 != 0)
        gdr_io_warn(&c->warnings, "%s: %s: %u indices is not a multiple of 3; the last %u ignored", c->name, place,
                    n, n % 3);
    a.triangles = malloc(sizeof(uint32_t) * 3 * (size_t)(n ? n : 1));
    if (!a.triangles) {
        status = gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", place);
        goto done;
    }
    uint32_t triangle_indices = triangulate(mode, a.indices, n, a.triangles);
    if (triangle_indices == 0) {
        gdr_io_warn(&c->warnings, "%s: %s: no triangles; skipped", c->name, place);
        goto done;
    }
    status = clean_triangles(c, place, &a, &vertex_count, &triangle_indices);
    if (status != GDR_OK || triangle_indices == 0)
        goto done;
    status = gdr_scene_add_mesh(c->scene, mesh_name, a.positions, a.normals, a.uvs, vertex_count, a.triangles,
                                triangle_indices, out_mesh, c->err);
    if (status == GDR_OK && a.colors)
        status = gdr_scene_set_mesh_colors(c->scene, *out_mesh, a.colors, c->err);
done:
    prim_arrays_free(&a);
    return status;
}

static gdr_status convert_mesh(gltf_ctx *c, uint32_t index, gdr_progress *progress, uint32_t *converted)
{
    if (c->mesh_first[index] != GDR_NO_INDEX)
        return GDR_OK;
    char here[48];
    snprintf(here, sizeof here, "meshes[%u]", index);
    const cJSON *json = c->mesh_at[index];
    const cJSON *prims = NULL;
    const char *name = NULL;
    uint32_t count = 0;
    gdr_status status = gltf_get_string(c, json, "name", here, &name);
    if (status == GDR_OK)
        status = gltf_get_array(c, json, "primitives", here, &prims, &count);
    if (status == GDR_OK && !prims)
        status = gltf_fail(c, GDR_ERROR_PARSE, "%s.primitives: required but missing", here);
    if (status == GDR_OK)
        status = grow_prims(c, count);
    if (status != GDR_OK)
        return status;
    uint32_t first = c->prim_count;
    uint32_t p = 0;
    for (const cJSON *prim = prims->child; prim; prim = prim->next, p++) {
        char place[80], mesh_name[GDR_NAME_MAX];
        snprintf(place, sizeof place, "%s.primitives[%u]", here, p);
        if (!cJSON_IsObject(prim))
            return gltf_fail(c, GDR_ERROR_PARSE, "%s: expected an object", place);
        if (count > 1)
            snprintf(mesh_name, sizeof mesh_name, "%.40s.%u", name ? name : here, p);
        else
            snprintf(mesh_name, sizeof mesh_name, "%s", name ? name : here);
        status = convert_primitive(c, prim, place, mesh_name, &c->prim_mesh[first + p], &c->prim_material[first + p]);
        if (status != GDR_OK)
            return status;
        gdr_progress_update(progress, ++*converted);
    }
    c->prim_count = first + count;
    c->mesh_first[index] = first;
    return GDR_OK;
}

/* --- nodes ----------------------------------------------------------------------------------- */

static gdr_status node_local(gltf_ctx *c, const cJSON *node, const char *place, gdr_mat4 *out)
{
    gdr_mat4 matrix = gdr_mat4_identity();
    gdr_vec3 t = {0, 0, 0}, s = {1, 1, 1};
    gdr_quat r = {0, 0, 0, 1};
    gdr_status status = gltf_get_floats(c, node, "matrix", place, 16, matrix.m);
    if (status == GDR_OK)
        status = gltf_get_floats(c, node, "translation", place, 3, &t.x);
    if (status == GDR_OK)
        status = gltf_get_floats(c, node, "rotation", place, 4, &r.x);
    if (status == GDR_OK)
        status = gltf_get_floats(c, node, "scale", place, 3, &s.x);
    if (status != GDR_OK)
        return status;
    int has_trs = cJSON_GetObjectItemCaseSensitive(node, "translation") ||
                  cJSON_GetObjectItemCaseSensitive(node, "rotation") || cJSON_GetObjectItemCaseSensitive(node, "scale");
    if (cJSON_GetObjectItemCaseSensitive(node, "matrix")) {
        if (has_trs)
            gdr_io_warn(&c->warnings, "%s: %s: both matrix and TRS given; the matrix is used", c->name, place);
        *out = matrix;
        return GDR_OK;
    }
    float q = sqrtf(r.x * r.x + r.y * r.y + r.z * r.z + r.w * r.w);
    if (!(q > 1e-6f) || !isfinite(q))
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.rotation: not a rotation (length %g)", place, q);
    *out = gdr_mat4_from_trs(t, gdr_quat_normalize(r), s);
    return GDR_OK;
}

/* The number of instances one placement of glTF mesh `mesh` makes (a converted mesh). */
static uint32_t mesh_instance_count(gltf_ctx *c, uint32_t mesh)
{
    const cJSON *prims = cJSON_GetObjectItemCaseSensitive(c->mesh_at[mesh], "primitives");
    uint32_t count = (uint32_t)cJSON_GetArraySize(prims), made = 0;
    for (uint32_t p = 0; p < count; p++)
        made += c->prim_mesh[c->mesh_first[mesh] + p] != GDR_NO_INDEX;
    return made;
}

/* One placement of a mesh; `budgeted`: its instances were already taken from the budget. */
static gdr_status add_instances(gltf_ctx *c, uint32_t mesh, gdr_mat4 transform, const char *place, int budgeted)
{
    uint32_t first = c->mesh_first[mesh];
    const cJSON *prims = cJSON_GetObjectItemCaseSensitive(c->mesh_at[mesh], "primitives");
    uint32_t count = (uint32_t)cJSON_GetArraySize(prims);
    if (!budgeted) {
        gdr_status status = gdr_io_budget_take(&c->budget, GDR_BUDGET_INSTANCES, mesh_instance_count(c, mesh),
                                               c->name, place, c->err);
        if (status != GDR_OK)
            return status;
    }
    for (uint32_t p = 0; p < count; p++) {
        if (c->prim_mesh[first + p] == GDR_NO_INDEX)
            continue;
        gdr_instance instance = {.transform = transform, .mesh = c->prim_mesh[first + p],
                                 .material = c->prim_material[first + p], .color = {1, 1, 1, 1}};
        gdr_status status = instance.material == GDR_NO_INDEX ? default_material(c, &instance.material) : GDR_OK;
        if (status != GDR_OK)
            return status;
        status = gdr_scene_add_instance(c->scene, &instance, c->err);
        /* A transform the scene refuses (beyond the limit on coordinates) is the file's fault. */
        if (status != GDR_OK)
            return gltf_fail(c, status == GDR_ERROR_INVALID_ARGUMENT ? GDR_ERROR_PARSE : status, "%s: meshes[%u]: %s",
                             place, mesh, c->err ? c->err->message : "");
    }
    return GDR_OK;
}

/* EXT_mesh_gpu_instancing: one instance per TRS triple, placed by the node's transform. */
static gdr_status gpu_instancing(gltf_ctx *c, const cJSON *ext, const char *place, uint32_t mesh,
                                 gdr_mat4 global)
{
    char here[96];
    snprintf(here, sizeof here, "%s.extensions.EXT_mesh_gpu_instancing", place);
    const cJSON *attributes = NULL;
    gdr_status status = gltf_get_object(c, ext, "attributes", here, 1, &attributes);
    if (status != GDR_OK)
        return status;
    static const char *const names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
    static const uint32_t components[3] = {3, 4, 3};
    float *data[3] = {NULL, NULL, NULL};
    uint32_t count = 0;
    /* The instances are taken from the budget before their attributes are read. */
    for (int k = 0; k < 3 && status == GDR_OK && count == 0; k++) {
        uint32_t accessor = GDR_NO_INDEX;
        gltf_accessor_info info = {0};
        char use[160], in[140];
        snprintf(in, sizeof in, "%s.attributes", here);
        snprintf(use, sizeof use, "%s.%s", in, names[k]);
        status = gltf_get_uint(c, attributes, names[k], in, 0, UINT32_MAX - 1, &accessor);
        if (status == GDR_OK && accessor != GDR_NO_INDEX)
            status = gltf_accessor_info_get(c, accessor, use, &info);
        count = info.count;
    }
    if (status == GDR_OK)
        status = gdr_io_budget_take(&c->budget, GDR_BUDGET_INSTANCES, (uint64_t)count * mesh_instance_count(c, mesh),
                                    c->name, here, c->err);
    count = 0;
    for (int k = 0; k < 3 && status == GDR_OK; k++)
        status = read_attribute(c, attributes, names[k], here, components[k], &count, &data[k]);
    for (uint32_t i = 0; status == GDR_OK && i < count; i++) {
        gdr_vec3 t = {0, 0, 0}, s = {1, 1, 1};
        gdr_quat r = {0, 0, 0, 1};
        if (data[0])
            memcpy(&t, data[0] + 3 * (size_t)i, sizeof t);
        if (data[1])
            memcpy(&r, data[1] + 4 * (size_t)i, sizeof r);
        if (data[2])
            memcpy(&s, data[2] + 3 * (size_t)i, sizeof s);
        float q = sqrtf(r.x * r.x + r.y * r.y + r.z * r.z + r.w * r.w);
        if (!(q > 1e-6f) || !isfinite(q)) {
            status = gltf_fail(c, GDR_ERROR_PARSE, "%s.attributes.ROTATION: element %u is not a rotation", here, i);
            break;
        }
        gdr_mat4 local = gdr_mat4_from_trs(t, gdr_quat_normalize(r), s);
        for (int e = 0; e < 16; e++)
            if (!isfinite(local.m[e])) {
                status = gltf_fail(c, GDR_ERROR_PARSE, "%s: instance %u transform is not finite", here, i);
                break;
            }
        if (status == GDR_OK)
            status = add_instances(c, mesh, gdr_mat4_mul(global, local), here, 1);
    }
    for (int k = 0; k < 3; k++)
        free(data[k]);
    return status;
}

/* A perspective camera's lens (cameras[i].perspective): yfov, znear, zfar (0: infinite), aspect. */
static gdr_status perspective_lens(gltf_ctx *c, const cJSON *json, const char *here, gdr_camera *cam)
{
    char pplace[64];
    snprintf(pplace, sizeof pplace, "%s.perspective", here);
    const cJSON *perspective = NULL;
    double yfov = 0.0, znear = 0.0, zfar = 0.0, aspect = 0.0;
    gdr_status status = gltf_get_object(c, json, "perspective", here, 1, &perspective);
    if (status == GDR_OK)
        status = gltf_get_number(c, perspective, "yfov", pplace, &yfov);
    if (status == GDR_OK)
        status = gltf_get_number(c, perspective, "znear", pplace, &znear);
    if (status == GDR_OK)
        status = gltf_get_number(c, perspective, "zfar", pplace, &zfar);
    if (status == GDR_OK)
        status = gltf_get_number(c, perspective, "aspectRatio", pplace, &aspect);
    if (status != GDR_OK)
        return status;
    if (!(yfov > 0.0 && yfov < 3.14159) || !(znear > 0.0) || zfar < 0.0 || (zfar > 0.0 && zfar <= znear) ||
        aspect < 0.0)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: yfov %g, znear %g, zfar %g, aspectRatio %g are out of range",
                         pplace, yfov, znear, zfar, aspect);
    *cam = (gdr_camera){.yfov = (float)yfov, .znear = (float)znear, .zfar = (float)zfar, .aspect = (float)aspect};
    return GDR_OK;
}

/* An orthographic camera's lens (cameras[i].orthographic): xmag, ymag (half extents, not zero),
 * znear >= 0 and a finite zfar > znear, all required. The image keeps ymag and takes its own aspect;
 * xmag / ymag is kept as the camera's aspect. */
static gdr_status orthographic_lens(gltf_ctx *c, const cJSON *json, const char *here, gdr_camera *cam)
{
    char oplace[64];
    snprintf(oplace, sizeof oplace, "%s.orthographic", here);
    const cJSON *ortho = NULL;
    double xmag = NAN, ymag = NAN, znear = NAN, zfar = NAN;
    gdr_status status = gltf_get_object(c, json, "orthographic", here, 1, &ortho);
    if (status == GDR_OK)
        status = gltf_get_number(c, ortho, "xmag", oplace, &xmag);
    if (status == GDR_OK)
        status = gltf_get_number(c, ortho, "ymag", oplace, &ymag);
    if (status == GDR_OK)
        status = gltf_get_number(c, ortho, "znear", oplace, &znear);
    if (status == GDR_OK)
        status = gltf_get_number(c, ortho, "zfar", oplace, &zfar);
    if (status != GDR_OK)
        return status;
    if (!(fabs(xmag) > 0.0 && fabs(xmag) <= 1e12) || !(fabs(ymag) > 0.0 && fabs(ymag) <= 1e12) || !(znear >= 0.0) ||
        !(zfar > znear && zfar <= 1e30))
        return gltf_fail(c, GDR_ERROR_PARSE, "%s: xmag %g, ymag %g, znear %g, zfar %g are missing or out of range",
                         oplace, xmag, ymag, znear, zfar);
    *cam = (gdr_camera){.ymag = (float)fabs(ymag), .znear = (float)znear, .zfar = (float)zfar,
                        .aspect = (float)(fabs(xmag) / fabs(ymag))};
    return GDR_OK;
}

static gdr_status add_camera(gltf_ctx *c, uint32_t index, const char *place, gdr_mat4 global)
{
    if (index >= c->camera_count)
        return gltf_fail(c, GDR_ERROR_PARSE, "%s.camera: camera %u does not exist (%u cameras)", place, index,
                         c->camera_count);
    char here[48];
    snprintf(here, sizeof here, "cameras[%u]", index);
    const cJSON *json = c->camera_at[index];
    const char *type = NULL, *name = NULL;
    gdr_status status = gltf_get_string(c, json, "type", here, &type);
    if (status == GDR_OK)
        status = gltf_get_string(c, json, "name", here, &name);
    if (status != GDR_OK)
        return status;
    bool perspective = type && strcmp(type, "perspective") == 0, ortho = type && strcmp(type, "orthographic") == 0;
    if (!perspective && !ortho) {
        gdr_io_warn(&c->warnings, "%s: %s: type '%.16s' skipped: cameras are perspective or orthographic", c->name,
                    here, type ? type : "(missing)");
        return GDR_OK;
    }
    gdr_camera cam;
    status = perspective ? perspective_lens(c, json, here, &cam) : orthographic_lens(c, json, here, &cam);
    if (status != GDR_OK)
        return status;
    cam.position = (gdr_vec3){global.m[12], global.m[13], global.m[14]};
    /* Rotation from the basis with the scale divided out. */
    snprintf(cam.name, sizeof cam.name, "%s", name ? name : here);
    gdr_vec3 x = gdr_vec3_normalize((gdr_vec3){global.m[0], global.m[1], global.m[2]});
    gdr_vec3 y = gdr_vec3_normalize((gdr_vec3){global.m[4], global.m[5], global.m[6]});
    gdr_vec3 z = gdr_vec3_normalize((gdr_vec3){global.m[8], global.m[9], global.m[10]});
    float trace = x.x + y.y + z.z;
    gdr_quat q;
    if (trace > 0.0f) {
        float s = sqrtf(trace + 1.0f) * 2.0f;
        q = (gdr_quat){(y.z - z.y) / s, (z.x - x.z) / s, (x.y - y.x) / s, 0.25f * s};
    } else if (x.x > y.y && x.x > z.z) {
        float s = sqrtf(1.0f + x.x - y.y - z.z) * 2.0f;
        q = (gdr_quat){0.25f * s, (y.x + x.y) / s, (z.x + x.z) / s, (y.z - z.y) / s};
    } else if (y.y > z.z) {
        float s = sqrtf(1.0f + y.y - x.x - z.z) * 2.0f;
        q = (gdr_quat){(y.x + x.y) / s, 0.25f * s, (z.y + y.z) / s, (z.x - x.z) / s};
    } else {
        float s = sqrtf(1.0f + z.z - x.x - y.y) * 2.0f;
        q = (gdr_quat){(z.x + x.z) / s, (z.y + y.z) / s, 0.25f * s, (x.y - y.x) / s};
    }
    cam.rotation = gdr_quat_normalize(q);
    if (!isfinite(cam.rotation.x + cam.rotation.y + cam.rotation.z + cam.rotation.w) ||
        !isfinite(cam.position.x + cam.position.y + cam.position.z)) {
        gdr_io_warn(&c->warnings, "%s: %s: camera transform is degenerate; skipped", c->name, place);
        return GDR_OK;
    }
    return gdr_scene_add_camera(c->scene, &cam, c->err);
}

typedef struct node_visit {
    uint32_t node;
    gdr_mat4 parent;
} node_visit;

/* Depth-first over the scene's roots with an explicit stack (no recursion depth to exhaust);
 * a node reached twice is a cycle or a node with two parents, both invalid glTF. */
static gdr_status walk_nodes(gltf_ctx *c, const uint32_t *roots, uint32_t root_count, const char *scene_place)
{
    uint8_t *seen = calloc(c->node_count ? c->node_count : 1, 1);
    node_visit *stack = malloc(sizeof(node_visit) * (c->node_count ? c->node_count : 1));
    gdr_status status = GDR_OK;
    if (!seen || !stack) {
        status = gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    uint32_t total_prims = 0, converted = 0;
    for (uint32_t m = 0; m < c->mesh_count; m++)
        total_prims += (uint32_t)cJSON_GetArraySize(
            cJSON_GetObjectItemCaseSensitive(c->mesh_at[m], "primitives"));
    gdr_progress progress;
    gdr_progress_begin(&progress, "import", total_prims, c->no_progress);
    for (uint32_t r = 0; r < root_count && status == GDR_OK; r++) {
        uint32_t top = 0;
        if (roots[r] >= c->node_count) {
            status = gltf_fail(c, GDR_ERROR_PARSE, "%s.nodes[%u]: node %u does not exist (%u nodes)", scene_place, r,
                               roots[r], c->node_count);
            break;
        }
        if (seen[roots[r]]) {
            status = gltf_fail(c, GDR_ERROR_PARSE, "%s.nodes[%u]: node %u is reached twice", scene_place, r, roots[r]);
            break;
        }
        seen[roots[r]] = 1;
        stack[top++] = (node_visit){roots[r], gdr_mat4_identity()};
        while (top > 0 && status == GDR_OK) {
            node_visit visit = stack[--top];
            char place[48];
            snprintf(place, sizeof place, "nodes[%u]", visit.node);
            const cJSON *node = c->node_at[visit.node];
            gdr_mat4 local;
            uint32_t mesh = GDR_NO_INDEX, camera = GDR_NO_INDEX, child_count = 0;
            const cJSON *children = NULL;
            status = node_local(c, node, place, &local);
            if (status == GDR_OK)
                status = gltf_get_uint(c, node, "mesh", place, 0, UINT32_MAX - 1, &mesh);
            if (status == GDR_OK)
                status = gltf_get_uint(c, node, "camera", place, 0, UINT32_MAX - 1, &camera);
            if (status == GDR_OK)
                status = gltf_get_array(c, node, "children", place, &children, &child_count);
            if (status != GDR_OK)
                break;
            gdr_mat4 global = gdr_mat4_mul(visit.parent, local);
            for (int e = 0; e < 16; e++)
                if (!isfinite(global.m[e])) {
                    status = gltf_fail(c, GDR_ERROR_PARSE, "%s: global transform is not finite", place);
                    break;
                }
            if (status == GDR_OK && mesh != GDR_NO_INDEX) {
                const cJSON *inst = gltf_extension(node, "EXT_mesh_gpu_instancing");
                if (mesh >= c->mesh_count)
                    status = gltf_fail(c, GDR_ERROR_PARSE, "%s.mesh: mesh %u does not exist (%u meshes)", place,
                                       mesh, c->mesh_count);
                if (status == GDR_OK)
                    status = convert_mesh(c, mesh, &progress, &converted);
                if (status == GDR_OK)
                    status = inst ? gpu_instancing(c, inst, place, mesh, global)
                                  : add_instances(c, mesh, global, place, 0);
            }
            if (status == GDR_OK && camera != GDR_NO_INDEX) {
                c->file_cameras++; /* counted whether or not gdr can use it: --camera-index says so */
                status = add_camera(c, camera, place, global);
            }
            uint32_t k = 0;
            for (const cJSON *child = children ? children->child : NULL; child && status == GDR_OK;
                 child = child->next, k++) {
                double v = child->valuedouble;
                if (!cJSON_IsNumber(child) || !(v >= 0.0) || v >= (double)c->node_count || floor(v) != v) {
                    status = gltf_fail(c, GDR_ERROR_PARSE, "%s.children[%u]: expected a node index in [0, %u)", place,
                                       k, c->node_count);
                    break;
                }
                uint32_t n = (uint32_t)v;
                if (seen[n]) {
                    status = gltf_fail(c, GDR_ERROR_PARSE, "%s.children[%u]: node %u is reached twice (a cycle or a "
                                       "second parent)", place, k, n);
                    break;
                }
                seen[n] = 1;
                stack[top++] = (node_visit){n, global};
            }
        }
    }
    gdr_progress_end(&progress);
done:
    free(seen);
    free(stack);
    return status;
}

/* The root's "scene": the index of the scene to show, GDR_NO_INDEX when absent. */
static gdr_status scene_index(gltf_ctx *c, uint32_t *scene)
{
    *scene = GDR_NO_INDEX;
    gdr_status status = gltf_get_uint(c, c->root, "scene", "(root)", 0, UINT32_MAX - 1, scene);
    if (status != GDR_OK)
        return gltf_fail(c, GDR_ERROR_PARSE, "scene: expected a scene index");
    if (*scene != GDR_NO_INDEX && *scene >= c->scene_count)
        return gltf_fail(c, GDR_ERROR_PARSE, "scene: scene %u does not exist (%u scenes)", *scene, c->scene_count);
    return GDR_OK;
}

static gdr_status load_scene(gltf_ctx *c)
{
    uint32_t scene;
    gdr_status status = scene_index(c, &scene);
    if (status != GDR_OK)
        return status;
    uint32_t *roots = NULL, root_count = 0;
    char place[48];
    if (scene == GDR_NO_INDEX && c->scene_count == 0) {
        /* No scene at all: show every root node rather than nothing. */
        snprintf(place, sizeof place, "(no scene)");
        roots = malloc(sizeof(uint32_t) * (c->node_count ? c->node_count : 1));
        uint8_t *is_child = calloc(c->node_count ? c->node_count : 1, 1);
        if (!roots || !is_child) {
            free(roots);
            free(is_child);
            return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
        }
        for (uint32_t n = 0; n < c->node_count; n++) {
            const cJSON *children = cJSON_GetObjectItemCaseSensitive(c->node_at[n], "children");
            for (const cJSON *ch = cJSON_IsArray(children) ? children->child : NULL; ch; ch = ch->next)
                if (cJSON_IsNumber(ch) && ch->valuedouble >= 0 && ch->valuedouble < c->node_count)
                    is_child[(uint32_t)ch->valuedouble] = 1;
        }
        for (uint32_t n = 0; n < c->node_count; n++)
            if (!is_child[n])
                roots[root_count++] = n;
        free(is_child);
        if (c->node_count)
            gdr_io_warn(&c->warnings, "%s: no scenes; showing the %u root nodes", c->name, root_count);
    } else {
        if (scene == GDR_NO_INDEX)
            scene = 0;
        snprintf(place, sizeof place, "scenes[%u]", scene);
        const cJSON *json = c->scene_at[scene], *nodes = NULL;
        uint32_t count = 0;
        status = gltf_get_array(c, json, "nodes", place, &nodes, &count);
        if (status != GDR_OK)
            return status;
        roots = malloc(sizeof(uint32_t) * (count ? count : 1));
        if (!roots)
            return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
        for (const cJSON *e = nodes ? nodes->child : NULL; e; e = e->next, root_count++) {
            double v = e->valuedouble;
            if (!cJSON_IsNumber(e) || !(v >= 0.0) || v > 4294967294.0 || floor(v) != v) {
                free(roots);
                return gltf_fail(c, GDR_ERROR_PARSE, "%s.nodes[%u]: expected a node index", place, root_count);
            }
            roots[root_count] = (uint32_t)v;
        }
        if (root_count == 0)
            gdr_io_warn(&c->warnings, "%s: %s has no nodes; the scene is empty", c->name, place);
    }
    status = walk_nodes(c, roots, root_count, place);
    free(roots);
    return status;
}

/* --- entry points ---------------------------------------------------------------------------- */

/* How deeply arrays and objects are nested at byte `end` of JSON text (strings skipped). */
static int json_depth(const char *json, size_t end)
{
    int depth = 0, in_string = 0;
    for (size_t i = 0; i < end; i++) {
        char ch = json[i];
        if (in_string) {
            if (ch == '\\')
                i++;
            else if (ch == '"')
                in_string = 0;
        } else if (ch == '"') {
            in_string = 1;
        } else if (ch == '[' || ch == '{') {
            depth++;
        } else if ((ch == ']' || ch == '}') && depth > 0) {
            depth--;
        }
    }
    return depth;
}

static gdr_status import_document(gltf_ctx *c, const uint8_t *data, size_t size)
{
    const char *json = (const char *)data;
    size_t json_size = size;
    if (size >= 4 && read_u32(data) == GLB_MAGIC) {
        c->is_glb = 1;
        gdr_status status = parse_glb(c, data, size, &json, &json_size);
        if (status != GDR_OK)
            return status;
    }
    c->root = cJSON_ParseWithLength(json, json_size);
    if (!c->root) {
        const char *at = cJSON_GetErrorPtr();
        size_t offset = at && at >= json && at <= json + json_size ? (size_t)(at - json) : 0;
        uint32_t line = 1;
        for (size_t i = 0; i < offset; i++)
            line += json[i] == '\n';
        if (json_depth(json, offset) >= CJSON_NESTING_LIMIT)
            return gltf_fail(c, GDR_ERROR_PARSE, "JSON nested deeper than %d arrays and objects at line %u (byte %zu)",
                             CJSON_NESTING_LIMIT, line, offset);
        return gltf_fail(c, GDR_ERROR_PARSE, "JSON syntax error at line %u (byte %zu)", line, offset);
    }
    if (!cJSON_IsObject(c->root))
        return gltf_fail(c, GDR_ERROR_PARSE, "(root): expected a JSON object");
    char place[512] = "";
    gdr_status status = check_asset_and_extensions(c);
    if (status == GDR_OK)
        status = check_extension_objects(c, c->root, place, 0, sizeof place);
    struct { const char *key; cJSON **array; uint32_t *count; const cJSON ***items; } tops[] = {
        {"accessors", &c->accessors, &c->accessor_count, &c->accessor_at},
        {"bufferViews", &c->buffer_views, &c->view_count, &c->view_at},
        {"buffers", &c->buffers_json, &c->buffer_count, &c->buffer_at},
        {"meshes", &c->meshes, &c->mesh_count, &c->mesh_at},
        {"nodes", &c->nodes, &c->node_count, &c->node_at},
        {"materials", &c->materials, &c->material_count, &c->material_at},
        {"textures", &c->textures, &c->texture_count, &c->texture_at},
        {"images", &c->images, &c->image_count, &c->image_at},
        {"cameras", &c->cameras, &c->camera_count, &c->camera_at},
        {"scenes", &c->scenes, &c->scene_count, &c->scene_at},
        {"samplers", &c->samplers, &c->sampler_count, &c->sampler_at},
    };
    for (size_t i = 0; i < sizeof tops / sizeof tops[0] && status == GDR_OK; i++)
        status = get_top_array(c, tops[i].key, tops[i].array, tops[i].count, tops[i].items);
    if (status != GDR_OK)
        return status;
    c->buffers = calloc(c->buffer_count + 1, sizeof *c->buffers);
    c->views = calloc(c->view_count + 1, sizeof *c->views);
    c->mesh_first = malloc(sizeof(uint32_t) * (c->mesh_count + 1));
    c->image_texture = malloc(sizeof(uint32_t) * 2 * (c->image_count + 1));
    if (!c->buffers || !c->views || !c->mesh_first || !c->image_texture)
        return gltf_fail(c, GDR_ERROR_OUT_OF_MEMORY, "out of memory");
    memset(c->mesh_first, 0xff, sizeof(uint32_t) * (c->mesh_count + 1));
    memset(c->image_texture, 0xff, sizeof(uint32_t) * 2 * (c->image_count + 1));
    gltf_report_unsupported(c);
    /* The document's structure, then the geometry's buffers, before the materials: a missing .bin
     * is said before any image is decoded. */
    uint32_t scene;
    status = scene_index(c, &scene);
    if (status == GDR_OK)
        status = gltf_load_mesh_buffers(c);
    for (uint32_t m = 0; m < c->material_count && status == GDR_OK; m++)
        status = load_material(c, m);
    if (status == GDR_OK)
        status = load_scene(c);
    return status;
}

gdr_status gdr_import_gltf_memory(const void *data, size_t size, const char *name, const char *base_dir,
                                  const gdr_import_options *options, gdr_scene **out, gdr_import_result *result,
                                  gdr_error *err)
{
    static const gdr_import_options defaults = {0};
    if (!options)
        options = &defaults;
    *out = NULL;
    gdr_error local_err;
    gltf_ctx c = {.name = name ? name : "(memory)", .base_dir = base_dir, .err = err ? err : &local_err,
                  .warnings = {options->warning, options->warning_user, 0}, .sources = options->sources,
                  .no_progress = options->no_progress, .allow_outside_files = options->allow_outside_files};
    gdr_io_budget_init(&c.budget, &options->budget);
    gdr_status status = gdr_scene_create(&c.scene, c.err);
    if (status == GDR_OK)
        status = import_document(&c, data, size);
    cJSON_Delete(c.root);
    const cJSON **items[] = {c.accessor_at, c.view_at, c.buffer_at, c.mesh_at, c.node_at, c.material_at,
                             c.texture_at, c.image_at, c.camera_at, c.scene_at, c.sampler_at};
    for (size_t i = 0; i < sizeof items / sizeof items[0]; i++)
        free(items[i]);
    gltf_buffers_free(&c);
    free(c.mesh_first);
    free(c.prim_mesh);
    free(c.prim_material);
    gltf_shared_meshes_free(&c.shared);
    free(c.image_texture);
    if (result) {
        result->warning_count = c.warnings.count;
        result->file_cameras = c.file_cameras;
    }
    if (status != GDR_OK) {
        gdr_scene_destroy(c.scene);
        return status;
    }
    *out = c.scene;
    return GDR_OK;
}

gdr_status gdr_import_gltf(const char *path, const gdr_import_options *options, gdr_scene **out,
                           gdr_import_result *result, gdr_error *err)
{
    *out = NULL;
    uint8_t *data;
    size_t size;
    gdr_status status = gdr_io_read_file(path, &data, &size, options ? options->sources : NULL, err);
    if (status != GDR_OK)
        return status;
    char dir[4096];
    gdr_io_dirname(path, dir, sizeof dir);
    status = gdr_import_gltf_memory(data, size, path, dir, options, out, result, err);
    free(data);
    return status;
}
