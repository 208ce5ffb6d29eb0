/* Frustum planes from a view-projection matrix (Gribb-Hartmann), normalised and permuted. */
#include <math.h>

#include "cull/cull_internal.h"

/* Row r of a column-major matrix as a plane (x, y, z, w coefficients). */
static gdr_vec4 matrix_row(const gdr_mat4 *m, int r)
{
    return (gdr_vec4){m->m[r], m->m[4 + r], m->m[8 + r], m->m[12 + r]};
}

static gdr_vec4 add4(gdr_vec4 a, gdr_vec4 b) { return (gdr_vec4){a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w}; }
static gdr_vec4 sub4(gdr_vec4 a, gdr_vec4 b) { return (gdr_vec4){a.x - b.x, a.y - b.y, a.z - b.z, a.w - b.w}; }

gdr_frustum gdr_frustum_from_matrix(gdr_mat4 view_projection)
{
    gdr_vec4 r0 = matrix_row(&view_projection, 0), r1 = matrix_row(&view_projection, 1);
    gdr_vec4 r2 = matrix_row(&view_projection, 2), r3 = matrix_row(&view_projection, 3);
    /* A clip-space point is inside when -w <= x <= w, -w <= y <= w and 0 <= z <= w; each bound
     * is a plane in world space once the rows are combined. */
    gdr_vec4 raw[6] = {add4(r3, r0), sub4(r3, r0), add4(r3, r1), sub4(r3, r1), r2, sub4(r3, r2)};

    gdr_frustum f = {0};
    for (int i = 0; i < 6; i++) {
        double len = sqrt((double)raw[i].x * raw[i].x + (double)raw[i].y * raw[i].y + (double)raw[i].z * raw[i].z);
        /* A vanishing normal (relative to the plane's offset) is the far plane of an infinite
         * projection: it is satisfied everywhere, so it is dropped. */
        if (!(len > 1e-12 * fabs((double)raw[i].w)) || len == 0.0) {
            if (raw[i].w < 0.0f) /* satisfied nowhere: keep a plane that rejects everything */
                f.planes[f.plane_count++] = (gdr_vec4){0.0f, 0.0f, 0.0f, -1.0f};
            continue;
        }
        float inv = (float)(1.0 / len);
        f.planes[f.plane_count++] = (gdr_vec4){raw[i].x * inv, raw[i].y * inv, raw[i].z * inv, raw[i].w * inv};
    }
    for (int i = 0; i < 8; i++) {
        /* unused lanes: 0 x + 0 y + 0 z + 1 >= anything the tests compare with */
        gdr_vec4 p = i < (int)f.plane_count ? f.planes[i] : (gdr_vec4){0.0f, 0.0f, 0.0f, INFINITY};
        f.px[i] = p.x;
        f.py[i] = p.y;
        f.pz[i] = p.z;
        f.pd[i] = p.w;
    }
    return f;
}
