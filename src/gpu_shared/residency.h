/* GLSL only: which LOD groups are resident, for the traversal and the cluster tests
 * (docs/STREAMING.md, "Never a hole, never a crack"). GdrGpuScene.page_table holds one word per
 * group of every mesh (GdrGpuMesh.page_table_offset + group): GDR_GPU_PAGE_ABSENT, or resident.
 * An absent group counts as passing the cut rule (passes'), so its own clusters are not drawn and
 * the clusters made from it, in the resident groups above, are drawn instead. The node test's
 * second side ("no refined group below passes") holds only where no refined group below is
 * absent: GdrGpuScene.node_absent_refined counts them per node. Both are read only when the frame
 * says some group is absent (GDR_FRAME_PARTIAL_RESIDENCY), so a fully resident scene pays nothing.
 * Include after glsl_buffers.h. */
#ifndef GDR_RESIDENCY_H
#define GDR_RESIDENCY_H

// Whether group `group` of mesh `mesh` (GdrGpuMesh index) is absent; a cluster without a group
// (GDR_GPU_NO_GROUP) has nothing to be absent.
bool gdr_group_absent(GdrGpuFrameGlobals g, uint mesh, uint group)
{
    if ((g.flags & GDR_FRAME_PARTIAL_RESIDENCY) == 0u || group == GDR_GPU_NO_GROUP)
        return false;
    uint base = MeshesRef(GDR_SCENE.meshes).items[mesh].page_table_offset;
    return UintsRef(GDR_SCENE.page_table).items[base + group] == GDR_GPU_PAGE_ABSENT;
}

// The node test's smallest refined error below global node `node`: 0 where a refined group below
// is absent (it counts as passing), which drops the test's second side there.
float gdr_node_min_refined_error(GdrGpuFrameGlobals g, uint node, float min_refined_error)
{
    if ((g.flags & GDR_FRAME_PARTIAL_RESIDENCY) == 0u)
        return min_refined_error;
    return UintsRef(GDR_SCENE.node_absent_refined).items[node] != 0u ? 0.0 : min_refined_error;
}

// The cluster test's request: a cluster drawn in the place of its absent refined group that the
// full cut would refine (the group's projected error is above the threshold) asks for the group,
// its projected error the priority. One append per such cluster (the CPU merges repeats); past
// GDR_STREAM_REQUEST_CAPACITY only counted.
void gdr_request_group(GdrGpuFrameGlobals g, uint instance, uint mesh, uint group, vec4 sphere, float error,
                       mat4 model)
{
    float projected = gdr_lod_group_projected_error(sphere, error, model[0].xyz, model[1].xyz, model[2].xyz,
                                                    model[3].xyz, g.camera_position.xyz, g.lod_znear,
                                                    g.lod_projection_scale);
    uint at = atomicAdd(DrawStatsRef(GDR_FRAME.draw_stats).value.stream_requests, 1u);
    if (at < GDR_STREAM_REQUEST_CAPACITY)
        StreamRequestsRef(GDR_FRAME.stream_requests).items[at] = GdrGpuStreamRequest(mesh, group, projected, instance);
}

// Streaming frames (stream_frame != 0): the first cluster test of the frame that draws a cluster of
// group `group` lists the group, so that the host never evicts a page the cut draws. The stamp
// makes each group appear once; the list has room for every group: it cannot overflow.
void gdr_mark_group_used(GdrGpuFrameGlobals g, uint mesh, uint group)
{
    if (g.stream_frame == 0u || group == GDR_GPU_NO_GROUP)
        return;
    uint word = MeshesRef(GDR_SCENE.meshes).items[mesh].page_table_offset + group;
    if (atomicExchange(WritableUintsRef(GDR_SCENE.group_stamps).items[word], g.stream_frame) == g.stream_frame)
        return;
    uint at = atomicAdd(DrawStatsRef(GDR_FRAME.draw_stats).value.groups_used, 1u);
    WritableUintsRef(GDR_FRAME.used_groups).items[at] = word;
}

#endif
