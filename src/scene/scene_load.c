/* Scene specifications: "demo[:key=value,...]" or a file path. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/io.h"
#include "gdr/scene.h"

static gdr_status parse_demo_options(const char *options, gdr_demo_desc *desc, gdr_error *err)
{
    char buffer[256];
    if (strlen(options) >= sizeof buffer)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "demo: options too long");
    strcpy(buffer, options);
    for (char *save = NULL, *item = strtok_r(buffer, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(item, '=');
        if (!eq)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "demo: option '%s' is not key=value", item);
        *eq = '\0';
        const char *key = item, *value = eq + 1;
        char *end;
        errno = 0;
        if (strcmp(key, "instances") == 0 || strcmp(key, "seed") == 0) {
            unsigned long long v = strtoull(value, &end, 10);
            if (errno || *end || end == value || value[0] == '-' || v == 0 || v > 16000000ull)
                return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                     "demo: %s=%s is not an integer in [1, 16000000]", key, value);
            if (key[0] == 'i')
                desc->instances = (uint32_t)v;
            else
                desc->seed = (uint32_t)v;
        } else if (strcmp(key, "spacing") == 0) {
            float v = strtof(value, &end);
            if (errno || *end || end == value)
                return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "demo: spacing=%s is not a number", value);
            desc->spacing = v;
        } else {
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                 "demo: unknown option '%s' (instances, seed, spacing)", key);
        }
    }
    return GDR_OK;
}

gdr_status gdr_scene_load_ex(const char *spec, const gdr_load_options *options, gdr_scene **out, gdr_error *err)
{
    *out = NULL;
    if (strcmp(spec, "demo") == 0 || strncmp(spec, "demo:", 5) == 0) {
        gdr_demo_desc desc = {0};
        gdr_status status = parse_demo_options(spec[4] ? spec + 5 : "", &desc, err);
        if (status == GDR_OK)
            status = gdr_scene_create_demo(&desc, out, err);
        /* The LOD DAG over the meshlets the demo scene comes with (src/geometry). */
        gdr_lod_options lod = {.no_progress = options && options->no_progress};
        if (status == GDR_OK && (status = gdr_scene_build_lod(*out, &lod, NULL, err)) != GDR_OK) {
            gdr_scene_destroy(*out);
            *out = NULL;
        }
        return status;
    }
    /* Files: .gltf / .glb / .obj through the processed-scene cache, .gdrc directly (src/io). */
    return gdr_scene_load_file(spec, options, out, err);
}

gdr_status gdr_scene_load(const char *spec, gdr_scene **out, gdr_error *err)
{
    return gdr_scene_load_ex(spec, NULL, out, err);
}
