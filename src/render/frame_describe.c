/* The frame plans as Markdown: gdr info --passes, and docs/PIPELINE.md (a test keeps them equal). */
#include <inttypes.h>

#include "render/frame_record.h"
#include "render/renderer_internal.h"

const char *gdr_frame_section_name(gdr_frame_section section)
{
    static const char *const names[GDR_SECTION_COUNT + 1] = {
        "instance_update", "cull", "draw", "pyramid", "late_cull", "late_draw", "readback", "-"};
    return (unsigned)section <= GDR_SECTION_COUNT ? names[section] : "?";
}

const char *gdr_frame_resource_name(gdr_frame_resource resource)
{
    static const char *const names[GDR_RES_COUNT] = {
        "instances", "occluded", "draw_stats", "draws", "tasks", "traversal", "visible_meshlets", "overdraw", "raster_counters",
        "raster_clusters", "visbuffer", "readback", "color", "depth", "hzb"};
    return (unsigned)resource < GDR_RES_COUNT ? names[resource] : "?";
}

typedef struct flag_name {
    uint64_t bit;
    const char *name;
} flag_name;

static const flag_name stage_names[] = {
    {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, "all"},      {VK_PIPELINE_STAGE_2_HOST_BIT, "host"},
    {VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, "indirect"}, {VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT, "vertex"},
    {VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT, "task"},   {VK_PIPELINE_STAGE_2_MESH_SHADER_BIT_EXT, "mesh"},
    {VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT, "early-tests"},
    {VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, "late-tests"},
    {VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, "fragment"},
    {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, "color-output"},
    {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, "compute"}, {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, "transfer"},
    {VK_PIPELINE_STAGE_2_COPY_BIT, "copy"},
};

static const flag_name access_names[] = {
    {VK_ACCESS_2_MEMORY_READ_BIT, "memory-read"},   {VK_ACCESS_2_MEMORY_WRITE_BIT, "memory-write"},
    {VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT, "indirect-read"},
    {VK_ACCESS_2_SHADER_READ_BIT, "read"},          {VK_ACCESS_2_SHADER_WRITE_BIT, "write"},
    {VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, "sampled"}, {VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, "storage-write"},
    {VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT, "attachment-read"},
    {VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, "attachment-write"},
    {VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT, "depth-read"},
    {VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, "depth-write"},
    {VK_ACCESS_2_TRANSFER_READ_BIT, "transfer-read"}, {VK_ACCESS_2_TRANSFER_WRITE_BIT, "transfer-write"},
    {VK_ACCESS_2_HOST_READ_BIT, "host-read"},
};

static void print_flags(FILE *out, uint64_t flags, const flag_name *names, size_t count)
{
    bool first = true;
    for (size_t i = 0; i < count; i++) {
        if (!(flags & names[i].bit))
            continue;
        fprintf(out, "%s%s", first ? "" : "+", names[i].name);
        first = false;
        flags &= ~names[i].bit;
    }
    if (first)
        fprintf(out, "none");
    if (flags)
        fprintf(out, "+0x%" PRIx64, flags);
}

static void print_scope(FILE *out, gdr_vk_scope scope)
{
    print_flags(out, scope.stages, stage_names, sizeof stage_names / sizeof stage_names[0]);
    if (scope.access) {
        fprintf(out, " ");
        print_flags(out, scope.access, access_names, sizeof access_names / sizeof access_names[0]);
    }
}

static const char *layout_name(VkImageLayout layout)
{
    switch (layout) {
    case VK_IMAGE_LAYOUT_UNDEFINED: return "undefined";
    case VK_IMAGE_LAYOUT_GENERAL: return "general";
    case VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL: return "color-attachment";
    case VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL: return "depth-attachment";
    case VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL: return "depth-read-only";
    case VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL: return "transfer-src";
    case VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL: return "transfer-dst";
    default: return "other";
    }
}

static void print_barrier(FILE *out, const gdr_frame_barrier *b, bool everything_before)
{
    bool any = false;
    if (b->src.stages || b->dst.stages) {
        fprintf(out, "%s", everything_before ? "everything before the frame" : "");
        if (!everything_before)
            print_scope(out, b->src);
        fprintf(out, " → ");
        print_scope(out, b->dst);
        any = true;
    }
    for (uint32_t i = 0; i < b->image_count; i++) {
        const gdr_image_transition *t = &b->images[i];
        fprintf(out, "%s%s %s→%s (", any ? "; " : "", gdr_frame_resource_name(t->resource), layout_name(t->from),
                layout_name(t->to));
        print_scope(out, t->src);
        fprintf(out, " → ");
        print_scope(out, t->dst);
        fprintf(out, ")");
        any = true;
    }
    if (!any)
        fprintf(out, "—");
}

static void print_uses(FILE *out, const gdr_frame_pass *p)
{
    for (uint32_t i = 0; i < p->use_count; i++) {
        const gdr_resource_use *u = &p->uses[i];
        fprintf(out, "%s%s: ", i ? "; " : "", gdr_frame_resource_name(u->resource));
        print_scope(out, (gdr_vk_scope){u->stages, u->access});
        if (u->resource >= GDR_RES_FIRST_IMAGE)
            fprintf(out, " in %s%s", layout_name(u->layout), u->discard ? ", discarded" : "");
    }
}

static const char *phase_name(gdr_occlusion_phase phase)
{
    return phase == GDR_PHASE_EARLY ? "early" : phase == GDR_PHASE_LATE ? "late" : "";
}

void gdr_frame_plan_describe(const gdr_frame_plan *plan, FILE *out)
{
    const gdr_frame_config *c = &plan->config;
    fprintf(out, "#### %s pipeline%s, occlusion %s%s%s", gdr_pipeline_name(c->pipeline),
            c->pipeline != GDR_PIPELINE_MESH ? "" : c->visbuffer ? ", visibility buffer" : ", forward raster",
            c->occlusion ? "on" : "off", c->overdraw ? ", overdraw view" : "", c->updates ? ", instance updates" : "");
    if (c->traversal_levels)
        fprintf(out, ", LOD hierarchy of %u levels", c->traversal_levels);
    fprintf(out, "\n\n");
    fprintf(out, "| # | pass | phase | timing | barrier before it | uses |\n|---|---|---|---|---|---|\n");
    for (uint32_t i = 0; i < plan->pass_count; i++) {
        const gdr_frame_pass *p = &plan->passes[i];
        fprintf(out, "| %u | %s", i + 1, p->template_->name);
        if (p->template_->record == gdr_pass_record_lod_traverse)
            fprintf(out, " (level %u)", p->step);
        fprintf(out, " | %s | %s | ", phase_name(p->phase), gdr_frame_section_name(p->section));
        print_barrier(out, &p->barrier, p->begins_everything_before);
        fprintf(out, " | ");
        print_uses(out, p);
        fprintf(out, " |\n");
    }
    fprintf(out, "| | frame_end | | | ");
    print_barrier(out, &plan->end_barrier, false);
    fprintf(out, " | |\n\n");
}

void gdr_describe_frame_passes(FILE *out)
{
    static const gdr_frame_config configs[] = {
        {GDR_PIPELINE_INDIRECT, false, false, false, true}, {GDR_PIPELINE_INDIRECT, false, true, false, true},
        {GDR_PIPELINE_CPU, false, false, false, true},      {GDR_PIPELINE_MESH, false, false, false, true},
        {GDR_PIPELINE_MESH, false, true, false, true},      {GDR_PIPELINE_MESH, true, false, false, true},
        {GDR_PIPELINE_MESH, true, true, false, true},       {GDR_PIPELINE_MESH, true, true, true, true},
        /* With the LOD cut: the traversal of hierarchies of 3 levels. */
        {GDR_PIPELINE_MESH, true, true, false, true, 3},    {GDR_PIPELINE_MESH, false, true, false, false, 3},
    };
    for (size_t i = 0; i < sizeof configs / sizeof configs[0]; i++) {
        gdr_frame_plan plan;
        gdr_frame_plan_build(&configs[i], &plan);
        gdr_frame_plan_describe(&plan, out);
    }
}
