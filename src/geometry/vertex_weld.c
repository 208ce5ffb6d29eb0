/* Vertices whose attributes are all bit-equal made one before clustering: some exporters write
 * every triangle with its own three vertices, and a cluster of 64 such vertices holds 21
 * triangles where a welded one holds up to 124; the LOD DAG finds no shared edges between them
 * and builds no coarser level (docs/GEOMETRY.md, "Welding equal vertices"). */
#include <stdlib.h>

#include <meshoptimizer.h>

#include "geometry/vertex_weld.h"

_Static_assert(sizeof(gdr_vec3) == 12 && sizeof(gdr_vec2) == 8 && sizeof(gdr_vec4) == 16,
               "attributes are compared as their bytes: no padding");

/* How many triangle corners use each vertex. Returns 0 when an index is out of range. */
static int count_uses(const gdr_mesh *mesh, uint32_t *uses)
{
    for (uint32_t i = 0; i < mesh->index_count; i++) {
        if (mesh->indices[i] >= mesh->vertex_count)
            return 0;
        uses[mesh->indices[i]]++;
    }
    return 1;
}

/* On entry remap[v] is v's class (its bit-equal vertices, classes numbered in the order of their
 * first vertex); on return it is v's new vertex: the class's latest copy while that copy serves
 * at most GDR_WELD_MAX_VERTEX_USES corners with v's, else a new copy. New vertices are numbered
 * in the order of their first old vertex. Returns the new vertex count. */
static uint32_t cap_uses(uint32_t *remap, const uint32_t *uses, uint32_t n, uint32_t classes, uint32_t *copy_of_class,
                         uint32_t *copy_uses)
{
    for (uint32_t c = 0; c < classes; c++)
        copy_of_class[c] = UINT32_MAX;
    uint32_t next = 0;
    for (uint32_t v = 0; v < n; v++) {
        uint32_t c = remap[v], copy = copy_of_class[c];
        if (copy != UINT32_MAX && (uint64_t)copy_uses[copy] + uses[v] <= GDR_WELD_MAX_VERTEX_USES) {
            copy_uses[copy] += uses[v];
        } else {
            copy = next++;
            copy_uses[copy] = uses[v];
            copy_of_class[c] = copy;
        }
        remap[v] = copy;
    }
    return next;
}

/* Every attribute array and the index buffer through remap, onto `count` vertices. All new arrays
 * are allocated before any is replaced, so that running out of memory leaves the mesh whole. */
static gdr_status apply_remap(gdr_mesh *m, const uint32_t *remap, uint32_t count)
{
    gdr_vec3 *p = malloc(sizeof *p * count), *nn = m->normals ? malloc(sizeof *nn * count) : NULL;
    gdr_vec2 *t = m->uvs ? malloc(sizeof *t * count) : NULL;
    gdr_vec4 *c = m->colors ? malloc(sizeof *c * count) : NULL;
    if (!p || (m->normals && !nn) || (m->uvs && !t) || (m->colors && !c)) {
        free(p), free(nn), free(t), free(c);
        return GDR_ERROR_OUT_OF_MEMORY;
    }
    meshopt_remapVertexBuffer(p, m->positions, m->vertex_count, sizeof *p, remap);
    if (nn)
        meshopt_remapVertexBuffer(nn, m->normals, m->vertex_count, sizeof *nn, remap);
    if (t)
        meshopt_remapVertexBuffer(t, m->uvs, m->vertex_count, sizeof *t, remap);
    if (c)
        meshopt_remapVertexBuffer(c, m->colors, m->vertex_count, sizeof *c, remap);
    meshopt_remapIndexBuffer(m->indices, m->indices, m->index_count, remap);
    free(m->positions), free(m->normals), free(m->uvs), free(m->colors);
    m->positions = p, m->normals = nn, m->uvs = t, m->colors = c;
    m->vertex_count = count;
    return GDR_OK;
}

/* The streams the weld compares: every attribute the mesh has. Returns how many. */
static size_t attribute_streams(const gdr_mesh *m, struct meshopt_Stream *streams)
{
    size_t k = 0;
    streams[k++] = (struct meshopt_Stream){m->positions, sizeof(gdr_vec3), sizeof(gdr_vec3)};
    if (m->normals)
        streams[k++] = (struct meshopt_Stream){m->normals, sizeof(gdr_vec3), sizeof(gdr_vec3)};
    if (m->uvs)
        streams[k++] = (struct meshopt_Stream){m->uvs, sizeof(gdr_vec2), sizeof(gdr_vec2)};
    if (m->colors)
        streams[k++] = (struct meshopt_Stream){m->colors, sizeof(gdr_vec4), sizeof(gdr_vec4)};
    return k;
}

/* remap[v]: the class of vertex v, the vertices bit-equal to it, classes numbered in the order of
 * their first vertex. Returns the number of classes, 0 when out of memory. meshoptimizer numbers
 * them in the order of an index buffer whose length is a multiple of 3: every vertex in order
 * (used or not), the last repeated up to twice. */
static uint32_t vertex_classes(const gdr_mesh *mesh, uint32_t *remap)
{
    uint32_t n = mesh->vertex_count;
    size_t count = ((size_t)n + 2) / 3 * 3;
    uint32_t *order = malloc(sizeof *order * count);
    if (!order)
        return 0;
    for (size_t i = 0; i < count; i++)
        order[i] = i < n ? (uint32_t)i : n - 1;
    struct meshopt_Stream streams[4];
    size_t stream_count = attribute_streams(mesh, streams);
    size_t classes = meshopt_generateVertexRemapMulti(remap, order, count, n, streams, stream_count);
    free(order);
    return (uint32_t)classes;
}

gdr_status gdr_mesh_weld_vertices(gdr_mesh *mesh, uint32_t *welded, gdr_error *err)
{
    if (welded)
        *welded = 0;
    uint32_t n = mesh->vertex_count;
    if (n < 2 || !mesh->positions || !mesh->indices || mesh->clusters.cluster_count)
        return GDR_OK;
    uint32_t *remap = malloc(sizeof *remap * n), *uses = calloc(n, sizeof *uses);
    uint32_t *copy_of_class = NULL, *copy_uses = NULL;
    gdr_status status = GDR_ERROR_OUT_OF_MEMORY;
    if (!remap || !uses)
        goto done;
    status = GDR_OK;
    if (!count_uses(mesh, uses))
        goto done; /* a bad index: gdr_meshlets_build names it */
    uint32_t classes = vertex_classes(mesh, remap);
    status = classes ? GDR_OK : GDR_ERROR_OUT_OF_MEMORY;
    if (classes == 0 || classes == n)
        goto done; /* already welded: untouched, bit for bit */
    copy_of_class = malloc(sizeof *copy_of_class * classes);
    copy_uses = malloc(sizeof *copy_uses * n);
    status = copy_of_class && copy_uses ? GDR_OK : GDR_ERROR_OUT_OF_MEMORY;
    uint32_t count = status == GDR_OK ? cap_uses(remap, uses, n, classes, copy_of_class, copy_uses) : n;
    if (count < n)
        status = apply_remap(mesh, remap, count);
    if (status == GDR_OK && welded)
        *welded = n - count;
done:
    free(remap), free(uses), free(copy_of_class), free(copy_uses);
    if (status != GDR_OK)
        return gdr_error_set(err, status, "mesh '%s': out of memory welding equal vertices", mesh->name);
    return GDR_OK;
}
