/* OBJ import: triangulation, negative indices, groups, missing attributes, errors with
 * file:line, and every OBJ file of assimp-testmodels imports or is refused cleanly. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/io.h"
#include "io_test_helpers.h"
#include "test_util.h"
#include "io/loaders.h"

static test_warnings warnings;
static gdr_error err;

static gdr_scene *import_text(const char *text)
{
    memset(&warnings, 0, sizeof warnings);
    gdr_import_options options = {.warning = test_collect_warning, .warning_user = &warnings, .no_progress = 1};
    gdr_scene *scene = NULL;
    if (gdr_import_obj_memory(text, strlen(text), "t.obj", &options, &scene, NULL, &err) != GDR_OK)
        return NULL;
    return scene;
}

static void test_basic(void)
{
    const char *text = "# a quad and a pentagon in two groups\n"
                       "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\r\n"
                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                       "vn 0 0 2\n"
                       "g first\n"
                       "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
                       "o second\n"
                       "v 2 0 0\nv 3 0 0\nv 3 1 0\nv 2.5 1.5 0\nv 2 1 0\n"
                       "f -5 -4 -3 -2 -1\n"
                       "s off\nusemtl x\nl 1 2\n";
    gdr_scene *s = import_text(text);
    CHECK(s != NULL);
    if (!s) {
        fprintf(stderr, "basic: %s\n", err.message);
        return;
    }
    CHECK(s->mesh_count == 2 && s->instance_count == 2);
    CHECK(strcmp(s->meshes[0].name, "first") == 0 && strcmp(s->meshes[1].name, "second") == 0);
    CHECK(s->meshes[0].vertex_count == 4 && s->meshes[0].index_count == 6);
    CHECK(s->meshes[1].vertex_count == 5 && s->meshes[1].index_count == 9);
    CHECK_NEAR(s->meshes[0].normals[0].z, 1.0, 1e-6);
    CHECK_NEAR(s->meshes[0].uvs[2].x, 1.0, 0);
    CHECK_NEAR(s->meshes[1].positions[3].x, 2.5, 0);
    CHECK_NEAR(s->meshes[1].normals[0].z, 1.0, 1e-6); /* generated: the pentagon faces +Z */
    CHECK(warnings.count == 1 && strstr(warnings.text, "t.obj:22: points and lines skipped"));
    gdr_scene_destroy(s);

    /* Shared corners are welded: a cube of 8 positions without normals or uvs. */
    s = import_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n");
    CHECK(s && s->mesh_count == 1 && s->meshes[0].vertex_count == 8 && s->meshes[0].index_count == 36);
    gdr_scene_destroy(s);
}

static void test_errors(void)
{
    /* Each refused as malformed (GDR_ERROR_PARSE), naming the file, the line and the keyword. */
    static const struct { const char *text, *place; } cases[] = {
        {"v 0 0 0\nv 1 0 0\nf 1 2 3\n", "t.obj:3: f: position index 3"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", "t.obj:4: f: position index -4"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "t.obj:4: f: position index 0"},
        {"v 0 0\n", "t.obj:1: v:"},
        {"\nv 0 nan 0\n", "t.obj:2: v: 'nan'"},
        {"v 0 x 0\n", "t.obj:1: v: 'x'"},
        {"v 1 1 1\nv 0 1 0\nv 0 0 1\nf 1/1 2/1 3/1\n", "t.obj:4: f: texture coordinate index 1"},
        {"v 1 1 1\nv 0 1 0\nv 0 0 1\nf 1//5 2//1 3//1\n", "t.obj:4: f: normal index 5"},
        {"v 1 1 1\nv 0 1 0\nv 0 0 1\nf 1/1/1/1 2 3\n", "t.obj:4: f: corner '1/1/1/1'"},
        {"v 1 1 1\nv 0 1 0\nv 0 0 1\nf 1 2 99999999999999999999999\n", "t.obj:4: f:"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        gdr_scene *s = import_text(cases[i].text);
        CHECK_STATUS(err, GDR_ERROR_PARSE);
        if (s || !strstr(err.message, cases[i].place)) {
            fprintf(stderr, "obj error case %zu: expected '%s', got '%s'\n", i, cases[i].place,
                    s ? "(success)" : err.message);
            test_failure_count++;
        }
        gdr_scene_destroy(s);
    }
    gdr_scene *s = import_text("v 0 0 0\nv 1 0 0\nf 1 2\n");
    CHECK(s && s->mesh_count == 0 && strstr(warnings.text, "t.obj:3: face with 2 corners skipped"));
    gdr_scene_destroy(s);
    const char utf16[] = "\xfe\xff\0v\0 \0001";
    memset(&warnings, 0, sizeof warnings);
    s = NULL;
    CHECK_FAILS(gdr_import_obj_memory(utf16, sizeof utf16, "u.obj", NULL, &s, NULL, &err), err, GDR_ERROR_UNSUPPORTED);
}

/* assimp's OBJ files: each imports or is refused with a message; never a crash. */
static void test_assimp_files(void)
{
    const char *dirs[] = {"/usr/share/assimp/models/OBJ", "/usr/share/assimp/models/invalid"};
    unsigned imported = 0, refused = 0;
    for (int d = 0; d < 2; d++) {
        struct dirent **entries;
        int n = scandir(dirs[d], &entries, NULL, alphasort);
        for (int i = 0; i < n; i++) {
            size_t length = strlen(entries[i]->d_name);
            if (length > 4 && strcmp(entries[i]->d_name + length - 4, ".obj") == 0) {
                char path[1024];
                snprintf(path, sizeof path, "%s/%s", dirs[d], entries[i]->d_name);
                gdr_scene *s = NULL;
                memset(&warnings, 0, sizeof warnings);
                gdr_import_options options = {.warning = test_collect_warning, .warning_user = &warnings,
                                              .no_progress = 1};
                if (gdr_import_obj(path, &options, &s, NULL, &err) == GDR_OK) {
                    imported++;
                    printf("imported %-40s %u meshes, %llu triangles%s\n", entries[i]->d_name, s->mesh_count,
                           (unsigned long long)gdr_scene_triangle_count(s), warnings.count ? " (warned)" : "");
                } else {
                    refused++;
                    CHECK_NAMES(err, entries[i]->d_name);
                    printf("refused  %-40s %s\n", entries[i]->d_name, strrchr(err.message, '/') + 1);
                }
                gdr_scene_destroy(s);
            }
            free(entries[i]);
        }
        if (n >= 0)
            free(entries);
    }
    printf("assimp OBJ files: %u imported, %u refused\n", imported, refused);
}

int main(void)
{
    test_basic();
    test_errors();
    test_assimp_files();
    return test_finish("test_obj");
}
