/* The overlay's text as rectangles: stb_easy_font draws each glyph from axis-aligned segments, so
 * the whole text is a list of clear rectangles, drawn without a shader or a font texture. */
#include <stdlib.h>
#include <string.h>

#include "present/presenter_internal.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wconversion"
#include <stb/stb_easy_font.h>
#pragma GCC diagnostic pop

typedef struct easy_font_vertex {
    float x, y, z;
    unsigned char color[4];
} easy_font_vertex;

/* A rectangle in pixels clipped to the image; false when nothing is left. */
static bool clip_rect(int x0, int y0, int x1, int y1, uint32_t width, uint32_t height, VkClearRect *out)
{
    x0 = x0 < 0 ? 0 : x0;
    y0 = y0 < 0 ? 0 : y0;
    x1 = x1 > (int)width ? (int)width : x1;
    y1 = y1 > (int)height ? (int)height : y1;
    if (x1 <= x0 || y1 <= y0)
        return false;
    *out = (VkClearRect){.rect = {{x0, y0}, {(uint32_t)(x1 - x0), (uint32_t)(y1 - y0)}}, .baseArrayLayer = 0,
                         .layerCount = 1};
    return true;
}

uint32_t gdr_overlay_rects(const char *text, int x, int y, int scale, uint32_t width, uint32_t height,
                           VkClearRect *rects, uint32_t capacity, uint32_t *background_count)
{
    *background_count = 0;
    size_t length = strlen(text);
    char *copy = malloc(length + 1); /* stb_easy_font takes a mutable string */
    /* Room for 16 quads of 4 vertices per character, more than a glyph has (stb_easy_font stops at
     * the buffer's end rather than overflow it). */
    size_t vertex_bytes = (length + 1) * 16 * 4 * sizeof(easy_font_vertex);
    easy_font_vertex *vertices = malloc(vertex_bytes);
    uint32_t count = 0;
    if (!copy || !vertices || capacity == 0)
        goto done;
    memcpy(copy, text, length + 1);
    int box_w = stb_easy_font_width(copy) * scale, box_h = stb_easy_font_height(copy) * scale;
    if (clip_rect(x - 4, y - 4, x + box_w + 4, y + box_h + 2, width, height, &rects[0]))
        count = *background_count = 1;
    int quads = stb_easy_font_print(0.0f, 0.0f, copy, NULL, vertices, (int)(vertex_bytes > INT32_MAX ? INT32_MAX : vertex_bytes));
    for (int q = 0; q < quads && count < capacity; q++) {
        const easy_font_vertex *v = &vertices[q * 4];
        int x0 = x + (int)(v[0].x * (float)scale), y0 = y + (int)(v[0].y * (float)scale);
        int x1 = x + (int)(v[2].x * (float)scale), y1 = y + (int)(v[2].y * (float)scale);
        count += clip_rect(x0, y0, x1, y1, width, height, &rects[count]);
    }
done:
    free(copy);
    free(vertices);
    return count;
}
