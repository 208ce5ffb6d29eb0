/* The scene cache written mesh by mesh (gdr_cache_write_meshes, gdr/io.h; docs/CACHE_FORMAT.md,
 * "Writing mesh by mesh"): workers make meshes side by side, each serialises its mesh's parts of the
 * sections that hold one part per mesh and its pages, then frees the mesh; the parts are appended
 * to one spool per section in mesh order (a worker waits for its turn), so the file is the one
 * gdr_cache_write writes for the whole scene, whatever the thread count. At the end the header, the
 * scene's other sections and the spools are written out in table order. */
#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include "core/output_file.h"
#include "core/progress.h"
#include "gdr/thread_pool.h"
#include "io/cache_internal.h"
#include "io/cache_pages.h"
#include "io/cache_spool.h"
#include "io/io_internal.h"

/* The sections whose bytes are one part per mesh, in mesh order, and nothing else (those of the whole
 * geometry only where the file has them). */
static const int per_mesh_sections[] = {CACHE_MESHES, CACHE_GEOMETRY, CACHE_COLORS, CACHE_CLUSTERS, CACHE_CLUSTER_GROUPS,
                                        CACHE_CLUSTER_DATA, CACHE_CLUSTER_GEOMETRY, CACHE_HIERARCHY};
enum { PER_MESH = sizeof per_mesh_sections / sizeof per_mesh_sections[0], PAGE_SPOOL = PER_MESH };

/* One mesh, serialised. */
typedef struct mesh_parts {
    writer parts[PER_MESH];
    cache_mesh_pages pages;
} mesh_parts;

typedef struct build_job {
    const char *path;
    const gdr_cache_mesh_source *source;
    const cache_write_input *in; /* the skeleton's */
    uint32_t mesh_count, threads_each;
    cache_spool spools[PER_MESH + 1]; /* the per-mesh sections, then the pages' bytes */
    cache_mesh_pages *index;          /* per mesh: its index entry (the pages' bytes are spooled) */
    pthread_mutex_t lock;
    pthread_cond_t turn;
    uint32_t next;                    /* the next mesh to append */
    atomic_int failed;
    gdr_status status;                /* the first failure in mesh order */
    gdr_error err;
    gdr_progress progress;
} build_job;

static int section_present(int k, const cache_write_input *in)
{
    return !gdr_cache_sections[k].present || gdr_cache_sections[k].present(in);
}

static void free_parts(mesh_parts *p)
{
    for (int k = 0; k < PER_MESH; k++)
        free(p->parts[k].data);
    cache_pages_free_mesh(&p->pages);
    *p = (mesh_parts){0};
}

/* Mesh i made, checked as the whole-scene writer checks it, serialised and freed. */
static gdr_status make_parts(build_job *job, uint32_t i, mesh_parts *p, gdr_error *err)
{
    gdr_scene *one = NULL;
    gdr_status status = job->source->make(job->source->user, i, job->threads_each, &one, err);
    if (status == GDR_OK && (!one || one->mesh_count != 1 || one->geometry_in_pages))
        status = gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "the mesh source made no scene of one mesh with "
                               "its geometry");
    cache_write_input in = *job->in;
    in.scene = one;
    for (int k = 0; k < PER_MESH && status == GDR_OK; k++) {
        const cache_section *sec = &gdr_cache_sections[per_mesh_sections[k]];
        status = sec->check ? sec->check(&in, job->path, err) : GDR_OK;
    }
    for (int k = 0; k < PER_MESH && status == GDR_OK; k++)
        if (section_present(per_mesh_sections[k], &in))
            gdr_cache_sections[per_mesh_sections[k]].write(&p->parts[k], &in);
    for (int k = 0; k < PER_MESH && status == GDR_OK; k++)
        if (p->parts[k].failed)
            status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory serialising the mesh", job->path);
    if (status == GDR_OK && !cache_pages_encode_mesh(&one->meshes[0], job->in->page_bytes, &p->pages))
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory encoding the mesh's pages", job->path);
    gdr_scene_destroy(one);
    return status;
}

/* Appends mesh i's parts to the spools (under the lock, in mesh order) and keeps its index entry. */
static gdr_status append_parts(build_job *job, uint32_t i, mesh_parts *p, gdr_error *err)
{
    int ok = 1;
    for (int k = 0; k < PER_MESH && ok; k++)
        ok = cache_spool_append(&job->spools[k], p->parts[k].data, p->parts[k].size);
    if (ok)
        ok = cache_spool_append(&job->spools[PAGE_SPOOL], p->pages.pages.data, p->pages.pages.size);
    if (!ok)
        return gdr_error_set(err, GDR_ERROR_IO, "%s: cannot write its temporary files: %s", job->path, strerror(errno));
    free(p->pages.pages.data);
    p->pages.pages = (writer){.size = p->pages.pages.size}; /* the size stays: it places the next mesh's pages */
    job->index[i] = p->pages;
    p->pages = (cache_mesh_pages){0};
    return GDR_OK;
}

static void mesh_task(void *user, uint32_t i, uint32_t worker)
{
    (void)worker;
    build_job *job = user;
    mesh_parts parts = {0};
    gdr_error err = {0};
    gdr_status status = atomic_load(&job->failed) ? GDR_ERROR_INVALID_ARGUMENT : make_parts(job, i, &parts, &err);
    pthread_mutex_lock(&job->lock);
    while (job->next != i)
        pthread_cond_wait(&job->turn, &job->lock);
    if (!atomic_load(&job->failed)) {
        if (status == GDR_OK)
            status = append_parts(job, i, &parts, &err);
        if (status != GDR_OK) {
            job->status = gdr_error_set(&job->err, status, "meshes[%u]: %s", i, err.message);
            atomic_store(&job->failed, 1);
        }
    }
    job->next++;
    gdr_progress_update(&job->progress, job->next);
    pthread_cond_broadcast(&job->turn);
    pthread_mutex_unlock(&job->lock);
    free_parts(&parts);
}

/* --- the file ------------------------------------------------------------------------------------ */

/* One section of the file: its bytes in memory, or a spool (with the PAGE section's header and
 * index in memory before it). */
typedef struct out_section {
    writer bytes;
    const cache_spool *spool;
} out_section;

/* The PAGE section's header and index, the index's page offsets placed after it. */
static int page_head(build_job *job, writer *w)
{
    uint64_t index_size = 0, offset;
    for (uint32_t m = 0; m < job->mesh_count; m++)
        index_size += job->index[m].index.size;
    offset = CACHE_PAGES_HEADER + index_size;
    XXH3_state_t *state = XXH3_createState();
    if (!state || XXH3_64bits_reset(state) != XXH_OK) {
        XXH3_freeState(state);
        return 0;
    }
    for (uint32_t m = 0; m < job->mesh_count; m++) {
        cache_pages_rebase(&job->index[m], offset);
        offset += job->index[m].pages.size;
        XXH3_64bits_update(state, job->index[m].index.data, job->index[m].index.size);
    }
    cache_pages_put_header(w, job->mesh_count, job->in->page_bytes, index_size, (uint64_t)XXH3_64bits_digest(state));
    XXH3_freeState(state);
    for (uint32_t m = 0; m < job->mesh_count; m++)
        put(w, job->index[m].index.data, job->index[m].index.size);
    return !w->failed;
}

/* The checksum of a section: of its bytes, or its spool's, or (PAGE) of both in turn. */
static int section_checksum(const out_section *s, uint64_t *out)
{
    if (!s->spool) {
        *out = gdr_io_hash(s->bytes.data, s->bytes.size);
        return 1;
    }
    if (s->bytes.size == 0) {
        *out = cache_spool_digest(s->spool);
        return 1;
    }
    XXH3_state_t *state = XXH3_createState();
    int ok = state && XXH3_64bits_reset(state) == XXH_OK;
    if (ok)
        XXH3_64bits_update(state, s->bytes.data, s->bytes.size);
    ok = ok && cache_spool_hash_into(s->spool, state);
    *out = ok ? (uint64_t)XXH3_64bits_digest(state) : 0;
    XXH3_freeState(state);
    return ok;
}

/* Every section of the table the file has, in order: bytes and table entries (offsets from `start`). */
static gdr_status gather_sections(build_job *job, out_section *sections, section_entry *entries, uint32_t *count,
                                  uint64_t start, uint64_t *end, gdr_error *err)
{
    uint32_t n = 0;
    uint64_t at = start;
    for (int k = 0; k < CACHE_SECTION_COUNT; k++) {
        const cache_section *sec = &gdr_cache_sections[k];
        if (sec->present && !sec->present(job->in))
            continue;
        out_section *s = &sections[n];
        int spooled = -1;
        for (int p = 0; p < PER_MESH; p++)
            spooled = per_mesh_sections[p] == k ? p : spooled;
        int ok = 1;
        if (spooled >= 0)
            s->spool = &job->spools[spooled];
        else if (k == CACHE_PAGES)
            s->spool = &job->spools[PAGE_SPOOL], ok = page_head(job, &s->bytes);
        else
            sec->write(&s->bytes, job->in), ok = !s->bytes.failed;
        at = (at + 7) & ~(uint64_t)7;
        entries[n] = (section_entry){sec->id, sec->flags, at, s->bytes.size + (s->spool ? s->spool->size : 0), 0};
        if (!ok || !section_checksum(s, &entries[n].checksum))
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory serialising the scene", job->path);
        at += entries[n].size;
        n++;
    }
    *count = n;
    *end = at;
    return GDR_OK;
}

/* Header, table, then each section after its zero padding. */
static int put_file(int fd, const uint8_t *head, size_t head_size, const out_section *sections,
                    const section_entry *entries, uint32_t count)
{
    static const uint8_t zeros[8] = {0};
    int ok = cache_write_all(fd, head, head_size);
    uint64_t at = head_size;
    for (uint32_t i = 0; i < count && ok; i++) {
        ok = cache_write_all(fd, zeros, (size_t)(entries[i].offset - at)) &&
             cache_write_all(fd, sections[i].bytes.data, sections[i].bytes.size) &&
             (!sections[i].spool || cache_spool_copy(sections[i].spool, fd));
        at = entries[i].offset + entries[i].size;
    }
    return ok;
}

static gdr_status write_file(build_job *job, gdr_error *err)
{
    out_section sections[CACHE_SECTION_COUNT] = {0};
    section_entry entries[CACHE_SECTION_COUNT];
    uint32_t count = 0;
    for (int k = 0; k < CACHE_SECTION_COUNT; k++)
        count += !gdr_cache_sections[k].present || gdr_cache_sections[k].present(job->in);
    size_t head_size = CACHE_HEADER_SIZE + (size_t)count * CACHE_ENTRY_SIZE;
    uint64_t size = 0;
    gdr_status status = gather_sections(job, sections, entries, &count, head_size, &size, err);
    uint8_t *head = status == GDR_OK ? calloc(1, head_size) : NULL;
    if (status == GDR_OK && !head)
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", job->path);
    gdr_output_file out;
    if (status == GDR_OK)
        status = gdr_output_open(job->path, &out, err);
    if (status == GDR_OK) {
        cache_put_header(head, entries, count, size, job->in->pages_only ? CACHE_FLAG_PAGES_ONLY : 0);
        int ok = fflush(out.file) == 0 && put_file(fileno(out.file), head, head_size, sections, entries, count);
        if (!ok)
            status = gdr_error_set(err, GDR_ERROR_IO, "%s: write failed: %s", job->path, strerror(errno));
        if (gdr_output_close(&out, ok, job->path, status == GDR_OK ? err : &(gdr_error){0}) != GDR_OK)
            status = err->status;
    }
    free(head);
    for (int k = 0; k < CACHE_SECTION_COUNT; k++)
        free(sections[k].bytes.data);
    return status;
}

/* --- the build ----------------------------------------------------------------------------------- */

/* The skeleton's sections that do not hold meshes are checked as gdr_cache_write checks them. */
static gdr_status check_skeleton(const cache_write_input *in, const char *path, gdr_error *err)
{
    if (in->page_bytes == 0)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: a cache written mesh by mesh needs pages "
                             "(page_bytes)", path);
    for (int k = 0; k < CACHE_SECTION_COUNT; k++) {
        const cache_section *sec = &gdr_cache_sections[k];
        int per_mesh = 0;
        for (int p = 0; p < PER_MESH; p++)
            per_mesh |= per_mesh_sections[p] == k;
        if (per_mesh || (sec->present && !sec->present(in)) || !sec->check)
            continue;
        gdr_status status = sec->check(in, path, err);
        if (status != GDR_OK)
            return status;
    }
    return GDR_OK;
}

/* Makes every mesh on `workers` threads and spools it; the first failure in mesh order, if any. */
static gdr_status build_meshes(build_job *job, uint32_t workers, gdr_error *err)
{
    gdr_thread_pool *pool = NULL;
    gdr_status status = workers > 1 ? gdr_thread_pool_create(workers, &pool, err) : GDR_OK;
    for (int k = 0; k <= PER_MESH && status == GDR_OK; k++)
        status = cache_spool_open(&job->spools[k], job->path, err);
    if (status != GDR_OK) {
        gdr_thread_pool_destroy(pool);
        return status;
    }
    gdr_progress_begin(&job->progress, "meshes", job->mesh_count, job->source->no_progress);
    gdr_thread_pool_run(pool, job->mesh_count, mesh_task, job);
    gdr_progress_end(&job->progress);
    gdr_thread_pool_destroy(pool);
    if (atomic_load(&job->failed)) {
        *err = job->err;
        return job->status;
    }
    return GDR_OK;
}

gdr_status gdr_cache_write_meshes(const char *path, const gdr_scene *skeleton, const gdr_cache_mesh_source *meshes,
                                  const gdr_cache_write_options *options, gdr_error *err)
{
    static const gdr_cache_write_options defaults = {0};
    options = options ? options : &defaults;
    if (!skeleton || !meshes || !meshes->make)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: no scene or mesh source", path);
    cache_write_input in = cache_write_input_of(skeleton, options);
    gdr_status status = check_skeleton(&in, path, err);
    if (status != GDR_OK)
        return status;
    uint32_t threads = meshes->thread_count ? meshes->thread_count : gdr_processor_count();
    uint32_t workers = threads < skeleton->mesh_count ? threads : skeleton->mesh_count;
    workers = workers ? workers : 1;
    build_job job = {.path = path, .source = meshes, .in = &in, .mesh_count = skeleton->mesh_count,
                     .threads_each = threads / workers ? threads / workers : 1};
    job.index = calloc(skeleton->mesh_count ? skeleton->mesh_count : 1, sizeof *job.index);
    for (int k = 0; k <= PER_MESH; k++)
        job.spools[k] = (cache_spool){.fd = -1};
    pthread_mutex_init(&job.lock, NULL);
    pthread_cond_init(&job.turn, NULL);
    atomic_init(&job.failed, 0);
    status = job.index ? build_meshes(&job, workers, err)
                       : gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    if (status == GDR_OK)
        status = write_file(&job, err);
    for (int k = 0; k <= PER_MESH; k++)
        cache_spool_close(&job.spools[k]);
    for (uint32_t m = 0; job.index && m < skeleton->mesh_count; m++)
        cache_pages_free_mesh(&job.index[m]);
    free(job.index);
    pthread_cond_destroy(&job.turn);
    pthread_mutex_destroy(&job.lock);
    return status;
}
