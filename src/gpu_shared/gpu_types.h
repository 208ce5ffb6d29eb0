/* Every struct the GPU reads or writes, declared once for C and GLSL (scalar block layout), each
 * followed by the C checks of its size and offsets. GPU pointers are typed references (GDR_REF). */
#ifndef GDR_GPU_TYPES_H
#define GDR_GPU_TYPES_H

#include "math/glsl_c_bridge.h"
#include "gpu_shared/gpu_config.h"
#include "gpu_shared/occlusion_math.h"

/* The reference types the structs below hold (GLSL defines them in glsl_buffers.h). */
GDR_DECLARE_REF(FrameGlobalsRef)
GDR_DECLARE_REF(SceneRef)
GDR_DECLARE_REF(FrameBuffersRef)
GDR_DECLARE_REF(InstancesRef)
GDR_DECLARE_REF(MeshesRef)
GDR_DECLARE_REF(VerticesRef)
GDR_DECLARE_REF(MeshletsRef)
GDR_DECLARE_REF(LodNodesRef)
GDR_DECLARE_REF(UintsRef)
GDR_DECLARE_REF(WritableUintsRef)
GDR_DECLARE_REF(DrawCommandsRef)
GDR_DECLARE_REF(DrawStatsRef)
GDR_DECLARE_REF(InstanceUpdatesRef)
GDR_DECLARE_REF(TaskCommandsRef)
GDR_DECLARE_REF(OverdrawRef)
GDR_DECLARE_REF(VisibleMeshletsRef)
GDR_DECLARE_REF(VisbufferRef)
GDR_DECLARE_REF(RasterParamsRef)
GDR_DECLARE_REF(RasterCountersRef)
GDR_DECLARE_REF(RasterClustersRef)
GDR_DECLARE_REF(NodeVisitsRef)
GDR_DECLARE_REF(MaterialsRef)
GDR_DECLARE_REF(StreamRequestsRef)

/* One vertex of the geometry pool (vertex input binding 0). */
GDR_STRUCT_BEGIN(GdrGpuVertex)
    gdr_vec3 position;
    gdr_vec3 normal;
    gdr_vec2 uv;
GDR_STRUCT_END(GdrGpuVertex)
GDR_ASSERT_SIZE(GdrGpuVertex, 32);
GDR_ASSERT_OFFSET(GdrGpuVertex, normal, 12);
GDR_ASSERT_OFFSET(GdrGpuVertex, uv, 24);

/* Where a mesh lives in the merged vertex, index and cluster buffers, and its bounds (seed 003, plan A).
 * The mesh's clusters are GdrGpuMeshlet[meshlet_offset .. + lod_cluster_count): level 0 first
 * (meshlet_count of them), then the coarser clusters of its LOD DAG, the root group's last. */
GDR_STRUCT_BEGIN(GdrGpuMesh)
    gdr_uint vertex_offset;
    gdr_uint first_index;
    gdr_uint index_count;
    gdr_uint meshlet_count;  /* level-0 clusters */
    gdr_vec4 bounds;         /* mesh-space sphere: centre xyz, radius w */
    gdr_uint meshlet_offset; /* first GdrGpuMeshlet of the mesh */
    gdr_uint task_count;     /* task workgroups per instance: ceil(meshlet_count / GDR_TASK_WORKGROUP_SIZE) */
    gdr_uint lod_cluster_count; /* every cluster of the DAG (= meshlet_count without a DAG) */
    gdr_uint lod_task_count;    /* ceil(lod_cluster_count / GDR_TASK_WORKGROUP_SIZE) */
    gdr_uint root_first;        /* first cluster of the root group, relative to meshlet_offset */
    gdr_uint root_cluster_count; /* 0 without a DAG: no root shortcut */
    /* The root chain: where the root group is one cluster, the lone clusters the build simplified
     * step by step down to it (docs/GEOMETRY.md, "A coarse end"), coarsest first, at root_first,
     * root_first - 1, ...: root_chain of them (the root's included; at most GDR_LOD_ROOT_CHAIN);
     * each but the root in a group of that one cluster, made from the group of the next. 0: none. */
    gdr_uint root_chain;
    gdr_uint lod_node_offset;   /* the mesh's LOD hierarchy: GdrGpuLodNode[lod_node_offset .. + lod_node_count) */
    /* The root shortcut: a sphere containing, and the largest error of, the groups the root
     * group's clusters were made from. When it passes, each of them passes (errors and spheres
     * are monotonic up the DAG), so the cut is exactly the root group's clusters. */
    gdr_vec4 root_refined_sphere;
    float root_refined_error;
    gdr_uint lod_node_count;    /* >= 1 for a mesh with clusters; node 0 of the mesh is its root */
    gdr_uint lod_node_levels;   /* levels of the mesh's hierarchy (a traversal level by level needs this many steps) */
    gdr_uint page_table_offset; /* the mesh's groups' words in GdrGpuScene.page_table (shared/residency.h) */
    /* The point level (shared/point_level.h): below the root, an instance whose whole mesh projects
     * within a pixel is one splat at its bounding sphere's centre. point_error: its deviation, the
     * bounds' radius (every point of the mesh lies that near the centre); 0: no point level.
     * point_radius: the splat's radius, that of a disc whose area is the mesh's mean projected area. */
    float point_error;
    float point_radius;
    gdr_uint point_pad[2];
GDR_STRUCT_END(GdrGpuMesh)
GDR_ASSERT_SIZE(GdrGpuMesh, 112);
GDR_ASSERT_OFFSET(GdrGpuMesh, bounds, 16);
GDR_ASSERT_OFFSET(GdrGpuMesh, task_count, 36);
GDR_ASSERT_OFFSET(GdrGpuMesh, root_refined_sphere, 64);

/* One cluster of the geometry pool (gdr_cluster of gdr/geometry.h, with pool-global offsets), with
 * what the LOD cut (gdr/geometry.h "The cut") needs of its two groups inline: the group it
 * is part of ("group": without one, error INFINITY, never passes) and the group it was made from
 * ("refined": without one, error 0 and depth -1, always passes). */
GDR_STRUCT_BEGIN(GdrGpuMeshlet)
    gdr_uint vertex_offset;   /* first entry in the meshlet vertex pool (global vertex indices) */
    gdr_uint triangle_offset; /* first byte in the meshlet triangle pool (3 bytes per triangle) */
    gdr_uint vertex_count;
    gdr_uint triangle_count;
    gdr_vec4 sphere;          /* mesh space */
    gdr_vec3 cone_apex;       /* mesh space */
    float cone_cutoff;        /* back-facing from p when dot(normalize(apex - p), axis) >= cutoff */
    gdr_vec3 cone_axis;
    gdr_uint group;           /* mesh-local group index, or GDR_GPU_NO_GROUP */
    gdr_uint refined_group;   /* mesh-local group index, or GDR_GPU_NO_GROUP */
    gdr_int group_depth;      /* DAG depth of the group (0 without one): the cluster's LOD level */
    gdr_int refined_depth;    /* DAG depth of the refined group, -1 without one */
    gdr_uint cluster_id;      /* its index among the records of the scene uploaded whole (meshlet_offset +
                                 cluster): the debug views colour by it, so that a streamed scene's records,
                                 which live in their pages' slots, colour alike */
    gdr_vec4 group_sphere;    /* mesh space */
    gdr_vec4 refined_sphere;  /* mesh space */
    float group_error;        /* mesh space; INFINITY for the root group and without a group */
    float refined_error;      /* mesh space; 0 without a refined group */
    gdr_uint reserved1;
    gdr_uint reserved2;
GDR_STRUCT_END(GdrGpuMeshlet)
GDR_ASSERT_SIZE(GdrGpuMeshlet, 128);
GDR_ASSERT_OFFSET(GdrGpuMeshlet, sphere, 16);
GDR_ASSERT_OFFSET(GdrGpuMeshlet, cone_cutoff, 44);
GDR_ASSERT_OFFSET(GdrGpuMeshlet, group, 60);
GDR_ASSERT_OFFSET(GdrGpuMeshlet, group_sphere, 80);
GDR_ASSERT_OFFSET(GdrGpuMeshlet, group_error, 112);

/* One node of a mesh's LOD hierarchy: gdr_lod_node of gdr/geometry.h, whose contract it shares
 * (its fields are uploaded as they are), and a culling sphere. Indices are mesh-local: an inner node's children are nodes
 * [first, first + count) of its mesh, a leaf's clusters are the mesh's clusters
 * [first, first + count). The node test is gdr_lod_node_may_draw (lod_math.h). */
GDR_STRUCT_BEGIN(GdrGpuLodNode)
    gdr_vec4 sphere;         /* mesh space: contains every group, refined group and cluster sphere below */
    float max_error;         /* largest group error below (INFINITY when the root group is below) */
    float min_refined_error; /* smallest refined-group error below; 0 when a cluster below has none */
    gdr_uint first;          /* inner: first child node; leaf: first cluster */
    gdr_uint count;          /* inner: children (1 .. GDR_GPU_LOD_NODE_MAX_CHILDREN); leaf: clusters */
    gdr_uint group;          /* leaf: its group (GDR_GPU_NO_GROUP without a DAG); inner: GDR_GPU_NO_GROUP */
    gdr_uint flags;          /* GDR_GPU_LOD_NODE_LEAF */
    gdr_uint reserved0;
    gdr_uint reserved1;
    /* Mesh space: contains the culling sphere of every cluster below, and nothing of the LOD
     * spheres, which grow with every level (`sphere` holds both): the frustum and occlusion tests
     * use it, the LOD test uses `sphere`. Computed at upload (gpu_scene.c). */
    gdr_vec4 bounds;
GDR_STRUCT_END(GdrGpuLodNode)
GDR_ASSERT_SIZE(GdrGpuLodNode, 64);
GDR_ASSERT_OFFSET(GdrGpuLodNode, bounds, 48);
GDR_ASSERT_OFFSET(GdrGpuLodNode, max_error, 16);
GDR_ASSERT_OFFSET(GdrGpuLodNode, min_refined_error, 20);
GDR_ASSERT_OFFSET(GdrGpuLodNode, first, 24);
GDR_ASSERT_OFFSET(GdrGpuLodNode, count, 28);
GDR_ASSERT_OFFSET(GdrGpuLodNode, group, 32);
GDR_ASSERT_OFFSET(GdrGpuLodNode, flags, 36);

#define GDR_GPU_LOD_NODE_LEAF 1u
#define GDR_GPU_LOD_NODE_MAX_CHILDREN 8u

/* Task-shader work written by the instance cull of the meshlet pipeline: one task workgroup tests
 * clusters [meshlet_first, meshlet_first + meshlet_count) of one instance. */
GDR_STRUCT_BEGIN(GdrGpuTaskCommand)
    gdr_uint instance;
    gdr_uint meshlet_first; /* global GdrGpuMeshlet index */
    gdr_uint meshlet_count; /* 1 .. GDR_TASK_WORKGROUP_SIZE */
    gdr_uint flags;         /* GDR_TASK_* */
GDR_STRUCT_END(GdrGpuTaskCommand)
GDR_ASSERT_SIZE(GdrGpuTaskCommand, 16);

/* A group a cluster test found absent while the full cut needs it (shared/residency.h): the
 * cluster drawn in its place was made from it and its projected error (`priority`) is above the
 * threshold. Read back into gdr_residency_plan's requests (mesh, group, priority). */
GDR_STRUCT_BEGIN(GdrGpuStreamRequest)
    gdr_uint mesh;
    gdr_uint group;    /* mesh-local */
    float priority;    /* the group's projected error, pixels */
    gdr_uint instance; /* the instance that asked */
GDR_STRUCT_END(GdrGpuStreamRequest)
GDR_ASSERT_SIZE(GdrGpuStreamRequest, 16);

/* One node visit of the LOD hierarchy traversal: node `node` (mesh-local GdrGpuLodNode index) of
 * instance `instance`, with the task flags its clusters' commands will carry (GDR_TASK_*). */
GDR_STRUCT_BEGIN(GdrGpuNodeVisit)
    gdr_uint instance;
    gdr_uint node;
    gdr_uint flags;
GDR_STRUCT_END(GdrGpuNodeVisit)
GDR_ASSERT_SIZE(GdrGpuNodeVisit, 12);

/* A level of the traversal: its visits' count and the VkDispatchIndirectCommand that launches
 * them (x = ceil(count / GDR_TRAVERSE_WORKGROUP_SIZE), y = z = 1 once a visit is queued). */
GDR_STRUCT_BEGIN(GdrGpuTraversalLevel)
    gdr_uint dispatch_x;
    gdr_uint dispatch_y;
    gdr_uint dispatch_z;
    gdr_uint count;
GDR_STRUCT_END(GdrGpuTraversalLevel)
GDR_ASSERT_SIZE(GdrGpuTraversalLevel, 16);

#define GDR_TASK_LOD_ACCEPTED 1u /* the root shortcut chose these clusters: no LOD test */
#define GDR_TASK_RETEST 2u       /* late phase: retest only the clusters of the command's retest mask
                                    (the early phase found them behind last frame's pyramid) */
#define GDR_TASK_FIRST 4u        /* the first command of its instance (for read-backs) */
#define GDR_GPU_NO_GROUP 0xffffffffu
#define GDR_GPU_PAGE_ABSENT 0xffffffffu /* a page-table word: the group is not resident */

/* One instance of the persistent instance buffer. */
GDR_STRUCT_BEGIN(GdrGpuInstance)
    gdr_mat4 model;
    gdr_vec4 color;
    gdr_uint mesh;
    gdr_uint material;     /* index into GdrGpuScene.materials; the scene's default material when it has none */
    float min_screen_size; /* culled below this screen size (gdr_instance); 0: no minimum */
    float max_screen_size; /* culled at this screen size or more; 0: no maximum */
GDR_STRUCT_END(GdrGpuInstance)
GDR_ASSERT_SIZE(GdrGpuInstance, 96);
GDR_ASSERT_OFFSET(GdrGpuInstance, color, 64);
GDR_ASSERT_OFFSET(GdrGpuInstance, mesh, 80);
GDR_ASSERT_OFFSET(GdrGpuInstance, material, 84);

#define GDR_GPU_NO_TEXTURE 0xffffffffu
#define GDR_GPU_NO_COLORS 0xffffffffu /* a mesh without vertex colours: white */
/* A material's use of a texture: the bindless image (set GDR_TEXTURE_SET, binding 0) or
 * GDR_GPU_NO_TEXTURE, the sampler (binding 1, one per packed GDR_SAMPLER_* state) and the
 * texture-coordinate transform uv' = offset + mat2(matrix) * uv (KHR_texture_transform's rotation
 * and scale, column-major). */
GDR_STRUCT_BEGIN(GdrGpuTextureRef)
    gdr_uint texture;
    gdr_uint sampler_slot;
    gdr_vec2 offset;
    gdr_vec4 matrix;
GDR_STRUCT_END(GdrGpuTextureRef)
GDR_ASSERT_SIZE(GdrGpuTextureRef, 32);

/* GdrGpuMaterial.alpha_mode: gdr_alpha_mode's values. */
#define GDR_ALPHA_MODE_OPAQUE 0u
#define GDR_ALPHA_MODE_MASK 1u
#define GDR_ALPHA_MODE_BLEND 2u

/* GdrGpuMaterial.textures: which texture is where. */
#define GDR_MATERIAL_BASE_COLOR 0
#define GDR_MATERIAL_METALLIC_ROUGHNESS 1
#define GDR_MATERIAL_NORMAL 2
#define GDR_MATERIAL_OCCLUSION 3
#define GDR_MATERIAL_EMISSIVE 4
#define GDR_MATERIAL_TEXTURES 5

/* One glTF metallic-roughness material of the material buffer (gdr_material, gdr/scene.h).
 * Colours are linear. */
GDR_STRUCT_BEGIN(GdrGpuMaterial)
    gdr_vec4 base_color;          /* factor, multiplied with the texture, the vertex and the instance colour */
    gdr_vec3 emissive;            /* factor, emissive strength applied */
    float metallic;
    float roughness;
    float normal_scale;
    float occlusion_strength;
    float alpha_cutoff;
    gdr_uint alpha_mode;          /* gdr_alpha_mode: 0 opaque, 1 mask, 2 blend */
    gdr_uint double_sided;
    gdr_uint reserved0;
    gdr_uint reserved1;
    GdrGpuTextureRef textures[GDR_MATERIAL_TEXTURES];
GDR_STRUCT_END(GdrGpuMaterial)
GDR_ASSERT_SIZE(GdrGpuMaterial, 224);
GDR_ASSERT_OFFSET(GdrGpuMaterial, textures, 64);

/* A fixed-size "tag + data" record of the per-frame instance ring (seed 000). */
#define GDR_UPDATE_TAG_INSTANCE 1u /* replace instance `index` with `instance` */
GDR_STRUCT_BEGIN(GdrGpuInstanceUpdate)
    gdr_uint tag;
    gdr_uint index;
    gdr_uint reserved0;
    gdr_uint reserved1;
    GdrGpuInstance instance;
GDR_STRUCT_END(GdrGpuInstanceUpdate)
GDR_ASSERT_SIZE(GdrGpuInstanceUpdate, 112);
GDR_ASSERT_OFFSET(GdrGpuInstanceUpdate, instance, 16);

/* VkDrawIndexedIndirectCommand, written by the cull pass. first_instance carries the instance index. */
GDR_STRUCT_BEGIN(GdrGpuDrawCommand)
    gdr_uint index_count;
    gdr_uint instance_count;
    gdr_uint first_index;
    gdr_int vertex_offset;
    gdr_uint first_instance;
GDR_STRUCT_END(GdrGpuDrawCommand)
GDR_ASSERT_SIZE(GdrGpuDrawCommand, 20); /* VkDrawIndexedIndirectCommand: gpu_types_check.c */

/* Counters of a frame, zeroed before the cull. draw_count (offset 0) is the count for
 * vkCmdDrawIndexedIndirectCount; task_groups (offset 16) is the VkDrawMeshTasksIndirectCommandEXT
 * of the meshlet pipeline, written by the submit pass. */
GDR_STRUCT_BEGIN(GdrGpuDrawStats)
    gdr_uint draw_count;     /* visible instances (indirect draws appended) */
    gdr_uint triangles_low;  /* 64-bit count of triangles drawn as two words: the carry is added */
    gdr_uint triangles_high; /* by the thread whose add wrapped the low word                     */
    gdr_uint task_count;     /* task commands appended (meshlet pipeline) */
    gdr_uint task_groups_x;  /* VkDrawMeshTasksIndirectCommandEXT */
    gdr_uint task_groups_y;
    gdr_uint task_groups_z;
    gdr_uint task_overflow;  /* task commands that did not fit (never expected: sized from the scene) */
    gdr_uint meshlets_tested;
    gdr_uint meshlets_frustum_culled;
    gdr_uint meshlets_cone_culled;
    gdr_uint meshlets_visible;
    gdr_uint triangles_backface_culled;
    gdr_uint triangles_small_culled; /* covering no sample */
    gdr_uint meshlets_recorded;      /* entries appended to the visible-meshlet record */
    gdr_uint meshlets_lod_culled;    /* not in the LOD cut */
    gdr_uint lod_clusters[GDR_LOD_STATS_DEPTHS];  /* clusters drawn per DAG depth (last: that depth or more) */
    gdr_uint lod_triangles[GDR_LOD_STATS_DEPTHS]; /* their triangles, before triangle culling */
    /* Two-phase occlusion culling. The early phase tests against last frame's pyramid and defers
     * what it hides to the occluded lists; the late phase retests only those against this frame's
     * pyramid, appending its draws and task commands after the early phase's region of those buffers
     * and launching them with its own commands. */
    gdr_uint late_draw_count;
    gdr_uint late_task_count;
    gdr_uint late_task_groups_x; /* VkDrawMeshTasksIndirectCommandEXT of the late phase */
    gdr_uint late_task_groups_y;
    gdr_uint late_task_groups_z;
    gdr_uint instances_early_drawn;    /* in the frustum, not behind last frame's pyramid */
    gdr_uint instances_early_occluded; /* in the frustum, behind last frame's pyramid: deferred */
    gdr_uint instances_late_tested;    /* the deferred ones, tested against this frame's pyramid */
    gdr_uint instances_late_occluded;
    gdr_uint instances_late_drawn;
    gdr_uint meshlets_early_drawn;
    gdr_uint meshlets_late_tested;     /* deferred clusters retested, and clusters of late commands that
                                          passed the other tests */
    gdr_uint meshlets_late_occluded;
    gdr_uint meshlets_late_drawn;
    gdr_uint meshlets_early_occluded;  /* behind last frame's pyramid: deferred to the late phase */
    gdr_uint occluded_overflow;        /* hidden items that found no room in an occluded list: drawn (or
                                          traversed) in the early phase instead, never lost */
    /* The cluster cull's launches (visibility-buffer modes): one workgroup per
     * GDR_CLUSTER_CULL_TASKS task commands, early (or only) and late phase. */
    gdr_uint cull_groups_x;
    gdr_uint cull_groups_y;
    gdr_uint cull_groups_z;
    gdr_uint late_cull_groups_x;
    gdr_uint late_cull_groups_y;
    gdr_uint late_cull_groups_z;
    gdr_uint stream_requests;       /* requests appended (GdrGpuFrameBuffers.stream_requests; may exceed
                                       GDR_STREAM_REQUEST_CAPACITY: the rest were dropped) */
    gdr_uint groups_used;           /* streaming frames: distinct groups the cut drew (GdrGpuFrameBuffers.used_groups) */
    /* The LOD hierarchy traversal: per phase (early or only, then late) and level. Level 0 holds
     * the roots the instance cull queues; the visits of level L + 1 the children of level L's. */
    GdrGpuTraversalLevel traversal[2 * GDR_LOD_TREE_LEVELS];
    gdr_uint nodes_tested;          /* node visits, both phases */
    gdr_uint nodes_lod_culled;      /* no cluster below can be in the LOD cut */
    gdr_uint nodes_frustum_culled;
    gdr_uint nodes_occluded;        /* late phase: behind this frame's pyramid */
    gdr_uint late_nodes_tested;
    gdr_uint traversal_overflow;    /* visits that did not fit a level (GDR_TRAVERSE_MAX_VISITS or the
                                       scene's capacity): their subtrees were not drawn */
    gdr_uint instances_listed;      /* mesh pipeline: visible instances in the draw-command list (read-backs) */
    gdr_uint nodes_early_occluded;  /* early phase: behind last frame's pyramid, deferred to the late phase */
    /* The occluded lists the early phase fills and the late phase reads: the late instance cull's
     * count and launch (over GdrGpuFrameBuffers.occluded_instances); the nodes deferred per level
     * (stored level after level in GdrGpuFrameBuffers.occluded_nodes: level L's start at the sum of
     * the counts before it), and the running total that places them. */
    GdrGpuTraversalLevel late_instances;
    gdr_uint occluded_nodes[GDR_LOD_TREE_LEVELS];
    gdr_uint occluded_node_total;
    /* The instance tests, each instance counted by the first that culls it (invalid, frustum, screen
     * size, clip plane): bounds that are not finite or have no volume, a screen size outside the
     * instance's range or below the frame's minimum, entirely behind the frame's clip plane. */
    gdr_uint instances_invalid;
    gdr_uint instances_screen_size_culled;
    gdr_uint instances_clip_plane_culled;
    gdr_uint instances_pvs_culled;  /* valid, in the frustum, not listed by the camera's PVS cell */
    gdr_uint instances_points;      /* visible instances drawn as their point level (GDR_FRAME_POINTS) */
GDR_STRUCT_END(GdrGpuDrawStats)
GDR_ASSERT_SIZE(GdrGpuDrawStats, 64 + 8 * GDR_LOD_STATS_DEPTHS + 96 + 32 * GDR_LOD_TREE_LEVELS + 32 + 32 +
                                     4 * GDR_LOD_TREE_LEVELS + 8);
GDR_ASSERT_OFFSET(GdrGpuDrawStats, draw_count, 0);
GDR_ASSERT_OFFSET(GdrGpuDrawStats, task_groups_x, 16);

/* The scene's buffers: written once, when the scene is uploaded. */
GDR_STRUCT_BEGIN(GdrGpuScene)
    GDR_REF(InstancesRef) instances;          /* GdrGpuInstance[], persistent; the update ring changes it */
    GDR_REF(MeshesRef) meshes;                /* GdrGpuMesh[] */
    GDR_REF(VerticesRef) vertices;            /* GdrGpuVertex[], all meshes merged */
    GDR_REF(MeshletsRef) meshlets;            /* GdrGpuMeshlet[], all meshes' clusters */
    GDR_REF(UintsRef) meshlet_vertices;       /* global vertex index per cluster-local vertex */
    GDR_REF(UintsRef) meshlet_triangles;      /* the bytes of the cluster-local triangles */
    GDR_REF(LodNodesRef) lod_nodes;           /* GdrGpuLodNode[], every mesh's LOD hierarchy (GdrGpuMesh.lod_node_*) */
    GDR_REF(MaterialsRef) materials;          /* GdrGpuMaterial[], the scene's, then glTF's default material */
    GDR_REF(UintsRef) vertex_colors;          /* 2 words (RGBA16 unorm) per vertex of the meshes with colours */
    GDR_REF(UintsRef) mesh_color_offsets;     /* per mesh: first vertex colour (2 words each), or GDR_GPU_NO_COLORS */
    GDR_REF(UintsRef) page_table;             /* per group of every mesh: GDR_GPU_PAGE_ABSENT or resident (shared/residency.h) */
    GDR_REF(UintsRef) node_absent_refined;    /* per LOD node: clusters below whose refined group is absent */
    GDR_REF(WritableUintsRef) group_stamps;   /* per group of every mesh: the last streaming frame that drew it */
GDR_STRUCT_END(GdrGpuScene)
GDR_ASSERT_SIZE(GdrGpuScene, 104);

/* A frame slot's buffers: written once, when the slot is made (and when a buffer made on first use
 * appears). Shaders read it and GdrGpuScene in place (GDR_SCENE, GDR_FRAME), never as a local
 * copy: a local struct holding references is invalid SPIR-V from glslang. */
GDR_STRUCT_BEGIN(GdrGpuFrameBuffers)
    GDR_REF(DrawCommandsRef) draws;           /* GdrGpuDrawCommand[2 * instances]: early (or only), late */
    GDR_REF(DrawStatsRef) draw_stats;         /* GdrGpuDrawStats */
    GDR_REF(InstanceUpdatesRef) updates;      /* this frame's segment of the instance update ring */
    GDR_REF(TaskCommandsRef) tasks;           /* GdrGpuTaskCommand[2 * task_capacity]: early (or only), late */
    GDR_REF(OverdrawRef) overdraw;            /* uint per pixel, then the maximum (overdraw view) */
    GDR_REF(VisibleMeshletsRef) visible_meshlets; /* (instance, global cluster) pairs when recording */
    GDR_REF(RasterParamsRef) raster;          /* GdrGpuRasterParams of the slot */
    GDR_REF(NodeVisitsRef) traversal;         /* GdrGpuNodeVisit[2 * traversal_capacity]: even, odd levels */
    /* Two-phase occlusion culling: what the early phase found behind last frame's pyramid. */
    GDR_REF(WritableUintsRef) occluded_instances;     /* instance indices [instance_count] */
    GDR_REF(NodeVisitsRef) occluded_nodes;    /* node visits [occluded_node_capacity], level after level */
    GDR_REF(WritableUintsRef) retest_masks;           /* per late task command with GDR_TASK_RETEST: its clusters to
                                                 retest (bit i: cluster meshlet_first + i) [task_capacity] */
    GDR_REF(StreamRequestsRef) stream_requests; /* GdrGpuStreamRequest[GDR_STREAM_REQUEST_CAPACITY], read by the host */
    GDR_REF(WritableUintsRef) used_groups;    /* streaming frames: page-table index of each group the cut drew,
                                                 once (room for every group), read by the host */
    /* GDR_FRAME_PVS: the instances the culling camera's precomputed-visibility cell lists (bit i of
     * word i / 32: instance i may be seen), host-written per frame */
    GDR_REF(UintsRef) pvs_visible;
GDR_STRUCT_END(GdrGpuFrameBuffers)
GDR_ASSERT_SIZE(GdrGpuFrameBuffers, 112);

/* Per-frame constants, written by the CPU into its frame's slot. */
GDR_STRUCT_BEGIN(GdrGpuFrameGlobals)
    gdr_mat4 view;
    gdr_mat4 view_projection;
    gdr_vec4 frustum;         /* symmetric (i, j, k, l) */
    gdr_vec4 camera_position; /* world space, w unused */
    gdr_vec4 light_direction; /* world space, towards the light */
    float znear;
    float zfar;               /* +inf for the infinite projection */
    gdr_uint instance_count;
    gdr_uint cull_enabled;
    gdr_uint update_count;    /* records in this frame's ring slot */
    gdr_uint flags;           /* GDR_FRAME_* */
    gdr_uint view_mode;       /* GDR_VIEW_* */
    gdr_uint task_capacity;   /* GdrGpuTaskCommand entries in the task buffer */
    gdr_vec2 viewport;        /* render target size in pixels */
    float lod_threshold;      /* pixels (GDR_FRAME_LOD) */
    float lod_projection_scale; /* P[1][1] * 0.5 * viewport height */
    gdr_int lod_depth;        /* GDR_FRAME_LOD_DEPTH: the discrete cut's depth */
    gdr_uint traversal_capacity; /* node visits one traversal level holds (<= GDR_TRAVERSE_MAX_VISITS) */
    gdr_uint occluded_node_capacity; /* node visits the occluded list holds */
    float min_screen_size;    /* the frame's smallest screen size drawn; 0: none */
    GdrOcclusionParams occlusion; /* GDR_FRAME_OCCLUSION: the camera and the depth pyramid */
    /* GDR_FRAME_HISTORY: last frame's camera, against whose pyramid the early phase tests. */
    gdr_mat4 previous_view;
    GdrOcclusionParams previous_occlusion;
    /* The instance tests: instances entirely on the negative side of the plane (world space,
     * n.p + d < 0) are culled; all zero: no plane. Screen size = screen_scale * radius / distance
     * of the bounding sphere (the camera inside it: infinite), about its projected diameter over the
     * viewport height, as gdr/cull.h defines it; screen_scale = max(|P00|, |P11|). */
    gdr_vec4 clip_plane;
    float screen_scale;
    gdr_uint stream_frame;    /* streaming with groups absent: this frame's number (never 0), stamped on
                                 the groups its cut draws; 0: no group-use list */
    gdr_vec2 frustum_offset;  /* the side planes' offsets (gdr_sphere_visible_offset): (xmag, ymag) for an
                                 orthographic camera, (0, 0) for a perspective one */
    gdr_vec4 eye_position;    /* world space: the rendering camera's (camera_position is the culling camera's) */
    /* The LOD tests' distance floor: znear for a perspective camera. An orthographic camera's
     * projected error is not divided by distance: camera_position and eye_position are then placed
     * GDR_ORTHO_VIEWER_DISTANCE behind the camera along its axis (the direction to the viewer, for
     * the cone test and shading, is the same everywhere), this floor is beyond every distance from
     * there and lod_projection_scale is multiplied by it, so error / floor * scale is the error
     * times P[1][1] * 0.5 * viewport height. */
    float lod_znear;
    gdr_uint orthographic;    /* 1: an orthographic camera */
    gdr_uint records_per_slot; /* GDR_FRAME_PAGED_RECORDS: a pool slot's room in the record pool (the
                                  records of the page in slot s start at s x records_per_slot) */
    gdr_uint reserved7;
GDR_STRUCT_END(GdrGpuFrameGlobals)
GDR_ASSERT_SIZE(GdrGpuFrameGlobals, 432);
/* An orthographic camera's viewer distance and LOD distance floor (lod_znear above): beyond a scene
 * within GDR_MAX_COORDINATE (1e12) of the origin, and squared within a float's range. */
#define GDR_ORTHO_VIEWER_DISTANCE 1.0e15f
#define GDR_ORTHO_LOD_DISTANCE 4.0e15f
GDR_ASSERT_OFFSET(GdrGpuFrameGlobals, frustum, 128);
GDR_ASSERT_OFFSET(GdrGpuFrameGlobals, znear, 176);
GDR_ASSERT_OFFSET(GdrGpuFrameGlobals, update_count, 192);
GDR_ASSERT_OFFSET(GdrGpuFrameGlobals, viewport, 208);

#define GDR_FRAME_MESHLET_FRUSTUM 1u  /* task shader: cluster sphere vs frustum */
#define GDR_FRAME_MESHLET_CONE 2u     /* task shader: cluster normal cone vs camera */
#define GDR_FRAME_TRIANGLE_CULL 4u    /* mesh shader: back-facing triangles and triangles covering no sample */
#define GDR_FRAME_RECORD_MESHLETS 8u  /* task shader: append (instance, cluster) of every visible cluster */
#define GDR_FRAME_LOD 16u             /* task shader: the LOD cut over every cluster of the DAG */
#define GDR_FRAME_LOD_DEPTH 32u       /* with GDR_FRAME_LOD: the discrete cut at depth lod_depth */
#define GDR_FRAME_OCCLUSION 64u       /* two-phase occlusion culling against the depth pyramid */
#define GDR_FRAME_HISTORY 128u        /* with GDR_FRAME_OCCLUSION: last frame's pyramid and camera are usable */
#define GDR_FRAME_DEBUG_SHRINK_NODES 512u /* tests: a deliberately wrong node test (spheres a quarter of their size) */
#define GDR_FRAME_LOD_HIERARCHY 256u  /* with GDR_FRAME_LOD: instances' clusters come from the traversal of
                                         their LOD hierarchy (lodtraverse.comp) instead of all their clusters */
#define GDR_FRAME_ALPHA_TEST 4096u     /* some material is MASK or BLEND: raster paths test alpha (shared/material.h) */
#define GDR_FRAME_DOUBLE_SIDED 8192u   /* some material is double-sided: back faces are culled per material */
#define GDR_FRAME_VERTEX_COLORS 16384u /* some mesh has vertex colours (GdrGpuScene.vertex_colors) */
#define GDR_FRAME_PARTIAL_RESIDENCY 2048u /* some LOD group is absent: read the page table (shared/residency.h) */
#define GDR_FRAME_PVS 32768u          /* the instance cull drops instances GdrGpuFrameBuffers.pvs_visible does not list */
#define GDR_FRAME_POINTS 65536u       /* visibility-buffer modes, LOD by error: instances within a pixel are
                                         drawn as their point level by the instance cull (shared/point_level.h) */
#define GDR_FRAME_PAGED_RECORDS 131072u /* streamed: the cluster records live in a pool of their pages' slots
                                          (records_per_slot each), so clusters are reached only through the
                                          hierarchy's leaves of resident groups, a leaf's at its group's slot
                                          (never a flat range over a mesh's clusters) */
#define GDR_FRAME_DIRECT_CLUSTERS 1024u /* visibility-buffer modes: the instance cull tests the clusters of an
                                           instance that needs at most GDR_DIRECT_CLUSTERS of them and bins
                                           them itself, instead of a task command for the cluster cull */


#define GDR_VIEW_SHADED 0u
#define GDR_VIEW_MESHLETS 1u  /* colour from a hash of the cluster's global index */
#define GDR_VIEW_INSTANCES 2u /* colour from a hash of the instance index */
#define GDR_VIEW_TRIANGLES 3u /* colour from a hash of the triangle: triangle density */
#define GDR_VIEW_OVERDRAW 4u  /* fragments per pixel, as a heat map */
#define GDR_VIEW_LOD 5u       /* colour from the cluster's DAG depth */

/* Push constants of every frame pass: the frame's globals and buffers, the scene, and the
 * visibility buffer, which every rasterised pixel writes (reading its address from memory per
 * fragment cost 9% of the mesh-shader raster on the H100). */
GDR_STRUCT_BEGIN(GdrGpuPushConstants)
    GDR_REF(FrameGlobalsRef) globals; /* GdrGpuFrameGlobals of the frame's slot */
    GDR_REF(FrameBuffersRef) frame;   /* GdrGpuFrameBuffers of the frame's slot */
    GDR_REF(SceneRef) scene;          /* GdrGpuScene */
    GDR_REF(VisbufferRef) visbuffer;  /* uint64 per pixel: the visibility buffer */
    gdr_uint step;                    /* a repeated pass's step (the traversal's level) */
    gdr_uint reserved0;
GDR_STRUCT_END(GdrGpuPushConstants)
GDR_ASSERT_SIZE(GdrGpuPushConstants, 40);

/* --- Hybrid rasterisation: the visibility buffer and the software rasteriser --------------------
 *
 * A visibility-buffer pixel is 64 bits: the high word the depth as float bits (reverse-Z, so
 * atomicMax keeps the nearest; 0 is empty), the low word (slot << GDR_VISBUFFER_TRIANGLE_BITS) |
 * triangle, where slot indexes the frame's list of visible clusters (GdrGpuRasterCluster). The
 * cluster cull (clustercull.comp) appends software-rasterised clusters from the front of that list
 * and mesh-shader clusters from the back; tiny software-rasterised clusters go to the part of their
 * size class (GDR_SW_TINY_*), after those `capacity` entries, which the compute rasteriser draws
 * several to a workgroup (a tiny cluster that finds its part full joins the front). Either way the
 * slot is the entry's index in the whole list. */
#define GDR_GPU_RASTER_FORWARD 0u /* the mesh shaders shade; no visibility buffer */
#define GDR_GPU_RASTER_HW 1u      /* every cluster through the mesh shaders into the visibility buffer */
#define GDR_GPU_RASTER_SW 2u      /* every cluster the compute rasteriser can take (see raster_bin.h) */
#define GDR_GPU_RASTER_HYBRID 3u  /* clusters whose triangles are small on screen to compute, the rest to mesh */

/* One entry of the frame's visible-cluster list. */
GDR_STRUCT_BEGIN(GdrGpuRasterCluster)
    gdr_uint instance;
    gdr_uint meshlet; /* global GdrGpuMeshlet index */
GDR_STRUCT_END(GdrGpuRasterCluster)
GDR_ASSERT_SIZE(GdrGpuRasterCluster, 8);

/* Counters of a frame, zeroed before the cull. The first three words are the
 * VkDispatchIndirectCommand of the software rasteriser, draw_x..z the VkDrawMeshTasksIndirectCommandEXT
 * of the mesh-shader clusters, both written by raster_submit.comp once per raster phase. */
GDR_STRUCT_BEGIN(GdrGpuRasterCounters)
    gdr_uint dispatch_x;
    gdr_uint dispatch_y;
    gdr_uint dispatch_z;
    gdr_uint used;         /* list entries reserved (both ends) */
    gdr_uint sw_clusters;  /* entries at the front: software-rasterised clusters */
    gdr_uint hw_clusters;  /* entries at the back: mesh-shader clusters */
    gdr_uint sw_triangles; /* triangles of those clusters (before back-face culling) */
    gdr_uint hw_triangles;
    gdr_uint overflow;     /* visible clusters dropped for want of room (never expected, see visbuffer.c) */
    gdr_uint sw_first;     /* first entry of the current software dispatch (raster_submit.comp) */
    gdr_uint sw_dispatched; /* entries launched by earlier dispatches of the frame (one per raster phase) */
    gdr_uint hw_first;      /* first entry of the current mesh-shader launch (the back grows down) */
    gdr_uint hw_count;      /* entries in it */
    gdr_uint hw_dispatched; /* back entries launched by earlier launches of the frame */
    gdr_uint draw_x;        /* VkDrawMeshTasksIndirectCommandEXT: one mesh workgroup per entry, in rows */
    gdr_uint draw_y;
    gdr_uint draw_z;
    gdr_uint phases;        /* raster phases launched so far in the frame */
    gdr_uint resolve_x;     /* VkDispatchIndirectCommand of the phase's resolve: GDR_RESOLVE_TILE tiles of */
    gdr_uint resolve_y;     /* the screen in the first phase and in a later phase that drew something, */
    gdr_uint resolve_z;     /* else none */
    /* Per tiny size class (the triangles of its clusters count in sw_triangles): */
    gdr_uint tiny_clusters[GDR_SW_TINY_CLASSES];   /* entries asked of the class's part: those beyond its
                                                      tiny_capacity went to the front instead */
    gdr_uint tiny_first[GDR_SW_TINY_CLASSES];      /* first entry of the current dispatch (in the part) */
    gdr_uint tiny_dispatched[GDR_SW_TINY_CLASSES]; /* entries launched by earlier dispatches of the frame */
    gdr_uint tiny_launch[3 * GDR_SW_TINY_CLASSES]; /* a VkDispatchIndirectCommand per class */
    gdr_uint reserved0;
GDR_STRUCT_END(GdrGpuRasterCounters)
GDR_ASSERT_SIZE(GdrGpuRasterCounters, 160);
GDR_ASSERT_OFFSET(GdrGpuRasterCounters, tiny_launch, 120);
GDR_ASSERT_OFFSET(GdrGpuRasterCounters, resolve_x, 72);
GDR_ASSERT_OFFSET(GdrGpuRasterCounters, dispatch_z, 8);

/* Per-frame raster parameters, written by the CPU into its frame's slot. */
GDR_STRUCT_BEGIN(GdrGpuRasterParams)
    GDR_REF(RasterClustersRef) clusters; /* GdrGpuRasterCluster[capacity + the tiny_capacity] */
    GDR_REF(RasterCountersRef) counters; /* GdrGpuRasterCounters */
    gdr_uint mode;          /* GDR_GPU_RASTER_* */
    gdr_uint capacity;      /* entries of the cluster list, <= GDR_RASTER_MAX_CLUSTERS */
    float sw_threshold_px;  /* hybrid: clusters whose triangles are smaller go to the compute rasteriser */
    gdr_uint hw_launch_limit; /* the most mesh workgroups one launch may have (maxMeshWorkGroupTotalCount) */
    gdr_vec2 ndc_scale;     /* the projection's P[0][0] and P[1][1] (x and y from view space to NDC) */
    gdr_uint tiny_capacity[GDR_SW_TINY_CLASSES]; /* entries of each tiny class's part (0: none) */
    gdr_uint tiny_base[GDR_SW_TINY_CLASSES];     /* its first slot: capacity + the parts before it */
GDR_STRUCT_END(GdrGpuRasterParams)
GDR_ASSERT_SIZE(GdrGpuRasterParams, 64);
GDR_ASSERT_OFFSET(GdrGpuRasterParams, mode, 16);
GDR_ASSERT_OFFSET(GdrGpuRasterParams, ndc_scale, 32);

#endif
