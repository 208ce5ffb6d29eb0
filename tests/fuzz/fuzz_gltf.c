/* libFuzzer target: glTF JSON and GLB from memory (external URIs are refused in memory). */
#include <stddef.h>
#include <stdint.h>

#include "gdr/io.h"
#include "fuzz_geometry.h"
#include "io/loaders.h"

static void ignore_warning(void *user, const char *message)
{
    (void)user;
    (void)message;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    gdr_import_options options = {.warning = ignore_warning, .no_progress = 1, .budget = fuzz_budget};
    gdr_scene *scene = NULL;
    gdr_error err;
    if (gdr_import_gltf_memory(data, size, "fuzz.gltf", NULL, &options, &scene, NULL, &err) == GDR_OK) {
        fuzz_build_geometry(scene);
        gdr_scene_destroy(scene);
    }
    return 0;
}
