/* Limits and workgroup sizes shared by the host and the shaders. */
#ifndef GDR_GPU_CONFIG_H
#define GDR_GPU_CONFIG_H

#define GDR_CULL_WORKGROUP_SIZE 64
#define GDR_SCATTER_WORKGROUP_SIZE 64
#define GDR_FRAMES_IN_FLIGHT 2
/* Instance records the CPU can send per frame through the update ring. */
#define GDR_INSTANCE_UPDATES_PER_FRAME 4096

#endif
