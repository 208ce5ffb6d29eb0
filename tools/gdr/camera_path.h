/* Camera paths: one camera pose per frame, in a text file (docs/VIEWER.md, "Camera paths"):
 *
 *   gdr-camera-path 1
 *   # px py pz qx qy qz qw
 *   0 1.6 12 0 0 0 1
 *   ...
 *
 * Written by gdr view --record-path, replayed by gdr render / gdr bench --camera-path. */
#ifndef GDR_CAMERA_PATH_H
#define GDR_CAMERA_PATH_H

#include <stdbool.h>
#include <stdint.h>

#include "gdr/gdr.h"

#define CAMERA_PATH_MAX_POSES 1000000u

typedef struct camera_pose {
    gdr_vec3 position;
    gdr_quat rotation;
} camera_pose;

typedef struct camera_path {
    camera_pose *poses;
    uint32_t count, capacity;
} camera_path;

/* Reads a path file (untrusted: every line checked, errors name the file and line). */
gdr_status camera_path_read(const char *file, camera_path *out, gdr_error *err);
/* Appends a pose; fails beyond CAMERA_PATH_MAX_POSES or without memory. */
gdr_status camera_path_append(camera_path *path, gdr_vec3 position, gdr_quat rotation, gdr_error *err);
/* Writes the path through a temporary file and a rename. */
gdr_status camera_path_write(const char *file, const camera_path *path, gdr_error *err);
void camera_path_free(camera_path *path);

#endif
