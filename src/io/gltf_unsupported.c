/* What a glTF file uses that gdr does not draw: one warning per feature, naming it and the first
 * place it occurs, so that a file never renders differently from what it says without a word. */
#include <stdio.h>
#include <string.h>

#include "io/gltf_internal.h"

/* Material extensions gdr applies (KHR_texture_transform sits on texture references, not here). */
static const char *const supported_material_extensions[] = {"KHR_materials_emissive_strength"};

#define DISTINCT_EXTENSIONS_MAX 64

static int nonempty_array(const cJSON *json) { return cJSON_IsArray(json) && json->child; }

/* Nodes with a skin: drawn in the bind pose (the mesh as stored). */
static void report_skins(gltf_ctx *c)
{
    uint32_t first = 0, count = 0;
    for (uint32_t n = 0; n < c->node_count; n++)
        if (cJSON_GetObjectItemCaseSensitive(c->node_at[n], "skin") && count++ == 0)
            first = n;
    if (count)
        gdr_io_warn(&c->warnings, "%s: nodes[%u].skin: skins are not supported (%u node%s one); skinned meshes "
                    "are drawn in their bind pose", c->name, first, count, count == 1 ? " uses" : "s use");
}

/* Primitives with morph targets: drawn as their base shape. */
static void report_morph_targets(gltf_ctx *c)
{
    uint32_t count = 0;
    char first[64] = "";
    for (uint32_t m = 0; m < c->mesh_count; m++) {
        const cJSON *prims = cJSON_GetObjectItemCaseSensitive(c->mesh_at[m], "primitives");
        uint32_t p = 0;
        for (const cJSON *prim = cJSON_IsArray(prims) ? prims->child : NULL; prim; prim = prim->next, p++)
            if (nonempty_array(cJSON_GetObjectItemCaseSensitive(prim, "targets")) && count++ == 0)
                snprintf(first, sizeof first, "meshes[%u].primitives[%u].targets", m, p);
    }
    if (count)
        gdr_io_warn(&c->warnings, "%s: %s: morph targets are not supported (%u primitive%s them); drawn as "
                    "the base shape", c->name, first, count, count == 1 ? " has" : "s have");
}

static void report_animations(gltf_ctx *c)
{
    const cJSON *animations = cJSON_GetObjectItemCaseSensitive(c->root, "animations");
    if (!nonempty_array(animations))
        return;
    int count = cJSON_GetArraySize(animations);
    gdr_io_warn(&c->warnings, "%s: animations[0]: animation is not supported (%d animation%s); the scene is drawn "
                "with its nodes as written", c->name, count, count == 1 ? "" : "s");
}

static int supported_material_extension(const char *name)
{
    for (size_t i = 0; i < sizeof supported_material_extensions / sizeof supported_material_extensions[0]; i++)
        if (strcmp(name, supported_material_extensions[i]) == 0)
            return 1;
    return 0;
}

/* Each material extension gdr does not apply, once, at the first material that has it. */
static void report_material_extensions(gltf_ctx *c)
{
    const char *names[DISTINCT_EXTENSIONS_MAX];
    uint32_t first[DISTINCT_EXTENSIONS_MAX], uses[DISTINCT_EXTENSIONS_MAX], distinct = 0, more = 0;
    for (uint32_t m = 0; m < c->material_count; m++) {
        const cJSON *extensions = cJSON_GetObjectItemCaseSensitive(c->material_at[m], "extensions");
        for (const cJSON *e = cJSON_IsObject(extensions) ? extensions->child : NULL; e; e = e->next) {
            if (!e->string || supported_material_extension(e->string))
                continue;
            uint32_t k = 0;
            while (k < distinct && strcmp(names[k], e->string) != 0)
                k++;
            if (k == distinct && distinct == DISTINCT_EXTENSIONS_MAX) {
                more++;
                continue;
            }
            if (k == distinct) {
                names[distinct] = e->string;
                first[distinct] = m;
                uses[distinct++] = 0;
            }
            uses[k]++;
        }
    }
    for (uint32_t k = 0; k < distinct; k++)
        gdr_io_warn(&c->warnings, "%s: materials[%u].extensions.%.64s: %.64s is not supported (%u material%s it); "
                    "left out", c->name, first[k], names[k], names[k], uses[k], uses[k] == 1 ? " uses" : "s use");
    if (more)
        gdr_io_warn(&c->warnings, "%s: %u more uses of unsupported material extensions beyond the %d named above",
                    c->name, more, DISTINCT_EXTENSIONS_MAX);
}

void gltf_report_unsupported(gltf_ctx *c)
{
    report_skins(c);
    report_morph_targets(c);
    report_animations(c);
    report_material_extensions(c);
}
