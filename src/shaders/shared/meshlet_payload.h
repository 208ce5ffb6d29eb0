/* GLSL only: what a task workgroup hands to its mesh workgroups, and the views of the cluster data. */
#ifndef GDR_MESHLET_PAYLOAD_H
#define GDR_MESHLET_PAYLOAD_H

struct GdrTaskPayload {
    uint instance;
    uint meshlets[GDR_TASK_WORKGROUP_SIZE]; /* global GdrGpuMeshlet indices of the visible clusters */
};

layout(buffer_reference, scalar) readonly buffer MeshletsRef { GdrGpuMeshlet items[]; };
layout(buffer_reference, scalar) readonly buffer TaskCommandsRef { GdrGpuTaskCommand items[]; };
layout(buffer_reference, scalar) readonly buffer UintsRef { uint items[]; };
layout(buffer_reference, scalar) readonly buffer VerticesRef { GdrGpuVertex items[]; };

#endif
