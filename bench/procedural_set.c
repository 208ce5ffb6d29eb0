/* The procedural meshes the LOD benches share by name (procedural_set.h). */
#include "procedural_set.h"

#include <stdio.h>
#include <string.h>

#include "procedural/procedural_meshes.h"

int bench_procedural_mesh(gdr_scene *scene, const char *name, uint32_t *mesh, gdr_status *status, gdr_error *err)
{
    uint32_t u = 0, v = 0;
    if (!strcmp(name, "blob"))
        *status = gdr_procedural_blob(scene, 6, mesh, err);
    else if (!strcmp(name, "knot"))
        *status = gdr_procedural_torus_knot(scene, 500, 100, mesh, err);
    else if (!strcmp(name, "torus-1m"))
        *status = gdr_procedural_torus(scene, 1.0f, 0.35f, 1000, 500, mesh, err);
    else if (sscanf(name, "torus-%ux%u", &u, &v) == 2)
        *status = gdr_procedural_torus(scene, 1.0f, 0.35f, u, v, mesh, err);
    else
        return 0;
    return 1;
}
