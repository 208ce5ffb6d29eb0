/* One view: the octree pass (its subtrees as tasks), then tasks over 32-bit words of the visibility
 * bitset. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gdr/thread_pool.h"
#include "cull/cull_internal.h"

#define CULL_DEFAULT_WORDS_PER_TASK 64u

typedef struct cull_context {
    const gdr_cull_scene *scene;
    const gdr_cull_view *view;
    const gdr_cull_result *result;
    gdr_frustum frustum;
    const uint32_t *node_bits; /* NULL: no octree (brute force or skip_frustum) */
    const uint32_t *pvs_bits;  /* NULL: no precomputed visibility for this view */
    uint32_t pvs_object_count;
    cull_distance_params distance;
    float screen_scale;
    bool clip_enabled;
    uint32_t word_count, words_per_task;
    gdr_cull_stats *task_stats;
} cull_context;

static bool view_needs_distance(const gdr_cull_object *o, const gdr_cull_view *v)
{
    return o->min_draw_distance > 0.0f || o->max_draw_distance > 0.0f || o->min_screen_size > 0.0f ||
           o->max_screen_size > 0.0f || v->min_screen_size > 0.0f;
}

/* Returns true when visible; sets the fade / clip flags; counts the culling test in st. */
static bool cull_object(const cull_context *ctx, uint32_t i, bool *fading, bool *clipping, gdr_cull_stats *st)
{
    const gdr_cull_scene *s = ctx->scene;
    const gdr_cull_object *o = &s->objects[i];
    const gdr_cull_view *v = ctx->view;
    if (o->flags & GDR_CULL_OBJECT_HIDDEN) {
        st->hidden++;
        return false;
    }
    if (o->flags & GDR_CULL_OBJECT_ALWAYS_VISIBLE) {
        st->always_visible++;
        return true;
    }
    uint32_t node = s->object_node[i];
    if (node == CULL_NODE_INVALID) {
        st->invalid++;
        return false;
    }
    if (!v->skip_frustum) {
        bool test = true;
        if (ctx->node_bits && node != CULL_NODE_NONE) {
            uint32_t bits = cull_node_bits(ctx->node_bits, node);
            if (!(bits & 1u)) {
                st->frustum++;
                return false;
            }
            test = (bits & 2u) != 0; /* a fully inside node vouches for its objects */
        }
        if (test) {
            st->objects_tested++;
            /* The sphere first: cheaper, and it rejects most of what is outside. */
            if (cull_sphere_outside(&ctx->frustum, o->center, o->radius) ||
                cull_box_outside(&ctx->frustum, o->center, o->extent)) {
                st->frustum++;
                return false;
            }
        }
    }
    if (ctx->pvs_bits && i < ctx->pvs_object_count && !(o->flags & GDR_CULL_OBJECT_DYNAMIC) &&
        !gdr_cull_bit(ctx->pvs_bits, i)) {
        st->precomputed++;
        return false;
    }
    if (view_needs_distance(o, v)) {
        gdr_vec3 d = gdr_vec3_sub(o->center, ctx->distance.origin);
        float distance = sqrtf(d.x * d.x + d.y * d.y + d.z * d.z);
        if (!cull_distance_visible(&ctx->distance, o, distance, fading)) {
            st->distance++;
            return false;
        }
        float size = cull_screen_size(ctx->screen_scale, o->radius, distance);
        if (!cull_screen_size_visible(size, v->min_screen_size, o)) {
            *fading = false;
            st->screen_size++;
            return false;
        }
    }
    if (ctx->clip_enabled) {
        gdr_cull_outcome outcome = gdr_plane_test_box(v->clip_plane, o->center, o->extent);
        if (outcome == GDR_CULL_OUTSIDE) {
            *fading = false;
            st->clip_plane++;
            return false;
        }
        *clipping = outcome == GDR_CULL_INTERSECTS;
    }
    return true;
}

static void cull_task(void *user, uint32_t task, uint32_t worker)
{
    (void)worker;
    const cull_context *ctx = user;
    gdr_cull_stats *st = &ctx->task_stats[task];
    uint32_t first = task * ctx->words_per_task;
    uint32_t last = first + ctx->words_per_task < ctx->word_count ? first + ctx->words_per_task : ctx->word_count;
    uint32_t object_count = ctx->scene->object_count;
    for (uint32_t w = first; w < last; w++) {
        uint32_t visible = 0, fading = 0, clipping = 0;
        uint32_t base = w * 32u;
        uint32_t n = object_count - base < 32u ? object_count - base : 32u;
        for (uint32_t b = 0; b < n; b++) {
            bool fade = false, clip = false;
            if (cull_object(ctx, base + b, &fade, &clip, st)) {
                visible |= 1u << b;
                fading |= (uint32_t)fade << b;
                clipping |= (uint32_t)clip << b;
            }
        }
        ctx->result->visible[w] = visible;
        if (ctx->result->fading)
            ctx->result->fading[w] = fading;
        if (ctx->result->needs_clipping)
            ctx->result->needs_clipping[w] = clipping;
        st->visible += (uint32_t)__builtin_popcount(visible);
        st->fading += (uint32_t)__builtin_popcount(fading);
        st->needs_clipping += (uint32_t)__builtin_popcount(clipping);
    }
}

static bool mat_finite(const gdr_mat4 *m)
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(m->m[i]))
            return false;
    return true;
}

gdr_status gdr_cull_execute(const gdr_cull_scene *scene, const gdr_cull_view *view, gdr_thread_pool *pool,
                            const gdr_cull_result *result, gdr_cull_stats *stats, gdr_error *err)
{
    if (!scene || !view || !result || !result->visible)
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "cull: scene, view and result->visible are required");
    if (!mat_finite(&view->view) || !mat_finite(&view->projection))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "cull view: a matrix has a NaN or infinity");
    gdr_mat4 inverse_view;
    if (!gdr_mat4_inverse(view->view, &inverse_view))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT, "cull view: the view matrix is not invertible");
    if (view->distance_scale < 0.0f || view->fade_range < 0.0f || view->screen_scale < 0.0f ||
        !isfinite(view->distance_scale) || !isfinite(view->fade_range) || !isfinite(view->screen_scale))
        return gdr_error_set(err, GDR_ERROR_INVALID_ARGUMENT,
                             "cull view: distance_scale, fade_range and screen_scale must be finite and >= 0");

    cull_context ctx = {0};
    ctx.scene = scene;
    ctx.view = view;
    ctx.result = result;
    ctx.frustum = gdr_frustum_from_matrix(gdr_mat4_mul(view->projection, view->view));
    ctx.distance.origin = (gdr_vec3){inverse_view.m[12], inverse_view.m[13], inverse_view.m[14]};
    ctx.distance.scale = view->distance_scale > 0.0f ? view->distance_scale : 1.0f;
    ctx.distance.fade_range = view->fade_range;
    ctx.distance.to_sphere_edge = view->distance_to_sphere_edge;
    ctx.screen_scale = view->screen_scale > 0.0f ? view->screen_scale
                                                 : fmaxf(fabsf(view->projection.m[0]), fabsf(view->projection.m[5]));
    ctx.clip_enabled = view->clip_plane.x != 0.0f || view->clip_plane.y != 0.0f || view->clip_plane.z != 0.0f;
    ctx.word_count = gdr_cull_word_count(scene->object_count);
    ctx.words_per_task = view->words_per_task ? view->words_per_task : CULL_DEFAULT_WORDS_PER_TASK;

    bool cell_found = false;
    if (view->visibility) {
        ctx.pvs_bits = gdr_pvs_lookup(view->visibility, ctx.distance.origin);
        ctx.pvs_object_count = gdr_pvs_object_count(gdr_pvs_cache_pvs(view->visibility));
        cell_found = ctx.pvs_bits != NULL;
    }

    uint32_t task_count = ctx.word_count ? (ctx.word_count - 1) / ctx.words_per_task + 1 : 0;
    uint32_t *node_bits = NULL;
    bool use_octree = !view->brute_force && !view->skip_frustum && scene->node_count > 0;
    size_t node_words = use_octree ? gdr_cull_word_count(2 * scene->node_count) : 0;
    ctx.task_stats = calloc((size_t)task_count + 1, sizeof(gdr_cull_stats));
    if (use_octree)
        node_bits = calloc(node_words, sizeof(uint32_t));
    if (!ctx.task_stats || (use_octree && !node_bits)) {
        free(ctx.task_stats);
        free(node_bits);
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "cull: out of memory for %u tasks", task_count);
    }
    gdr_cull_stats total = {0};
    if (use_octree) {
        gdr_status st = cull_octree_classify(scene, &ctx.frustum, pool, node_bits, &total.nodes_tested,
                                             &total.nodes_inside, err);
        if (st != GDR_OK) {
            free(ctx.task_stats);
            free(node_bits);
            return st;
        }
        ctx.node_bits = node_bits;
    }

    gdr_thread_pool_run(pool, task_count, cull_task, &ctx);

    for (uint32_t t = 0; t < task_count; t++) {
        const gdr_cull_stats *s = &ctx.task_stats[t];
        total.visible += s->visible;
        total.fading += s->fading;
        total.needs_clipping += s->needs_clipping;
        total.hidden += s->hidden;
        total.invalid += s->invalid;
        total.frustum += s->frustum;
        total.precomputed += s->precomputed;
        total.distance += s->distance;
        total.screen_size += s->screen_size;
        total.clip_plane += s->clip_plane;
        total.always_visible += s->always_visible;
        total.objects_tested += s->objects_tested;
    }
    total.tasks = task_count;
    total.visibility_cell_found = cell_found;
    if (stats)
        *stats = total;
    free(ctx.task_stats);
    free(node_bits);
    return GDR_OK;
}
