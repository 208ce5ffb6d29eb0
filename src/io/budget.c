/* Budgets: how much one untrusted file may make gdr allocate (docs/SECURITY.md). */
#include "io/io_internal.h"

gdr_budget gdr_budget_resolve(const gdr_budget *budget)
{
    gdr_budget b = budget ? *budget : (gdr_budget){0};
    if (!b.triangles)
        b.triangles = GDR_DEFAULT_MAX_TRIANGLES;
    if (!b.instances)
        b.instances = GDR_DEFAULT_MAX_INSTANCES;
    if (!b.texture_pixels)
        b.texture_pixels = GDR_DEFAULT_MAX_TEXTURE_PIXELS;
    if (!b.decoded_bytes)
        b.decoded_bytes = GDR_DEFAULT_MAX_DECODED_BYTES;
    return b;
}

void gdr_io_budget_init(gdr_io_budget *b, const gdr_budget *limits)
{
    gdr_budget r = gdr_budget_resolve(limits);
    *b = (gdr_io_budget){.limit = {r.triangles, r.instances, r.texture_pixels, r.decoded_bytes}};
}

gdr_status gdr_io_budget_take(gdr_io_budget *b, gdr_io_budget_kind kind, uint64_t amount, const char *name,
                              const char *place, gdr_error *err)
{
    /* The names are those of gdr's --budget option. */
    static const char *const names[GDR_BUDGET_KIND_COUNT] = {"triangles", "instances", "pixels", "bytes"};
    static const char *const what[GDR_BUDGET_KIND_COUNT] = {"triangles", "instances", "texture pixels",
                                                            "decoded bytes"};
    uint64_t used = b->used[kind];
    if (amount > b->limit[kind] || used > b->limit[kind] - amount)
        return gdr_error_set(err, GDR_ERROR_BUDGET, "%s: %s: %llu %s (%llu before it) exceed the budget of %llu; "
                             "raise it with --budget %s=N (gdr_budget.%s)", name, place, (unsigned long long)amount,
                             what[kind], (unsigned long long)used, (unsigned long long)b->limit[kind], names[kind],
                             kind == GDR_BUDGET_TEXTURE_PIXELS ? "texture_pixels"
                             : kind == GDR_BUDGET_DECODED_BYTES ? "decoded_bytes" : names[kind]);
    b->used[kind] = used + amount;
    return GDR_OK;
}

void gdr_io_budget_give(gdr_io_budget *b, gdr_io_budget_kind kind, uint64_t amount)
{
    b->used[kind] -= amount < b->used[kind] ? amount : b->used[kind];
}
