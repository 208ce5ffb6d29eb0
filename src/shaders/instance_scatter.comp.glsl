#version 460
// Applies this frame's "tag + data" records from the instance ring to the persistent instance buffer.
#include "gpu_shared/glsl_buffers.h"

layout(local_size_x = GDR_SCATTER_WORKGROUP_SIZE) in;

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    uint id = gl_GlobalInvocationID.x;
    if (id >= g.update_count)
        return;
    GdrGpuInstanceUpdate update = InstanceUpdatesRef(GDR_FRAME.updates).items[id];
    if (update.tag == GDR_UPDATE_TAG_INSTANCE && update.index < g.instance_count)
        InstancesRef(GDR_SCENE.instances).items[update.index] = update.instance;
}
