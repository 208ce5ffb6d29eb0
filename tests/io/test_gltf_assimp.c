/* Every glTF 2.0 file of Debian's assimp-testmodels: valid ones import with the counts the file
 * declares (computed here independently from the JSON); broken ones fail or warn with a clear
 * message naming the problem. Runs under ASan + UBSan too (label "unit"). */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cJSON.h>

#include "gdr/io.h"
#include "test_util.h"
#include "io/loaders.h"

#ifndef ASSIMP_GLTF2_DIR
#define ASSIMP_GLTF2_DIR "/usr/share/assimp/models/glTF2"
#endif

/* Files that must be refused: the status, and the place the message names. */
static const struct { const char *file; gdr_status status; const char *place; } broken[] = {
    {"IndexOutOfRange/IndexOutOfRange.gltf", GDR_ERROR_PARSE, "meshes[0].primitives[0].indices"},
    {"IndexOutOfRange/AllIndicesOutOfRange.gltf", GDR_ERROR_PARSE, "meshes[0].primitives[0].indices"},
    {"MissingBin/BoxTextured.gltf", GDR_ERROR_IO, "BoxTextured0.bin"},
    {"RecursiveNodes/RecursiveNodes.gltf", GDR_ERROR_PARSE, "nodes[1].children[0]"},
    {"SchemaFailures/sceneWrongType.gltf", GDR_ERROR_PARSE, "scene:"},
    {"TestNoRootNode/NoScene.gltf", GDR_ERROR_PARSE, "scene:"},
    {"wrongTypes/badArray.gltf", GDR_ERROR_PARSE, "meshes[0].primitives"},
    {"wrongTypes/badExtension.gltf", GDR_ERROR_PARSE, "KHR_texture_transform"},
    {"wrongTypes/badNumber.gltf", GDR_ERROR_PARSE, "normalTexture.scale"},
    {"wrongTypes/badObject.gltf", GDR_ERROR_PARSE, "materials[0].pbrMetallicRoughness"},
    {"wrongTypes/badString.gltf", GDR_ERROR_PARSE, "scenes[0].name"},
    {"wrongTypes/badUint.gltf", GDR_ERROR_PARSE, "baseColorTexture.index"},
    {"BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", GDR_ERROR_PARSE, "attributes.POSITION: vertex 0"},
    {"draco/2CylinderEngine.gltf", GDR_ERROR_UNSUPPORTED, "extensionsRequired: KHR_draco_mesh_compression"},
    {"BoxTextured-glTF-techniqueWebGL/BoxTextured.gltf", GDR_ERROR_UNSUPPORTED, "extensionsRequired: KHR_technique_webgl"},
};

/* Files that load but must warn, with a part of one expected warning. */
static const struct { const char *file, *warning; } warned[] = {
    {"BoxBadNormals-glTF-Binary/BoxBadNormals.glb", "normals generated from the faces"},
    {"IncorrectVertexArrays/Cube.gltf", "is not a multiple of 3"},
    {"TestNoRootNode/SceneWithoutNodes.gltf", "has no nodes"},
    {"glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_00.gltf", "(points) skipped"},
    {"glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_01.gltf", "(lines) skipped"},
    {"glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_02.gltf", "(line loop) skipped"},
    {"glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_03.gltf", "(line strip) skipped"},
    {"glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_07.gltf", "(points) skipped"},
    {"glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_08.gltf", "(lines) skipped"},
    {"glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_09.gltf", "(line loop) skipped"},
    {"glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_10.gltf", "(line strip) skipped"},
    /* material extensions gdr does not apply: said once, at the first material using one */
    {"BoxTextured-glTF-pbrSpecularGlossiness/BoxTextured.gltf",
     "materials[0].extensions.KHR_materials_pbrSpecularGlossiness: KHR_materials_pbrSpecularGlossiness is not supported"},
    {"ClearCoat-glTF/ClearCoatTest.gltf", "KHR_materials_clearcoat is not supported (6 materials use it)"},
    /* skins, morph targets, animation: drawn at rest, said once each */
    {"simple_skin/simple_skin.gltf", "nodes[0].skin: skins are not supported (1 node uses one)"},
    {"glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf",
     "meshes[0].primitives[0].targets: morph targets are not supported (1 primitive has them)"},
};

typedef struct collected {
    unsigned count;
    char text[8192];
} collected;

static void collect(void *user, const char *message)
{
    collected *c = user;
    c->count++;
    size_t used = strlen(c->text);
    snprintf(c->text + used, sizeof c->text - used, "%s\n", message);
}

/* --- expected counts from the JSON, by a plain recursive walk (valid files only) ---------------- */

typedef struct expected {
    uint32_t instances, meshes, cameras, materials;
    /* The geometries seen: primitives of one mode and the same indices, POSITION, NORMAL, TEXCOORD_0
     * and COLOR_0 accessors share one mesh. */
    int geometry[4096][6];
    uint32_t geometry_count;
    int default_material; /* an instanced triangle primitive has no material: glTF's default one is added */
} expected;

static int triangle_primitive(const cJSON *prim)
{
    const cJSON *mode = cJSON_GetObjectItem(prim, "mode");
    const cJSON *attributes = cJSON_GetObjectItem(prim, "attributes");
    int m = mode ? mode->valueint : 4;
    return m >= 4 && cJSON_GetObjectItem(attributes, "POSITION") != NULL;
}

/* 1 when the primitive reads accessors no earlier one read (recorded then). */
static int new_geometry(const cJSON *prim, expected *e)
{
    static const char *const semantics[4] = {"POSITION", "NORMAL", "TEXCOORD_0", "COLOR_0"};
    const cJSON *attributes = cJSON_GetObjectItem(prim, "attributes");
    const cJSON *mode = cJSON_GetObjectItem(prim, "mode"), *indices = cJSON_GetObjectItem(prim, "indices");
    int key[6] = {mode ? mode->valueint : 4, indices ? indices->valueint : -1};
    for (int k = 0; k < 4; k++) {
        const cJSON *a = cJSON_GetObjectItem(attributes, semantics[k]);
        key[2 + k] = a ? a->valueint : -1;
    }
    for (uint32_t i = 0; i < e->geometry_count; i++)
        if (memcmp(e->geometry[i], key, sizeof key) == 0)
            return 0;
    if (e->geometry_count < 4096)
        memcpy(e->geometry[e->geometry_count++], key, sizeof key);
    return 1;
}

static void walk(const cJSON *root, int node, expected *e)
{
    const cJSON *n = cJSON_GetArrayItem(cJSON_GetObjectItem(root, "nodes"), node);
    const cJSON *mesh = cJSON_GetObjectItem(n, "mesh"), *camera = cJSON_GetObjectItem(n, "camera");
    if (mesh) {
        const cJSON *m = cJSON_GetArrayItem(cJSON_GetObjectItem(root, "meshes"), mesh->valueint);
        for (const cJSON *prim = cJSON_GetObjectItem(m, "primitives")->child; prim; prim = prim->next) {
            if (!triangle_primitive(prim))
                continue;
            e->instances++;
            e->default_material |= cJSON_GetObjectItem(prim, "material") == NULL;
            if (new_geometry(prim, e))
                e->meshes++;
        }
    }
    if (camera) {
        const cJSON *cam = cJSON_GetArrayItem(cJSON_GetObjectItem(root, "cameras"), camera->valueint);
        const cJSON *type = cJSON_GetObjectItem(cam, "type");
        e->cameras += type && (strcmp(type->valuestring, "perspective") == 0 ||
                               strcmp(type->valuestring, "orthographic") == 0);
    }
    for (const cJSON *child = cJSON_GetObjectItem(n, "children") ? cJSON_GetObjectItem(n, "children")->child : NULL;
         child; child = child->next)
        walk(root, child->valueint, e);
}

static int expected_counts(const char *path, expected *e)
{
    memset(e, 0, sizeof *e);
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *data = malloc((size_t)size + 1);
    size_t got = fread(data, 1, (size_t)size, f);
    fclose(f);
    data[got] = 0;
    const char *json = data;
    size_t json_size = got;
    if (got >= 20 && memcmp(data, "glTF", 4) == 0) {
        uint32_t length;
        memcpy(&length, data + 12, 4);
        json = data + 20;
        json_size = length;
    }
    cJSON *root = cJSON_ParseWithLength(json, json_size);
    free(data);
    if (!root)
        return 0;
    const cJSON *scene = cJSON_GetObjectItem(root, "scene");
    const cJSON *s = cJSON_GetArrayItem(cJSON_GetObjectItem(root, "scenes"), scene ? scene->valueint : 0);
    for (const cJSON *n = s && cJSON_GetObjectItem(s, "nodes") ? cJSON_GetObjectItem(s, "nodes")->child : NULL; n;
         n = n->next)
        walk(root, n->valueint, e);
    e->materials = (uint32_t)cJSON_GetArraySize(cJSON_GetObjectItem(root, "materials")) + (e->default_material ? 1u : 0u);
    cJSON_Delete(root);
    return 1;
}

/* --- the walk over the folder ------------------------------------------------------------------ */

static unsigned files_total, files_imported, files_refused, files_warned;

static void check_file(const char *relative)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", ASSIMP_GLTF2_DIR, relative);
    collected warnings = {0};
    gdr_import_options options = {.warning = collect, .warning_user = &warnings, .no_progress = 1};
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_status status = gdr_import_gltf(path, &options, &scene, NULL, &err);
    files_total++;
    for (size_t i = 0; i < sizeof broken / sizeof broken[0]; i++)
        if (strcmp(relative, broken[i].file) == 0) {
            files_refused++;
            if (status != broken[i].status || !strstr(err.message, broken[i].place)) {
                fprintf(stderr, "%s: expected %s naming '%s', got %s: %s\n", relative,
                        gdr_status_name(broken[i].status), broken[i].place, gdr_status_name(status), err.message);
                test_failure_count++;
            } else {
                printf("refused  %-60s %s\n", relative, err.message + strlen(ASSIMP_GLTF2_DIR) + 1);
            }
            gdr_scene_destroy(scene);
            return;
        }
    if (status != GDR_OK) {
        fprintf(stderr, "%s: import failed: %s\n", relative, err.message);
        test_failure_count++;
        return;
    }
    files_imported++;
    int expect_warning = 0;
    for (size_t i = 0; i < sizeof warned / sizeof warned[0]; i++)
        if (strcmp(relative, warned[i].file) == 0) {
            expect_warning = 1;
            files_warned++;
            if (!strstr(warnings.text, warned[i].warning)) {
                fprintf(stderr, "%s: expected a warning containing '%s', got:\n%s", relative, warned[i].warning,
                        warnings.text);
                test_failure_count++;
            }
        }
    if (!expect_warning && warnings.count && !strstr(warnings.text, "texture left out")) {
        fprintf(stderr, "%s: unexpected warnings:\n%s", relative, warnings.text);
        test_failure_count++;
    }
    expected e;
    if (expected_counts(path, &e)) {
        if (scene->instance_count != e.instances || scene->mesh_count != e.meshes || scene->camera_count != e.cameras ||
            scene->material_count != e.materials) {
            fprintf(stderr, "%s: got %u instances, %u meshes, %u cameras, %u materials; the file declares %u, %u, %u, "
                    "%u\n", relative, scene->instance_count, scene->mesh_count, scene->camera_count,
                    scene->material_count, e.instances, e.meshes, e.cameras, e.materials);
            test_failure_count++;
        }
    }
    for (uint32_t i = 0; i < scene->mesh_count; i++)
        CHECK(scene->meshes[i].index_count % 3 == 0 && scene->meshes[i].index_count > 0);
    printf("imported %-60s %u meshes, %u instances, %llu triangles, %u textures%s\n", relative, scene->mesh_count,
           scene->instance_count, (unsigned long long)gdr_scene_triangle_count(scene), scene->texture_count,
           warnings.count ? " (warned)" : "");
    gdr_scene_destroy(scene);
}

static void scan(const char *relative)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", ASSIMP_GLTF2_DIR, relative);
    struct dirent **entries;
    int n = scandir(path, &entries, NULL, alphasort);
    for (int i = 0; i < n; i++) {
        const char *name = entries[i]->d_name;
        char child[2048];
        snprintf(child, sizeof child, "%s%s%s", relative, relative[0] ? "/" : "", name);
        size_t length = strlen(name);
        if (name[0] != '.') {
            char full[8192];
            struct stat st;
            snprintf(full, sizeof full, "%s/%s", ASSIMP_GLTF2_DIR, child);
            if (stat(full, &st) == 0 && S_ISDIR(st.st_mode))
                scan(child);
            else if ((length > 5 && strcmp(name + length - 5, ".gltf") == 0) ||
                     (length > 4 && strcmp(name + length - 4, ".glb") == 0))
                check_file(child);
        }
        free(entries[i]);
    }
    if (n >= 0)
        free(entries);
}

int main(void)
{
    struct stat st;
    if (stat(ASSIMP_GLTF2_DIR, &st) != 0) {
        printf("test_gltf_assimp: %s not found (install assimp-testmodels); skipped\n", ASSIMP_GLTF2_DIR);
        return 77;
    }
    scan("");
    printf("%u files: %u imported (%u with expected warnings), %u refused as expected\n", files_total,
           files_imported, files_warned, files_refused);
    CHECK(files_total >= 40);
    CHECK(files_refused == sizeof broken / sizeof broken[0]);
    return test_finish("test_gltf_assimp");
}
