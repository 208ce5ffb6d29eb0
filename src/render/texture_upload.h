/* A scene texture into a sampled image with every mip level: in its block format where the device
 * samples that format, else decoded to RGBA8 on the CPU first. */
#ifndef GDR_RENDER_TEXTURE_UPLOAD_H
#define GDR_RENDER_TEXTURE_UPLOAD_H

#include "gdr/scene.h"
#include "vk/vk_image.h"

typedef struct gdr_renderer gdr_renderer;

/* Creates *image (SHADER_READ_ONLY_OPTIMAL once done) and counts it in r->materials (bytes,
 * texture_bytes, textures_compressed or textures_decoded). */
gdr_status gdr_texture_upload(gdr_renderer *r, const gdr_texture *t, gdr_vk_image *image, gdr_error *err);

#endif
