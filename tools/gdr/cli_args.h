/* Strict parsing of command-line values: the whole string must be a valid value in range. */
#ifndef GDR_CLI_ARGS_H
#define GDR_CLI_ARGS_H

#include <stdbool.h>
#include <stdint.h>

#include "gdr/renderer.h"
#include "gdr/io.h"
#include "gdr/scene.h"

/* Each prints "gdr: OPTION VALUE: why" on failure and returns false. */
/* GDR_DISABLE_BC_TEXTURES=1 in the environment: behave as a device without BC texture sampling
 * (gdr_renderer_desc.disable_texture_compression_bc), so that tests reach the decoding fallback. */
bool cli_bc_textures_disabled(void);
bool cli_parse_u32(const char *option, const char *text, uint32_t min, uint32_t max, uint32_t *out);
/* A finite decimal number in [min, max]. */
bool cli_parse_float(const char *option, const char *text, float min, float max, float *out);
bool cli_parse_on_off(const char *option, const char *text, bool *out);
/* One of names[0 .. count): *out is its index. */
bool cli_parse_choice(const char *option, const char *text, const char *const *names, int count, int *out);
/* --pipeline mesh|indirect|cpu (cpu: only with the culling module) */
bool cli_parse_pipeline(const char *option, const char *text, gdr_pipeline *out);
/* --raster hybrid|hw|sw|forward */
bool cli_parse_raster(const char *option, const char *text, gdr_raster *out);
/* "px,py,pz,qx,qy,qz,qw": position and rotation quaternion (normalised; must not be zero). */
bool cli_parse_camera(const char *option, const char *text, gdr_vec3 *position, gdr_quat *rotation);
/* `count` finite numbers separated by commas into out[0 .. count); false (nothing printed) if not. */
bool cli_parse_floats(const char *text, int count, float *out);
/* --budget "triangles=N,instances=N,pixels=N,bytes=N" (any of them, each a positive integer): the
 * limits on what one untrusted file may make gdr allocate (docs/SECURITY.md). */
bool cli_parse_budget(const char *option, const char *text, gdr_budget *out);
/* Whether the library holds the culling module (gdr/config.h), which `what` (an option) needs; if
 * not, prints "gdr: WHAT: built without the culling module (GDR_EXCLUDE_MODULES)" and returns false. */
bool cli_needs_cull(const char *what);
/* Prints "gdr: MESSAGE" for a scene that did not load and returns the exit status: 2 (bad usage)
 * for a built-in scene's options out of range, 1 otherwise. */
int cli_load_failed(const char *spec, const gdr_error *err);
/* Returns the option's value (argv[*i + 1]) and advances *i, or prints an error and returns NULL. */
const char *cli_value(int argc, char **argv, int *i);
/* cli_value for an option of `command` that must be one of `known` (NULL-terminated): an option
 * not in the list is "unknown", never "needs a value". */
const char *cli_known_value(const char *command, const char *const *known, int argc, char **argv, int *i);
/* Prints "gdr: MESSAGE" for a renderer that could not be made and returns the exit status: 2 when a
 * value given on the command line was refused (GDR_ERROR_INVALID_ARGUMENT: a device number or name,
 * a size), 1 otherwise. */
int cli_renderer_failed(const gdr_error *err);

#endif
