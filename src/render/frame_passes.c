/* The table of a frame's passes: each pass as a template (its recording function and the
 * resources it uses), and which passes a configuration's frame is made of (frame_plan.h). The
 * visibility buffer's passes record in visbuffer.c. */
#include <assert.h>

#include "render/frame_record.h"
#include "render/renderer_internal.h"

#define COMPUTE VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT
#define INDIRECT VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT
#define VERTEX VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT
#define TASK VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT
#define MESH VK_PIPELINE_STAGE_2_MESH_SHADER_BIT_EXT
#define FRAGMENT VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT
#define FRAGMENT_TESTS (VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT)
#define COLOR_OUTPUT VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT
#define TRANSFER VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT /* vkCmdFillBuffer: copy or clear stage */
#define COPY VK_PIPELINE_STAGE_2_COPY_BIT

#define READ VK_ACCESS_2_SHADER_READ_BIT
#define WRITE VK_ACCESS_2_SHADER_WRITE_BIT
#define READ_WRITE (VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT)
#define SAMPLED VK_ACCESS_2_SHADER_SAMPLED_READ_BIT
#define INDIRECT_READ VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT
#define COPY_READ VK_ACCESS_2_TRANSFER_READ_BIT
#define COPY_WRITE VK_ACCESS_2_TRANSFER_WRITE_BIT

/* The attachments of a forward raster pass: cleared by the first phase, loaded by the late one. */
#define COLOR_TARGET                                                                                                \
    {GDR_RES_COLOR, COLOR_OUTPUT, VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, \
     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, .flags = GDR_USE_CLEARS}
#define DEPTH_TARGET                                                                                                \
    {GDR_RES_DEPTH, FRAGMENT_TESTS,                                                                                 \
     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,               \
     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, .flags = GDR_USE_CLEARS}
#define HZB_READ(stages) {GDR_RES_HZB, stages, SAMPLED, VK_IMAGE_LAYOUT_GENERAL}
#define OVERDRAW_COUNTS(stages) {GDR_RES_OVERDRAW, stages, READ_WRITE, .flags = GDR_USE_OVERDRAW_VIEW}

static const gdr_pass_template instance_scatter = {
    "instance_scatter", gdr_pass_record_instance_scatter, .what = "instance updates from the ring into the instances",
    .uses = {{GDR_RES_INSTANCES, COMPUTE, WRITE}}};

static const gdr_pass_template clear = {
    "clear", gdr_pass_record_clear, .what = "counters (and overdraw counts, the visibility buffer) to zero",
    .uses = {{GDR_RES_DRAW_STATS, TRANSFER, COPY_WRITE},
             {GDR_RES_OVERDRAW, TRANSFER, COPY_WRITE, .flags = GDR_USE_OVERDRAW_VIEW},
             {GDR_RES_RASTER_COUNTERS, TRANSFER, COPY_WRITE, .flags = GDR_USE_VISBUFFER},
             {GDR_RES_VISBUFFER, TRANSFER, COPY_WRITE, .flags = GDR_USE_VISBUFFER}}};

static const gdr_pass_template cull_draws = {
    "instance_cull", gdr_pass_record_instance_cull,
    .what = "instances (late phase: those the early one deferred): frustum, occlusion; appends draw commands",
    .uses = {{GDR_RES_DRAW_STATS, INDIRECT, INDIRECT_READ}, {GDR_RES_INSTANCES, COMPUTE, READ},
             {GDR_RES_OCCLUDED, COMPUTE, READ_WRITE}, HZB_READ(COMPUTE), {GDR_RES_DRAWS, COMPUTE, WRITE},
             {GDR_RES_DRAW_STATS, COMPUTE, READ_WRITE}}};

static const gdr_pass_template draw_indexed = {
    "draw_indexed", gdr_pass_record_draw_indexed, .what = "one vkCmdDrawIndexedIndirectCount",
    .uses = {{GDR_RES_DRAWS, INDIRECT, INDIRECT_READ}, {GDR_RES_DRAW_STATS, INDIRECT, INDIRECT_READ},
             {GDR_RES_INSTANCES, VERTEX, READ}, COLOR_TARGET, DEPTH_TARGET, OVERDRAW_COUNTS(FRAGMENT)}};

static const gdr_pass_template cull_tasks = {
    "instance_cull", gdr_pass_record_instance_cull,
    .what = "instances (late phase: those the early one deferred): frustum, occlusion, LOD root shortcut; "
            "appends task commands; draws the point level's splats",
    .uses = {{GDR_RES_DRAW_STATS, INDIRECT, INDIRECT_READ}, {GDR_RES_INSTANCES, COMPUTE, READ},
             {GDR_RES_OCCLUDED, COMPUTE, READ_WRITE}, HZB_READ(COMPUTE),
             {GDR_RES_TASKS, COMPUTE, WRITE}, {GDR_RES_DRAW_STATS, COMPUTE, READ_WRITE},
             {GDR_RES_DRAWS, COMPUTE, WRITE}, {GDR_RES_TRAVERSAL, COMPUTE, WRITE, .flags = GDR_USE_TRAVERSAL},
             {GDR_RES_VISBUFFER, COMPUTE, READ_WRITE, .flags = GDR_USE_VISBUFFER}}};

static const gdr_pass_template lod_traverse = {
    "lod_traverse", gdr_pass_record_lod_traverse,
    .what = "one level of the LOD hierarchies: nodes by LOD error, frustum, occlusion; leaves append tasks",
    .uses = {{GDR_RES_DRAW_STATS, INDIRECT, INDIRECT_READ}, {GDR_RES_DRAW_STATS, COMPUTE, READ_WRITE},
             {GDR_RES_TRAVERSAL, COMPUTE, READ_WRITE}, {GDR_RES_INSTANCES, COMPUTE, READ}, HZB_READ(COMPUTE),
             {GDR_RES_OCCLUDED, COMPUTE, READ_WRITE}, {GDR_RES_TASKS, COMPUTE, WRITE}}};

static const gdr_pass_template task_submit = {
    "task_submit", gdr_pass_record_task_submit, .what = "the task commands' count into the launches",
    .uses = {{GDR_RES_DRAW_STATS, COMPUTE, READ_WRITE}}};

static const gdr_pass_template meshlets = {
    "meshlets", gdr_pass_record_meshlets,
    .what = "task shaders test clusters (the early phase defers hidden ones), mesh shaders cull triangles, "
            "fragments shade",
    .uses = {{GDR_RES_DRAW_STATS, INDIRECT, INDIRECT_READ}, {GDR_RES_DRAW_STATS, TASK | MESH, READ_WRITE},
             {GDR_RES_TASKS, TASK, READ_WRITE}, {GDR_RES_INSTANCES, TASK | MESH, READ},
             {GDR_RES_OCCLUDED, TASK, READ_WRITE}, HZB_READ(TASK), {GDR_RES_VISIBLE_MESHLETS, TASK, WRITE},
             COLOR_TARGET, DEPTH_TARGET, OVERDRAW_COUNTS(FRAGMENT)}};

static const gdr_pass_template cluster_cull = {
    "cluster_cull", gdr_visbuffer_record_cluster_cull, GDR_RASTER_TIMER_CULL,
    .what = "clusters: LOD cut, frustum, cone, occlusion (the early phase defers hidden ones); binned into the "
            "visible-cluster list",
    .uses = {{GDR_RES_DRAW_STATS, INDIRECT, INDIRECT_READ}, {GDR_RES_DRAW_STATS, COMPUTE, READ_WRITE},
             {GDR_RES_TASKS, COMPUTE, READ_WRITE}, {GDR_RES_INSTANCES, COMPUTE, READ},
             {GDR_RES_OCCLUDED, COMPUTE, READ_WRITE}, HZB_READ(COMPUTE),
             {GDR_RES_RASTER_COUNTERS, COMPUTE, READ_WRITE}, {GDR_RES_RASTER_CLUSTERS, COMPUTE, WRITE},
             {GDR_RES_VISIBLE_MESHLETS, COMPUTE, WRITE}}};

static const gdr_pass_template raster_submit = {
    "raster_submit", gdr_visbuffer_record_raster_submit, GDR_RASTER_TIMER_CULL,
    .what = "both rasterisers' launches", .uses = {{GDR_RES_RASTER_COUNTERS, COMPUTE, READ_WRITE}}};

static const gdr_pass_template raster_hw = {
    "raster_hw", gdr_visbuffer_record_raster_hw, GDR_RASTER_TIMER_HW,
    .what = "mesh shaders over the back of the list into the visibility buffer",
    .uses = {{GDR_RES_RASTER_COUNTERS, INDIRECT, INDIRECT_READ}, {GDR_RES_RASTER_COUNTERS, MESH, READ},
             {GDR_RES_RASTER_CLUSTERS, MESH, READ}, {GDR_RES_INSTANCES, MESH, READ},
             {GDR_RES_DRAW_STATS, MESH, READ_WRITE}, {GDR_RES_VISBUFFER, FRAGMENT, READ_WRITE},
             OVERDRAW_COUNTS(FRAGMENT)}};

static const gdr_pass_template raster_sw = {
    "raster_sw", gdr_visbuffer_record_raster_sw, GDR_RASTER_TIMER_SW,
    .what = "the compute rasteriser into the visibility buffer: each tiny class's part of the list several "
            "clusters to a workgroup, then the front one to a workgroup",
    .uses = {{GDR_RES_RASTER_COUNTERS, INDIRECT, INDIRECT_READ}, {GDR_RES_RASTER_COUNTERS, COMPUTE, READ},
             {GDR_RES_RASTER_CLUSTERS, COMPUTE, READ}, {GDR_RES_INSTANCES, COMPUTE, READ},
             {GDR_RES_VISBUFFER, COMPUTE, READ_WRITE}, OVERDRAW_COUNTS(COMPUTE)}};

static const gdr_pass_template resolve = {
    "resolve", gdr_visbuffer_record_resolve, GDR_RASTER_TIMER_RESOLVE,
    .what = "shades every pixel of the visibility buffer (a late phase that drew nothing: no pixel)",
    .uses = {{GDR_RES_RASTER_COUNTERS, INDIRECT, INDIRECT_READ}, {GDR_RES_VISBUFFER, COMPUTE, READ},
             {GDR_RES_RASTER_CLUSTERS, COMPUTE, READ},
             {GDR_RES_INSTANCES, COMPUTE, READ},
             {GDR_RES_COLOR, COMPUTE, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL,
              .flags = GDR_USE_CLEARS}}};

/* The visibility-buffer modes build the pyramid from the visibility buffer's depth, not the depth
 * image, which they never write (its descriptor is bound all the same: it gets the layout). */
static const gdr_pass_template pyramid_visbuffer = {
    "pyramid", gdr_pass_record_pyramid,
    .what = "the depth pyramid of the visibility buffer's depth so far (its build orders its levels)",
    .uses = {{GDR_RES_VISBUFFER, COMPUTE, READ},
             {GDR_RES_DEPTH, COMPUTE, SAMPLED, VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL, true},
             {GDR_RES_HZB, COMPUTE, SAMPLED | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL}}};

static const gdr_pass_template pyramid = {
    "pyramid", gdr_pass_record_pyramid, .what = "the depth pyramid of the depth so far (its build orders its levels)",
    .uses = {{GDR_RES_DEPTH, COMPUTE, SAMPLED, VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL},
             {GDR_RES_HZB, COMPUTE, SAMPLED | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL}}};

static const gdr_pass_template overdraw_max = {
    "overdraw_max", gdr_pass_record_overdraw_max, .what = "the largest fragment count",
    .uses = {{GDR_RES_OVERDRAW, COMPUTE, READ_WRITE}}};

static const gdr_pass_template overdraw_paint = {
    "overdraw_paint", gdr_pass_record_overdraw_paint, .what = "the counts over the image as a heat map",
    .uses = {{GDR_RES_OVERDRAW, FRAGMENT, READ},
             {GDR_RES_COLOR, COLOR_OUTPUT, VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
              VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL}}};

static const gdr_pass_template cpu_draw = {
    "cpu_draws", gdr_pass_record_cpu_draws, .what = "one bind and draw per instance the CPU found visible",
    .uses = {{GDR_RES_INSTANCES, VERTEX, READ}, COLOR_TARGET, DEPTH_TARGET, OVERDRAW_COUNTS(FRAGMENT)}};

static const gdr_pass_template readback = {
    "readback", gdr_pass_record_readback, .what = "the counters copied for the CPU",
    .uses = {{GDR_RES_DRAW_STATS, COPY, COPY_READ},
             {GDR_RES_RASTER_COUNTERS, COPY, COPY_READ, .flags = GDR_USE_VISBUFFER},
             {GDR_RES_READBACK, COPY, COPY_WRITE}}};

/* Culling and raster of one phase. */
static void add_phase(gdr_frame_plan *plan, gdr_occlusion_phase phase)
{
    const gdr_frame_config *c = &plan->config;
    gdr_frame_section cull = phase == GDR_PHASE_LATE ? GDR_SECTION_LATE_CULL : GDR_SECTION_CULL;
    gdr_frame_section draw = phase == GDR_PHASE_LATE ? GDR_SECTION_LATE_DRAW : GDR_SECTION_DRAW;
    if (c->pipeline == GDR_PIPELINE_CPU) {
        gdr_frame_plan_add(plan, &cpu_draw, phase, draw); /* culled on the CPU before recording */
    } else if (c->pipeline == GDR_PIPELINE_INDIRECT) {
        gdr_frame_plan_add(plan, &cull_draws, phase, cull);
        gdr_frame_plan_add(plan, &draw_indexed, phase, draw);
    } else {
        gdr_frame_plan_add(plan, &cull_tasks, phase, cull);
        for (uint32_t level = 0; level < c->traversal_levels; level++)
            gdr_frame_plan_add_step(plan, &lod_traverse, phase, level, cull);
        gdr_frame_plan_add(plan, &task_submit, phase, cull);
        if (!c->visbuffer) {
            gdr_frame_plan_add(plan, &meshlets, phase, draw);
            return;
        }
        const gdr_pass_template *raster[] = {&cluster_cull, &raster_submit, &raster_hw, &raster_sw, &resolve};
        for (size_t i = 0; i < sizeof raster / sizeof raster[0]; i++)
            gdr_frame_plan_add(plan, raster[i], phase, draw);
    }
}

void gdr_frame_plan_build(const gdr_frame_config *config, gdr_frame_plan *plan)
{
    *plan = (gdr_frame_plan){.config = *config};
    if (config->updates)
        gdr_frame_plan_add(plan, &instance_scatter, GDR_PHASE_ONLY, GDR_SECTION_INSTANCE_UPDATE);
    gdr_frame_plan_add(plan, &clear, GDR_PHASE_ONLY, GDR_SECTION_INSTANCE_UPDATE);
    bool two_phases = config->occlusion && config->pipeline != GDR_PIPELINE_CPU;
    if (two_phases) {
        add_phase(plan, GDR_PHASE_EARLY);
        gdr_frame_plan_add(plan, config->visbuffer ? &pyramid_visbuffer : &pyramid, GDR_PHASE_EARLY,
                           GDR_SECTION_PYRAMID);
    }
    gdr_occlusion_phase last = two_phases ? GDR_PHASE_LATE : GDR_PHASE_ONLY;
    add_phase(plan, last);
    if (config->overdraw) {
        gdr_frame_section draw = two_phases ? GDR_SECTION_LATE_DRAW : GDR_SECTION_DRAW;
        gdr_frame_plan_add(plan, &overdraw_max, last, draw);
        gdr_frame_plan_add(plan, &overdraw_paint, last, draw);
    }
    gdr_frame_plan_add(plan, &readback, GDR_PHASE_ONLY, GDR_SECTION_READBACK);
    assert(plan->pass_count < GDR_FRAME_MAX_PASSES);
    gdr_frame_plan_derive(plan);
}
