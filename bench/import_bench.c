/* Import and cache benchmark: import speed (MB/s, triangles/s) for large generated
 * OBJ and GLB files and a real one, and cache load time against import time. Prints a table and
 * JSON. usage: import_bench [--grid N] [--dir DIR] [--repeat R] [--json FILE] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "gdr/io.h"
#include "io/loaders.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* An N x N grid of quads with a bumpy height, as OBJ text (v/vt/vn, quads). */
static int write_obj(const char *path, int n)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return 0;
    for (int y = 0; y <= n; y++)
        for (int x = 0; x <= n; x++)
            fprintf(f, "v %.6f %.6f %.6f\n", x / (float)n, 0.05f * (float)((x * 7 + y * 13) % 17) / 17.0f, y / (float)n);
    for (int y = 0; y <= n; y++)
        for (int x = 0; x <= n; x++)
            fprintf(f, "vt %.6f %.6f\n", x / (float)n, y / (float)n);
    fprintf(f, "vn 0 1 0\n");
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            int a = y * (n + 1) + x + 1, b = a + 1, c = a + n + 2, d = a + n + 1;
            fprintf(f, "f %d/%d/1 %d/%d/1 %d/%d/1 %d/%d/1\n", a, a, d, d, c, c, b, b);
        }
    return fclose(f) == 0;
}

/* The same grid as a GLB: float positions, normals, uvs, uint32 indices. */
static int write_glb(const char *path, int n)
{
    size_t vertices = (size_t)(n + 1) * (n + 1), indices = (size_t)n * n * 6;
    size_t bin_size = vertices * 32 + indices * 4;
    unsigned char *bin = malloc(bin_size);
    if (!bin)
        return 0;
    float *p = (float *)bin, *nn = p + vertices * 3, *uv = nn + vertices * 3;
    unsigned *ix = (unsigned *)(uv + vertices * 2);
    for (int y = 0; y <= n; y++)
        for (int x = 0; x <= n; x++) {
            size_t v = (size_t)y * (n + 1) + x;
            p[v * 3] = x / (float)n;
            p[v * 3 + 1] = 0.05f * (float)((x * 7 + y * 13) % 17) / 17.0f;
            p[v * 3 + 2] = y / (float)n;
            nn[v * 3] = 0;
            nn[v * 3 + 1] = 1;
            nn[v * 3 + 2] = 0;
            uv[v * 2] = x / (float)n;
            uv[v * 2 + 1] = y / (float)n;
        }
    size_t k = 0;
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            unsigned a = (unsigned)(y * (n + 1) + x), b = a + 1, c = a + (unsigned)n + 2, d = a + (unsigned)n + 1;
            unsigned quad[6] = {a, d, c, a, c, b};
            memcpy(ix + k, quad, sizeof quad);
            k += 6;
        }
    char json[2048];
    int length = snprintf(json, sizeof json,
        "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":["
        "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},"
        "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
        "{\"bufferView\":1,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC2\"},"
        "{\"bufferView\":3,\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":3}]}],"
        "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
        bin_size, vertices * 12, vertices * 12, vertices * 12, vertices * 24, vertices * 8, vertices * 32, indices * 4,
        vertices, vertices, vertices, indices);
    while (length % 4)
        json[length++] = ' ';
    unsigned header[5] = {0x46546C67u, 2, (unsigned)(12 + 8 + length + 8 + bin_size), (unsigned)length, 0x4E4F534Au};
    unsigned bin_header[2] = {(unsigned)bin_size, 0x004E4942u};
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(header, 4, 5, f) == 5 && fwrite(json, 1, (size_t)length, f) == (size_t)length &&
             fwrite(bin_header, 4, 2, f) == 2 && fwrite(bin, 1, bin_size, f) == bin_size;
    free(bin);
    return f && fclose(f) == 0 && ok;
}

typedef struct result {
    const char *label;
    double megabytes, triangles, import_s, write_s, load_s, cache_megabytes;
} result;

static int measure(const char *label, const char *path, const char *dir, int repeat, result *r)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return 0;
    *r = (result){.label = label, .megabytes = (double)st.st_size / 1e6, .import_s = 1e30, .load_s = 1e30};
    gdr_error err;
    gdr_scene *scene = NULL;
    for (int i = 0; i < repeat; i++) {
        gdr_scene_destroy(scene);
        double t0 = now();
        if (gdr_import_file(path, &(gdr_import_options){.no_progress = 1}, &scene, NULL, &err) != GDR_OK) {
            fprintf(stderr, "import_bench: %s\n", err.message);
            return 0;
        }
        double t = now() - t0;
        r->import_s = t < r->import_s ? t : r->import_s;
    }
    r->triangles = (double)gdr_scene_triangle_count(scene);
    char cache[4096];
    snprintf(cache, sizeof cache, "%s/%s.gdrc", dir, label);
    double t0 = now();
    gdr_cache_write_options plain_options = {.source = {gdr_cache_build_options(), NULL}};
    if (gdr_cache_write(cache, scene, &plain_options, &err) != GDR_OK) {
        fprintf(stderr, "import_bench: %s\n", err.message);
        gdr_scene_destroy(scene);
        return 0;
    }
    r->write_s = now() - t0;
    gdr_scene_destroy(scene);
    stat(cache, &st);
    r->cache_megabytes = (double)st.st_size / 1e6;
    for (int i = 0; i < repeat; i++) {
        t0 = now();
        if (gdr_cache_read(cache, gdr_cache_build_options(), &scene, NULL, &err) != GDR_OK) {
            fprintf(stderr, "import_bench: %s\n", err.message);
            return 0;
        }
        double t = now() - t0;
        r->load_s = t < r->load_s ? t : r->load_s;
        gdr_scene_destroy(scene);
    }
    return 1;
}

int main(int argc, char **argv)
{
    int grid = 1000, repeat = 3;
    const char *dir = "/tmp", *json_path = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--grid") == 0 && i + 1 < argc)
            grid = atoi(argv[++i]);
        else if (strcmp(argv[i], "--dir") == 0 && i + 1 < argc)
            dir = argv[++i];
        else if (strcmp(argv[i], "--repeat") == 0 && i + 1 < argc)
            repeat = atoi(argv[++i]);
        else if (strcmp(argv[i], "--json") == 0 && i + 1 < argc)
            json_path = argv[++i];
        else {
            fprintf(stderr, "usage: import_bench [--grid N] [--dir DIR] [--repeat R] [--json FILE]\n");
            return 2;
        }
    }
    if (grid < 1 || grid > 4000 || repeat < 1) {
        fprintf(stderr, "import_bench: --grid must be in [1, 4000], --repeat at least 1\n");
        return 2;
    }
    char obj[4096], glb[4096];
    snprintf(obj, sizeof obj, "%s/import_bench_grid.obj", dir);
    snprintf(glb, sizeof glb, "%s/import_bench_grid.glb", dir);
    if (!write_obj(obj, grid) || !write_glb(glb, grid)) {
        fprintf(stderr, "import_bench: cannot write the generated files in %s\n", dir);
        return 1;
    }
    result results[3];
    int count = 0;
    count += measure("grid_obj", obj, dir, repeat, &results[count]);
    count += measure("grid_glb", glb, dir, repeat, &results[count]);
    count += measure("2CylinderEngine_glb", "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
                     dir, repeat, &results[count]);
    printf("%-20s %9s %11s %10s %9s %12s %10s %10s %9s\n", "file", "MB", "triangles", "import ms", "MB/s",
           "Mtri/s", "cache MB", "load ms", "speedup");
    for (int i = 0; i < count; i++) {
        result *r = &results[i];
        printf("%-20s %9.2f %11.0f %10.2f %9.1f %12.2f %10.2f %10.2f %8.1fx\n", r->label, r->megabytes, r->triangles,
               r->import_s * 1e3, r->megabytes / r->import_s, r->triangles / r->import_s / 1e6, r->cache_megabytes,
               r->load_s * 1e3, r->import_s / r->load_s);
    }
    FILE *json = json_path ? fopen(json_path, "w") : stdout;
    if (!json)
        return 1;
    fprintf(json, "{\"grid\": %d, \"results\": [", grid);
    for (int i = 0; i < count; i++)
        fprintf(json, "%s{\"file\": \"%s\", \"megabytes\": %.3f, \"triangles\": %.0f, \"import_ms\": %.3f, "
                "\"cache_write_ms\": %.3f, \"cache_load_ms\": %.3f, \"cache_megabytes\": %.3f}", i ? ", " : "",
                results[i].label, results[i].megabytes, results[i].triangles, results[i].import_s * 1e3,
                results[i].write_s * 1e3, results[i].load_s * 1e3, results[i].cache_megabytes);
    fprintf(json, "]}\n");
    if (json_path)
        fclose(json);
    remove(obj);
    remove(glb);
    return count == 3 ? 0 : 1;
}
