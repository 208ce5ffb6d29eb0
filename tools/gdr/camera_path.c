#include "camera_path.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CAMERA_PATH_HEADER "gdr-camera-path 1"
#define CAMERA_PATH_MAX_LINE 1024

gdr_status camera_path_append(camera_path *path, gdr_vec3 position, gdr_quat rotation, gdr_error *err)
{
    if (path->count >= CAMERA_PATH_MAX_POSES)
        return gdr_error_set(err, GDR_ERROR_CAPACITY, "camera path: more than %u poses", CAMERA_PATH_MAX_POSES);
    if (path->count == path->capacity) {
        uint32_t capacity = path->capacity ? path->capacity * 2 : 256;
        camera_pose *grown = realloc(path->poses, sizeof *grown * capacity);
        if (!grown)
            return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "camera path: out of memory");
        path->poses = grown;
        path->capacity = capacity;
    }
    path->poses[path->count++] = (camera_pose){position, rotation};
    return GDR_OK;
}

/* One pose line: exactly 7 finite numbers, the quaternion not zero. */
static bool parse_pose(const char *line, gdr_vec3 *position, gdr_quat *rotation)
{
    float v[7];
    const char *cursor = line;
    for (int i = 0; i < 7; i++) {
        char *end;
        errno = 0;
        v[i] = strtof(cursor, &end);
        if (end == cursor || errno || !isfinite(v[i]))
            return false;
        cursor = end;
    }
    while (*cursor == ' ' || *cursor == '\t' || *cursor == '\r' || *cursor == '\n')
        cursor++;
    float length = sqrtf(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
    if (*cursor || !(length > 1e-6f))
        return false;
    *position = (gdr_vec3){v[0], v[1], v[2]};
    /* A unit quaternion is kept as written, so that a recorded path replays the recorded frames bit
     * for bit (normalising again can change the last bit). */
    gdr_quat q = {v[3], v[4], v[5], v[6]};
    *rotation = fabsf(length - 1.0f) < 1e-5f ? q : gdr_quat_normalize(q);
    return true;
}

static bool blank_or_comment(const char *line)
{
    while (*line == ' ' || *line == '\t' || *line == '\r')
        line++;
    return *line == '#' || *line == '\n' || *line == '\0';
}

static gdr_status read_lines(FILE *f, const char *file, camera_path *out, gdr_error *err)
{
    char line[CAMERA_PATH_MAX_LINE];
    bool header = false;
    for (uint32_t number = 1; fgets(line, sizeof line, f); number++) {
        if (!strchr(line, '\n') && !feof(f))
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s:%u: line longer than %d characters", file, number,
                                 CAMERA_PATH_MAX_LINE - 2);
        if (blank_or_comment(line))
            continue;
        if (!header) {
            if (strncmp(line, CAMERA_PATH_HEADER, strlen(CAMERA_PATH_HEADER)) != 0 ||
                !blank_or_comment(line + strlen(CAMERA_PATH_HEADER)))
                return gdr_error_set(err, GDR_ERROR_PARSE, "%s:%u: expected the header '%s'", file, number,
                                     CAMERA_PATH_HEADER);
            header = true;
            continue;
        }
        gdr_vec3 position;
        gdr_quat rotation;
        if (!parse_pose(line, &position, &rotation))
            return gdr_error_set(err, GDR_ERROR_PARSE,
                                 "%s:%u: expected 7 finite numbers 'px py pz qx qy qz qw' (quaternion not zero)", file,
                                 number);
        gdr_status status = camera_path_append(out, position, rotation, err);
        if (status != GDR_OK)
            return status;
    }
    if (ferror(f))
        return gdr_error_set(err, GDR_ERROR_IO, "%s: read error", file);
    if (out->count == 0)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: %s", file, header ? "no poses" : "empty (no header)");
    return GDR_OK;
}

gdr_status camera_path_read(const char *file, camera_path *out, gdr_error *err)
{
    *out = (camera_path){0};
    FILE *f = fopen(file, "r");
    if (!f)
        return gdr_error_set(err, GDR_ERROR_IO, "%s: %s", file, strerror(errno));
    gdr_status status = read_lines(f, file, out, err);
    fclose(f);
    if (status != GDR_OK)
        camera_path_free(out);
    return status;
}

gdr_status camera_path_write(const char *file, const camera_path *path, gdr_error *err)
{
    /* About 100 characters per pose at most ("%.9g" x 7). */
    size_t capacity = 128 + (size_t)path->count * 128;
    char *text = malloc(capacity);
    if (!text)
        return gdr_error_set(err, GDR_ERROR_OUT_OF_MEMORY, "camera path: out of memory");
    size_t used = (size_t)snprintf(text, capacity, "%s\n# px py pz qx qy qz qw (one frame per line)\n",
                                   CAMERA_PATH_HEADER);
    for (uint32_t i = 0; i < path->count; i++) {
        const camera_pose *p = &path->poses[i];
        used += (size_t)snprintf(text + used, capacity - used, "%.9g %.9g %.9g %.9g %.9g %.9g %.9g\n",
                                 (double)p->position.x, (double)p->position.y, (double)p->position.z,
                                 (double)p->rotation.x, (double)p->rotation.y, (double)p->rotation.z,
                                 (double)p->rotation.w);
    }
    gdr_status status = gdr_write_file_atomic(file, text, used, err);
    free(text);
    return status;
}

void camera_path_free(camera_path *path)
{
    free(path->poses);
    *path = (camera_path){0};
}
