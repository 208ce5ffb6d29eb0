/* Loading is linear: adding the instances of a scene and computing the culling library's bounds
 * of every instance (what the CPU pipeline builds on first use, and gdr_cull_objects_from_scene)
 * costs O(1) per instance, whatever the size of the instance's mesh: per-mesh work is done once
 * per mesh. Work is counted, not timed: instructions under valgrind's callgrind (collected only
 * inside load_instances), reproducible to the instruction. The program runs itself under valgrind
 * ("probe N T": N instances of a lod-field mesh of about T triangles) and compares the counts.
 * Skipped (77) where valgrind is not installed. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gdr/cull.h"
#include "gdr/procedural.h"
#include "gdr/scene.h"
#include "test_util.h"

#define SKIP 77

/* What is counted: N instances of mesh 0 added to `scene`, then their culling bounds. */
__attribute__((noinline)) static int load_instances(gdr_scene *scene, const gdr_instance *instances, uint32_t n,
                                                    gdr_cull_object *objects)
{
    gdr_error err = {0};
    for (uint32_t i = 0; i < n; i++)
        if (gdr_scene_add_instance(scene, &instances[i], &err) != GDR_OK)
            return 0;
    return gdr_cull_objects_from_scene(objects, scene, &err) == GDR_OK;
}

static int probe(uint32_t n, uint32_t triangles)
{
    /* The mesh of a lod-field scene, and N instances of it from another lod-field scene. */
    gdr_scene *field = NULL, *scene = NULL;
    gdr_error err = {0};
    if (gdr_scene_create_lod_field(&(gdr_lod_field_desc){.instances = n, .triangles = triangles}, &field, &err) !=
            GDR_OK ||
        gdr_scene_create(&scene, &err) != GDR_OK) {
        fprintf(stderr, "probe: %s\n", err.message);
        return 1;
    }
    const gdr_mesh *m = &field->meshes[0];
    if (gdr_scene_add_mesh(scene, m->name, m->positions, m->normals, m->uvs, m->vertex_count, m->indices,
                           m->index_count, NULL, &err) != GDR_OK) {
        fprintf(stderr, "probe: %s\n", err.message);
        return 1;
    }
    gdr_instance *instances = malloc(sizeof *instances * n);
    gdr_cull_object *objects = malloc(sizeof *objects * n);
    for (uint32_t i = 0; i < n; i++) {
        instances[i] = field->instances[i];
        instances[i].mesh = 0;
        instances[i].material = GDR_NO_INDEX;
    }
    int ok = load_instances(scene, instances, n, objects);
    free(instances);
    free(objects);
    gdr_scene_destroy(scene);
    gdr_scene_destroy(field);
    return ok ? 0 : 1;
}

/* Instructions of load_instances in a run of "probe n triangles" under callgrind; 0 on failure. */
static uint64_t count_instructions(const char *self, uint32_t n, uint32_t triangles)
{
    char out[256], command[1024];
    snprintf(out, sizeof out, "%s/callgrind-load-%u-%u.out", GDR_TEST_TMP, n, triangles);
    snprintf(command, sizeof command,
             "valgrind --tool=callgrind --collect-atstart=no --toggle-collect=load_instances "
             "--callgrind-out-file=%s %s probe %u %u > /dev/null 2>&1", out, self, n, triangles);
    if (system(command) != 0) {
        fprintf(stderr, "failed: %s\n", command);
        return 0;
    }
    FILE *f = fopen(out, "r");
    uint64_t total = 0;
    char line[512];
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "totals:", 7) == 0 || strncmp(line, "summary:", 8) == 0)
            total = strtoull(strchr(line, ':') + 1, NULL, 10);
    if (f)
        fclose(f);
    remove(out);
    printf("%6u instances of a %6u-triangle mesh: %10llu instructions\n", n, triangles, (unsigned long long)total);
    return total;
}

int main(int argc, char **argv)
{
    if (argc == 4 && strcmp(argv[1], "probe") == 0)
        return probe((uint32_t)strtoul(argv[2], NULL, 10), (uint32_t)strtoul(argv[3], NULL, 10));
    if (system("valgrind --version > /dev/null 2>&1") != 0) {
        printf("test_load_scaling: skipped: valgrind is not installed\n");
        return SKIP;
    }
    const uint32_t n = 1000, t = 2000;
    uint64_t w_n_t = count_instructions(argv[0], n, t), w_4n_t = count_instructions(argv[0], 4 * n, t);
    uint64_t w_n_4t = count_instructions(argv[0], n, 4 * t), w_4n_4t = count_instructions(argv[0], 4 * n, 4 * t);
    CHECK(w_n_t && w_4n_t && w_n_4t && w_4n_4t);
    if (!(w_n_t && w_4n_t && w_n_4t && w_4n_4t))
        return test_finish("test_load_scaling");
    /* 4x the instances: at most about 4x the work. */
    double ratio = (double)w_4n_t / (double)w_n_t, ratio_big = (double)w_4n_4t / (double)w_n_4t;
    printf("4x instances: %.2fx the work (%u-triangle mesh), %.2fx (%u-triangle mesh)\n", ratio, t, ratio_big, 4 * t);
    CHECK(ratio <= 4.2 && ratio_big <= 4.2);
    /* An instance costs the same whatever its mesh: the marginal cost per instance barely moves
     * when the mesh has 4x the triangles (a scan of the mesh per instance would make it 4x). */
    double per = (double)(w_4n_t - w_n_t) / (3.0 * n), per_big = (double)(w_4n_4t - w_n_4t) / (3.0 * n);
    printf("instructions per instance: %.0f (%u-triangle mesh), %.0f (%u-triangle mesh)\n", per, t, per_big, 4 * t);
    CHECK(per_big <= 1.1 * per);
    return test_finish("test_load_scaling");
}
