#version 460
// Overdraw view, step 2: each pixel's fragment count as a heat map (black, blue, green, yellow, red,
// white), normalised by the frame's maximum. Pixels no fragment reached keep the background.
#include "gpu_shared/glsl_buffers.h"

layout(location = 0) out vec4 out_color;

vec3 heat(float t)
{
    const vec3 stops[6] = vec3[](vec3(0.0), vec3(0.0, 0.2, 1.0), vec3(0.0, 0.9, 0.2), vec3(1.0, 0.9, 0.0),
                                 vec3(1.0, 0.1, 0.0), vec3(1.0));
    float x = clamp(t, 0.0, 1.0) * 5.0;
    int i = min(int(x), 4);
    return mix(stops[i], stops[i + 1], x - float(i));
}

void main()
{
    GdrGpuFrameGlobals g = FrameGlobalsRef(push.globals).value;
    uint width = uint(g.viewport.x), pixels = width * uint(g.viewport.y);
    OverdrawRef counts = OverdrawRef(GDR_FRAME.overdraw);
    // gl_FragCoord is in framebuffer coordinates in every pass, whatever the viewport's flip.
    uint count = counts.items[uint(gl_FragCoord.y) * width + uint(gl_FragCoord.x)];
    uint maximum = max(counts.items[pixels], 1u);
    if (count == 0u)
        discard;
    out_color = vec4(heat(float(count) / float(maximum)), 1.0);
}
