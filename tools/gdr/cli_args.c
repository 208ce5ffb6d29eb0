#include "gdr/io.h"
#include "cli_args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool cli_parse_u32(const char *option, const char *text, uint32_t min, uint32_t max, uint32_t *out)
{
    char *end;
    errno = 0;
    unsigned long long value = strtoull(text, &end, 10);
    if (errno || end == text || *end || text[0] == '-' || text[0] == '+' || value < min || value > max) {
        fprintf(stderr, "gdr: %s %s: expected an integer from %u to %u\n", option, text, min, max);
        return false;
    }
    *out = (uint32_t)value;
    return true;
}

bool cli_parse_float(const char *option, const char *text, float min, float max, float *out)
{
    char *end;
    errno = 0;
    float value = strtof(text, &end);
    if (errno || end == text || *end || !(value >= min && value <= max)) {
        fprintf(stderr, "gdr: %s %s: expected a number from %g to %g\n", option, text, (double)min, (double)max);
        return false;
    }
    *out = value;
    return true;
}

bool cli_parse_on_off(const char *option, const char *text, bool *out)
{
    if (strcmp(text, "on") == 0 || strcmp(text, "off") == 0) {
        *out = text[1] == 'n';
        return true;
    }
    fprintf(stderr, "gdr: %s %s: expected 'on' or 'off'\n", option, text);
    return false;
}

bool cli_parse_choice(const char *option, const char *text, const char *const *names, int count, int *out)
{
    for (int i = 0; i < count; i++) {
        if (strcmp(text, names[i]) == 0) {
            *out = i;
            return true;
        }
    }
    char list[256] = "";
    for (int i = 0; i < count; i++) {
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", names[i]);
    }
    fprintf(stderr, "gdr: %s %s: expected one of %s\n", option, text, list);
    return false;
}

bool cli_parse_floats(const char *text, int count, float *out)
{
    const char *cursor = text;
    for (int i = 0; i < count; i++) {
        char *end;
        errno = 0;
        out[i] = strtof(cursor, &end);
        bool separator_ok = i < count - 1 ? *end == ',' : *end == '\0';
        if (errno || end == cursor || !separator_ok || !isfinite(out[i]))
            return false;
        cursor = end + 1;
    }
    return true;
}

bool cli_parse_camera(const char *option, const char *text, gdr_vec3 *position, gdr_quat *rotation)
{
    float v[7];
    if (!cli_parse_floats(text, 7, v)) {
        fprintf(stderr, "gdr: %s %s: expected 7 finite numbers px,py,pz,qx,qy,qz,qw\n", option, text);
        return false;
    }
    float length = sqrtf(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
    if (length < 1e-6f) {
        fprintf(stderr, "gdr: %s %s: the rotation quaternion must not be zero\n", option, text);
        return false;
    }
    *position = (gdr_vec3){v[0], v[1], v[2]};
    *rotation = gdr_quat_normalize((gdr_quat){v[3], v[4], v[5], v[6]});
    return true;
}

const char *cli_value(int argc, char **argv, int *i)
{
    if (*i + 1 >= argc) {
        fprintf(stderr, "gdr: %s needs a value\n", argv[*i]);
        return NULL;
    }
    *i += 1;
    return argv[*i];
}

const char *cli_known_value(const char *command, const char *const *known, int argc, char **argv, int *i)
{
    for (const char *const *k = known; *k; k++)
        if (strcmp(argv[*i], *k) == 0)
            return cli_value(argc, argv, i);
    fprintf(stderr, "gdr %s: unknown option '%s' (see gdr --help)\n", command, argv[*i]);
    return NULL;
}

int cli_renderer_failed(const gdr_error *err)
{
    fprintf(stderr, "gdr: %s\n", err->message);
    return err->status == GDR_ERROR_INVALID_ARGUMENT ? 2 : 1;
}

bool cli_parse_pipeline(const char *option, const char *text, gdr_pipeline *out)
{
    static const char *const names[] = {"mesh", "indirect", "cpu"};
    static const gdr_pipeline values[] = {GDR_PIPELINE_MESH, GDR_PIPELINE_INDIRECT, GDR_PIPELINE_CPU};
    int index;
    if (!cli_parse_choice(option, text, names, 3, &index))
        return false;
    char what[96];
    snprintf(what, sizeof what, "%s cpu", option);
    if (values[index] == GDR_PIPELINE_CPU && !cli_needs_cull(what))
        return false;
    *out = values[index];
    return true;
}

bool cli_needs_cull(const char *what)
{
    if (GDR_HAVE_CULL)
        return true;
    fprintf(stderr, "gdr: %s: built without the culling module (GDR_EXCLUDE_MODULES)\n", what);
    return false;
}

bool cli_parse_raster(const char *option, const char *text, gdr_raster *out)
{
    static const char *const names[] = {"hybrid", "hw", "sw", "forward"};
    static const gdr_raster values[] = {GDR_RASTER_HYBRID, GDR_RASTER_HW, GDR_RASTER_SW, GDR_RASTER_FORWARD};
    int index;
    if (!cli_parse_choice(option, text, names, 4, &index))
        return false;
    *out = values[index];
    return true;
}

bool cli_parse_budget(const char *option, const char *text, gdr_budget *out)
{
    static const char *const keys[] = {"triangles", "instances", "pixels", "bytes"};
    uint64_t *fields[] = {&out->triangles, &out->instances, &out->texture_pixels, &out->decoded_bytes};
    const char *p = text;
    while (*p) {
        const char *equals = strchr(p, '='), *comma = strchr(p, ',');
        const char *end = comma ? comma : p + strlen(p);
        int key = -1;
        for (int k = 0; k < 4 && equals && equals < end; k++)
            if ((size_t)(equals - p) == strlen(keys[k]) && strncmp(p, keys[k], strlen(keys[k])) == 0)
                key = k;
        char number[32];
        char *stop = NULL;
        unsigned long long value = 0;
        if (key >= 0 && (size_t)(end - equals - 1) < sizeof number && end > equals + 1 && equals[1] != '-' &&
            equals[1] != '+') {
            snprintf(number, sizeof number, "%.*s", (int)(end - equals - 1), equals + 1);
            errno = 0;
            value = strtoull(number, &stop, 10);
        }
        if (key < 0 || !stop || *stop || errno || value == 0) {
            fprintf(stderr, "gdr: %s %s: expected KEY=N[,KEY=N...] with KEY triangles, instances, pixels or bytes "
                    "and N a positive integer\n", option, text);
            return false;
        }
        *fields[key] = value;
        p = comma ? comma + 1 : end;
    }
    if (p == text) {
        fprintf(stderr, "gdr: %s: expected KEY=N[,KEY=N...]\n", option);
        return false;
    }
    return true;
}

int cli_load_failed(const char *spec, const gdr_error *err)
{
    fprintf(stderr, "gdr: %s\n", err->message);
    return gdr_scene_spec_is_builtin(spec) && err->status == GDR_ERROR_INVALID_ARGUMENT ? 2 : 1;
}

bool cli_bc_textures_disabled(void)
{
    const char *value = getenv("GDR_DISABLE_BC_TEXTURES");
    return value && strcmp(value, "1") == 0;
}
