/* The cluster LOD DAG (seed 004): group neighbouring clusters with METIS, merge and
 * simplify each group with its shared border locked (meshoptimizer), split the result into new
 * clusters, repeat up to a root. The contract (and the cut rule it serves) is in gdr/geometry.h;
 * docs/GEOMETRY.md explains the choices.
 *
 * Determinism: the groups of one step are simplified in parallel, each task writing only its own
 * result; results are appended in group order by the calling thread, and METIS runs with a fixed
 * seed on the calling thread. A step's only group measures its samples in parallel ranges whose
 * results are then taken in sample order, as one thread would. The bytes produced do not depend on
 * the thread count. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geometry/lod_internal.h"

/* Smallest group error, relative to the mesh's bounding radius: errors are > 0, so threshold 0
 * selects level 0 even where simplification was exact (flat areas). */
#define LOD_MIN_ERROR_SCALE 1e-6f
#define LOD_MAX_GROUP_SIZE 32u
/* Groups of about 16 level-0 clusters' worth of triangles: measured against 4 and 8 in
 * docs/GEOMETRY.md (fewer half-empty clusters, fewer triangles at the same deviation). */
#define LOD_DEFAULT_GROUP_SIZE 16u
/* Meshes with fewer triangles are built side by side, one per task, by gdr_scene_build_lod. */
#define LOD_SMALL_MESH_TRIANGLES 65536u

/* Grows *p to hold at least `need` elements of `size` bytes; returns 0 when out of memory. An eighth
 * more than asked, not the next power of two: the workers' scratch arrays reach their largest size
 * on the groups near the DAG's root, which gather most of the mesh, and doubling would leave up to
 * half of that unused at the build's peak. */
int gdr_lod_reserve(void *pp, size_t *cap, size_t need, size_t size)
{
    void **p = pp;
    if (need <= *cap)
        return 1;
    size_t n = need + need / 8;
    n = n < 16 ? 16 : n;
    void *q = realloc(*p, n * size);
    if (!q)
        return 0;
    *p = q;
    *cap = n;
    return 1;
}

void gdr_lod_progress_add(lod_build *b, uint64_t amount, uint32_t worker)
{
    if (!b->progress)
        return;
    atomic_fetch_add(&b->progress_given, amount);
    uint64_t done = atomic_fetch_add(&b->progress->done, amount) + amount;
    if (b->worker_base + worker == 0)
        gdr_progress_update(&b->progress->bar, done);
}

/* --- one mesh ----------------------------------------------------------------------------------- */

static int push_group(lod_build *b, gdr_cluster_group g)
{
    if (!gdr_lod_reserve(&b->groups, &b->group_cap, b->group_count + 1, sizeof *b->groups))
        return 0;
    b->groups[b->group_count++] = g;
    return 1;
}

static int push_cluster(lod_build *b, gdr_cluster c)
{
    if (!gdr_lod_reserve(&b->clusters, &b->cluster_cap, b->cluster_count + 1, sizeof *b->clusters))
        return 0;
    b->clusters[b->cluster_count++] = c;
    return 1;
}

/* Appends a formed group's clusters, made from group `group`, to the build (from
 * r->first_cluster on) and frees r's copy of them. */
static int append_result(lod_build *b, group_result *r, uint32_t group, uint32_t *frontier, uint32_t *frontier_count)
{
    if (!gdr_lod_reserve(&b->vertices, &b->vertex_cap, b->vertex_count + r->vertex_count, sizeof *b->vertices) ||
        !gdr_lod_reserve(&b->triangles, &b->triangle_cap, b->triangle_bytes + r->triangle_bytes, 1) ||
        b->vertex_count + r->vertex_count > UINT32_MAX || b->triangle_bytes + r->triangle_bytes > UINT32_MAX)
        return 0;
    r->first_cluster = (uint32_t)b->cluster_count;
    for (uint32_t i = 0; i < r->cluster_count; i++) {
        gdr_cluster c = r->clusters[i];
        c.vertex_offset += (uint32_t)b->vertex_count;
        c.triangle_offset += (uint32_t)b->triangle_bytes;
        c.refined_group = group;
        frontier[(*frontier_count)++] = (uint32_t)b->cluster_count;
        if (!push_cluster(b, c))
            return 0;
    }
    memcpy(b->vertices + b->vertex_count, r->vertices, (size_t)r->vertex_count * sizeof *b->vertices);
    memcpy(b->triangles + b->triangle_bytes, r->triangles, r->triangle_bytes);
    b->vertex_count += r->vertex_count;
    b->triangle_bytes += r->triangle_bytes;
    free(r->clusters);
    free(r->vertices);
    free(r->triangles);
    r->clusters = NULL;
    r->vertices = NULL;
    r->triangles = NULL;
    return 1;
}

/* Forms the root group over the frontier. */
static int form_root(lod_build *b, uint32_t depth)
{
    lod_scratch *s = &b->scratch[0];
    if (!gdr_lod_reserve(&s->spheres, &s->spheres_cap, (size_t)b->frontier_count * 2, sizeof *s->spheres))
        return 0;
    uint32_t n = 0;
    for (uint32_t f = 0; f < b->frontier_count; f++) {
        const gdr_cluster *c = &b->clusters[b->frontier[f]];
        s->spheres[n++] = c->sphere;
        if (c->refined_group != GDR_NO_INDEX)
            s->spheres[n++] = b->groups[c->refined_group].sphere;
        b->stats.root_triangles += c->triangle_count;
    }
    uint32_t root = (uint32_t)b->group_count;
    if (!push_group(b, (gdr_cluster_group){.sphere = gdr_lod_enclosing_sphere(s->spheres, n), .error = INFINITY,
                                           .depth = depth}))
        return 0;
    for (uint32_t f = 0; f < b->frontier_count; f++)
        b->clusters[b->frontier[f]].group = root;
    b->stats.root_clusters = b->frontier_count;
    return 1;
}

/* Groups are the non-empty parts, in order: fills members (frontier clusters ordered by group,
 * stably) and start (group g: members[start[g] .. start[g + 1])); returns the group count. part
 * is rewritten from parts to groups. */
static uint32_t group_members(const lod_build *b, int32_t *part, uint32_t parts, uint32_t *members, uint32_t *start)
{
    uint32_t n = b->frontier_count;
    memset(start, 0, ((size_t)parts + 1) * sizeof *start);
    for (uint32_t f = 0; f < n; f++)
        start[part[f]]++; /* members per part */
    uint32_t groups = 0;
    for (uint32_t p = 0; p < parts; p++) {
        uint32_t size = start[p];
        start[p] = groups; /* part -> group */
        groups += size > 0;
    }
    for (uint32_t f = 0; f < n; f++)
        part[f] = (int32_t)start[part[f]];
    memset(start, 0, ((size_t)parts + 1) * sizeof *start);
    for (uint32_t f = 0; f < n; f++)
        start[part[f] + 1]++;
    for (uint32_t g = 0; g < groups; g++)
        start[g + 1] += start[g];
    for (uint32_t f = 0; f < n; f++)
        members[start[part[f]]++] = b->frontier[f];
    for (uint32_t g = groups; g > 0; g--) /* start[g] now holds the end of group g: shift back */
        start[g] = start[g - 1];
    start[0] = 0;
    return groups;
}

/* One step's groups, from their partition until their errors are set. */
typedef struct lod_stage {
    uint32_t depth;
    uint32_t parts, groups;
    int32_t *part;             /* frontier cluster -> part, until grouped */
    uint32_t *members, *start; /* group g: members[start[g] .. start[g + 1]) */
    group_result *results;     /* parts entries */
    uint32_t *measured;        /* the groups that formed, in order: their deviation is measured */
    uint32_t measured_count;
} lod_stage;

static void stage_free(lod_stage *st)
{
    if (st->results)
        for (uint32_t g = 0; g < st->parts; g++)
            gdr_lod_result_free(&st->results[g]);
    free(st->results);
    free(st->part);
    free(st->members);
    free(st->start);
    free(st->measured);
    memset(st, 0, sizeof *st);
}

/* Marks in b->owner the positions that more than one group of the step uses (clear: resets them). */
static void mark_shared(lod_build *b, const lod_stage *st, int clear)
{
    for (uint32_t g = 0; g < st->groups; g++)
        for (uint32_t i = st->start[g]; i < st->start[g + 1]; i++) {
            const gdr_cluster *c = &b->clusters[st->members[i]];
            const uint32_t *v = gdr_lod_cluster_vertices(b, c);
            for (uint32_t j = 0; j < c->vertex_count; j++) {
                uint32_t *o = &b->owner[b->position_id[v[j]]];
                *o = clear ? OWNER_NONE : *o == OWNER_NONE || *o == g ? g : OWNER_SHARED;
            }
        }
}

/* The arrays of a step over the frontier (b->frontier); returns 0 when out of memory. */
static int stage_alloc(lod_build *b, uint32_t depth, lod_stage *st)
{
    uint32_t n = b->frontier_count;
    st->depth = depth;
    st->parts = gdr_lod_part_count(b);
    st->part = malloc((size_t)n * sizeof *st->part);
    st->members = malloc((size_t)n * sizeof *st->members);
    st->start = malloc(((size_t)st->parts + 1) * sizeof *st->start);
    st->results = calloc(st->parts, sizeof *st->results);
    st->measured = malloc((size_t)st->parts * sizeof *st->measured);
    return st->part && st->members && st->start && st->results && st->measured;
}

/* Partitions the frontier into the step's groups and marks the positions they share; the cluster
 * graph is built on `pool`, or (NULL) on this thread as `worker`. */
static gdr_status stage_partition(lod_build *b, lod_stage *st, gdr_thread_pool *pool, uint32_t worker,
                                  gdr_error *err)
{
    gdr_status status = gdr_lod_partition(b, pool, worker, st->part, st->parts, err);
    if (status != GDR_OK)
        return status;
    st->groups = group_members(b, st->part, st->parts, st->members, st->start);
    free(st->part);
    st->part = NULL;
    mark_shared(b, st, 0);
    return GDR_OK;
}

/* Task 0 of a job that also partitions the next step: the others' simplification waits for it. */
static void partition_task(lod_build *b, uint32_t worker)
{
    gdr_error err = {0};
    gdr_status status = stage_partition(b, b->partitioning, NULL, worker, &err);
    pthread_mutex_lock(&b->partition_lock);
    b->partition_status = status;
    b->partition_error = err;
    b->partitioned = 1;
    pthread_cond_broadcast(&b->partition_cond);
    pthread_mutex_unlock(&b->partition_lock);
}

/* Whether group g of the step being partitioned in this job is there to simplify, once the
 * partition is done. (Tasks are taken in order, so the partition has started by then.) */
static int partitioned_group(lod_build *b, uint32_t g)
{
    pthread_mutex_lock(&b->partition_lock);
    while (!b->partitioned)
        pthread_cond_wait(&b->partition_cond, &b->partition_lock);
    pthread_mutex_unlock(&b->partition_lock);
    return b->partition_status == GDR_OK && g < b->partitioning->groups;
}

/* The tasks of a job, in order: the partition of the next step (when it runs here), the
 * deviations, the simplifications. */
static void step_task(void *user, uint32_t i, uint32_t worker)
{
    lod_build *b = user;
    if (b->partitioning && i-- == 0) {
        partition_task(b, worker);
        return;
    }
    if (i < b->measured_count)
        gdr_lod_measure_group_task(b, i, worker);
    else if (!b->partitioning || partitioned_group(b, i - b->measured_count))
        gdr_lod_simplify_group_task(b, i - b->measured_count, worker);
}

/* One job on the pool: the deviation of the groups `measured` formed (NULL: none) and the
 * simplification of the groups of `simplified` (NULL: none), which depends only on the geometry
 * `measured` made. With `partition` set, the job partitions `simplified` first, beside the
 * deviations (in task 0: the simplification tasks, parts of them, wait for it). A lone measured
 * group runs on this thread after the others, outside any job, so that it may hand its samples to
 * the pool (lod_error.c, samples_to_simplified). */
static void run_job(lod_build *b, const lod_stage *measured, lod_stage *simplified, int partition)
{
    uint32_t tasks = simplified ? (partition ? simplified->parts : simplified->groups) : 0;
    b->members = simplified ? simplified->members : NULL;
    b->member_start = simplified ? simplified->start : NULL;
    b->results = simplified ? simplified->results : NULL;
    b->measured = measured ? measured->measured : NULL;
    b->measured_count = measured ? measured->measured_count : 0;
    b->measured_members = measured ? measured->members : NULL;
    b->measured_member_start = measured ? measured->start : NULL;
    b->measured_results = measured ? measured->results : NULL;
    b->partitioning = partition ? simplified : NULL;
    b->partitioned = 0;
    b->lone_group = b->measured_count == 1;
    if (b->lone_group) { /* never with the partition: that runs beside several */
        b->measured_count = 0;
        gdr_thread_pool_run(b->pool, tasks, step_task, b);
        gdr_lod_measure_group_task(b, 0, 0);
    } else {
        gdr_thread_pool_run(b->pool, (partition != 0) + b->measured_count + tasks, step_task, b);
    }
    if (simplified && (!partition || b->partition_status == GDR_OK))
        mark_shared(b, simplified, 1);
    b->lone_group = 0;
    b->partitioning = NULL;
}

/* Takes in the groups of the step that simplified (and, at step 0, the others as pass-through
 * groups), in group order: their records (sphere and error set later by finish_errors) and their
 * new clusters; next receives the next frontier. Returns 0 when out of memory. */
static int take_geometry(lod_build *b, lod_stage *st, uint32_t *next, uint32_t *next_count)
{
    *next_count = 0;
    for (uint32_t g = 0; g < st->groups; g++) {
        group_result *r = &st->results[g];
        uint32_t first = st->start[g], end = st->start[g + 1];
        if (!r->formed && st->depth > 0) {
            /* Regrouped at the next step with other neighbours. */
            for (uint32_t i = first; i < end; i++)
                next[(*next_count)++] = st->members[i];
            continue;
        }
        r->group = (uint32_t)b->group_count;
        if (!push_group(b, (gdr_cluster_group){.depth = st->depth}))
            return 0;
        for (uint32_t i = first; i < end; i++)
            b->clusters[st->members[i]].group = r->group;
        if (r->formed) {
            st->measured[st->measured_count++] = g;
            if (!append_result(b, r, r->group, next, next_count))
                return 0;
            continue;
        }
        /* Step 0: the members pass through unchanged, sharing their data, so that level-0
         * clusters only ever belong to step-0 groups (and stay contiguous). */
        r->first_cluster = (uint32_t)b->cluster_count;
        for (uint32_t i = first; i < end; i++) {
            gdr_cluster c = b->clusters[st->members[i]];
            c.group = GDR_NO_INDEX;
            c.refined_group = r->group;
            next[(*next_count)++] = (uint32_t)b->cluster_count;
            if (!push_cluster(b, c))
                return 0;
        }
        b->stats.passthrough_clusters += end - first;
    }
    return 1;
}

/* Each group's sphere and error (its deviation, or the largest error of the groups its members
 * came from where that is larger: r->error, which the measuring task set, 0 for a group passed
 * through at step 0) into its result, once every deviation of the step is measured. Returns 0
 * when out of memory. */
static int stage_bounds(lod_build *b, lod_stage *st)
{
    lod_scratch *s = &b->scratch[0];
    for (uint32_t g = 0; g < st->groups; g++) {
        group_result *r = &st->results[g];
        uint32_t count = st->start[g + 1] - st->start[g];
        if (!r->formed && st->depth > 0)
            continue;
        if (!LOD_RESERVE(s, spheres, (size_t)count * 2))
            return 0;
        gdr_lod_group_sphere(b, s, st->members + st->start[g], count, r);
        r->error = r->deviation > r->error ? r->deviation : r->error;
    }
    return 1;
}

/* The step's results into the build: each group's sphere and error, its new clusters' samples, and
 * the samples of `frontier` (the one the step made) packed into one array (b->results is st's: the
 * gather reads the samples there). Returns 0 when out of memory. */
static int set_errors(lod_build *b, const lod_stage *st, const uint32_t *frontier, uint32_t frontier_count)
{
    for (uint32_t g = 0; g < st->groups; g++) {
        const group_result *r = &st->results[g];
        const uint32_t *members = st->members + st->start[g];
        uint32_t count = st->start[g + 1] - st->start[g];
        if (!r->formed && st->depth > 0)
            continue;
        b->groups[r->group].sphere = r->sphere;
        b->groups[r->group].error = r->error > b->min_error ? r->error : b->min_error;
        for (uint32_t i = 0; i < (r->formed ? r->cluster_count : count); i++)
            if (!(r->formed ? gdr_lod_error_adopt(b, r->first_cluster + i, g, r, i)
                            : gdr_lod_error_inherit(b, r->first_cluster + i, members[i])))
                return 0;
    }
    return gdr_lod_error_gather(b, frontier, frontier_count);
}

/* Shows an observer (a test) the step st (NULL: level 0, before the first step) once its errors
 * are set. */
static void observe(const lod_build *b, const lod_stage *st, const uint32_t *frontier, uint32_t frontier_count)
{
    if (!b->observer)
        return;
    lod_step_view v = {.frontier = frontier, .frontier_count = frontier_count};
    if (st)
        v = (lod_step_view){.depth = st->depth, .groups = st->groups, .members = st->members,
                            .member_start = st->start, .results = st->results, .frontier = frontier,
                            .frontier_count = frontier_count};
    b->observer->step(b->observer->user, b, &v);
}

/* The step's errors, once every deviation of its groups is measured (the job after its own has
 * run): here, between stage_bounds and set_errors, each result holds its group's deviation,
 * error, sphere and samples by new cluster, and nothing of them is in the build yet. Returns 0
 * when out of memory. */
static int finish_errors(lod_build *b, lod_stage *st, const uint32_t *frontier, uint32_t frontier_count)
{
    if (!stage_bounds(b, st))
        return 0;
    b->results = st->results; /* what the redirection and the gather read */
    int ok = gdr_lod_redirect_samples(b, st->groups) && set_errors(b, st, frontier, frontier_count);
    b->results = NULL;
    if (ok)
        observe(b, st, frontier, frontier_count);
    return ok;
}

/* Whether the job left any group of these out of memory. */
static int stage_out_of_memory(const lod_stage *st)
{
    for (uint32_t g = 0; g < st->parts; g++)
        if (st->results[g].out_of_memory)
            return 1;
    return 0;
}

static int compare_by_data(const void *a, const void *b)
{
    const gdr_cluster *x = a, *y = b;
    if (x->triangle_offset != y->triangle_offset)
        return x->triangle_offset < y->triangle_offset ? -1 : 1;
    return x->vertex_offset < y->vertex_offset ? -1 : x->vertex_offset > y->vertex_offset;
}

/* Drops any DAG of c: back to level 0 in its original data extents, groups freed. Level 0 is put
 * back in data order, the order gdr_meshlets_build made it in (a DAG build reorders it by
 * group), so a rebuild gives the same bytes as the first build. */
static void truncate_to_level0(gdr_mesh_clusters *c)
{
    size_t vertex_end = 0, triangle_end = 0;
    for (uint32_t i = 0; i < c->level0_cluster_count; i++) {
        const gdr_cluster *k = &c->clusters[i];
        size_t ve = (size_t)k->vertex_offset + k->vertex_count;
        size_t te = gdr_lod_align4((size_t)k->triangle_offset + (size_t)k->triangle_count * 3);
        vertex_end = ve > vertex_end ? ve : vertex_end;
        triangle_end = te > triangle_end ? te : triangle_end;
    }
    if (c->cluster_count > c->level0_cluster_count || c->group_count) {
        c->cluster_count = c->level0_cluster_count;
        c->vertex_count = (uint32_t)(vertex_end < c->vertex_count ? vertex_end : c->vertex_count);
        c->triangle_byte_count = (uint32_t)(triangle_end < c->triangle_byte_count ? triangle_end
                                                                                   : c->triangle_byte_count);
    }
    for (uint32_t i = 0; i < c->cluster_count; i++)
        c->clusters[i].group = c->clusters[i].refined_group = GDR_NO_INDEX;
    if (c->cluster_count > 1)
        qsort(c->clusters, c->cluster_count, sizeof *c->clusters, compare_by_data);
    free(c->groups);
    c->groups = NULL;
    c->group_count = 0;
    free(c->lod_nodes); /* the hierarchy of what was there; rebuilt by build_one */
    c->lod_nodes = NULL;
    c->lod_node_count = c->lod_node_levels = 0;
    c->dag_depth = 0;
}

/* Level 0 must be whole and in range before anything reads it. */
static gdr_status check_level0(const gdr_mesh *mesh, gdr_error *err)
{
    const gdr_mesh_clusters *c = &mesh->clusters;
    if (!c->vertices || !c->triangles)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': clusters without data", mesh->name);
    if (!mesh->positions || mesh->vertex_count == 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': no vertex positions", mesh->name);
    for (uint32_t i = 0; i < c->level0_cluster_count; i++) {
        const gdr_cluster *k = &c->clusters[i];
        if (k->vertex_count == 0 || k->vertex_count > GDR_CLUSTER_MAX_VERTICES || k->triangle_count == 0 ||
            k->triangle_count > GDR_CLUSTER_MAX_TRIANGLES ||
            (uint64_t)k->vertex_offset + k->vertex_count > c->vertex_count ||
            (uint64_t)k->triangle_offset + (uint64_t)k->triangle_count * 3 > c->triangle_byte_count)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                 "mesh '%s': clusters[%u]: counts or offsets out of range", mesh->name, i);
        for (uint32_t j = 0; j < k->triangle_count * 3; j++)
            if (c->triangles[k->triangle_offset + j] >= k->vertex_count)
                return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                     "mesh '%s': clusters[%u]: triangle corner %u out of range", mesh->name, i, j);
        for (uint32_t j = 0; j < k->vertex_count; j++)
            if (c->vertices[k->vertex_offset + j] >= mesh->vertex_count)
                return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                                     "mesh '%s': clusters[%u]: vertex %u out of range", mesh->name, i, j);
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const gdr_vec3 p = mesh->positions[v];
        if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "mesh '%s': position %u is not finite", mesh->name,
                                 v);
    }
    return GDR_OK;
}

static gdr_status resolve_options(const gdr_lod_options *in, gdr_lod_options *out, gdr_error *err)
{
    gdr_lod_options o = in ? *in : (gdr_lod_options){0};
    if (o.group_size == 0)
        o.group_size = LOD_DEFAULT_GROUP_SIZE;
    if (o.target_ratio == 0.0f)
        o.target_ratio = 0.5f;
    if (o.root_triangles == 0)
        o.root_triangles = GDR_LOD_DEFAULT_ROOT_TRIANGLES;
    if (o.root_triangles > GDR_CLUSTER_MAX_TRIANGLES)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "LOD options: root_triangles %u is outside [1, %u]",
                             o.root_triangles, GDR_CLUSTER_MAX_TRIANGLES);
    if (o.group_size < 2 || o.group_size > LOD_MAX_GROUP_SIZE)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "LOD options: group_size %u is outside [2, %u]",
                             o.group_size, LOD_MAX_GROUP_SIZE);
    if (!(o.target_ratio > 0.0f && o.target_ratio < (float)LOD_MAX_KEPT_SHARE))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "LOD options: target_ratio %g is outside (0, %g)",
                             (double)o.target_ratio, LOD_MAX_KEPT_SHARE);
    if (o.thread_count > GDR_THREAD_POOL_MAX_THREADS)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "LOD options: thread_count %u exceeds %u",
                             o.thread_count, GDR_THREAD_POOL_MAX_THREADS);
    *out = o;
    return GDR_OK;
}

/* Orders the clusters by group (stable), so each group's clusters are contiguous, and fills in
 * first_cluster / cluster_count. Level-0 clusters only belong to step-0 groups (or to a root
 * formed at step 0), which come first, so level 0 stays in front. */
static int order_by_group(lod_build *b)
{
    size_t n = b->cluster_count;
    gdr_cluster *sorted = malloc(n * sizeof *sorted);
    uint32_t *start = calloc(b->group_count + 1, sizeof *start);
    if (!sorted || !start) {
        free(sorted);
        free(start);
        return 0;
    }
    for (size_t i = 0; i < n; i++)
        start[b->clusters[i].group + 1]++;
    for (size_t g = 0; g < b->group_count; g++) {
        b->groups[g].first_cluster = start[g];
        b->groups[g].cluster_count = start[g + 1];
        start[g + 1] += start[g];
    }
    for (size_t i = 0; i < n; i++)
        sorted[start[b->clusters[i].group]++] = b->clusters[i];
    free(start);
    free(b->clusters);
    b->clusters = sorted;
    b->cluster_cap = n;
    return 1;
}

/* Takes the mesh's level-0 arrays into the build and sets up the position ids, the owner table
 * and the workers' scratch. Returns 0 when out of memory. */
static int setup(lod_build *b)
{
    gdr_mesh *mesh = b->mesh;
    gdr_mesh_clusters *mc = &mesh->clusters;
    b->clusters = mc->clusters;
    b->cluster_count = b->cluster_cap = mc->cluster_count;
    b->vertices = mc->vertices;
    b->vertex_count = b->vertex_cap = mc->vertex_count;
    b->triangles = mc->triangles;
    b->triangle_bytes = b->triangle_cap = mc->triangle_byte_count;
    mc->clusters = NULL;
    mc->vertices = NULL;
    mc->triangles = NULL;
    b->min_error = fmaxf(mesh->bounds.w * LOD_MIN_ERROR_SCALE, FLT_MIN);
    uint32_t level0 = mc->level0_cluster_count;
    for (uint32_t i = 0; i < level0; i++)
        b->stats.input_triangles += b->clusters[i].triangle_count;
    b->progress_budget = b->stats.input_triangles;
    b->group_triangles = (b->stats.input_triangles * b->opt.group_size + level0 - 1) / level0;

    b->position_id = malloc((size_t)mesh->vertex_count * sizeof *b->position_id);
    b->scratch = calloc(b->scratch_count, sizeof *b->scratch);
    if (!b->position_id || !b->scratch)
        return 0;
    b->position_count = (uint32_t)meshopt_generateVertexRemap(b->position_id, NULL, mesh->vertex_count,
                                                              mesh->positions, mesh->vertex_count, sizeof(gdr_vec3));
    b->owner = malloc((size_t)b->position_count * sizeof *b->owner);
    if (!b->owner || !gdr_lod_weld_setup(b))
        return 0;
    memset(b->owner, 0xff, (size_t)b->position_count * sizeof *b->owner);
    if (!gdr_lod_error_setup(b))
        return 0;
    for (uint32_t w = 0; w < b->scratch_count; w++) {
        b->scratch[w].map = malloc((size_t)mesh->vertex_count * sizeof *b->scratch[w].map);
        if (!b->scratch[w].map)
            return 0;
        memset(b->scratch[w].map, 0xff, (size_t)mesh->vertex_count * sizeof *b->scratch[w].map);
        b->scratch[w].position_map = malloc((size_t)b->position_count * sizeof *b->scratch[w].position_map);
        if (!b->scratch[w].position_map)
            return 0;
        memset(b->scratch[w].position_map, 0xff, (size_t)b->position_count * sizeof *b->scratch[w].position_map);
    }
    return 1;
}

static gdr_status out_of_memory(const lod_build *b, gdr_error *err)
{
    return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory for the LOD DAG", b->mesh->name);
}

/* Step cur over the frontier (b->frontier): its partition, the job that measures prev's groups
 * (none at step 0) and simplifies cur's, then prev's errors; prev is freed. Sets *progressed when
 * cur formed a group. */
static gdr_status step(lod_build *b, lod_stage *prev, lod_stage *cur, uint32_t depth, int *progressed,
                       gdr_error *err)
{
    if (!stage_alloc(b, depth, cur))
        return out_of_memory(b, err);
    /* The partition runs beside the deviations of the step before where there are several. */
    int partition_in_job = prev->measured_count > 1;
    gdr_status status = partition_in_job ? GDR_OK : stage_partition(b, cur, b->pool, 0, err);
    if (status != GDR_OK)
        return status;
    run_job(b, prev, cur, partition_in_job);
    if (partition_in_job && b->partition_status != GDR_OK) {
        if (err)
            *err = b->partition_error;
        return b->partition_status;
    }
    if (stage_out_of_memory(prev) || stage_out_of_memory(cur))
        return out_of_memory(b, err);
    *progressed = 0;
    for (uint32_t g = 0; g < cur->groups; g++) {
        *progressed |= cur->results[g].formed;
        b->stats.stuck_groups += !cur->results[g].formed;
        b->stats.border_rejects += (uint64_t)cur->results[g].border_reject;
    }
    if (prev->groups && !finish_errors(b, prev, b->frontier, b->frontier_count))
        return out_of_memory(b, err);
    stage_free(prev);
    return GDR_OK;
}

/* Where step cur formed no group (prev is finished and empty by then): the step again as one
 * group over the whole frontier, simplified by vertex clustering (lod_sloppy.c), which merges
 * separate pieces that edge collapses never join. An ordinary group otherwise: its error measured
 * against level 0, its sphere enclosing, nothing locked (it has no neighbour). Sets *progressed
 * when it formed. */
static gdr_status sloppy_step(lod_build *b, lod_stage *prev, lod_stage *cur, uint32_t depth, int *progressed,
                              gdr_error *err)
{
    stage_free(cur);
    uint32_t n = b->frontier_count;
    *cur = (lod_stage){.depth = depth, .parts = 1, .groups = 1};
    cur->members = malloc((size_t)n * sizeof *cur->members);
    cur->start = malloc(2 * sizeof *cur->start);
    cur->results = calloc(1, sizeof *cur->results);
    cur->measured = malloc(sizeof *cur->measured);
    if (!cur->members || !cur->start || !cur->results || !cur->measured)
        return out_of_memory(b, err);
    memcpy(cur->members, b->frontier, (size_t)n * sizeof *cur->members);
    cur->start[0] = 0;
    cur->start[1] = n;
    mark_shared(b, cur, 0);
    b->sloppy = 1;
    run_job(b, prev, cur, 0);
    b->sloppy = 0;
    if (stage_out_of_memory(cur))
        return out_of_memory(b, err);
    *progressed = cur->results[0].formed;
    b->stats.sloppy_groups += (uint64_t)*progressed;
    return GDR_OK;
}

/* Whether the frontier `current` is one cluster of at most opt.root_triangles triangles: the root.
 * One full cluster is not the end: an instance a pixel or two across would still draw its 60-124
 * triangles, so the lone cluster is simplified further, step by step (one group, nothing locked),
 * each step an ordinary group with its measured error. */
static int small_root(const lod_build *b, const uint32_t *current)
{
    return b->frontier_count == 1 && b->clusters[current[0]].triangle_count <= b->opt.root_triangles;
}

/* Steps from level 0 until one small cluster is left, a step makes no progress or the level limit;
 * leaves the last frontier in *frontier (b->frontier) and the step count in *depth.
 *
 * A step's simplification and its errors are taken apart: which groups form, and so the next
 * frontier, its partition and simplification, depend only on the geometry, while measuring a
 * group's deviation needs its members' samples as the step before handed them on. So the job of
 * step k measures the deviations of step k - 1 beside simplifying the groups of step k; then step
 * k - 1's errors are set (finish_errors) and step k's geometry is taken in. */
static gdr_status run_steps(lod_build *b, uint32_t **frontier, uint32_t *depth, gdr_lod_stop *stop, gdr_error *err)
{
    uint32_t level0 = b->mesh->clusters.level0_cluster_count;
    uint32_t *current = malloc((size_t)level0 * sizeof *current), *next = NULL;
    lod_stage prev = {0}, cur = {0}; /* prev: simplified, deviations not yet measured */
    gdr_status status = GDR_OK;
    if (!current)
        goto oom;
    for (uint32_t i = 0; i < level0; i++)
        current[i] = i;
    b->frontier_count = level0;
    observe(b, NULL, current, level0);
    for (*depth = 0;; ++*depth) {
        b->frontier = current;
        if (small_root(b, current) || *depth >= GDR_LOD_MAX_LEVELS) {
            *stop = small_root(b, current) ? GDR_LOD_STOP_SINGLE_CLUSTER : GDR_LOD_STOP_LEVEL_LIMIT;
            break;
        }
        /* The next frontier: members carried or passed through, plus new clusters, of which a
         * group makes fewer than it had triangles. */
        size_t bound = b->frontier_count;
        for (uint32_t f = 0; f < b->frontier_count; f++)
            bound += b->clusters[current[f]].triangle_count;
        free(next);
        next = malloc(bound * sizeof *next);
        if (!next)
            goto oom;
        int progressed = 0;
        if ((status = step(b, &prev, &cur, *depth, &progressed, err)) != GDR_OK)
            goto done;
        /* Edge collapses are stuck (separate pieces, seams): vertex clustering over the whole
         * frontier, down to one cluster and on to the small root. */
        if (!progressed && (status = sloppy_step(b, &prev, &cur, *depth, &progressed, err)) != GDR_OK)
            goto done;
        if (!progressed) {
            *stop = b->frontier_count == 1 ? GDR_LOD_STOP_SINGLE_CLUSTER : GDR_LOD_STOP_NO_PROGRESS;
            break;
        }
        uint32_t next_count = 0;
        if (!take_geometry(b, &cur, next, &next_count))
            goto oom;
        prev = cur;
        memset(&cur, 0, sizeof cur);
        uint32_t *t = current;
        current = next;
        next = t;
        b->frontier_count = next_count;
    }
    if (prev.groups) { /* the last step's deviations */
        run_job(b, &prev, NULL, 0);
        if (stage_out_of_memory(&prev) || !finish_errors(b, &prev, current, b->frontier_count))
            goto oom;
    }
    goto done;
oom:
    status = out_of_memory(b, err);
done:
    stage_free(&prev);
    stage_free(&cur);
    free(next);
    *frontier = current;
    return status;
}

/* Gives the result to the mesh (arrays sized exactly) and fills the stats. */
static void hand_over(lod_build *b, uint32_t depth, gdr_lod_stop stop)
{
    /* A sample stands for every vertex of its position id, up to weld_slack away: each error
     * gets it added (the same to all, so errors stay monotonic along DAG edges). */
    for (uint32_t g = 0; g < b->group_count && b->weld_slack > 0.0f; g++)
        if (isfinite(b->groups[g].error))
            b->groups[g].error = nextafterf(b->groups[g].error + b->weld_slack, INFINITY);
    gdr_mesh_clusters *mc = &b->mesh->clusters;
    gdr_cluster *cl = realloc(b->clusters, b->cluster_count * sizeof *cl);
    uint32_t *vx = realloc(b->vertices, (b->vertex_count ? b->vertex_count : 1) * sizeof *vx);
    uint8_t *tr = realloc(b->triangles, b->triangle_bytes ? b->triangle_bytes : 1);
    gdr_cluster_group *gr = realloc(b->groups, b->group_count * sizeof *gr);
    mc->clusters = cl ? cl : b->clusters;
    mc->cluster_count = (uint32_t)b->cluster_count;
    mc->vertices = vx ? vx : b->vertices;
    mc->vertex_count = (uint32_t)b->vertex_count;
    mc->triangles = tr ? tr : b->triangles;
    mc->triangle_byte_count = (uint32_t)b->triangle_bytes;
    mc->groups = gr ? gr : b->groups;
    mc->group_count = (uint32_t)b->group_count;
    mc->dag_depth = depth;
    b->clusters = NULL;
    b->vertices = NULL;
    b->triangles = NULL;
    b->groups = NULL;
    b->stats.mesh_count = 1;
    b->stats.stop_counts[stop] = 1;
    b->stats.max_depth = depth;
    b->stats.group_count = mc->group_count;
    b->stats.cluster_count = mc->cluster_count;
    for (uint32_t i = 0; i < mc->cluster_count; i++)
        b->stats.dag_triangles += mc->clusters[i].triangle_count;
}

/* After a failure: the mesh gets its level 0 back, in its original order. */
static void give_back_level0(lod_build *b)
{
    gdr_mesh_clusters *mc = &b->mesh->clusters;
    mc->clusters = b->clusters;
    mc->vertices = b->vertices;
    mc->triangles = b->triangles;
    mc->cluster_count = (uint32_t)b->cluster_count;
    mc->vertex_count = (uint32_t)b->vertex_count;
    mc->triangle_byte_count = (uint32_t)b->triangle_bytes;
    truncate_to_level0(mc);
    b->clusters = NULL;
    b->vertices = NULL;
    b->triangles = NULL;
    free(b->groups);
    b->groups = NULL;
    b->group_count = 0;
}

/* Builds the DAG of b->mesh, whose level 0 is checked. */
static gdr_status build_mesh(lod_build *b, gdr_error *err)
{
    uint32_t *frontier = NULL, depth = 0;
    gdr_lod_stop stop = GDR_LOD_STOP_NONE;
    gdr_status status = GDR_OK;
    pthread_mutex_init(&b->partition_lock, NULL);
    pthread_cond_init(&b->partition_cond, NULL);
    if (!setup(b))
        status = out_of_memory(b, err);
    if (status == GDR_OK)
        status = run_steps(b, &frontier, &depth, &stop, err);
    b->frontier = frontier;
    if (status == GDR_OK && (!form_root(b, depth) || !order_by_group(b)))
        status = out_of_memory(b, err);
    if (status == GDR_OK) {
        hand_over(b, depth, stop);
        uint64_t given = atomic_load(&b->progress_given);
        gdr_lod_progress_add(b, given < b->progress_budget ? b->progress_budget - given : 0, 0);
    } else {
        give_back_level0(b);
    }
    free(frontier);
    gdr_lod_error_free(b);
    free(b->position_id);
    free(b->owner);
    if (b->scratch)
        for (uint32_t w = 0; w < b->scratch_count; w++)
            gdr_lod_scratch_free(&b->scratch[w]);
    free(b->scratch);
    pthread_cond_destroy(&b->partition_cond);
    pthread_mutex_destroy(&b->partition_lock);
    return status;
}

static void stats_add(gdr_lod_stats *sum, const gdr_lod_stats *s)
{
    sum->mesh_count += s->mesh_count;
    for (int i = 0; i < GDR_LOD_STOP_COUNT; i++)
        sum->stop_counts[i] += s->stop_counts[i];
    sum->max_depth = s->max_depth > sum->max_depth ? s->max_depth : sum->max_depth;
    sum->group_count += s->group_count;
    sum->cluster_count += s->cluster_count;
    sum->input_triangles += s->input_triangles;
    sum->dag_triangles += s->dag_triangles;
    sum->root_clusters += s->root_clusters;
    sum->root_triangles += s->root_triangles;
    sum->stuck_groups += s->stuck_groups;
    sum->border_rejects += s->border_rejects;
    sum->passthrough_clusters += s->passthrough_clusters;
    sum->sloppy_groups += s->sloppy_groups;
}

/* Builds one mesh's DAG with `pool` (NULL: on the calling thread, as worker `worker`). */
static gdr_status build_one(gdr_mesh *mesh, const gdr_lod_options *o, const lod_texture_set *texture,
                            gdr_thread_pool *pool, uint32_t worker, lod_progress *progress,
                            const lod_observer *observer, gdr_lod_stats *stats, gdr_error *err)
{
    const gdr_mesh_clusters *c = &mesh->clusters;
    if (c->level0_cluster_count == 0 || c->level0_cluster_count > c->cluster_count || !c->clusters)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "mesh '%s': the LOD DAG needs level-0 clusters (gdr_meshlets_build)", mesh->name);
    truncate_to_level0(&mesh->clusters);
    gdr_status status = check_level0(mesh, err);
    if (status != GDR_OK)
        return status;
    lod_build b = {.mesh = mesh, .opt = *o, .texture = texture, .observer = observer, .pool = pool, .worker_base = worker,
                   .progress = progress, .scratch_count = gdr_thread_pool_thread_count(pool)};
    status = build_mesh(&b, err);
    if (status == GDR_OK && (status = gdr_mesh_clusters_build_hierarchy(&mesh->clusters, err)) != GDR_OK)
        truncate_to_level0(&mesh->clusters);
    if (status != GDR_OK) /* level 0 is back: its own hierarchy, when memory allows */
        gdr_mesh_clusters_build_hierarchy(&mesh->clusters, NULL);
    if (status == GDR_OK && stats)
        *stats = b.stats;
    return status;
}

gdr_status gdr_mesh_build_lod_dag(gdr_mesh *mesh, const gdr_lod_options *options, gdr_lod_stats *stats,
                                  gdr_error *err)
{
    return gdr_lod_build_observed(mesh, options, NULL, stats, err);
}

gdr_status gdr_lod_build_observed(gdr_mesh *mesh, const gdr_lod_options *options, const lod_observer *observer,
                                  gdr_lod_stats *stats, gdr_error *err)
{
    return gdr_lod_build_textured(mesh, options, NULL, observer, stats, err);
}

gdr_status gdr_lod_build_textured(gdr_mesh *mesh, const gdr_lod_options *options, const lod_texture_set *texture,
                                  const lod_observer *observer, gdr_lod_stats *stats, gdr_error *err)
{
    if (!mesh)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "gdr_mesh_build_lod_dag: mesh must not be NULL");
    if (stats)
        *stats = (gdr_lod_stats){0};
    gdr_lod_options o = {0};
    gdr_status status = resolve_options(options, &o, err);
    if (status != GDR_OK)
        return status;
    gdr_thread_pool *pool = NULL;
    if (o.thread_count != 1) {
        status = gdr_thread_pool_create(o.thread_count, &pool, err);
        if (status != GDR_OK)
            return status;
    }
    lod_progress progress;
    gdr_progress_begin(&progress.bar, "LOD DAG", mesh->clusters.level0_cluster_count ? mesh->index_count / 3 : 1,
                       o.no_progress);
    atomic_init(&progress.done, 0);
    status = build_one(mesh, &o, texture, pool, 0, &progress, observer, stats, err);
    gdr_progress_end(&progress.bar);
    gdr_thread_pool_destroy(pool);
    return status;
}

/* --- a scene ------------------------------------------------------------------------------------- */

typedef struct scene_job {
    gdr_scene *scene;
    const gdr_lod_options *opt;
    const uint32_t *small; /* mesh indices built one per task */
    const uint8_t *textured; /* per mesh: an instance has a textured material */
    const lod_scene_textures *textures; /* what the textured meshes' materials sample */
    lod_progress *progress;
    gdr_lod_stats *stats;  /* per mesh */
    gdr_status *status;    /* per mesh */
    gdr_error *errors;     /* per mesh */
} scene_job;

/* Whether a material samples any texture (through the mesh's uvs). */
static int material_textured(const gdr_material *m)
{
    return m->base_color_texture.texture != GDR_NO_INDEX || m->metallic_roughness_texture.texture != GDR_NO_INDEX ||
           m->normal_texture.texture != GDR_NO_INDEX || m->occlusion_texture.texture != GDR_NO_INDEX ||
           m->emissive_texture.texture != GDR_NO_INDEX;
}

/* textured[m] = 1 where an instance of mesh m has a textured material: only there do the uvs steer
 * simplification and enter the error (an untextured mesh's uvs are never seen). */
static void mark_textured_meshes(const gdr_scene *scene, uint8_t *textured)
{
    for (uint32_t i = 0; i < scene->instance_count; i++) {
        const gdr_instance *in = &scene->instances[i];
        if (in->mesh < scene->mesh_count && in->material < scene->material_count &&
            material_textured(&scene->materials[in->material]))
            textured[in->mesh] = 1;
    }
}

/* Builds mesh m with the scene's options, its uvs ignored where nothing samples a texture, its
 * slides weighed by what its textures show where they slide. */
static gdr_status build_scene_mesh(scene_job *job, uint32_t m, gdr_thread_pool *pool, uint32_t worker)
{
    gdr_lod_options o = *job->opt;
    o.ignore_uvs = o.ignore_uvs || !job->textured[m];
    const lod_texture_set *texture = job->textures->sets[m].count ? &job->textures->sets[m] : NULL;
    return build_one(&job->scene->meshes[m], &o, texture, pool, worker, job->progress, NULL, &job->stats[m],
                     &job->errors[m]);
}

static void small_mesh_task(void *user, uint32_t i, uint32_t worker)
{
    scene_job *job = user;
    uint32_t m = job->small[i];
    job->status[m] = build_scene_mesh(job, m, NULL, worker);
}

static int needs_dag(const gdr_mesh *m) { return m->clusters.level0_cluster_count > 0 && m->clusters.group_count == 0; }

/* Marks the meshes whose DAG is built here (built), lists the small ones (built one per task), and
 * returns their triangles, for the progress bar. */
static uint64_t select_meshes(const gdr_scene *scene, uint8_t *built, uint32_t *small, uint32_t *small_count)
{
    uint64_t total = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++)
        if (needs_dag(&scene->meshes[m])) {
            total += scene->meshes[m].index_count / 3;
            built[m] = 1;
            if (scene->meshes[m].index_count / 3 < LOD_SMALL_MESH_TRIANGLES)
                small[(*small_count)++] = m;
        }
    return total;
}

/* The first mesh's failure as the scene's error; on failure every built mesh goes back to level 0,
 * else their statistics are summed into stats. */
static gdr_status finish_meshes(gdr_scene *scene, const scene_job *job, const uint8_t *built, gdr_lod_stats *stats,
                                gdr_error *err)
{
    gdr_status status = GDR_OK;
    uint32_t n = scene->mesh_count;
    for (uint32_t m = 0; m < n && status == GDR_OK; m++)
        if (built[m] && job->status[m] != GDR_OK)
            status = gdr_error_set(err, job->status[m], "meshes[%u]: %s", m, job->errors[m].message);
    for (uint32_t m = 0; m < n; m++) {
        if (!built[m])
            continue;
        if (status != GDR_OK) {
            truncate_to_level0(&scene->meshes[m].clusters);
            gdr_mesh_clusters_build_hierarchy(&scene->meshes[m].clusters, NULL);
        } else if (stats) {
            stats_add(stats, &job->stats[m]);
        }
    }
    return status;
}

gdr_status gdr_scene_build_lod(gdr_scene *scene, const gdr_lod_options *options, gdr_lod_stats *stats,
                               gdr_error *err)
{
    if (!scene)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "gdr_scene_build_lod: scene must not be NULL");
    if (scene->geometry_in_pages)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "LOD DAG: the scene was read for streaming and holds "
                             "no geometry to build it from");
    if (stats)
        *stats = (gdr_lod_stats){0};
    gdr_lod_options o = {0};
    gdr_status status = resolve_options(options, &o, err);
    if (status != GDR_OK)
        return status;
    gdr_meshlet_options meshlet_options = {.thread_count = o.thread_count};
    status = gdr_scene_build_clusters(scene, &meshlet_options, err);
    if (status != GDR_OK)
        return status;

    uint32_t n = scene->mesh_count;
    uint32_t *small = malloc((n ? n : 1) * sizeof *small);
    uint8_t *built = calloc(n ? n : 1, 1);
    uint8_t *textured = calloc(n ? n : 1, 1);
    gdr_lod_stats *mesh_stats = calloc(n ? n : 1, sizeof *mesh_stats);
    gdr_status *statuses = calloc(n ? n : 1, sizeof *statuses);
    gdr_error *errors = calloc(n ? n : 1, sizeof *errors);
    gdr_thread_pool *pool = NULL;
    lod_scene_textures textures = {0};
    if (!small || !built || !textured || !mesh_stats || !statuses || !errors) {
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "gdr_scene_build_lod: out of memory");
        goto done;
    }
    if (o.thread_count != 1) {
        status = gdr_thread_pool_create(o.thread_count, &pool, err);
        if (status != GDR_OK)
            goto done;
    }
    uint32_t small_count = 0;
    uint64_t total = select_meshes(scene, built, small, &small_count);
    lod_progress progress;
    gdr_progress_begin(&progress.bar, "LOD DAG", total, o.no_progress);
    atomic_init(&progress.done, 0);
    mark_textured_meshes(scene, textured);
    for (uint32_t m = 0; m < n; m++)
        textured[m] &= built[m]; /* the textures' ranges only for meshes built here */
    if ((status = lod_scene_textures_build(scene, textured, &textures, err)) != GDR_OK) {
        gdr_progress_end(&progress.bar);
        goto done;
    }
    scene_job job = {.scene = scene, .opt = &o, .small = small, .textured = textured, .textures = &textures,
                     .progress = &progress, .stats = mesh_stats, .status = statuses, .errors = errors};
    gdr_thread_pool_run(pool, small_count, small_mesh_task, &job);
    for (uint32_t m = 0; m < n; m++)
        if (built[m] && scene->meshes[m].index_count / 3 >= LOD_SMALL_MESH_TRIANGLES)
            statuses[m] = build_scene_mesh(&job, m, pool, 0);
    gdr_progress_end(&progress.bar);
    status = finish_meshes(scene, &job, built, stats, err);
done:
    lod_scene_textures_free(&textures);
    gdr_thread_pool_destroy(pool);
    free(small);
    free(built);
    free(textured);
    free(mesh_stats);
    free(statuses);
    free(errors);
    return status;
}

