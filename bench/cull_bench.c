/* CPU culling library benchmark: 100k and 1M objects, octree vs brute force, 1 and 2
 * threads. Prints a table and JSON. Usage: cull_bench [views] (default 24). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gdr/thread_pool.h"
#include "gdr/cull.h"

static unsigned rng_state = 2024;
static float rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return (float)(rng_state >> 8) / 16777216.0f;
}
static float rnd_range(float lo, float hi) { return lo + (hi - lo) * rnd(); }

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* A city-like spread: objects over a square world, most small, some large, a third with a max
 * draw distance. */
static gdr_cull_object *make_objects(uint32_t count, float world)
{
    gdr_cull_object *objects = malloc((size_t)count * sizeof(*objects));
    for (uint32_t i = 0; i < count; i++) {
        gdr_cull_object o = {0};
        float u = rnd();
        float size = u < 0.8f ? rnd_range(0.2f, 2.0f) : u < 0.98f ? rnd_range(2, 15) : rnd_range(15, 60);
        o.center = (gdr_vec3){rnd_range(-world, world), rnd_range(0, 30), rnd_range(-world, world)};
        o.extent = (gdr_vec3){size * rnd_range(0.3f, 1), size * rnd_range(0.3f, 1), size * rnd_range(0.3f, 1)};
        o.radius = gdr_vec3_length(o.extent);
        if (rnd() < 0.33f)
            o.max_draw_distance = rnd_range(100, 600);
        objects[i] = o;
    }
    return objects;
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

typedef struct result_row {
    uint32_t objects;
    const char *method;
    uint32_t threads;
    double median_ms, mean_visible;
} result_row;

int main(int argc, char **argv)
{
    uint32_t views = argc > 1 ? (uint32_t)atoi(argv[1]) : 24;
    if (views == 0)
        views = 24;
    uint32_t sizes[2] = {100000, 1000000};
    gdr_thread_pool *pools[2];
    gdr_error err;
    if (gdr_thread_pool_create(1, &pools[0], &err) != GDR_OK || gdr_thread_pool_create(2, &pools[1], &err) != GDR_OK) {
        fprintf(stderr, "cull_bench: %s\n", err.message);
        return 1;
    }
    result_row rows[8];
    uint32_t row_count = 0;
    for (int s = 0; s < 2; s++) {
        uint32_t count = sizes[s];
        float world = count >= 1000000 ? 2000.0f : 650.0f; /* similar density */
        gdr_cull_object *objects = make_objects(count, world);
        gdr_cull_scene_desc desc = {objects, count, 0, 0};
        gdr_cull_scene *scene;
        double t0 = now_ms();
        if (gdr_cull_scene_create(&desc, &scene, &err) != GDR_OK) {
            fprintf(stderr, "cull_bench: %s\n", err.message);
            return 1;
        }
        double build_ms = now_ms() - t0;
        fprintf(stderr, "%u objects: octree of %u nodes built in %.1f ms\n", count, gdr_cull_scene_node_count(scene),
                build_ms);
        uint32_t *visible = malloc(gdr_cull_word_count(count) * 4);
        gdr_cull_view *view_list = malloc(views * sizeof(*view_list));
        for (uint32_t v = 0; v < views; v++) {
            gdr_cull_view view = {0};
            gdr_vec3 eye = {rnd_range(-world, world), rnd_range(2, 40), rnd_range(-world, world)};
            gdr_quat yaw = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, rnd_range(-3.14f, 3.14f));
            gdr_quat pitch = gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, rnd_range(-0.3f, 0.1f));
            view.view = gdr_view_from_pose(eye, gdr_quat_mul(yaw, pitch));
            view.projection = gdr_perspective_reverse_z_infinite(1.0f, 16.0f / 9.0f, 0.1f);
            view_list[v] = view;
        }
        /* interleave the four configurations view by view, so noise hits them alike */
        double *times[4];
        double visible_sum[4] = {0};
        for (int c = 0; c < 4; c++)
            times[c] = malloc(views * sizeof(double));
        for (uint32_t v = 0; v < views; v++) {
            for (int c = 0; c < 4; c++) {
                gdr_cull_view view = view_list[v];
                view.brute_force = (c & 1) != 0;
                gdr_thread_pool *pool = pools[c >> 1];
                gdr_cull_result result = {visible, NULL, NULL};
                gdr_cull_stats stats;
                double best = 1e30;
                for (int rep = 0; rep < 3; rep++) {
                    double start = now_ms();
                    gdr_cull_execute(scene, &view, pool, &result, &stats, &err);
                    double ms = now_ms() - start;
                    best = ms < best ? ms : best;
                }
                times[c][v] = best;
                visible_sum[c] += stats.visible;
            }
        }
        const char *names[4] = {"octree", "brute force", "octree", "brute force"};
        for (int c = 0; c < 4; c++) {
            qsort(times[c], views, sizeof(double), compare_double);
            rows[row_count++] = (result_row){count, names[c], (uint32_t)(c >> 1) + 1, times[c][views / 2],
                                             visible_sum[c] / views};
            free(times[c]);
        }
        free(view_list);
        free(visible);
        gdr_cull_scene_destroy(scene);
        free(objects);
    }

    printf("| objects | method | threads | median ms/view | vs brute force, 1 thread | visible |\n");
    printf("|--------:|--------|--------:|---------------:|-------------------------:|--------:|\n");
    for (uint32_t r = 0; r < row_count; r++) {
        double base = rows[r - r % 4 + 1].median_ms; /* brute force, 1 thread, same size */
        printf("| %u | %s | %u | %.3f | %.2fx | %.0f |\n", rows[r].objects, rows[r].method, rows[r].threads,
               rows[r].median_ms, base / rows[r].median_ms, rows[r].mean_visible);
    }
    printf("\n{\"benchmark\": \"cull\", \"views\": %u, \"results\": [", views);
    for (uint32_t r = 0; r < row_count; r++)
        printf("%s\n  {\"objects\": %u, \"method\": \"%s\", \"threads\": %u, \"median_ms\": %.4f, \"visible\": %.0f}",
               r ? "," : "", rows[r].objects, rows[r].method, rows[r].threads, rows[r].median_ms,
               rows[r].mean_visible);
    printf("\n]}\n");
    gdr_thread_pool_destroy(pools[0]);
    gdr_thread_pool_destroy(pools[1]);
    return 0;
}
