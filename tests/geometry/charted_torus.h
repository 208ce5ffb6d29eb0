/* A generated UV-mapped mesh for the LOD tests: a torus cut into CHARTED_TORUS_CHARTS_U x
 * CHARTED_TORUS_CHARTS_V charts, every chart with its own vertices (every chart border a uv seam,
 * every chart corner a position held by four vertices), half of the charts with uvs mirrored in u,
 * and every other row of charts with tilted normals (a hard normal edge along each row border).
 * Each chart's uvs fill its own tile of a CHARTED_TORUS_CHARTS_U x CHARTED_TORUS_CHARTS_V atlas.
 * Used by tests/geometry/test_lod_seams.c (the DAG) and tests/gpu/test_gpu_lod_texture.c (the
 * image); header-only, so that each test links nothing more. */
#ifndef GDR_TEST_CHARTED_TORUS_H
#define GDR_TEST_CHARTED_TORUS_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/scene.h"
#include "procedural/procedural_meshes.h"

#define CHARTED_TORUS_CHARTS_U 12u
#define CHARTED_TORUS_CHARTS_V 6u

static inline void charted_torus_check(gdr_status s, const gdr_error *err, const char *what)
{
    if (s != GDR_OK) {
        fprintf(stderr, "%s: %s\n", what, err->message);
        exit(1);
    }
}

/* Adds to s a torus of `segments` x `sides` quads (major radius 1, minor 0.35) whose triangles are
 * cut into charts (a cell of the charts grid in the torus's own uv), each chart with its own copy of
 * every vertex it uses: uv in the chart's atlas tile (mirrored in u on odd charts), the smooth
 * normal, except that odd chart rows tilt theirs (a hard normal edge along each row border).
 * Returns the new mesh's index. */
static inline uint32_t add_charted_torus(gdr_scene *s, uint32_t segments, uint32_t sides)
{
    gdr_scene *t = NULL;
    gdr_error err = {0};
    uint32_t torus;
    charted_torus_check(gdr_scene_create(&t, &err), &err, "scene");
    charted_torus_check(gdr_procedural_torus(t, 1.0f, 0.35f, segments, sides, &torus, &err), &err, "torus");
    const gdr_mesh *m = &t->meshes[torus];
    uint32_t n = m->index_count;
    gdr_vec3 *p = malloc(sizeof *p * n), *nr = malloc(sizeof *nr * n);
    gdr_vec2 *uv = malloc(sizeof *uv * n);
    uint32_t *idx = malloc(sizeof *idx * n);
    const uint32_t nu = CHARTED_TORUS_CHARTS_U, nv = CHARTED_TORUS_CHARTS_V;
    const size_t charts = (size_t)nu * nv;
    uint32_t *slot = malloc(sizeof *slot * m->vertex_count * charts);
    memset(slot, 0xff, sizeof *slot * m->vertex_count * charts);
    uint32_t count = 0;
    for (uint32_t i = 0; i < n; i += 3) {
        /* the chart of the triangle's centre, in the torus's (seam-free) parameter */
        float cu = 0.0f, cv = 0.0f;
        for (int k = 0; k < 3; k++) {
            gdr_vec3 q = m->positions[m->indices[i + k]];
            cu += atan2f(q.z, q.x);
            float ring = sqrtf(q.x * q.x + q.z * q.z) - 1.0f;
            cv += atan2f(q.y, ring);
        }
        /* centres of triangles spanning the angle's wrap fall back into range below */
        float fu = cu / 3.0f / 6.2831853f + 0.5f, fv = cv / 3.0f / 6.2831853f + 0.5f;
        uint32_t gu = (uint32_t)(fu * nu) % nu, gv = (uint32_t)(fv * nv) % nv;
        uint32_t chart = gv * nu + gu;
        for (int k = 0; k < 3; k++) {
            uint32_t v = m->indices[i + k];
            uint32_t *sl = &slot[(size_t)v * charts + chart];
            if (*sl == UINT32_MAX) {
                gdr_vec3 q = m->positions[v];
                float lu = atan2f(q.z, q.x) / 6.2831853f + 0.5f, ring = sqrtf(q.x * q.x + q.z * q.z) - 1.0f;
                float lv = atan2f(q.y, ring) / 6.2831853f + 0.5f;
                lu = lu * nu - (float)gu, lv = lv * nv - (float)gv;
                lu -= roundf(lu - 0.5f), lv -= roundf(lv - 0.5f); /* into the chart's cell across the wrap */
                if (chart % 2)
                    lu = 1.0f - lu;
                *sl = count;
                p[count] = q;
                uv[count] = (gdr_vec2){((float)gu + lu) / nu, ((float)gv + lv) / nv};
                gdr_vec3 nn = m->normals[v];
                if (gv % 2) {
                    nn = (gdr_vec3){nn.x + 0.5f, nn.y, nn.z};
                    float l = sqrtf(nn.x * nn.x + nn.y * nn.y + nn.z * nn.z);
                    nn = (gdr_vec3){nn.x / l, nn.y / l, nn.z / l};
                }
                nr[count++] = nn;
            }
            idx[i + k] = *sl;
        }
    }
    uint32_t out = 0;
    charted_torus_check(gdr_scene_add_mesh(s, "charted", p, nr, uv, count, idx, n, &out, &err), &err, "charted torus");
    free(p), free(nr), free(uv), free(idx), free(slot);
    gdr_scene_destroy(t);
    return out;
}

#endif
