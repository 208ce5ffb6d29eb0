/* The cluster records (GdrGpuMeshlet) of a scene. A scene of a billion source triangles holds about
 * 23 million clusters: building their records one by one on one thread is a large part of the
 * renderer's set-up, so they are built in chunks on a thread pool. Each chunk is a range of global
 * record indices; each record is written from its own cluster and groups alone, so the output does
 * not depend on the chunking or the order the threads run in. */
#include "render/cluster_records.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h" /* gdr_lod_enclosing_sphere */

GdrGpuMeshlet gdr_cluster_record(const gdr_mesh_clusters *c, uint32_t i, uint32_t vertex_base, uint32_t byte_base)
{
    return gdr_cluster_record_of(c, &c->clusters[i], vertex_base, byte_base);
}

GdrGpuMeshlet gdr_cluster_record_of(const gdr_mesh_clusters *c, const gdr_cluster *k, uint32_t vertex_base,
                                    uint32_t byte_base)
{
    GdrGpuMeshlet m = {
        .vertex_offset = vertex_base + k->vertex_offset, .triangle_offset = byte_base + k->triangle_offset,
        .vertex_count = k->vertex_count, .triangle_count = k->triangle_count, .sphere = k->sphere,
        .cone_apex = k->cone_apex, .cone_cutoff = k->cone_cutoff, .cone_axis = k->cone_axis,
        .group = k->group, .refined_group = k->refined_group,
        .group_depth = 0, .refined_depth = -1, .group_error = INFINITY, .refined_error = 0.0f};
    if (k->group != GDR_NO_INDEX && k->group < c->group_count) {
        const gdr_cluster_group *g = &c->groups[k->group];
        m.group_depth = (int32_t)g->depth;
        m.group_sphere = g->sphere;
        m.group_error = g->error;
    }
    if (k->refined_group != GDR_NO_INDEX && k->refined_group < c->group_count) {
        const gdr_cluster_group *g = &c->groups[k->refined_group];
        m.refined_depth = (int32_t)g->depth;
        m.refined_sphere = g->sphere;
        m.refined_error = g->error;
    }
    return m;
}

typedef struct fill_job {
    GdrGpuMeshlet *out;
    const gdr_cluster_record_layout *layout;
    uint64_t total;
    uint32_t chunk;
} fill_job;

/* The mesh holding global record `at`: the last mesh whose first record is at or before it and that
 * holds clusters (binary search over the ascending first records). */
static uint32_t mesh_of(const gdr_cluster_record_layout *l, uint64_t at)
{
    uint32_t lo = 0, hi = l->mesh_count;
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (l->first[mid] <= at)
            lo = mid;
        else
            hi = mid;
    }
    while (lo + 1 < l->mesh_count && (uint64_t)l->first[lo] + l->clusters[lo]->cluster_count <= at)
        lo++; /* meshes without clusters share their first record with the next one */
    return lo;
}

/* Records [task * chunk, (task + 1) * chunk) of the whole, across meshes where the range spans them. */
static void fill_chunk(void *user, uint32_t task, uint32_t worker)
{
    (void)worker;
    const fill_job *job = user;
    const gdr_cluster_record_layout *l = job->layout;
    uint64_t at = (uint64_t)task * job->chunk;
    uint64_t end = at + job->chunk < job->total ? at + job->chunk : job->total;
    for (uint32_t m = mesh_of(l, at); at < end && m < l->mesh_count; m++) {
        const gdr_mesh_clusters *c = l->clusters[m];
        for (uint32_t i = (uint32_t)(at - l->first[m]); i < c->cluster_count && at < end; i++, at++) {
            job->out[at] = gdr_cluster_record(c, i, l->vertex_base[m], l->byte_base[m]);
            job->out[at].cluster_id = (uint32_t)at;
        }
    }
}

void gdr_cluster_records_fill(GdrGpuMeshlet *out, const gdr_cluster_record_layout *layout, uint32_t chunk,
                              gdr_thread_pool *pool)
{
    uint64_t total = 0;
    for (uint32_t m = 0; m < layout->mesh_count; m++)
        total += layout->clusters[m]->cluster_count;
    if (total == 0)
        return;
    fill_job job = {out, layout, total, chunk ? chunk : 1};
    uint64_t tasks = (total + job.chunk - 1) / job.chunk;
    if (!pool) {
        for (uint64_t t = 0; t < tasks; t++)
            fill_chunk(&job, (uint32_t)t, 0);
        return;
    }
    gdr_thread_pool_run(pool, (uint32_t)tasks, fill_chunk, &job);
}

/* One buffer of cluster spheres for every leaf of the scene, grown to the largest leaf, instead of
 * an allocation per leaf. */
typedef struct sphere_scratch {
    gdr_vec4 *spheres;
    uint32_t capacity;
} sphere_scratch;

/* Room for `count` spheres, or NULL without memory (the leaf keeps its LOD sphere, which holds them). */
static gdr_vec4 *scratch_spheres(sphere_scratch *s, uint32_t count)
{
    if (count > s->capacity) {
        gdr_vec4 *grown = realloc(s->spheres, sizeof *grown * count);
        if (!grown)
            return NULL;
        s->spheres = grown;
        s->capacity = count;
    }
    return s->spheres;
}

/* Mesh c's nodes for the GPU: each gdr_lod_node's bytes, then its culling sphere, which encloses its
 * clusters' spheres (leaf) or its children's culling spheres (inner node). Children follow their
 * parent in the array (the root is node 0), so one pass from the end finds every child's first;
 * a node whose children do not follow it keeps its LOD sphere, which also holds them. */
static void mesh_node_records(const gdr_mesh_clusters *c, GdrGpuLodNode *out, sphere_scratch *scratch)
{
    gdr_vec4 spheres[GDR_LOD_NODE_MAX_CHILDREN];
    for (uint32_t n = c->lod_node_count; n-- > 0;) {
        const gdr_lod_node *node = &c->lod_nodes[n];
        memcpy(&out[n], node, sizeof *node);
        out[n].bounds = node->sphere;
        bool leaf = (node->flags & GDR_LOD_NODE_LEAF) != 0;
        if (leaf && !c->clusters) { /* read for streaming: the file holds the bounds of a group's clusters */
            if (c->group_bounds && node->group < c->group_count)
                out[n].bounds = c->group_bounds[node->group];
        } else if (leaf && (uint64_t)node->first + node->count <= c->cluster_count) {
            gdr_vec4 *cluster_spheres = scratch_spheres(scratch, node->count);
            for (uint32_t i = 0; cluster_spheres && i < node->count; i++)
                cluster_spheres[i] = c->clusters[node->first + i].sphere;
            if (cluster_spheres && node->count)
                out[n].bounds = gdr_lod_enclosing_sphere(cluster_spheres, node->count);
        } else if (!leaf && node->first > n && node->count <= GDR_LOD_NODE_MAX_CHILDREN &&
                   (uint64_t)node->first + node->count <= c->lod_node_count && node->count) {
            for (uint32_t i = 0; i < node->count; i++)
                spheres[i] = out[node->first + i].bounds;
            out[n].bounds = gdr_lod_enclosing_sphere(spheres, node->count);
        }
    }
}

typedef struct node_job {
    GdrGpuLodNode *out;
    const gdr_mesh_clusters *const *clusters;
    const uint32_t *first;
    sphere_scratch *scratch; /* per worker */
} node_job;

static void node_task(void *user, uint32_t mesh, uint32_t worker)
{
    const node_job *job = user;
    mesh_node_records(job->clusters[mesh], job->out + job->first[mesh], &job->scratch[worker]);
}

void gdr_lod_node_records_fill(GdrGpuLodNode *out, const gdr_mesh_clusters *const *clusters, const uint32_t *first,
                               uint32_t mesh_count, gdr_thread_pool *pool)
{
    uint32_t workers = pool ? gdr_thread_pool_thread_count(pool) : 1;
    sphere_scratch *scratch = pool ? calloc(workers, sizeof *scratch) : NULL;
    sphere_scratch one = {0};
    node_job job = {out, clusters, first, scratch ? scratch : &one};
    if (scratch && mesh_count > 1) {
        gdr_thread_pool_run(pool, mesh_count, node_task, &job);
    } else {
        for (uint32_t m = 0; m < mesh_count; m++)
            node_task(&job, m, 0);
    }
    for (uint32_t w = 0; scratch && w < workers; w++)
        free(scratch[w].spheres);
    free(scratch);
    free(one.spheres);
}
