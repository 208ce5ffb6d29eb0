/* The LOD nodes' absent counts updated per changed group (src/stream/node_counts.c,
 * docs/STREAMING.md "Node counts"), on two meshes of `unique-field` with many groups. Starting with
 * every group absent, then through batches of random residency changes (groups coming and going,
 * some set twice, some set to what they already are):
 * - after every batch the counts equal gdr_lod_nodes_count_absent_refined over the groups'
 *   residency (a node skipped by the walk, or counted twice, fails it), the mesh's absent groups
 *   are counted right, and every node whose count changed lies in the runs handed back for upload;
 * - the runs are sorted, disjoint and coalesced (no two touch), their words exactly the nodes
 *   touched since the last batch, and each of those nodes is an ancestor (or leaf) of a leaf holding
 *   a cluster made from a group that changed;
 * - each change updates exactly the leaves holding clusters made from the group and their ancestors
 *   (the sum of those paths, computed here from the hierarchy), a setting that changes nothing
 *   updates nothing, and no change comes near the mesh's node count (each at most a tenth of it).
 * Before the incremental update the renderer recomputed and uploaded the whole mesh per change. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "geometry/lod_cut.h"
#include "io/loaders.h"
#include "render/node_counts.h"
#include "test_util.h"

#define BATCHES 60

typedef struct mesh_view {
    const gdr_mesh_clusters *c;
    uint32_t offset;   /* global index of its node 0 */
    uint32_t *depth;   /* per node: its depth below the root */
    uint32_t *parent;  /* per node: its parent, UINT32_MAX at the root */
} mesh_view;

/* The hierarchy's parents and depths, found here independently of node_counts.c. */
static void view_init(mesh_view *v, const gdr_mesh_clusters *c, uint32_t offset)
{
    v->c = c, v->offset = offset;
    v->depth = calloc(c->lod_node_count, sizeof *v->depth);
    v->parent = malloc(sizeof *v->parent * c->lod_node_count);
    for (uint32_t n = 0; v->parent && n < c->lod_node_count; n++)
        v->parent[n] = UINT32_MAX;
    for (uint32_t n = 0; v->depth && v->parent && n < c->lod_node_count; n++) {
        const gdr_lod_node *node = &c->lod_nodes[n];
        for (uint32_t k = 0; !(node->flags & GDR_LOD_NODE_LEAF) && k < node->count; k++) {
            v->parent[node->first + k] = n;
            v->depth[node->first + k] = v->depth[n] + 1;
        }
    }
}

static bool leaf_refines(const gdr_mesh_clusters *c, const gdr_lod_node *leaf, uint32_t group)
{
    for (uint32_t i = leaf->first; i < leaf->first + leaf->count; i++)
        if (c->clusters[i].refined_group == group)
            return true;
    return false;
}

/* The node updates a change of `group` needs: for each leaf holding a cluster made from it, the
 * leaf and its ancestors. Marks those nodes in `reach` (global). */
static uint32_t expected_updates(const mesh_view *v, uint32_t group, uint8_t *reach)
{
    uint32_t updates = 0;
    for (uint32_t n = 0; n < v->c->lod_node_count; n++) {
        const gdr_lod_node *node = &v->c->lod_nodes[n];
        if (!(node->flags & GDR_LOD_NODE_LEAF) || !leaf_refines(v->c, node, group))
            continue;
        updates += v->depth[n] + 1;
        for (uint32_t a = n; a != UINT32_MAX; a = v->parent[a])
            reach[v->offset + a] = 1;
    }
    return updates;
}

static uint32_t rng_next(uint64_t *state)
{
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(*state >> 33);
}

typedef struct fixture {
    mesh_view views[2];
    uint8_t *resident[2];
    uint32_t *full, *before, node_total;
    gdr_node_run *runs;
    uint8_t *reach, *in_runs;
} fixture;

/* The counts against the whole recomputation, and the runs against the nodes that changed. */
static void check_batch(gdr_node_counts *nc, fixture *f, uint32_t expected_absent[2])
{
    const uint32_t *words = gdr_node_counts_words(nc);
    uint32_t wrong = 0, missed = 0, outside = 0, word_count = 0;
    for (int m = 0; m < 2; m++) {
        gdr_lod_nodes_count_absent_refined(f->views[m].c, f->resident[m], f->full + f->views[m].offset);
        CHECK(gdr_node_counts_absent_groups(nc, (uint32_t)m) == expected_absent[m]);
    }
    uint32_t run_count = gdr_node_counts_take_changes(nc, f->runs, &word_count);
    memset(f->in_runs, 0, f->node_total);
    uint32_t covered = 0;
    for (uint32_t i = 0; i < run_count; i++) {
        CHECK(f->runs[i].count > 0 && (uint64_t)f->runs[i].first + f->runs[i].count <= f->node_total);
        CHECK(i == 0 || f->runs[i].first > f->runs[i - 1].first + f->runs[i - 1].count); /* sorted, coalesced */
        for (uint32_t n = f->runs[i].first; n < f->runs[i].first + f->runs[i].count && n < f->node_total; n++)
            f->in_runs[n] = 1, covered++;
    }
    CHECK(covered == word_count);
    for (uint32_t n = 0; n < f->node_total; n++) {
        wrong += words[n] != f->full[n];
        missed += f->full[n] != f->before[n] && !f->in_runs[n];
        outside += f->in_runs[n] && !f->reach[n];
    }
    CHECK(wrong == 0 && missed == 0 && outside == 0);
    if (wrong || missed || outside)
        fprintf(stderr, "  %u counts wrong, %u changed nodes not uploaded, %u uploaded outside the changes\n", wrong,
                missed, outside);
    memcpy(f->before, f->full, sizeof *f->full * f->node_total);
    memset(f->reach, 0, f->node_total);
}

static void run(const gdr_scene *scene)
{
    fixture f = {0};
    const gdr_mesh_clusters *meshes[2] = {&scene->meshes[0].clusters, &scene->meshes[1].clusters};
    /* The second mesh's nodes after a gap: global indices are the caller's. */
    uint32_t offsets[2] = {0, meshes[0]->lod_node_count + 5};
    f.node_total = offsets[1] + meshes[1]->lod_node_count;
    gdr_node_counts *nc = NULL;
    gdr_error err = {0};
    CHECK(gdr_node_counts_create(meshes, offsets, 2, &nc, &err) == GDR_OK);
    f.full = calloc(f.node_total, sizeof *f.full), f.before = calloc(f.node_total, sizeof *f.before);
    f.runs = malloc(sizeof *f.runs * f.node_total);
    f.reach = calloc(f.node_total, 1), f.in_runs = calloc(f.node_total, 1);
    uint32_t absent[2];
    for (int m = 0; m < 2; m++) {
        view_init(&f.views[m], meshes[m], offsets[m]);
        f.resident[m] = calloc(meshes[m]->group_count, 1);
        absent[m] = meshes[m]->group_count;
        for (uint32_t n = 0; n < meshes[m]->lod_node_count; n++)
            f.reach[offsets[m] + n] = 1, f.before[offsets[m] + n] = UINT32_MAX; /* the first runs: every node */
    }
    if (!nc || !f.full || !f.before || !f.runs || !f.reach || !f.in_runs || !f.resident[0] || !f.resident[1] ||
        !f.views[0].parent || !f.views[1].parent) {
        CHECK(!"out of memory");
        return;
    }
    printf("meshes: %u groups, %u nodes; %u groups, %u nodes\n", meshes[0]->group_count, meshes[0]->lod_node_count,
           meshes[1]->group_count, meshes[1]->lod_node_count);
    check_batch(nc, &f, absent);
    uint64_t rng = 12345, updates_total = 0, changes = 0;
    uint32_t largest = 0, bad_updates = 0, noop_updates = 0;
    for (uint32_t batch = 0; batch < BATCHES; batch++) {
        uint32_t sets = 1 + rng_next(&rng) % 24;
        for (uint32_t k = 0; k < sets; k++) {
            uint32_t m = rng_next(&rng) % 2, group = rng_next(&rng) % meshes[m]->group_count;
            bool resident = batch < BATCHES / 2 ? rng_next(&rng) % 4 != 0 : rng_next(&rng) % 2 == 0;
            bool change = f.resident[m][group] != resident;
            uint32_t expected = change ? expected_updates(&f.views[m], group, f.reach) : 0;
            uint32_t updates = gdr_node_counts_set(nc, m, group, resident);
            bad_updates += updates != expected;
            noop_updates += !change && updates != 0;
            if (change) {
                f.resident[m][group] = resident;
                absent[m] += resident ? (uint32_t)-1 : 1u;
                updates_total += updates, changes++;
                largest = updates > largest ? updates : largest;
                CHECK(10u * updates <= meshes[m]->lod_node_count);
            }
        }
        check_batch(nc, &f, absent);
    }
    printf("%llu changes: %.1f node updates per change on average, %u at most\n", (unsigned long long)changes,
           changes ? (double)updates_total / (double)changes : 0.0, largest);
    CHECK(bad_updates == 0 && noop_updates == 0 && changes > 100);
    for (int m = 0; m < 2; m++)
        free(f.views[m].depth), free(f.views[m].parent), free(f.resident[m]);
    free(f.full), free(f.before), free(f.runs), free(f.reach), free(f.in_runs);
    gdr_node_counts_destroy(nc);
}

/* The scene written with pages and read for streaming holds no clusters: its counts come from its
 * groups' refinements (section 'CLGR'). Through the same random changes they are the counts over the
 * clusters, word for word, with the same node updates. */
static void run_without_clusters(const gdr_scene *scene)
{
    char path[256];
    const char *tmp = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/gdr_node_counts_%ld.gdrc", tmp ? tmp : "/tmp", (long)getpid());
    gdr_error err = {0};
    gdr_scene *paged = NULL;
    gdr_cache_write_options write = {.page_bytes = GDR_PAGE_BYTES_DEFAULT};
    CHECK(gdr_cache_write(path, scene, &write, &err) == GDR_OK);
    CHECK(gdr_cache_read_for_streaming(path, NULL, &paged, NULL, NULL, &err) == GDR_OK && paged);
    unlink(path);
    if (!paged)
        return;
    CHECK(!paged->meshes[0].clusters.clusters && !paged->meshes[1].clusters.clusters &&
          paged->meshes[0].clusters.refinement_count > 0);
    const gdr_mesh_clusters *whole[2] = {&scene->meshes[0].clusters, &scene->meshes[1].clusters};
    const gdr_mesh_clusters *streamed[2] = {&paged->meshes[0].clusters, &paged->meshes[1].clusters};
    uint32_t offsets[2] = {0, whole[0]->lod_node_count + 5}, total = offsets[1] + whole[1]->lod_node_count;
    gdr_node_counts *a = NULL, *b = NULL;
    CHECK(gdr_node_counts_create(whole, offsets, 2, &a, &err) == GDR_OK);
    CHECK(gdr_node_counts_create(streamed, offsets, 2, &b, &err) == GDR_OK);
    /* Made on four threads, one task a mesh: the same counts, from the clusters and from the
     * refinements. */
    gdr_thread_pool *pool = NULL;
    gdr_node_counts *c = NULL, *d = NULL;
    CHECK(gdr_thread_pool_create(4, &pool, &err) == GDR_OK);
    CHECK(gdr_node_counts_create_on(whole, offsets, 2, pool, &c, &err) == GDR_OK);
    CHECK(gdr_node_counts_create_on(streamed, offsets, 2, pool, &d, &err) == GDR_OK);
    gdr_thread_pool_destroy(pool);
    uint32_t threaded_differ = !a || !c || !d || memcmp(gdr_node_counts_words(a), gdr_node_counts_words(c), 4ull * total) ||
                               memcmp(gdr_node_counts_words(a), gdr_node_counts_words(d), 4ull * total);
    for (uint32_t k = 0; !threaded_differ && k < 2000; k++) {
        uint64_t pick = 7 + k;
        uint32_t m = (uint32_t)(pick % 2), group = (uint32_t)((pick * 2654435761u) % whole[m]->group_count);
        threaded_differ += gdr_node_counts_set(c, m, group, true) != gdr_node_counts_set(d, m, group, true);
    }
    threaded_differ += c && d && memcmp(gdr_node_counts_words(c), gdr_node_counts_words(d), 4ull * total) != 0;
    printf("made on four threads: %s\n", threaded_differ ? "the counts differ" : "the same counts");
    CHECK(threaded_differ == 0);
    gdr_node_counts_destroy(c);
    gdr_node_counts_destroy(d);
    uint64_t rng = 777;
    uint32_t differ = 0, sets = 0;
    for (uint32_t k = 0; a && b && k < 4000; k++, sets++) {
        if (k == 0 || k % 100 == 0) /* every group absent first, then every hundred changes */
            differ += memcmp(gdr_node_counts_words(a), gdr_node_counts_words(b), 4ull * total) != 0;
        uint32_t m = rng_next(&rng) % 2, group = rng_next(&rng) % whole[m]->group_count;
        bool resident = rng_next(&rng) % 3 != 0;
        differ += gdr_node_counts_set(a, m, group, resident) != gdr_node_counts_set(b, m, group, resident);
    }
    if (a && b)
        differ += memcmp(gdr_node_counts_words(a), gdr_node_counts_words(b), 4ull * total) != 0;
    printf("without clusters: %u of %u changes or comparisons differ\n", differ, sets);
    CHECK(differ == 0);
    gdr_node_counts_destroy(a);
    gdr_node_counts_destroy(b);
    gdr_scene_destroy(paged);
}

int main(void)
{
    gdr_scene *scene = NULL;
    gdr_error err = {0};
    gdr_load_options load = {.no_progress = 1};
    CHECK(gdr_scene_load("unique-field:meshes=2,triangles=250000,seed=5", &load, &scene, &err) == GDR_OK);
    if (scene && scene->mesh_count == 2)
        run(scene);
    if (scene && scene->mesh_count == 2)
        run_without_clusters(scene);
    gdr_scene_destroy(scene);
    return test_finish("test_node_counts");
}
