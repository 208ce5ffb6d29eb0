/* The subcommands of the gdr program. Each takes argv with argv[0] = the subcommand's name and
 * returns the process exit status: 0 success, 1 failure, 2 bad usage (render and view: 3 validation
 * messages; render, view, info and build: 4 warnings under --strict, GDR_EXIT_STRICT). */
#ifndef GDR_COMMANDS_H
#define GDR_COMMANDS_H

int gdr_cmd_render(int argc, char **argv);
int gdr_cmd_bench(int argc, char **argv);
int gdr_cmd_build(int argc, char **argv); /* gdr build INPUT -o OUTPUT.gdrc */
int gdr_cmd_info(int argc, char **argv);  /* gdr info FILE */
int gdr_cmd_view(int argc, char **argv);  /* gdr view SCENE: the interactive window */
int gdr_cmd_cache(int argc, char **argv); /* gdr cache list|clear: the cache folder */

#endif
