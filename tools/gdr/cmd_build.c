/* gdr build INPUT -o OUTPUT.gdrc: import a scene (or build the demo) and write the cache. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "gdr/io.h"

static void build_usage(void)
{
    fputs("usage: gdr build INPUT -o OUTPUT.gdrc [--no-progress]\n"
          "  INPUT: a .gltf, .glb or .obj file, a .gdrc cache, or a built-in scene: 'demo', 'lod-field'\n"
          "         or 'occlusion', each with optional ':key=value,...' (see gdr --help)\n",
          stderr);
}

int gdr_cmd_build(int argc, char **argv)
{
    const char *input = NULL, *output = NULL;
    int no_progress = 0;
    for (int i = 1; i < argc; i++) {
        if ((strcmp(argv[i], "-o") == 0 || strcmp(argv[i], "--out") == 0) && i + 1 < argc) {
            output = argv[++i];
        } else if (strcmp(argv[i], "--no-progress") == 0) {
            no_progress = 1;
        } else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            build_usage();
            return 0;
        } else if (argv[i][0] == '-' || input) {
            fprintf(stderr, "gdr: build: unexpected argument '%s'\n", argv[i]);
            build_usage();
            return 2;
        } else {
            input = argv[i];
        }
    }
    if (!input || !output) {
        build_usage();
        return 2;
    }
    gdr_error err = {0};
    gdr_scene *scene = NULL;
    gdr_source_list sources = {0};
    gdr_status status;
    int is_builtin = gdr_scene_spec_is_builtin(input);
    size_t length = strlen(input);
    if (is_builtin || (length > 5 && strcmp(input + length - 5, ".gdrc") == 0)) {
        gdr_load_options load = {.no_cache = 1, .no_progress = no_progress};
        status = gdr_scene_load_ex(input, &load, &scene, &err);
    } else {
        gdr_import_options import = {.no_progress = no_progress, .sources = &sources};
        status = gdr_import_file(input, &import, &scene, NULL, &err);
    }
    if (status == GDR_OK) {
        gdr_cache_source source = {gdr_cache_build_options(), &sources};
        status = gdr_cache_write(output, scene, &source, &err);
    }
    if (status == GDR_OK)
        printf("%s: %u meshes, %u instances, %llu triangles, %u materials, %u textures, %u cameras\n", output,
               scene->mesh_count, scene->instance_count, (unsigned long long)gdr_scene_triangle_count(scene),
               scene->material_count, scene->texture_count, scene->camera_count);
    else
        fprintf(stderr, "gdr: %s\n", err.message);
    gdr_source_list_free(&sources);
    gdr_scene_destroy(scene);
    return status == GDR_OK ? 0 : 1;
}
