/* gdr view's keys: each changes one setting of the frame and says so in the overlay. */
#include <stdio.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "view.h"

const char view_key_help[] =
    "    W A S D        move            Q E     down / up\n"
    "    right button   look            wheel   speed (shift: x4)\n"
    "    V  view mode   P  pipeline     R  raster mode\n"
    "    O  occlusion   C  culling      F  freeze culling\n"
    "    ]  LOD threshold x2            [  LOD threshold /2\n"
    "    J  jump to the start and back\n"
    "    F12  screenshot  Y  vsync  TAB  overlay  H  keys  ESC  quit\n";

static void next_view(view_settings *s)
{
    s->frame.view = (gdr_view)(((int)s->frame.view + 1) % (GDR_VIEW_MODE_LOD + 1));
    snprintf(s->message, sizeof s->message, "view %s", gdr_view_name(s->frame.view));
}

/* mesh (where the device has it) -> indirect -> cpu (where the library has the culling module) -> ...;
 * raster modes are the mesh pipeline's. */
static void next_pipeline(view_settings *s)
{
    gdr_pipeline p = s->frame.pipeline;
    if (s->streamed) {
        snprintf(s->message, sizeof s->message, "a streamed scene draws with the mesh pipeline only");
        return;
    }
    if (p == GDR_PIPELINE_DEFAULT)
        p = s->has_mesh_pipeline ? GDR_PIPELINE_MESH : GDR_PIPELINE_INDIRECT;
    p = p == GDR_PIPELINE_MESH ? GDR_PIPELINE_INDIRECT
        : p == GDR_PIPELINE_INDIRECT && GDR_HAVE_CULL ? GDR_PIPELINE_CPU
        : s->has_mesh_pipeline ? GDR_PIPELINE_MESH : GDR_PIPELINE_INDIRECT;
    s->frame.pipeline = p;
    if (p != GDR_PIPELINE_MESH)
        s->frame.raster = GDR_RASTER_DEFAULT;
    snprintf(s->message, sizeof s->message, "pipeline %s", gdr_pipeline_name(p));
}

static void next_raster(view_settings *s)
{
    bool mesh = s->frame.pipeline == GDR_PIPELINE_MESH ||
                (s->frame.pipeline == GDR_PIPELINE_DEFAULT && s->has_mesh_pipeline);
    if (!mesh) {
        snprintf(s->message, sizeof s->message, "raster modes are the mesh pipeline's");
        return;
    }
    s->frame.raster = s->frame.raster == GDR_RASTER_FORWARD ? GDR_RASTER_HYBRID : (gdr_raster)(s->frame.raster + 1);
    snprintf(s->message, sizeof s->message, "raster %s", gdr_raster_name(s->frame.raster));
}

static void next_occlusion(view_settings *s)
{
    s->frame.occlusion = s->frame.occlusion == GDR_CULL_DEFAULT ? GDR_CULL_ON
                         : s->frame.occlusion == GDR_CULL_ON    ? GDR_CULL_OFF
                                                                : GDR_CULL_DEFAULT;
    static const char *const names[] = {"default", "on", "off"};
    snprintf(s->message, sizeof s->message, "occlusion culling %s", names[s->frame.occlusion]);
}

static void scale_lod(view_settings *s, bool up)
{
    float e = s->frame.lod_error_px;
    e = up ? (e < 0.25f ? 0.25f : e * 2.0f) : (e <= 0.25f ? (s->streamed ? 0.25f : 0.0f) : e * 0.5f);
    s->frame.lod_error_px = e > 4096.0f ? 4096.0f : e;
    s->frame.lod_fixed_depth = false;
    snprintf(s->message, sizeof s->message, "LOD threshold %g px", (double)s->frame.lod_error_px);
}

void view_key(view_settings *s, const gdr_camera *camera, int key, int mods)
{
    (void)mods;
    switch (key) {
    case GLFW_KEY_ESCAPE: s->quit = true; break;
    case GLFW_KEY_V: next_view(s); break;
    case GLFW_KEY_P: next_pipeline(s); break;
    case GLFW_KEY_R: next_raster(s); break;
    case GLFW_KEY_O: next_occlusion(s); break;
    case GLFW_KEY_C:
        s->frame.cull = s->frame.cull == GDR_CULL_OFF ? GDR_CULL_ON : GDR_CULL_OFF;
        snprintf(s->message, sizeof s->message, "culling %s", s->frame.cull == GDR_CULL_OFF ? "off" : "on");
        break;
    case GLFW_KEY_F:
        s->freeze_culling = !s->freeze_culling;
        s->cull_camera = *camera;
        snprintf(s->message, sizeof s->message, "culling %s", s->freeze_culling ? "frozen" : "follows the camera");
        break;
    case GLFW_KEY_RIGHT_BRACKET: case GLFW_KEY_EQUAL: case GLFW_KEY_KP_ADD: scale_lod(s, true); break;
    case GLFW_KEY_LEFT_BRACKET: case GLFW_KEY_MINUS: case GLFW_KEY_KP_SUBTRACT: scale_lod(s, false); break;
    case GLFW_KEY_F12: s->screenshot = true; break;
    case GLFW_KEY_J: s->jump = true; break;
    case GLFW_KEY_Y:
        s->vsync = !s->vsync;
        snprintf(s->message, sizeof s->message, "vsync %s", s->vsync ? "on" : "off");
        break;
    case GLFW_KEY_TAB: s->overlay = !s->overlay; break;
    case GLFW_KEY_H: case GLFW_KEY_F1: s->help = !s->help; break;
    default: break;
    }
}

void view_jump(view_settings *s, gdr_vec3 *position, gdr_quat *rotation)
{
    if (s->away) {
        *position = s->away_position, *rotation = s->away_rotation;
        snprintf(s->message, sizeof s->message, "jumped back");
    } else {
        s->away_position = *position, s->away_rotation = *rotation;
        *position = s->home_position, *rotation = s->home_rotation;
        snprintf(s->message, sizeof s->message, "jumped to the start (J: back)");
    }
    s->away = !s->away;
}
