/* The frame plan's mechanics (frame_plan.h): choosing a template's uses for a configuration, the
 * barriers derived from the uses, the timestamps, and the description. */
#include "render/frame_plan.h"

#include <string.h>

static const VkAccessFlags2 write_access =
    VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT |
    VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
    VK_ACCESS_2_HOST_WRITE_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;

static bool use_applies(const gdr_resource_use *use, const gdr_frame_config *config)
{
    if ((use->flags & GDR_USE_OVERDRAW_VIEW) && !config->overdraw)
        return false;
    if ((use->flags & GDR_USE_VISBUFFER) && !config->visbuffer)
        return false;
    if ((use->flags & GDR_USE_TRAVERSAL) && config->traversal_levels == 0)
        return false;
    return use->stages != 0;
}

void gdr_frame_plan_add(gdr_frame_plan *plan, const gdr_pass_template *pass, gdr_occlusion_phase phase,
                        gdr_frame_section section)
{
    gdr_frame_plan_add_step(plan, pass, phase, 0, section);
}

void gdr_frame_plan_add_step(gdr_frame_plan *plan, const gdr_pass_template *pass, gdr_occlusion_phase phase,
                             uint32_t step, gdr_frame_section section)
{
    if (plan->pass_count == GDR_FRAME_MAX_PASSES)
        return; /* the builder's passes are counted: frame_passes.c asserts they fit */
    gdr_frame_pass *p = &plan->passes[plan->pass_count++];
    *p = (gdr_frame_pass){.template_ = pass, .phase = phase, .step = step, .section = section, .timestamp = -1};
    for (uint32_t i = 0; i < GDR_PASS_MAX_USES; i++) {
        gdr_resource_use use = pass->uses[i];
        if (!use_applies(&use, &plan->config))
            continue;
        if (use.flags & GDR_USE_CLEARS)
            use.discard = phase != GDR_PHASE_LATE;
        p->uses[p->use_count++] = use;
    }
}

/* --- barriers ------------------------------------------------------------------------------- */

/* What the passes so far did to one resource. */
typedef struct resource_state {
    gdr_vk_scope write;                /* the last write; empty: nothing to wait for */
    gdr_vk_scope visible;              /* whom a barrier has made that write visible to */
    VkPipelineStageFlags2 read_stages; /* reads since the last write (a later write waits for them) */
    VkImageLayout layout;
    bool untouched;                    /* not used yet in this frame */
} resource_state;

static VkImageLayout home_layout(gdr_frame_resource resource)
{
    switch (resource) {
    case GDR_RES_COLOR: return VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    case GDR_RES_DEPTH: return VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    case GDR_RES_HZB: return VK_IMAGE_LAYOUT_GENERAL;
    default: return VK_IMAGE_LAYOUT_UNDEFINED;
    }
}

static bool covered(gdr_vk_scope scope, gdr_vk_scope by)
{
    return (scope.stages & ~by.stages) == 0 && (scope.access & ~by.access) == 0;
}

static void add_scope(gdr_vk_scope *to, gdr_vk_scope scope)
{
    to->stages |= scope.stages;
    to->access |= scope.access;
}

/* The hazards of one use against the state before its pass, added to the pass's barrier. */
static void add_hazards(const resource_state *s, const gdr_resource_use *use, gdr_frame_barrier *b)
{
    gdr_vk_scope dst = {use->stages, use->access};
    bool writes = (use->access & write_access) != 0;
    if (use->resource >= GDR_RES_FIRST_IMAGE && (use->layout != s->layout || use->discard)) {
        gdr_image_transition *t = &b->images[b->image_count++];
        *t = (gdr_image_transition){.resource = use->resource, .from = use->discard ? VK_IMAGE_LAYOUT_UNDEFINED : s->layout,
                                    .to = use->layout, .src = s->write, .dst = dst};
        t->src.stages |= s->read_stages | (s->untouched ? VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT : 0);
        return;
    }
    if (use->access == 0)
        return; /* the layout alone */
    if (s->write.stages && (writes || !covered(dst, s->visible))) { /* read or write after write */
        add_scope(&b->src, s->write);
        add_scope(&b->dst, dst);
    }
    if (writes && s->read_stages) { /* write after read: an execution dependency */
        b->src.stages |= s->read_stages;
        b->dst.stages |= use->stages;
    }
}

/* The state after a pass, from its uses of `resource`. */
static void apply_uses(resource_state *s, const gdr_frame_pass *p, gdr_frame_resource resource)
{
    gdr_vk_scope written = {0}, read = {0};
    bool used = false, transitioned = false;
    for (uint32_t i = 0; i < p->use_count; i++) {
        const gdr_resource_use *u = &p->uses[i];
        if (u->resource != resource)
            continue;
        used = true;
        transitioned |= resource >= GDR_RES_FIRST_IMAGE && (u->layout != s->layout || u->discard);
        if (u->access & write_access)
            add_scope(&written, (gdr_vk_scope){u->stages, u->access & write_access});
        add_scope(&read, (gdr_vk_scope){u->stages, u->access});
        if (resource >= GDR_RES_FIRST_IMAGE)
            s->layout = u->layout;
    }
    if (!used)
        return;
    s->untouched = false;
    if (written.stages || transitioned) { /* a layout transition counts as a write in its stages */
        s->write = written.stages ? written : (gdr_vk_scope){read.stages, 0};
        s->visible = transitioned && !written.stages ? read : (gdr_vk_scope){0};
        s->read_stages = read.stages;
        return;
    }
    if (s->write.stages)
        add_scope(&s->visible, read); /* add_hazards made the write visible to these reads */
    s->read_stages |= read.stages;
}

static void derive_pass(resource_state states[GDR_RES_COUNT], gdr_frame_pass *p)
{
    p->barrier = (gdr_frame_barrier){0};
    for (uint32_t i = 0; i < p->use_count; i++)
        add_hazards(&states[p->uses[i].resource], &p->uses[i], &p->barrier);
    for (uint32_t r = 0; r < GDR_RES_COUNT; r++)
        apply_uses(&states[r], p, (gdr_frame_resource)r);
}

static void derive_timestamps(gdr_frame_plan *plan)
{
    uint32_t n = 0;
    int last = -1;
    for (uint32_t i = 0; i < plan->pass_count; i++) {
        gdr_frame_pass *p = &plan->passes[i];
        if (p->section == GDR_SECTION_NONE)
            continue;
        int key = (int)p->section * GDR_RASTER_TIMER_COUNT + (int)p->template_->timer;
        if (key == last)
            continue;
        last = key;
        p->timestamp = (int)n;
        plan->interval_section[n] = p->section;
        plan->interval_timer[n] = p->template_->timer;
        n++;
    }
    plan->timestamp_count = n + 1; /* the end */
}

void gdr_frame_plan_derive(gdr_frame_plan *plan)
{
    /* Nothing is known of what came before the frame: its first barrier waits for all of it. After
     * it every resource is in its home layout and nothing is left to make visible; every later
     * command runs after that barrier, and a layout transition chains through it (untouched). */
    resource_state states[GDR_RES_COUNT];
    for (uint32_t r = 0; r < GDR_RES_COUNT; r++)
        states[r] = (resource_state){.layout = home_layout((gdr_frame_resource)r), .untouched = true};
    for (uint32_t i = 0; i < plan->pass_count; i++) {
        gdr_frame_pass *p = &plan->passes[i];
        derive_pass(states, p);
        if (i == 0) {
            p->begins_everything_before = true;
            p->barrier.src = (gdr_vk_scope){VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT};
            p->barrier.dst = (gdr_vk_scope){VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                            VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT};
            for (uint32_t t = 0; t < p->barrier.image_count; t++)
                p->barrier.images[t].src = p->barrier.src;
        }
    }
    gdr_frame_pass end = {.template_ = &gdr_frame_end_template, .section = GDR_SECTION_NONE};
    for (uint32_t i = 0; i < GDR_PASS_MAX_USES; i++)
        if (gdr_frame_end_template.uses[i].stages)
            end.uses[end.use_count++] = gdr_frame_end_template.uses[i];
    derive_pass(states, &end);
    plan->end_barrier = end.barrier;
    derive_timestamps(plan);
}

/* The frame's end: the images back in the layouts the next frame and the read-backs expect, the
 * counters' copies and the lists written with the counters visible to the host. */
const gdr_pass_template gdr_frame_end_template = {
    .name = "frame_end",
    .what = "images back in their home layouts; the counters' copies and the host-read lists visible to the host",
    .uses = {
        {GDR_RES_COLOR, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
        {GDR_RES_DEPTH, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL},
        {GDR_RES_READBACK, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT},
        /* The lists the host reads in place (streaming's requests and groups used), written with the
         * counters. */
        {GDR_RES_DRAW_STATS, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT},
    },
};
