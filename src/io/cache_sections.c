/* What each section of the scene cache holds (docs/CACHE_FORMAT.md): one description per section,
 * its writer and its reader side by side, in the order the file holds them. The container
 * (cache.c) walks the same table to write the file and to read it back. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/cache_decode.h"
#include "gdr/geometry.h"
#include "io/cache_internal.h"
#include "io/cache_pages.h"
#include "io/cache_pvs.h"
#include "io/io_internal.h"

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the cache reader and writer assume a little-endian host"
#endif

enum { TEXTURE_REF_RECORD = 4 * 4 + 4 * 4, QUANTIZATION_RECORD = 4 + 4 + 12 + 4 + 8 + 4 };

#define FOURCC(a, b, c, d) ((uint32_t)(a) | (uint32_t)(b) << 8 | (uint32_t)(c) << 16 | (uint32_t)(d) << 24)

enum { MESH_RECORD = 64 + 8 + 16 + QUANTIZATION_RECORD, MATERIAL_RECORD = 64 + 16 + 5 * TEXTURE_REF_RECORD + 12 + 5 * 4 + 8, INSTANCE_RECORD = CACHE_INSTANCE_RECORD,
       CAMERA_RECORD = 64 + 12 + 16 + 20, TEXTURE_RECORD = 64 + 16, CLUSTERS_RECORD = 6 * 4,
       CLUSTER_RECORD = 4 * 4 + 16 + 12 + 12 + 4 + 3 * 4, GROUP_RECORD = 16 + 4 + 3 * 4 + 16,
       REFINEMENT_RECORD = 3 * 4, SIZE_CLASSES_RECORD = 4 * GDR_CLUSTER_SIZE_CLASSES,
       NODE_RECORD = 16 + 4 + 4 + 4 * 4 + 2 * 4 };

/* What the sections read so far hand to the ones after them. */
struct cache_read_state {
    const char *name; /* the file, for messages */
    const uint8_t *file; /* its bytes, for offsets in messages */
    gdr_scene *scene; /* being built */
    gdr_pvs **out_pvs;
    uint32_t mesh_count, material_count, instance_count, camera_count, texture_count; /* SCNE */
    reader textures;  /* TEXR, read again with TXPX */
    reader meshes;    /* MESH, read again with GEOM */
    reader clusters;  /* CLUS, read again with CLGR */
    int paged;        /* the geometry stays in the file's pages: GEOM, VCOL, CLGM and PAGE are not read */
};

static int all_finite(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* A section of fixed-size records: its size must be count records exactly. */
static gdr_status expect_records(const cache_read_state *st, const reader *r, uint32_t id, uint32_t count,
                                 uint32_t record, gdr_error *err)
{
    if (r->size == (uint64_t)count * record)
        return GDR_OK;
    char text[5];
    fourcc_text(id, text);
    return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section '%s' holds %zu bytes, %u records need %llu", st->name,
                         text, r->size, count, (unsigned long long)count * record);
}

/* A section read to its end. */
static gdr_status expect_end(const cache_read_state *st, const reader *r, const char *id, gdr_error *err)
{
    if (r->at == r->size)
        return GDR_OK;
    return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section '%s' has %zu bytes left over", st->name, id,
                         r->size - r->at);
}

/* --- SRCE: what the cache was built from (read by the container, for staleness) --------------- */

static void write_source(writer *w, const cache_write_input *in)
{
    const gdr_cache_source *source = in->source;
    put_string(w, source && source->build_options ? source->build_options : "");
    uint32_t files = source && source->files ? source->files->count : 0;
    put_u32(w, files);
    for (uint32_t i = 0; i < files; i++) {
        const gdr_source_file *f = &source->files->files[i];
        put_string(w, f->path);
        put_u32(w, (uint32_t)f->state);
        put_u64(w, f->size);
        put_u64(w, (uint64_t)f->mtime_ns);
        put_u64(w, f->hash);
    }
}

/* --- REPT: what the import said (read by the container) ----------------------------------------- */

static void write_report(writer *w, const cache_write_input *in)
{
    const gdr_import_report *report = in->report;
    uint32_t kept = report ? report->warning_count : 0;
    if (kept > GDR_REPORT_MAX_WARNINGS)
        kept = GDR_REPORT_MAX_WARNINGS;
    put_u32(w, report ? report->file_cameras : 0);
    put_u32(w, report && report->warning_total > kept ? report->warning_total : kept);
    put_u32(w, kept);
    for (uint32_t i = 0; i < kept; i++) {
        size_t length = strlen(report->warnings[i]);
        put_u32(w, (uint32_t)(length > GDR_REPORT_MAX_WARNING_BYTES ? GDR_REPORT_MAX_WARNING_BYTES : length));
        put(w, report->warnings[i], length > GDR_REPORT_MAX_WARNING_BYTES ? GDR_REPORT_MAX_WARNING_BYTES : length);
    }
}

/* --- SCNE: counts and extensions --------------------------------------------------------------- */

static void write_scene(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    put_u32(w, s->mesh_count);
    put_u32(w, s->material_count);
    put_u32(w, s->instance_count);
    put_u32(w, s->camera_count);
    put_u32(w, s->texture_count);
    put_string(w, s->extensions);
}

static gdr_status read_scene(cache_read_state *st, reader *r, gdr_error *err)
{
    st->mesh_count = get_u32(r);
    st->material_count = get_u32(r);
    st->instance_count = get_u32(r);
    st->camera_count = get_u32(r);
    st->texture_count = get_u32(r);
    uint32_t ext_length;
    const char *ext = get_string(r, &ext_length);
    if (r->failed || r->at != r->size)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'SCNE' has the wrong size", st->name);
    if (!ext_length)
        return GDR_OK;
    char *copy = malloc(ext_length + 1);
    if (!copy)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", st->name);
    memcpy(copy, ext, ext_length);
    copy[ext_length] = 0;
    gdr_status status = gdr_scene_set_extensions(st->scene, copy, err);
    free(copy);
    return status;
}

/* --- TEXR (per texture: name, size, sRGB, format) and TXPX (their levels) --------------------- */

/* The reader's limit on a texture's sides, enforced by the writer: no cache it cannot read back. */
static gdr_status check_texture_sides(const cache_write_input *in, const char *path, gdr_error *err)
{
    for (uint32_t i = 0; i < in->scene->texture_count; i++) {
        const gdr_texture *t = &in->scene->textures[i];
        if (t->width == 0 || t->height == 0 || t->width > CACHE_MAX_TEXTURE_SIDE || t->height > CACHE_MAX_TEXTURE_SIDE)
            return gdr_error_set(err, GDR_ERROR_CAPACITY, "%s: texture %u is %ux%u; a cache holds at most %ux%u", path,
                                 i, t->width, t->height, CACHE_MAX_TEXTURE_SIDE, CACHE_MAX_TEXTURE_SIDE);
    }
    return GDR_OK;
}

static void write_textures(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->texture_count; i++) {
        put_name(w, s->textures[i].name);
        put_u32(w, s->textures[i].width);
        put_u32(w, s->textures[i].height);
        put_u32(w, s->textures[i].srgb);
        put_u32(w, s->textures[i].format);
    }
}

static gdr_status read_textures(cache_read_state *st, reader *r, gdr_error *err)
{
    st->textures = *r;
    return expect_records(st, r, FOURCC('T', 'E', 'X', 'R'), st->texture_count, TEXTURE_RECORD, err);
}

static void write_pixels(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->texture_count; i++)
        put(w, s->textures[i].rgba, gdr_texture_format_level_offset(s->textures[i].format, s->textures[i].width,
                                                                    s->textures[i].height, s->textures[i].levels));
}

static gdr_status read_pixels(cache_read_state *st, reader *px, gdr_error *err)
{
    reader *tr = &st->textures;
    for (uint32_t i = 0; i < st->texture_count; i++) {
        char tname[GDR_NAME_MAX];
        get_name(tr, tname);
        uint32_t width = get_u32(tr), height = get_u32(tr), srgb = get_u32(tr), format = get_u32(tr);
        if (width == 0 || height == 0 || width > CACHE_MAX_TEXTURE_SIDE || height > CACHE_MAX_TEXTURE_SIDE ||
            srgb > 1)
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: texture %u: size %ux%u or flags are out of range",
                                 st->name, i, width, height);
        if (format >= GDR_TEXTURE_FORMAT_COUNT)
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: texture %u: format %u is not one this build reads "
                                 "(0 to %u)", st->name, i, format, GDR_TEXTURE_FORMAT_COUNT - 1);
        /* The whole mip chain, texels or blocks, stored so that loading builds and encodes nothing. */
        size_t chain = gdr_texture_format_level_offset(format, width, height, gdr_texture_level_count(width, height));
        const uint8_t *pixels = take(px, chain);
        if (!pixels)
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: texture %u (%s, %ux%u): its %zu bytes of levels run past "
                                 "section 'TXPX'", st->name, i, gdr_texture_format_name(format), width, height, chain);
        gdr_status status = gdr_scene_add_texture_format(st->scene, tname, width, height, format, pixels, srgb, NULL,
                                                         err);
        if (status != GDR_OK)
            return status;
    }
    return expect_end(st, px, "TXPX", err);
}

/* --- MESH (per mesh: name, counts, bounds) and GEOM (their vertices and indices) --------------- */

static void write_meshes(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh *m = &s->meshes[i];
        put_name(w, m->name);
        put_u32(w, m->vertex_count);
        put_u32(w, m->index_count);
        put_f32s(w, &m->bounds.x, 4);
        const gdr_vertex_quantization *q = &m->quantization;
        put_u32(w, q->enabled);
        put_u32(w, (uint32_t)q->position_exponent);
        put_f32s(w, &q->position_origin.x, 3);
        put_u32(w, (uint32_t)q->uv_exponent);
        put_f32s(w, &q->uv_origin.x, 2);
        put_f32s(w, &q->max_displacement, 1);
    }
}

/* One MESH record: name, counts, bounds and the vertex grid, the grid checked. */
typedef struct mesh_record {
    char name[GDR_NAME_MAX];
    uint32_t vertex_count, index_count;
    gdr_vec4 bounds;
    gdr_vertex_quantization quantization;
} mesh_record;

static gdr_status get_mesh_record(cache_read_state *st, uint32_t i, mesh_record *m, gdr_error *err)
{
    reader *r = &st->meshes;
    get_name(r, m->name);
    m->vertex_count = get_u32(r), m->index_count = get_u32(r);
    get_f32s(r, &m->bounds.x, 4);
    gdr_vertex_quantization *q = &m->quantization;
    q->enabled = get_u32(r);
    q->position_exponent = (int32_t)get_u32(r);
    get_f32s(r, &q->position_origin.x, 3);
    q->uv_exponent = (int32_t)get_u32(r);
    get_f32s(r, &q->uv_origin.x, 2);
    get_f32s(r, &q->max_displacement, 1);
    if (q->enabled > 1 || q->position_exponent < -126 || q->position_exponent > 100 || q->uv_exponent < -126 ||
        q->uv_exponent > 100 || !all_finite(&q->position_origin.x, 3) || !all_finite(&q->uv_origin.x, 2) ||
        !(q->max_displacement >= 0.0f && q->max_displacement <= 1e30f))
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'MESH': mesh %u: vertex grid is malformed", st->name,
                             i);
    return GDR_OK;
}

static gdr_status add_paged_meshes(cache_read_state *st, gdr_error *err);

/* Read for streaming, the meshes are made from these records alone (GEOM may not be in the file);
 * else GEOM's reader makes them. */
static gdr_status read_meshes(cache_read_state *st, reader *r, gdr_error *err)
{
    st->meshes = *r;
    gdr_status status = expect_records(st, r, FOURCC('M', 'E', 'S', 'H'), st->mesh_count, MESH_RECORD, err);
    return status == GDR_OK && st->paged ? add_paged_meshes(st, err) : status;
}

/* A file without the whole geometry: written with pages alone, unless asked for it. */
static int has_whole_geometry(const cache_write_input *in) { return !in->pages_only; }

static void write_geometry(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh *m = &s->meshes[i];
        put(w, m->positions, sizeof(gdr_vec3) * m->vertex_count);
        put(w, m->normals, sizeof(gdr_vec3) * m->vertex_count);
        put(w, m->uvs, sizeof(gdr_vec2) * m->vertex_count);
        put(w, m->indices, sizeof(uint32_t) * m->index_count);
    }
}

/* One mesh: its arrays copied (aligned, so gdr_scene_add_mesh can read them as arrays) and added. */
static gdr_status read_one_mesh(cache_read_state *st, reader *geo, uint32_t i, gdr_error *err)
{
    mesh_record m;
    gdr_status status = get_mesh_record(st, i, &m, err);
    if (status != GDR_OK)
        return status;
    const char *mname = m.name;
    uint32_t vertex_count = m.vertex_count, index_count = m.index_count;
    gdr_vec4 bounds = m.bounds;
    uint64_t need = (uint64_t)vertex_count * 32 + (uint64_t)index_count * 4;
    if (need > geo->size - geo->at)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: mesh %u: %u vertices and %u indices run past section 'GEOM'",
                             st->name, i, vertex_count, index_count);
    const void *positions = take(geo, (size_t)vertex_count * 12), *normals = take(geo, (size_t)vertex_count * 12);
    const void *uvs = take(geo, (size_t)vertex_count * 8), *indices = take(geo, (size_t)index_count * 4);
    gdr_vec3 *p = malloc((size_t)vertex_count * 12 + 1), *n = malloc((size_t)vertex_count * 12 + 1);
    gdr_vec2 *t = malloc((size_t)vertex_count * 8 + 1);
    uint32_t *idx = malloc((size_t)index_count * 4 + 1);
    if (p && n && t && idx) {
        memcpy(p, positions, (size_t)vertex_count * 12);
        memcpy(n, normals, (size_t)vertex_count * 12);
        memcpy(t, uvs, (size_t)vertex_count * 8);
        memcpy(idx, indices, (size_t)index_count * 4);
        if (!all_finite((const float *)n, (size_t)vertex_count * 3) ||
            !all_finite((const float *)t, (size_t)vertex_count * 2) || !all_finite(&bounds.x, 4))
            status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: mesh %u: normals, uvs or bounds are not finite",
                                   st->name, i);
        else
            status = gdr_scene_add_mesh(st->scene, mname, p, n, t, vertex_count, idx, index_count, NULL, err);
    } else {
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", st->name);
    }
    free(p);
    free(n);
    free(t);
    free(idx);
    if (status == GDR_OK) {
        st->scene->meshes[st->scene->mesh_count - 1].bounds = bounds;
        st->scene->meshes[st->scene->mesh_count - 1].quantization = m.quantization;
    }
    return status;
}

/* --- VCOL: per mesh, 0, or 1 and its vertex colours (RGBA floats) ---------------------------------- */

static void write_colors(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh *m = &s->meshes[i];
        put_u32(w, m->colors ? 1u : 0u);
        if (m->colors)
            put(w, m->colors, sizeof(gdr_vec4) * m->vertex_count);
    }
}

static gdr_status read_colors(cache_read_state *st, reader *r, gdr_error *err)
{
    if (st->paged)
        return GDR_OK; /* streamed meshes draw without vertex colours */
    for (uint32_t i = 0; i < st->scene->mesh_count; i++) {
        uint32_t flag = get_u32(r);
        if (flag > 1)
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: mesh %u: vertex colour flag %u is not 0 or 1", st->name, i,
                                 flag);
        if (!flag)
            continue;
        uint32_t n = st->scene->meshes[i].vertex_count;
        const void *data = take(r, sizeof(gdr_vec4) * (size_t)n);
        gdr_vec4 *colors = data ? malloc(sizeof(gdr_vec4) * ((size_t)n + 1)) : NULL;
        if (!data)
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: mesh %u: vertex colours run past section 'VCOL'", st->name, i);
        if (!colors)
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory", st->name);
        memcpy(colors, data, sizeof(gdr_vec4) * (size_t)n);
        gdr_status status = gdr_scene_set_mesh_colors(st->scene, i, colors, err); /* checks each value */
        free(colors);
        if (status != GDR_OK)
            return status;
    }
    return expect_end(st, r, "VCOL", err);
}

/* A scene read for streaming: each mesh from its MESH record alone (counts and bounds, no arrays). */
static gdr_status add_paged_meshes(cache_read_state *st, gdr_error *err)
{
    st->scene->geometry_in_pages = 1;
    for (uint32_t i = 0; i < st->mesh_count; i++) {
        mesh_record m;
        gdr_status status = get_mesh_record(st, i, &m, err);
        if (status == GDR_OK && (!all_finite(&m.bounds.x, 4) || !(m.bounds.w >= 0.0f)))
            status = gdr_error_set(err, GDR_ERROR_PARSE, "%s: mesh %u: bounds are not finite", st->name, i);
        if (status == GDR_OK)
            status = gdr_scene_add_paged_mesh(st->scene, m.name, m.vertex_count, m.index_count, m.bounds, err);
        if (status != GDR_OK)
            return status;
        st->scene->meshes[i].quantization = m.quantization;
    }
    return GDR_OK;
}

static gdr_status read_geometry(cache_read_state *st, reader *geo, gdr_error *err)
{
    if (st->paged)
        return GDR_OK; /* the meshes were made from their MESH records */
    for (uint32_t i = 0; i < st->mesh_count; i++) {
        gdr_status status = read_one_mesh(st, geo, i, err);
        if (status != GDR_OK)
            return status;
    }
    return expect_end(st, geo, "GEOM", err);
}

/* --- CLUS (per mesh: the counts of its clusters) and CLDT (their arrays) ----------------------- */

static void write_cluster_counts(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh_clusters *c = &s->meshes[i].clusters;
        put_u32(w, c->cluster_count);
        put_u32(w, c->level0_cluster_count);
        put_u32(w, c->vertex_count);
        put_u32(w, c->triangle_byte_count);
        put_u32(w, c->group_count);
        put_u32(w, c->dag_depth);
    }
}

static gdr_status read_cluster_counts(cache_read_state *st, reader *r, gdr_error *err)
{
    st->clusters = *r;
    return expect_records(st, r, FOURCC('C', 'L', 'U', 'S'), st->mesh_count, CLUSTERS_RECORD, err);
}

static void write_cluster_records(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh_clusters *c = &s->meshes[i].clusters;
        for (uint32_t k = 0; k < c->cluster_count; k++) {
            const gdr_cluster *cl = &c->clusters[k];
            put_u32(w, cl->vertex_offset);
            put_u32(w, cl->triangle_offset);
            put_u32(w, cl->vertex_count);
            put_u32(w, cl->triangle_count);
            put_f32s(w, &cl->sphere.x, 4);
            put_f32s(w, &cl->cone_apex.x, 3);
            put_f32s(w, &cl->cone_axis.x, 3);
            put_f32s(w, &cl->cone_cutoff, 1);
            put_u32(w, cl->group);
            put_u32(w, cl->refined_group);
            put_u32(w, cl->reserved);
        }
    }
}

/* Group g's clusters' spheres enclosed (gdr_lod_enclosing_sphere, in cluster order, into `spheres`,
 * room for the group's clusters): what the hierarchy's leaf of g bounds its clusters with. */
static gdr_vec4 group_cluster_bounds(const gdr_mesh_clusters *c, const gdr_cluster_group *g, gdr_vec4 *spheres)
{
    for (uint32_t i = 0; i < g->cluster_count; i++)
        spheres[i] = c->clusters[g->first_cluster + i].sphere;
    return g->cluster_count ? gdr_lod_enclosing_sphere(spheres, g->cluster_count) : g->sphere;
}

/* Group g's refinements (its clusters' refined groups in order of first use, with their counts),
 * written where w is not NULL; counted into *count. `refined` and `clusters`: room for the group's
 * clusters. */
static void put_group_refinements(writer *w, const gdr_mesh_clusters *c, uint32_t g, uint32_t *refined,
                                  uint32_t *clusters, uint32_t *count)
{
    const gdr_cluster_group *gr = &c->groups[g];
    uint32_t n = 0;
    for (uint32_t i = gr->first_cluster; i < gr->first_cluster + gr->cluster_count; i++) {
        uint32_t r = c->clusters[i].refined_group, k = 0;
        if (r == GDR_NO_INDEX)
            continue;
        while (k < n && refined[k] != r)
            k++;
        if (k == n)
            refined[n] = r, clusters[n++] = 0;
        clusters[k]++;
    }
    for (uint32_t k = 0; k < n; k++) {
        if (w) {
            put_u32(w, g);
            put_u32(w, refined[k]);
            put_u32(w, clusters[k]);
        }
        ++*count;
    }
}

/* CLGR: per mesh, what the clusters say about their groups, for a reader without the clusters. */
static void write_cluster_groups(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->mesh_count && !w->failed; i++) {
        const gdr_mesh_clusters *c = &s->meshes[i].clusters;
        uint32_t largest = 1;
        for (uint32_t k = 0; k < c->group_count; k++)
            largest = c->groups[k].cluster_count > largest ? c->groups[k].cluster_count : largest;
        gdr_vec4 *spheres = malloc(sizeof *spheres * largest);
        uint32_t *refined = malloc(2 * sizeof *refined * largest);
        if (!spheres || !refined) {
            free(spheres), free(refined);
            w->failed = 1;
            return;
        }
        uint32_t classes[GDR_CLUSTER_SIZE_CLASSES] = {0};
        for (uint32_t k = 0; k < c->cluster_count; k++)
            classes[gdr_cluster_size_class(c->clusters[k].vertex_count, c->clusters[k].triangle_count)]++;
        for (uint32_t b = 0; b < GDR_CLUSTER_SIZE_CLASSES; b++)
            put_u32(w, classes[b]);
        for (uint32_t k = 0; k < c->group_count; k++) {
            const gdr_cluster_group *g = &c->groups[k];
            gdr_vec4 bounds = group_cluster_bounds(c, g, spheres);
            put_f32s(w, &g->sphere.x, 4);
            put_f32s(w, &g->error, 1);
            put_u32(w, g->depth);
            put_u32(w, g->first_cluster);
            put_u32(w, g->cluster_count);
            put_f32s(w, &bounds.x, 4);
        }
        uint32_t refinements = 0;
        for (uint32_t k = 0; k < c->group_count; k++)
            put_group_refinements(NULL, c, k, refined, refined + largest, &refinements);
        put_u32(w, refinements);
        refinements = 0;
        for (uint32_t k = 0; k < c->group_count; k++)
            put_group_refinements(w, c, k, refined, refined + largest, &refinements);
        free(spheres);
        free(refined);
    }
}

static void write_cluster_geometry(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh_clusters *c = &s->meshes[i].clusters;
        put(w, c->vertices, sizeof(uint32_t) * c->vertex_count);
        put(w, c->triangles, c->triangle_byte_count);
        put_align(w, 4);
    }
}

static int bad_sphere(const gdr_vec4 *sphere) { return !all_finite(&sphere->x, 4) || !(sphere->w >= 0.0f); }

#define CLDT(fmt, ...) gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'CLDT': mesh %u" fmt, name, m, __VA_ARGS__)

/* One cluster record, checked against the limits, the mesh's counts and its groups. */
static gdr_status read_cluster_record(const char *name, reader *r, uint32_t m, uint32_t k, gdr_mesh_clusters *c,
                                      gdr_error *err)
{
    gdr_cluster *cl = &c->clusters[k];
    cl->vertex_offset = get_u32(r);
    cl->triangle_offset = get_u32(r);
    cl->vertex_count = get_u32(r);
    cl->triangle_count = get_u32(r);
    get_f32s(r, &cl->sphere.x, 4);
    get_f32s(r, &cl->cone_apex.x, 3);
    get_f32s(r, &cl->cone_axis.x, 3);
    get_f32s(r, &cl->cone_cutoff, 1);
    cl->group = get_u32(r);
    cl->refined_group = get_u32(r);
    cl->reserved = get_u32(r);
    if (cl->vertex_count < 1 || cl->vertex_count > GDR_CLUSTER_MAX_VERTICES || cl->triangle_count < 1 ||
        cl->triangle_count > GDR_CLUSTER_MAX_TRIANGLES)
        return CLDT(" cluster %u: %u vertices and %u triangles (1 to %u and %u)", k, cl->vertex_count,
                    cl->triangle_count, GDR_CLUSTER_MAX_VERTICES, GDR_CLUSTER_MAX_TRIANGLES);
    if ((uint64_t)cl->vertex_offset + cl->vertex_count > c->vertex_count)
        return CLDT(" cluster %u: vertices %u..%u lie outside the mesh's %u cluster vertices", k, cl->vertex_offset,
                    cl->vertex_offset + (cl->vertex_count - 1), c->vertex_count);
    if (cl->triangle_offset % 4 != 0 ||
        (uint64_t)cl->triangle_offset + 3ull * cl->triangle_count > c->triangle_byte_count)
        return CLDT(" cluster %u: triangle bytes at %u (%u triangles) are unaligned or lie outside the mesh's %u", k,
                    cl->triangle_offset, cl->triangle_count, c->triangle_byte_count);
    if (bad_sphere(&cl->sphere) || !all_finite(&cl->cone_apex.x, 3) || !all_finite(&cl->cone_axis.x, 3) ||
        !all_finite(&cl->cone_cutoff, 1))
        return CLDT(" cluster %u: bounds are not finite (or a negative radius)", k);
    if ((cl->group != GDR_NO_INDEX && cl->group >= c->group_count) ||
        (cl->refined_group != GDR_NO_INDEX && cl->refined_group >= c->group_count))
        return CLDT(" cluster %u: group %u / refined group %u does not exist (%u groups)", k, cl->group,
                    cl->refined_group, c->group_count);
    return GDR_OK;
}

/* Reads one mesh's cluster records (counts and groups already read, the array allocated) and checks
 * every offset, count and index against the limits, the counts and the mesh. */
static gdr_status read_mesh_clusters(const char *name, reader *r, uint32_t m, const gdr_mesh *mesh,
                                     gdr_mesh_clusters *c, gdr_error *err)
{
    uint64_t level0_triangles = 0;
    for (uint32_t k = 0; k < c->cluster_count; k++) {
        gdr_status status = read_cluster_record(name, r, m, k, c, err);
        if (status != GDR_OK)
            return status;
        if (k < c->level0_cluster_count)
            level0_triangles += c->clusters[k].triangle_count;
    }
    if (r->failed) /* the caller checked the sizes: only a programming error gets here */
        return CLDT(" %s", "runs past the section");
    if (level0_triangles != mesh->index_count / 3)
        return CLDT(": level-0 clusters hold %llu triangles, the mesh %u", (unsigned long long)level0_triangles,
                    mesh->index_count / 3);
    return GDR_OK;
}
#undef CLDT

/* One mesh's counts from section 'CLUS', checked against each other and the mesh. */
static gdr_status read_mesh_cluster_counts(cache_read_state *st, uint32_t m, gdr_mesh_clusters *c, gdr_error *err)
{
    reader *counts = &st->clusters;
    const gdr_mesh *mesh = &st->scene->meshes[m];
    c->cluster_count = get_u32(counts);
    c->level0_cluster_count = get_u32(counts);
    c->vertex_count = get_u32(counts);
    c->triangle_byte_count = get_u32(counts);
    c->group_count = get_u32(counts);
    c->dag_depth = get_u32(counts);
    if (c->level0_cluster_count > c->cluster_count ||
        (c->cluster_count == 0 && (c->vertex_count || c->triangle_byte_count || c->group_count || c->dag_depth)) ||
        (c->cluster_count > 0 && (c->level0_cluster_count == 0 || mesh->index_count == 0)))
        return gdr_error_set(err, GDR_ERROR_PARSE,
                             "%s: section 'CLUS': mesh %u: %u clusters (%u of level 0) for %u indices, %u cluster "
                             "vertices, %u triangle bytes, %u groups: inconsistent", st->name, m, c->cluster_count,
                             c->level0_cluster_count, mesh->index_count, c->vertex_count, c->triangle_byte_count,
                             c->group_count);
    return GDR_OK;
}

/* --- CLGR (per mesh: its groups and what its clusters say of them) ------------------------------- */

#define CLGR(fmt, ...) gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'CLGR': mesh %u" fmt, name, m, __VA_ARGS__)

/* Where each mesh's part of a section lies, for the meshes decoded at once. */
typedef struct mesh_decode {
    cache_read_state *st;
    const reader *data;
    size_t *at; /* per mesh: its part's offset in data */
} mesh_decode;

/* Mesh m's groups (and, for a streamed scene, the clusters' bounds per group), checked. */
static gdr_status read_mesh_groups(const char *name, reader *r, uint32_t m, gdr_mesh_clusters *c, bool keep,
                                   gdr_error *err)
{
    for (uint32_t k = 0; k < c->group_count; k++) {
        gdr_cluster_group *g = &c->groups[k];
        gdr_vec4 bounds;
        get_f32s(r, &g->sphere.x, 4);
        get_f32s(r, &g->error, 1);
        g->depth = get_u32(r);
        g->first_cluster = get_u32(r);
        g->cluster_count = get_u32(r);
        get_f32s(r, &bounds.x, 4);
        if (bad_sphere(&g->sphere) || isnan(g->error) || bad_sphere(&bounds))
            return CLGR(" group %u: sphere, bounds or error is not a number", k);
        if ((uint64_t)g->first_cluster + g->cluster_count > c->cluster_count)
            return CLGR(" group %u: clusters %u (+%u) lie outside the mesh's %u", k, g->first_cluster,
                        g->cluster_count, c->cluster_count);
        if (keep)
            c->group_bounds[k] = bounds;
    }
    return GDR_OK;
}

/* Mesh m's refinements: per group in order, refined groups that exist, other than the group, each
 * with clusters, adding up to at most the group's clusters. */
static gdr_status read_mesh_refinements(const char *name, reader *r, uint32_t m, gdr_mesh_clusters *c,
                                        uint32_t count, bool keep, gdr_error *err)
{
    uint32_t group = 0;
    uint64_t used = 0;
    for (uint32_t k = 0; k < count; k++) {
        gdr_cluster_refinement f = {get_u32(r), get_u32(r), get_u32(r)};
        if (f.group != group)
            used = 0;
        if (f.group < group || f.group >= c->group_count || f.refined_group >= c->group_count ||
            f.refined_group == f.group || f.cluster_count == 0 ||
            used + f.cluster_count > c->groups[f.group].cluster_count)
            return CLGR(" refinement %u: group %u, refined group %u, %u clusters: out of order or beyond the "
                        "mesh's %u groups and their clusters", k, f.group, f.refined_group, f.cluster_count,
                        c->group_count);
        group = f.group;
        used += f.cluster_count;
        if (keep)
            c->refinements[k] = f;
    }
    return GDR_OK;
}

static gdr_status decode_mesh_groups(void *user, uint32_t m, gdr_error *err)
{
    const mesh_decode *d = user;
    const char *name = d->st->name;
    gdr_mesh_clusters *c = &d->st->scene->meshes[m].clusters;
    reader r = {d->data->data, d->data->size, d->at[m], 0};
    uint64_t classes = 0;
    for (uint32_t b = 0; b < GDR_CLUSTER_SIZE_CLASSES; b++) {
        uint32_t n = get_u32(&r);
        classes += n;
        if (d->st->paged)
            c->size_classes[b] = n;
    }
    if (classes != c->cluster_count)
        return CLGR(": its size classes hold %llu clusters, the mesh %u", (unsigned long long)classes,
                    c->cluster_count);
    gdr_status status = read_mesh_groups(name, &r, m, c, d->st->paged, err);
    uint32_t count = get_u32(&r);
    if (status == GDR_OK)
        status = read_mesh_refinements(name, &r, m, c, count, d->st->paged, err);
    if (status == GDR_OK && r.failed) /* the caller checked the sizes */
        return CLGR(" %s", "runs past the section");
    return status;
}

/* One mesh's counts (CLUS), its part of CLGR placed against what is left of the section, and its
 * arrays; *at its part. A streamed scene keeps the clusters' bounds per group and the refinements. */
static gdr_status place_mesh_groups(cache_read_state *st, reader *data, uint32_t m, size_t *at, gdr_error *err)
{
    const char *name = st->name;
    gdr_mesh_clusters *c = &st->scene->meshes[m].clusters; /* owned by the scene from here: freed with it */
    gdr_status status = read_mesh_cluster_counts(st, m, c, err);
    if (status != GDR_OK)
        return status;
    *at = data->at;
    uint64_t head = SIZE_CLASSES_RECORD + (uint64_t)c->group_count * GROUP_RECORD;
    if (head + 4 > data->size - data->at)
        return CLGR(": %u groups run past the section", c->group_count);
    data->at += (size_t)head;
    uint32_t refinements = get_u32(data);
    if ((uint64_t)refinements * REFINEMENT_RECORD > data->size - data->at)
        return CLGR(": %u refinements run past the section", refinements);
    data->at += (size_t)refinements * REFINEMENT_RECORD;
    bool keep = st->paged;
    c->groups = c->group_count ? malloc(sizeof *c->groups * (size_t)c->group_count) : NULL;
    c->group_bounds = keep && c->group_count ? malloc(sizeof *c->group_bounds * (size_t)c->group_count) : NULL;
    c->refinements = keep && refinements ? malloc(sizeof *c->refinements * (size_t)refinements) : NULL;
    c->refinement_count = keep ? refinements : 0;
    if ((c->group_count && (!c->groups || (keep && !c->group_bounds))) || (keep && refinements && !c->refinements))
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: mesh %u: out of memory for %u groups", name, m,
                             c->group_count);
    return GDR_OK;
}
#undef CLGR

/* How much decoding a mesh's part of a section costs (cache_decode.c's threads follow it). */
typedef uint64_t mesh_work_fn(const gdr_mesh_clusters *c);
static uint64_t group_work(const gdr_mesh_clusters *c) { return c->group_count; }
static uint64_t cluster_work(const gdr_mesh_clusters *c) { return c->cluster_count; }

/* Every mesh's counts and place first, in order, up to the first that fails; then the meshes
 * placed, decoded at once (cache_decode.c). A failure of an earlier mesh's data comes before a later
 * mesh's counts, as when each mesh was read whole before the next. */
static gdr_status read_in_meshes(cache_read_state *st, reader *data, const char *id,
                                 gdr_status (*place)(cache_read_state *, reader *, uint32_t, size_t *, gdr_error *),
                                 cache_mesh_decode_fn *decode, mesh_work_fn *work, gdr_error *err)
{
    size_t *at = malloc(sizeof *at * (st->mesh_count ? st->mesh_count : 1));
    if (!at)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: out of memory for %u meshes", st->name,
                             st->mesh_count);
    gdr_status placed = GDR_OK;
    uint32_t ready = 0;
    uint64_t records = 0;
    for (; ready < st->mesh_count && placed == GDR_OK; ready++) {
        placed = place(st, data, ready, &at[ready], err);
        records += work(&st->scene->meshes[ready].clusters);
    }
    if (placed != GDR_OK)
        ready--; /* the failed mesh is not decoded */
    mesh_decode d = {st, data, at};
    gdr_status status = cache_decode_meshes(ready, records, decode, &d, err);
    free(at);
    if (status != GDR_OK)
        return status;
    return placed != GDR_OK ? placed : expect_end(st, data, id, err);
}

static gdr_status read_cluster_groups(cache_read_state *st, reader *data, gdr_error *err)
{
    return read_in_meshes(st, data, "CLGR", place_mesh_groups, decode_mesh_groups, group_work, err);
}

/* --- CLDT (per mesh: its cluster records; absent where the pages alone hold them) ---------------- */

static gdr_status decode_mesh_clusters(void *user, uint32_t m, gdr_error *err)
{
    const mesh_decode *d = user;
    gdr_mesh *mesh = &d->st->scene->meshes[m];
    if (mesh->clusters.cluster_count == 0)
        return GDR_OK;
    reader r = {d->data->data, d->data->size, d->at[m], 0};
    return read_mesh_clusters(d->st->name, &r, m, mesh, &mesh->clusters, err);
}

/* One mesh's records placed against what is left of the section, and its array; *at its records. */
static gdr_status place_mesh_clusters(cache_read_state *st, reader *data, uint32_t m, size_t *at, gdr_error *err)
{
    gdr_mesh_clusters *c = &st->scene->meshes[m].clusters;
    uint64_t need = (uint64_t)c->cluster_count * CLUSTER_RECORD;
    if (need > data->size - data->at)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'CLDT': mesh %u: %u clusters run past the section",
                             st->name, m, c->cluster_count);
    *at = data->at;
    data->at += (size_t)need;
    if (c->cluster_count == 0)
        return GDR_OK;
    c->clusters = malloc(sizeof(gdr_cluster) * (size_t)c->cluster_count);
    if (!c->clusters)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: mesh %u: out of memory for %u clusters", st->name, m,
                             c->cluster_count);
    return GDR_OK;
}

static gdr_status read_cluster_data(cache_read_state *st, reader *data, gdr_error *err)
{
    if (st->paged)
        return GDR_OK; /* the pages hold the records */
    return read_in_meshes(st, data, "CLDT", place_mesh_clusters, decode_mesh_clusters, cluster_work, err);
}

#define CLGM(fmt, ...) gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'CLGM': mesh %u" fmt, name, m, __VA_ARGS__)

/* One mesh's cluster vertex list and triangle bytes, each index checked against what it indexes. */
static gdr_status read_mesh_cluster_geometry(const char *name, reader *r, uint32_t m, const gdr_mesh *mesh,
                                             gdr_mesh_clusters *c, gdr_error *err)
{
    uint64_t need = (uint64_t)c->vertex_count * 4 + ((uint64_t)c->triangle_byte_count + 3) / 4 * 4;
    if (need > r->size - r->at)
        return CLGM(": %u cluster vertices and %u triangle bytes run past the section", c->vertex_count,
                    c->triangle_byte_count);
    if (c->cluster_count == 0)
        return GDR_OK;
    c->vertices = malloc(sizeof(uint32_t) * (size_t)c->vertex_count + 1);
    c->triangles = malloc((size_t)c->triangle_byte_count + 1);
    if (!c->vertices || !c->triangles)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: mesh %u: out of memory for %u clusters", name, m,
                             c->cluster_count);
    memcpy(c->vertices, take(r, sizeof(uint32_t) * (size_t)c->vertex_count), sizeof(uint32_t) * (size_t)c->vertex_count);
    memcpy(c->triangles, take(r, c->triangle_byte_count), c->triangle_byte_count);
    take(r, (4 - c->triangle_byte_count % 4) % 4);
    for (uint32_t k = 0; k < c->vertex_count; k++)
        if (c->vertices[k] >= mesh->vertex_count)
            return CLGM(" cluster vertex %u: mesh vertex %u does not exist (%u vertices)", k, c->vertices[k],
                        mesh->vertex_count);
    for (uint32_t k = 0; k < c->cluster_count; k++) {
        const gdr_cluster *cl = &c->clusters[k];
        const uint8_t *local = c->triangles + cl->triangle_offset;
        for (uint32_t t = 0; t < 3 * cl->triangle_count; t++)
            if (local[t] >= cl->vertex_count)
                return CLGM(" cluster %u triangle %u: local vertex %u, the cluster has %u", k, t / 3, local[t],
                            cl->vertex_count);
    }
    return GDR_OK;
}
#undef CLGM

static gdr_status read_cluster_geometry(cache_read_state *st, reader *data, gdr_error *err)
{
    if (st->paged)
        return GDR_OK; /* the pages hold it */
    for (uint32_t m = 0; m < st->mesh_count; m++) {
        gdr_mesh *mesh = &st->scene->meshes[m];
        gdr_status status = read_mesh_cluster_geometry(st->name, data, m, mesh, &mesh->clusters, err);
        if (status != GDR_OK)
            return status;
    }
    return expect_end(st, data, "CLGM", err);
}

/* --- LODH: per mesh, the LOD hierarchy over its clusters ---------------------------------------- */

/* Clusters come with their hierarchy (gdr_meshlets_build, gdr_mesh_build_lod_dag). */
static gdr_status check_hierarchy_present(const cache_write_input *in, const char *path, gdr_error *err)
{
    for (uint32_t i = 0; i < in->scene->mesh_count; i++) {
        const gdr_mesh *m = &in->scene->meshes[i];
        if (m->clusters.cluster_count > 0 && m->clusters.lod_node_count == 0)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: mesh %u ('%s') has clusters without their LOD "
                                 "hierarchy (gdr_mesh_clusters_build_hierarchy)", path, i, m->name);
    }
    return GDR_OK;
}

static void write_hierarchy(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const gdr_mesh_clusters *c = &s->meshes[i].clusters;
        put_u32(w, c->lod_node_count);
        put_u32(w, c->lod_node_levels);
        for (uint32_t k = 0; k < c->lod_node_count; k++) {
            const gdr_lod_node *n = &c->lod_nodes[k];
            put_f32s(w, &n->sphere.x, 4);
            put_f32s(w, &n->max_error, 1);
            put_f32s(w, &n->min_refined_error, 1);
            put_u32(w, n->first);
            put_u32(w, n->count);
            put_u32(w, n->group);
            put_u32(w, n->flags);
            put_u32(w, n->reserved[0]);
            put_u32(w, n->reserved[1]);
        }
    }
}

/* Mesh m's node count and levels, checked against its clusters and what is left of the section, and
 * its node array; *at its nodes, which the reader skips. */
static gdr_status place_mesh_hierarchy(cache_read_state *st, reader *r, uint32_t m, size_t *at, gdr_error *err)
{
    gdr_mesh_clusters *c = &st->scene->meshes[m].clusters;
    uint32_t node_count = get_u32(r), levels = get_u32(r);
    if (r->failed || (c->cluster_count == 0) != (node_count == 0) ||
        (uint64_t)node_count * NODE_RECORD > r->size - r->at)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'LODH': mesh %u: %u nodes for %u clusters "
                             "(the section holds %zu more bytes)", st->name, m, node_count, c->cluster_count,
                             r->failed ? (size_t)0 : r->size - r->at);
    *at = r->at;
    r->at += (size_t)node_count * NODE_RECORD;
    if (node_count == 0)
        return GDR_OK;
    c->lod_nodes = malloc(sizeof *c->lod_nodes * node_count); /* owned by the scene from here */
    if (!c->lod_nodes)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "%s: mesh %u: out of memory for %u hierarchy nodes",
                             st->name, m, node_count);
    c->lod_node_count = node_count;
    c->lod_node_levels = levels;
    return GDR_OK;
}

/* Mesh m's nodes, then the whole hierarchy checked against the mesh's clusters. */
static gdr_status decode_mesh_hierarchy(void *user, uint32_t m, gdr_error *err)
{
    const mesh_decode *d = user;
    gdr_mesh_clusters *c = &d->st->scene->meshes[m].clusters;
    if (c->lod_node_count == 0)
        return GDR_OK;
    reader r = {d->data->data, d->data->size, d->at[m], 0};
    for (uint32_t k = 0; k < c->lod_node_count; k++) {
        gdr_lod_node *n = &c->lod_nodes[k];
        get_f32s(&r, &n->sphere.x, 4);
        get_f32s(&r, &n->max_error, 1);
        get_f32s(&r, &n->min_refined_error, 1);
        n->first = get_u32(&r);
        n->count = get_u32(&r);
        n->group = get_u32(&r);
        n->flags = get_u32(&r);
        n->reserved[0] = get_u32(&r);
        n->reserved[1] = get_u32(&r);
    }
    char what[192];
    if (!gdr_mesh_clusters_check_hierarchy(c, what, sizeof what))
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'LODH': mesh %u: %s", d->st->name, m, what);
    return GDR_OK;
}

static uint64_t hierarchy_work(const gdr_mesh_clusters *c) { return (uint64_t)c->lod_node_count + c->cluster_count; }

/* Every hierarchy is checked whole (gdr_mesh_clusters_check_hierarchy) against the clusters read,
 * the meshes decoded and checked at once (read_in_meshes), the first failure in mesh order refusing
 * the file. */
static gdr_status read_hierarchy(cache_read_state *st, reader *r, gdr_error *err)
{
    return read_in_meshes(st, r, "LODH", place_mesh_hierarchy, decode_mesh_hierarchy, hierarchy_work, err);
}

/* --- MATL: materials --------------------------------------------------------------------------- */

static void put_texture_ref(writer *w, const gdr_texture_ref *t)
{
    put_u32(w, t->texture);
    put_u32(w, t->sampler);
    put_f32s(w, (const float[5]){t->offset.x, t->offset.y, t->scale.x, t->scale.y, t->rotation}, 5);
    put_u32(w, 0); /* reserved */
}

/* The reader's rule for a material's values (gdr_material_problem), enforced by the writer. */
static gdr_status check_materials(const cache_write_input *in, const char *path, gdr_error *err)
{
    for (uint32_t i = 0; i < in->scene->material_count; i++) {
        const char *problem = gdr_material_problem(&in->scene->materials[i]);
        if (problem)
            return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: material %u: %s; a cache cannot hold it", path,
                                 i, problem);
    }
    return GDR_OK;
}

static void write_materials(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->material_count; i++) {
        const gdr_material *m = &s->materials[i];
        put_name(w, m->name);
        put_f32s(w, &m->base_color.x, 4);
        const gdr_texture_ref *refs[5] = {&m->base_color_texture, &m->metallic_roughness_texture, &m->normal_texture,
                                          &m->occlusion_texture, &m->emissive_texture};
        for (int k = 0; k < 5; k++)
            put_texture_ref(w, refs[k]);
        put_f32s(w, &m->emissive.x, 3);
        put_f32s(w, (const float[5]){m->metallic_factor, m->roughness_factor, m->normal_scale, m->occlusion_strength,
                                     m->alpha_cutoff}, 5);
        put_u32(w, m->alpha_mode);
        put_u32(w, m->double_sided);
    }
}

/* One texture reference: the texture must exist; its sampler state and transform are checked with the
 * material (gdr_material_problem). */
static gdr_status get_texture_ref(cache_read_state *st, reader *ma, uint32_t material, gdr_texture_ref *t, gdr_error *err)
{
    t->texture = get_u32(ma);
    t->sampler = get_u32(ma);
    float f[5];
    get_f32s(ma, f, 5);
    (void)get_u32(ma);
    t->offset = (gdr_vec2){f[0], f[1]};
    t->scale = (gdr_vec2){f[2], f[3]};
    t->rotation = f[4];
    if (t->texture != GDR_NO_INDEX && t->texture >= st->texture_count)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: material %u: texture %u does not exist (%u textures)",
                             st->name, material, t->texture, st->texture_count);
    return GDR_OK;
}

static gdr_status read_one_material(cache_read_state *st, reader *ma, uint32_t i, gdr_error *err)
{
    gdr_material m;
    float factors[5];
    get_name(ma, m.name);
    get_f32s(ma, &m.base_color.x, 4);
    gdr_texture_ref *refs[5] = {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture,
                                &m.occlusion_texture, &m.emissive_texture};
    for (int k = 0; k < 5; k++) {
        gdr_status status = get_texture_ref(st, ma, i, refs[k], err);
        if (status != GDR_OK)
            return status;
    }
    get_f32s(ma, &m.emissive.x, 3);
    get_f32s(ma, factors, 5);
    m.metallic_factor = factors[0];
    m.roughness_factor = factors[1];
    m.normal_scale = factors[2];
    m.occlusion_strength = factors[3];
    m.alpha_cutoff = factors[4];
    m.alpha_mode = get_u32(ma);
    m.double_sided = get_u32(ma);
    const char *problem = gdr_material_problem(&m);
    if (problem)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: material %u: %s", st->name, i, problem);
    return gdr_scene_add_material(st->scene, &m, NULL, err);
}

static gdr_status read_materials(cache_read_state *st, reader *r, gdr_error *err)
{
    gdr_status status = expect_records(st, r, FOURCC('M', 'A', 'T', 'L'), st->material_count, MATERIAL_RECORD, err);
    for (uint32_t i = 0; i < st->material_count && status == GDR_OK; i++)
        status = read_one_material(st, r, i, err);
    return status;
}

/* --- INST: instances ------------------------------------------------------------------------------ */

static void write_instances(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->instance_count; i++) {
        const gdr_instance *inst = &s->instances[i];
        put_f32s(w, inst->transform.m, 16);
        put_u32(w, inst->mesh);
        put_u32(w, inst->material);
        put_f32s(w, &inst->color.x, 4);
        put_f32s(w, &inst->min_screen_size, 1);
        put_f32s(w, &inst->max_screen_size, 1);
    }
}

static gdr_status read_instances(cache_read_state *st, reader *in, gdr_error *err)
{
    gdr_status status = expect_records(st, in, FOURCC('I', 'N', 'S', 'T'), st->instance_count, INSTANCE_RECORD, err);
    for (uint32_t i = 0; i < st->instance_count && status == GDR_OK; i++) {
        gdr_instance inst;
        cache_get_instance(in, &inst);
        if (!all_finite(&inst.color.x, 4))
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: instance %u: colour is not finite", st->name, i);
        status = gdr_scene_add_instance(st->scene, &inst, err);
    }
    return status;
}

/* --- CAMR: cameras ---------------------------------------------------------------------------------- */

static void write_cameras(writer *w, const cache_write_input *in)
{
    const gdr_scene *s = in->scene;
    for (uint32_t i = 0; i < s->camera_count; i++) {
        const gdr_camera *cam = &s->cameras[i];
        put_name(w, cam->name);
        put_f32s(w, &cam->position.x, 3);
        put_f32s(w, &cam->rotation.x, 4);
        put_f32s(w, (const float[5]){cam->yfov, cam->znear, cam->zfar, cam->aspect, cam->ymag}, 5);
    }
}

static gdr_status read_cameras(cache_read_state *st, reader *ca, gdr_error *err)
{
    gdr_status status = expect_records(st, ca, FOURCC('C', 'A', 'M', 'R'), st->camera_count, CAMERA_RECORD, err);
    for (uint32_t i = 0; i < st->camera_count && status == GDR_OK; i++) {
        gdr_camera cam;
        float lens[5];
        get_name(ca, cam.name);
        get_f32s(ca, &cam.position.x, 3);
        get_f32s(ca, &cam.rotation.x, 4);
        get_f32s(ca, lens, 5);
        cam.yfov = lens[0];
        cam.znear = lens[1];
        cam.zfar = lens[2];
        cam.aspect = lens[3];
        cam.ymag = lens[4];
        if (!all_finite(&cam.position.x, 3) || !all_finite(&cam.rotation.x, 4) || !all_finite(lens, 5))
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s: camera %u: values are not finite", st->name, i);
        status = gdr_scene_add_camera(st->scene, &cam, err);
    }
    return status;
}

/* --- PVIS (optional): the precomputed-visibility blob (cache_pvs.h) ------------------------------ */

/* Checked whether or not the caller wants it (out_pvs may be NULL), like every section. */
static gdr_status read_pvs(cache_read_state *st, reader *r, gdr_error *err)
{
    return cache_pvs_read(st->name, r, (size_t)(r->data - st->file), st->scene->instance_count, st->out_pvs, err);
}

/* --- PAGE: the geometry in pages, for reading on demand (cache_pages.c, paged_cache.c) --------- */

static int has_pages(const cache_write_input *in) { return in->page_bytes != 0; }

static gdr_status check_page_bytes(const cache_write_input *in, const char *path, gdr_error *err)
{
    if (in->page_bytes >= GDR_PAGE_BYTES_MIN && in->page_bytes <= GDR_PAGE_BYTES_MAX)
        return GDR_OK;
    return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: page size %u bytes is outside [%u, %u]", path,
                         in->page_bytes, GDR_PAGE_BYTES_MIN, GDR_PAGE_BYTES_MAX);
}

static void write_pages(writer *w, const cache_write_input *in) { cache_pages_write(w, in->scene, in->page_bytes); }

/* The whole-file reader checks the page index (the section checksum covers the pages' bytes);
 * the pages themselves are decoded, and checked, by the paged reader. */
static gdr_status read_pages(cache_read_state *st, reader *r, gdr_error *err)
{
    if (st->paged)
        return GDR_OK; /* gdr_paged_cache_open reads and checks the index, each page its own checksum */
    uint32_t mesh_count;
    uint64_t index_size, index_hash;
    gdr_status status = cache_pages_parse_header(st->name, r->data, r->size, &mesh_count, &index_size,
                                                 &index_hash, err);
    if (status != GDR_OK)
        return status;
    if (mesh_count != st->mesh_count)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: section 'PAGE': %u meshes, the scene has %u", st->name,
                             mesh_count, st->mesh_count);
    if (gdr_io_hash(r->data + CACHE_PAGES_HEADER, (size_t)index_size) != index_hash)
        return gdr_error_set(err, GDR_ERROR_CORRUPT, "%s: section 'PAGE': index checksum mismatch", st->name);
    gdr_paged_mesh *meshes;
    status = cache_pages_parse_index(st->name, r->data + CACHE_PAGES_HEADER, index_size, mesh_count, 0, r->size,
                                     &meshes, err);
    cache_pages_free_index(meshes, mesh_count);
    return status;
}

/* --- the table ------------------------------------------------------------------------------------- */

#define REQUIRED CACHE_SECTION_REQUIRED
const cache_section gdr_cache_sections[CACHE_SECTION_COUNT] = {
    [CACHE_SOURCE] = {FOURCC('S', 'R', 'C', 'E'), 0, 1, NULL, NULL, write_source, NULL, 0, 0},
    [CACHE_REPORT] = {FOURCC('R', 'E', 'P', 'T'), REQUIRED, 0, NULL, NULL, write_report, NULL, 0, 0},
    [CACHE_SCENE] = {FOURCC('S', 'C', 'N', 'E'), REQUIRED, 0, NULL, NULL, write_scene, read_scene, 0, 0},
    [CACHE_TEXTURES] = {FOURCC('T', 'E', 'X', 'R'), REQUIRED, 0, NULL, check_texture_sides, write_textures,
                        read_textures, 0, 0},
    [CACHE_PIXELS] = {FOURCC('T', 'X', 'P', 'X'), REQUIRED, 0, NULL, NULL, write_pixels, read_pixels, 0, 0},
    [CACHE_MESHES] = {FOURCC('M', 'E', 'S', 'H'), REQUIRED, 0, NULL, NULL, write_meshes, read_meshes, 0, 0},
    [CACHE_GEOMETRY] = {FOURCC('G', 'E', 'O', 'M'), REQUIRED, 0, has_whole_geometry, NULL, write_geometry,
                        read_geometry, 1, 1},
    [CACHE_COLORS] = {FOURCC('V', 'C', 'O', 'L'), REQUIRED, 0, has_whole_geometry, NULL, write_colors, read_colors, 1,
                      1},
    [CACHE_CLUSTERS] = {FOURCC('C', 'L', 'U', 'S'), REQUIRED, 0, NULL, NULL, write_cluster_counts, read_cluster_counts, 0, 0},
    [CACHE_CLUSTER_GROUPS] = {FOURCC('C', 'L', 'G', 'R'), REQUIRED, 0, NULL, NULL, write_cluster_groups,
                              read_cluster_groups, 0, 0},
    [CACHE_CLUSTER_DATA] = {FOURCC('C', 'L', 'D', 'T'), REQUIRED, 0, has_whole_geometry, NULL, write_cluster_records,
                            read_cluster_data, 1, 1},
    [CACHE_CLUSTER_GEOMETRY] = {FOURCC('C', 'L', 'G', 'M'), REQUIRED, 0, has_whole_geometry, NULL,
                                write_cluster_geometry, read_cluster_geometry, 1, 1},
    [CACHE_HIERARCHY] = {FOURCC('L', 'O', 'D', 'H'), REQUIRED, 0, NULL, check_hierarchy_present, write_hierarchy,
                         read_hierarchy, 0, 0},
    [CACHE_MATERIALS] = {FOURCC('M', 'A', 'T', 'L'), REQUIRED, 0, NULL, check_materials, write_materials, read_materials, 0, 0},
    [CACHE_INSTANCES] = {FOURCC('I', 'N', 'S', 'T'), REQUIRED, 0, NULL, NULL, write_instances, read_instances, 0, 0},
    [CACHE_CAMERAS] = {FOURCC('C', 'A', 'M', 'R'), REQUIRED, 0, NULL, NULL, write_cameras, read_cameras, 0, 0},
    /* optional: readers that predate it skip it */
    [CACHE_PVS] = {FOURCC('P', 'V', 'I', 'S'), 0, 1, cache_pvs_present, cache_pvs_check, cache_pvs_write, read_pvs,
                   0, 0},
    [CACHE_PAGES] = {FOURCC('P', 'A', 'G', 'E'), 0, 1, has_pages, check_page_bytes, write_pages, read_pages, 1, 0},
};
#undef REQUIRED

gdr_status gdr_cache_read_sections(const char *name, cache_view *v, int paged, gdr_scene **out, gdr_pvs **out_pvs,
                                   gdr_error *err)
{
    if (!paged && (v->flags & CACHE_FLAG_PAGES_ONLY))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: its geometry is in its pages alone (a cache for "
                             "streaming): stream it (gdr render --geometry-budget MIB), or use the source or a "
                             "cache with the whole geometry (gdr build without --pages, or with --pages "
                             "--whole-geometry)", name);
    cache_read_state st = {.name = name, .file = v->data, .out_pvs = out_pvs, .paged = paged};
    gdr_status status = gdr_scene_create(&st.scene, err);
    for (uint32_t k = 0; k < CACHE_SECTION_COUNT && status == GDR_OK; k++)
        if (gdr_cache_sections[k].read && v->present[k])
            status = gdr_cache_sections[k].read(&st, &v->sections[k], err);
    if (status != GDR_OK) {
        if (out_pvs && *out_pvs) {
            cache_pvs_destroy(*out_pvs);
            *out_pvs = NULL;
        }
        gdr_scene_destroy(st.scene);
        return status;
    }
    *out = st.scene;
    return GDR_OK;
}
