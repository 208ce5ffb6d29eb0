/* GLSL only: what a task workgroup hands to its mesh workgroups, and the views of the cluster data. */
#ifndef GDR_MESHLET_PAYLOAD_H
#define GDR_MESHLET_PAYLOAD_H

struct GdrTaskPayload {
    uint instance;
    uint meshlets[GDR_TASK_WORKGROUP_SIZE]; /* global GdrGpuMeshlet indices of the visible clusters */
};


#endif
