/* Scene specifications: a built-in scene, "NAME[:key=value,...]", or a file path. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/io.h"
#include "gdr/geometry.h"
#include "gdr/procedural.h"
#include "gdr/scene.h"
#include "io/loaders.h"

/* One option of a built-in scene: an integer in [min, max] or, with `number` set, a float whose
 * range the scene's create function checks. */
typedef struct scene_option {
    const char *key;
    uint32_t *integer;
    float *number;
    uint32_t min, max;
} scene_option;

#define OPTIONS_MAX 4

static gdr_status parse_value(const char *scene, const scene_option *o, const char *value, gdr_error *err)
{
    char *end;
    errno = 0;
    if (o->number) {
        float v = strtof(value, &end);
        if (errno || *end || end == value)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: %s=%s is not a number", scene, o->key, value);
        *o->number = v;
        return GDR_OK;
    }
    unsigned long long v = strtoull(value, &end, 10);
    if (errno || *end || end == value || value[0] == '-' || value[0] == '+' || v < o->min || v > o->max)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: %s=%s is not an integer in [%u, %u]", scene,
                             o->key, value, o->min, o->max);
    *o->integer = (uint32_t)v;
    return GDR_OK;
}

/* Parses "key=value,key=value" against `options` (count entries); each key at most once. */
static gdr_status parse_options(const char *scene, const char *text, const scene_option *options, int count,
                                gdr_error *err)
{
    char buffer[256], keys[128] = "";
    if (strlen(text) >= sizeof buffer)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: options too long", scene);
    for (int i = 0; i < count; i++)
        snprintf(keys + strlen(keys), sizeof keys - strlen(keys), "%s%s", i ? ", " : "", options[i].key);
    bool seen[OPTIONS_MAX] = {false};
    strcpy(buffer, text);
    for (char *save = NULL, *item = strtok_r(buffer, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(item, '=');
        if (!eq)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: option '%s' is not key=value", scene, item);
        *eq = '\0';
        int found = -1;
        for (int i = 0; i < count && found < 0; i++)
            if (strcmp(item, options[i].key) == 0)
                found = i;
        if (found < 0)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: unknown option '%s' (%s)", scene, item, keys);
        if (seen[found])
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: option '%s' given twice", scene, item);
        seen[found] = true;
        gdr_status status = parse_value(scene, &options[found], eq + 1, err);
        if (status != GDR_OK)
            return status;
    }
    return GDR_OK;
}

typedef enum builtin_scene {
    BUILTIN_NONE, BUILTIN_DEMO, BUILTIN_LOD_FIELD, BUILTIN_OCCLUSION, BUILTIN_UNIQUE_FIELD, BUILTIN_ROOMS
} builtin_scene;

static const char *const builtin_names[] = {NULL, "demo", "lod-field", "occlusion", "unique-field", "rooms"};

/* Which built-in scene `spec` names, and where its options start ("" when there are none). */
static builtin_scene find_builtin(const char *spec, const char **options)
{
    for (int b = BUILTIN_DEMO; b <= BUILTIN_ROOMS; b++) {
        size_t n = strlen(builtin_names[b]);
        if (strncmp(spec, builtin_names[b], n) == 0 && (spec[n] == '\0' || spec[n] == ':')) {
            *options = spec[n] ? spec + n + 1 : "";
            return (builtin_scene)b;
        }
    }
    return BUILTIN_NONE;
}

bool gdr_scene_spec_is_builtin(const char *spec)
{
    const char *options;
    return find_builtin(spec, &options) != BUILTIN_NONE;
}

static gdr_status parse_unique_field(const char *text, gdr_unique_field_desc *d, gdr_error *err)
{
    scene_option o[] = {{"meshes", &d->meshes, NULL, 1, 100000},
                        {"seed", &d->seed, NULL, 1, 16000000},
                        {"triangles", &d->triangles, NULL, 1000, 16000000},
                        {"spacing", NULL, &d->spacing, 0, 0}};
    return parse_options(builtin_names[BUILTIN_UNIQUE_FIELD], text, o, 4, err);
}

gdr_status gdr_io_unique_field_spec(const char *spec, gdr_unique_field_desc *d, bool *is_unique, gdr_error *err)
{
    const char *text;
    *d = (gdr_unique_field_desc){0};
    *is_unique = find_builtin(spec, &text) == BUILTIN_UNIQUE_FIELD;
    return *is_unique ? parse_unique_field(text, d, err) : GDR_OK;
}

static gdr_status create_builtin(builtin_scene which, const char *text, gdr_scene **out, gdr_error *err)
{
    const char *name = builtin_names[which];
    gdr_status status;
    if (which == BUILTIN_DEMO) {
        gdr_demo_desc d = {0};
        scene_option o[] = {{"instances", &d.instances, NULL, 1, 16000000},
                            {"seed", &d.seed, NULL, 1, 16000000},
                            {"spacing", NULL, &d.spacing, 0, 0},
                            {"textures", &d.textures, NULL, 0, 1}};
        status = parse_options(name, text, o, 4, err);
        return status == GDR_OK ? gdr_scene_create_demo(&d, out, err) : status;
    }
    if (which == BUILTIN_LOD_FIELD) {
        gdr_lod_field_desc d = {0};
        scene_option o[] = {{"instances", &d.instances, NULL, 1, 16000000},
                            {"seed", &d.seed, NULL, 1, 16000000},
                            {"triangles", &d.triangles, NULL, 1000, 16000000},
                            {"spacing", NULL, &d.spacing, 0, 0}};
        status = parse_options(name, text, o, 4, err);
        return status == GDR_OK ? gdr_scene_create_lod_field(&d, out, err) : status;
    }
    if (which == BUILTIN_UNIQUE_FIELD) {
        gdr_unique_field_desc d = {0};
        status = parse_unique_field(text, &d, err);
        return status == GDR_OK ? gdr_scene_create_unique_field(&d, out, err) : status;
    }
    if (which == BUILTIN_ROOMS) {
        gdr_rooms_scene_desc d = {0};
        scene_option o[] = {{"rooms", &d.rooms, NULL, 1, GDR_ROOMS_MAX},
                            {"seed", &d.seed, NULL, 1, 16000000},
                            {"objects", &d.objects, NULL, 1, GDR_ROOMS_MAX_OBJECTS}};
        status = parse_options(name, text, o, 3, err);
        return status == GDR_OK ? gdr_scene_create_rooms(&d, out, err) : status;
    }
    gdr_occlusion_scene_desc d = {0};
    scene_option o[] = {{"seed", &d.seed, NULL, 1, 16000000},
                        {"hidden", &d.hidden, NULL, 1, 1000000},
                        {"visible", &d.visible, NULL, 1, 1000000}};
    status = parse_options(name, text, o, 3, err);
    return status == GDR_OK ? gdr_scene_create_occlusion(&d, out, err) : status;
}

gdr_status gdr_scene_load(const char *spec, const gdr_load_options *options, gdr_scene **out, gdr_error *err)
{
    *out = NULL;
    if (options && options->pvs)
        *options->pvs = NULL;
    if (options && options->sources)
        *options->sources = (gdr_source_list){0};
    if (options && options->report)
        *options->report = (gdr_import_report){0};
    const char *text;
    builtin_scene which = find_builtin(spec, &text);
    if (which != BUILTIN_NONE && options && options->geometry_in_pages)
        return gdr_io_load_paged(spec, options, NULL, 0, out, options->pvs, options->report, err);
    if (which != BUILTIN_NONE) {
        gdr_status status = create_builtin(which, text, out, err);
        /* The LOD DAG over the meshlets the built-in scenes come with (src/geometry). */
        gdr_lod_options lod = {.no_progress = options && options->no_progress};
        if (status == GDR_OK && (status = gdr_scene_build_lod(*out, &lod, NULL, err)) != GDR_OK) {
            gdr_scene_destroy(*out);
            *out = NULL;
        }
        return status;
    }
    /* Files: .gltf / .glb / .obj through the processed-scene cache, .gdrc directly (src/io). */
    return gdr_scene_load_file(spec, options, out, options ? options->pvs : NULL, err);
}
