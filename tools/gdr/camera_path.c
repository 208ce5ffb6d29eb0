#include "camera_path.h"

#include "gdr/io.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CAMERA_PATH_HEADER "gdr-camera-path 1"
#define CAMERA_PATH_MAX_LINE 1024
/* Room for CAMERA_PATH_MAX_POSES poses of about 100 characters, and comments. */
#define CAMERA_PATH_MAX_BYTES ((size_t)256 << 20)

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

/* One pose line: exactly 7 numbers, each finite as a 32-bit float (a value too small for one, such
 * as 1e-45, rounds to the nearest float, 0 or a denormal), the quaternion not zero. On failure,
 * `why` says what is wrong. */
static bool parse_pose(const char *line, gdr_vec3 *position, gdr_quat *rotation, char *why, size_t why_size)
{
    float v[7];
    const char *cursor = line;
    for (int i = 0; i < 7; i++) {
        while (*cursor == ' ' || *cursor == '\t')
            cursor++;
        char *end;
        double d = strtod(cursor, &end);
        if (end == cursor) {
            int n = (int)strcspn(cursor, " \t\r\n");
            if (n == 0)
                snprintf(why, why_size, "expected 7 numbers 'px py pz qx qy qz qw', found %d", i);
            else
                snprintf(why, why_size, "number %d: '%.*s' is not a number", i + 1, n > 32 ? 32 : n, cursor);
            return false;
        }
        if (!isfinite(d) || fabs(d) > FLT_MAX) {
            snprintf(why, why_size, "number %d: '%.*s' is not finite as a 32-bit float (at most %g in magnitude)",
                     i + 1, (int)(end - cursor) > 32 ? 32 : (int)(end - cursor), cursor, (double)FLT_MAX);
            return false;
        }
        v[i] = (float)d;
        cursor = end;
    }
    while (*cursor == ' ' || *cursor == '\t' || *cursor == '\r' || *cursor == '\n')
        cursor++;
    if (*cursor) {
        int n = (int)strcspn(cursor, "\r\n");
        snprintf(why, why_size, "text after the 7 numbers: '%.*s'", n > 32 ? 32 : n, cursor);
        return false;
    }
    float length = sqrtf(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
    if (!(length > 1e-6f)) {
        snprintf(why, why_size, "the quaternion (qx qy qz qw) is zero");
        return false;
    }
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

/* One line of the file (without its newline, NUL-terminated in `line`). */
static gdr_status read_line(const char *line, const char *file, uint32_t number, bool *header, camera_path *out,
                            gdr_error *err)
{
    if (blank_or_comment(line))
        return GDR_OK;
    if (!*header) {
        if (strncmp(line, CAMERA_PATH_HEADER, strlen(CAMERA_PATH_HEADER)) != 0 ||
            !blank_or_comment(line + strlen(CAMERA_PATH_HEADER)))
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s:%u: expected the header '%s'", file, number,
                                 CAMERA_PATH_HEADER);
        *header = true;
        return GDR_OK;
    }
    gdr_vec3 position;
    gdr_quat rotation;
    char why[160];
    if (!parse_pose(line, &position, &rotation, why, sizeof why))
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s:%u: %s", file, number, why);
    return camera_path_append(out, position, rotation, err);
}

static gdr_status read_lines(const char *text, size_t size, const char *file, camera_path *out, gdr_error *err)
{
    char line[CAMERA_PATH_MAX_LINE];
    bool header = false;
    uint32_t number = 1;
    for (size_t at = 0; at < size; number++) {
        const char *newline = memchr(text + at, '\n', size - at);
        size_t length = (newline ? (size_t)(newline - text) : size) - at;
        const char *nul = memchr(text + at, '\0', length);
        if (nul)
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s:%u: a NUL byte at column %zu (not a text file)", file,
                                 number, (size_t)(nul - (text + at)) + 1);
        if (length > CAMERA_PATH_MAX_LINE - 2)
            return gdr_error_set(err, GDR_ERROR_PARSE, "%s:%u: line longer than %d characters", file, number,
                                 CAMERA_PATH_MAX_LINE - 2);
        memcpy(line, text + at, length);
        line[length] = 0;
        gdr_status status = read_line(line, file, number, &header, out, err);
        if (status != GDR_OK)
            return status;
        at += length + 1;
    }
    if (out->count == 0)
        return gdr_error_set(err, GDR_ERROR_PARSE, "%s: %s", file, header ? "no poses" : "empty (no header)");
    return GDR_OK;
}

gdr_status camera_path_read(const char *file, camera_path *out, gdr_error *err)
{
    *out = (camera_path){0};
    char *text;
    size_t size;
    /* A FIFO or device is refused at once, never waited on. */
    gdr_status status = gdr_read_file(file, CAMERA_PATH_MAX_BYTES, &text, &size, err);
    if (status != GDR_OK)
        return status;
    status = read_lines(text, size, file, out, err);
    free(text);
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
