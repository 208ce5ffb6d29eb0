/* gdr view: the interactive window's state, its camera and its keys. */
#ifndef GDR_VIEW_H
#define GDR_VIEW_H

#include <stdbool.h>
#include <stdint.h>

#include "gdr/gdr.h"

/* A fly camera: position and rotation, yaw about world +Y and pitch about the camera's X. */
typedef struct fly_camera {
    gdr_vec3 position;
    gdr_quat rotation;
    float speed; /* metres per second */
} fly_camera;

/* Movement keys held (each -1, 0 or +1) and mouse motion since the last frame, in pixels. */
typedef struct fly_input {
    int forward, right, up;
    bool fast;
    double look_dx, look_dy;
} fly_input;

void fly_camera_update(fly_camera *camera, const fly_input *input, double seconds);
/* The wheel: each notch multiplies the speed by 1.25 (up) or divides it. */
void fly_camera_scroll(fly_camera *camera, double notches);

/* What the keys change. */
typedef struct view_settings {
    gdr_frame_desc frame;     /* pipeline, raster, view, culling, occlusion, LOD threshold */
    bool freeze_culling;      /* culling keeps cull_camera while the view camera moves */
    gdr_camera cull_camera;
    bool overlay;
    bool vsync;
    bool help;                /* the key list on screen */
    bool screenshot;          /* one wanted this frame */
    bool quit;
    bool has_mesh_pipeline;
    bool streamed;            /* the scene streams: the mesh pipeline and a LOD threshold above 0 only */
    bool jump;                /* J pressed: the camera jumps (view_jump) */
    gdr_vec3 home_position, away_position; /* J jumps between the start and where it was pressed */
    gdr_quat home_rotation, away_rotation;
    bool away;                /* the camera is at home after a jump; J goes back */
    char message[160];        /* the last key's effect, shown in the overlay */
} view_settings;

/* A key pressed (GLFW key code and modifier bits): changes the settings, never the camera. */
void view_key(view_settings *settings, const gdr_camera *camera, int key, int mods);
/* J: the camera jumps to where the view started, or back to where it was when J was pressed. */
void view_jump(view_settings *settings, gdr_vec3 *position, gdr_quat *rotation);
/* The on-screen key list, also printed by gdr view --help. */
extern const char view_key_help[];

#endif
