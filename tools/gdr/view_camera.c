#include <math.h>

#include "view.h"

#define LOOK_RADIANS_PER_PIXEL 0.003f
#define PITCH_LIMIT 1.55f

void fly_camera_update(fly_camera *c, const fly_input *in, double seconds)
{
    if (in->look_dx != 0.0 || in->look_dy != 0.0) {
        /* Yaw about the world's up axis (so the horizon stays level), pitch about the camera's
         * own X axis, refused beyond straight up or down. */
        gdr_quat yaw = gdr_quat_from_axis_angle((gdr_vec3){0, 1, 0}, -(float)in->look_dx * LOOK_RADIANS_PER_PIXEL);
        gdr_quat pitch = gdr_quat_from_axis_angle((gdr_vec3){1, 0, 0}, -(float)in->look_dy * LOOK_RADIANS_PER_PIXEL);
        gdr_quat turned = gdr_quat_normalize(gdr_quat_mul(yaw, c->rotation));
        gdr_quat pitched = gdr_quat_normalize(gdr_quat_mul(turned, pitch));
        gdr_vec3 forward = gdr_quat_rotate(pitched, (gdr_vec3){0, 0, -1});
        c->rotation = fabsf(forward.y) < sinf(PITCH_LIMIT) ? pitched : turned;
    }
    float step = c->speed * (float)seconds * (in->fast ? 4.0f : 1.0f);
    gdr_vec3 forward = gdr_quat_rotate(c->rotation, (gdr_vec3){0, 0, -1});
    gdr_vec3 right = gdr_quat_rotate(c->rotation, (gdr_vec3){1, 0, 0});
    gdr_vec3 move = gdr_vec3_add(gdr_vec3_scale(forward, (float)in->forward),
                                 gdr_vec3_add(gdr_vec3_scale(right, (float)in->right),
                                              gdr_vec3_scale((gdr_vec3){0, 1, 0}, (float)in->up)));
    c->position = gdr_vec3_add(c->position, gdr_vec3_scale(move, step));
}

void fly_camera_scroll(fly_camera *c, double notches)
{
    c->speed *= powf(1.25f, (float)notches);
    c->speed = c->speed < 0.01f ? 0.01f : c->speed > 10000.0f ? 10000.0f : c->speed;
}
