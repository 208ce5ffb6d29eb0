/* A scene's paged cache made mesh by mesh (loaders.h, gdr_io_paged_source; gdr_cache_build_paged,
 * gdr/io.h): the unique field is made one mesh at a time (made, clustered, its LOD DAG built, moved
 * onto its grid, written, freed), so that memory follows the meshes in flight, not the scene; any
 * other scene is made or imported whole as gdr_scene_load makes it, then each mesh is taken out of
 * it, moved onto its grid, written and freed. Both give the bytes gdr_cache_write writes for the
 * whole scene quantized (gdr_scene_quantize_vertices). */
#include <stdlib.h>
#include <string.h>

#include "gdr/geometry.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "io/import_report.h"
#include "io/io_internal.h"
#include "io/loaders.h"

static void free_mesh_arrays(gdr_mesh *mesh)
{
    free(mesh->positions), free(mesh->normals), free(mesh->uvs), free(mesh->colors), free(mesh->indices);
    gdr_mesh_clusters_free(&mesh->clusters);
}

/* A scene holding `mesh` alone (it owns the mesh's arrays from here, also on failure), moved onto
 * its grid. */
static gdr_status quantized_scene_of(gdr_mesh *mesh, gdr_scene **out, gdr_error *err)
{
    gdr_scene *one = NULL;
    gdr_status status = gdr_scene_create(&one, err);
    if (status == GDR_OK && !(one->meshes = malloc(sizeof *one->meshes)))
        status = gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "mesh '%s': out of memory", mesh->name);
    if (status != GDR_OK) {
        free_mesh_arrays(mesh);
        gdr_scene_destroy(one);
        return status;
    }
    one->meshes[0] = *mesh;
    one->mesh_count = one->mesh_capacity = 1;
    if ((status = gdr_scene_quantize_vertices(one, err)) != GDR_OK) {
        gdr_scene_destroy(one);
        return status;
    }
    *out = one;
    return GDR_OK;
}

/* gdr_cache_mesh_fn of a scene made whole: mesh m taken out of it (its place left empty). */
static gdr_status take_mesh(void *user, uint32_t m, uint32_t threads, gdr_scene **out, gdr_error *err)
{
    (void)threads;
    gdr_io_paged_source *src = user;
    gdr_mesh mesh = src->skeleton->meshes[m];
    gdr_mesh *place = &src->skeleton->meshes[m];
    *place = (gdr_mesh){0};
    memcpy(place->name, mesh.name, sizeof place->name);
    return quantized_scene_of(&mesh, out, err);
}

/* gdr_cache_mesh_fn of the unique field: mesh m made, its clusters and LOD DAG built as
 * gdr_scene_load builds them (no material: the uvs are not seen), onto its grid. */
static gdr_status make_unique_mesh(void *user, uint32_t m, uint32_t threads, gdr_scene **out, gdr_error *err)
{
    gdr_io_paged_source *src = user;
    gdr_status status = gdr_scene_create_unique_field_mesh(&src->unique, m, out, err);
    gdr_lod_options lod = {.no_progress = 1, .thread_count = threads};
    if (status == GDR_OK)
        status = gdr_scene_build_lod(*out, &lod, NULL, err);
    if (status == GDR_OK)
        status = gdr_scene_quantize_vertices(*out, err);
    if (status != GDR_OK) {
        gdr_scene_destroy(*out);
        *out = NULL;
    }
    return status;
}

/* The scene whole, as gdr_scene_load gives it: made, or imported (its files in *sources, its
 * warnings in *report). */
static gdr_status whole_scene(const char *spec, const gdr_load_options *o, bool builtin, gdr_scene **scene,
                              gdr_source_list *sources, gdr_import_report *report, gdr_error *err)
{
    if (builtin) {
        gdr_load_options plain = *o;
        plain.geometry_in_pages = 0, plain.pvs = NULL, plain.sources = NULL, plain.cache_path = NULL;
        plain.report = NULL;
        return gdr_scene_load(spec, &plain, scene, err);
    }
    gdr_io_report_collector kept = {o, report};
    gdr_import_options import = {.warning = gdr_io_report_collect, .warning_user = &kept,
                                 .no_progress = o->no_progress, .sources = sources, .budget = o->budget,
                                 .allow_outside_files = o->allow_outside_files};
    gdr_import_result result = {0};
    gdr_status status = gdr_import_file(spec, &import, scene, &result, err);
    report->file_cameras = result.file_cameras;
    return status;
}

gdr_status gdr_io_paged_source_open(const char *spec, const gdr_load_options *o, bool builtin,
                                    gdr_io_paged_source *src, gdr_source_list *sources, gdr_import_report *report,
                                    gdr_error *err)
{
    *src = (gdr_io_paged_source){0};
    bool unique = false;
    gdr_status status = builtin ? gdr_io_unique_field_spec(spec, &src->unique, &unique, err) : GDR_OK;
    if (status != GDR_OK)
        return status;
    src->generated = unique;
    return unique ? gdr_scene_create_unique_field_skeleton(&src->unique, &src->skeleton, err)
                  : whole_scene(spec, o, builtin, &src->skeleton, sources, report, err);
}

gdr_status gdr_io_paged_source_write(gdr_io_paged_source *src, const char *path, const gdr_cache_write_options *write,
                                     uint32_t threads, int no_progress, gdr_error *err)
{
    gdr_cache_mesh_source meshes = {.make = src->generated ? make_unique_mesh : take_mesh, .user = src,
                                    .thread_count = threads, .no_progress = no_progress};
    return gdr_cache_write_meshes(path, src->skeleton, &meshes, write, err);
}

void gdr_io_paged_source_close(gdr_io_paged_source *src)
{
    gdr_scene_destroy(src->skeleton);
    *src = (gdr_io_paged_source){0};
}

gdr_status gdr_cache_build_paged(const char *spec, const char *path, const gdr_paged_build_options *options,
                                 gdr_error *err)
{
    static const gdr_paged_build_options defaults = {0};
    options = options ? options : &defaults;
    if (!gdr_scene_spec_is_builtin(spec))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "%s: not a built-in scene (a file is built with "
                             "gdr_scene_load and gdr_cache_write)", spec);
    gdr_load_options load = {.no_progress = options->no_progress};
    gdr_io_paged_source src;
    gdr_status status = gdr_io_paged_source_open(spec, &load, true, &src, NULL, NULL, err);
    gdr_source_list none = {0};
    gdr_cache_write_options write = {.source = {gdr_cache_build_options(), &none},
                                     .page_bytes = options->page_bytes ? options->page_bytes : GDR_PAGE_BYTES_DEFAULT,
                                     .whole_geometry = options->whole_geometry};
    if (status == GDR_OK)
        status = gdr_io_paged_source_write(&src, path, &write, options->thread_count, options->no_progress, err);
    gdr_io_paged_source_close(&src);
    return status;
}
