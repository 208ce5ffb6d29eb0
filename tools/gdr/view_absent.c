/* gdr view in a build whose library has no presenter (gdr/config.h: GDR_HAVE_PRESENT 0;
 * docs/ARCHITECTURE.md, "Optional modules"): the command says so and exits 2, a command this build
 * cannot run, and the help has no keys to list. No window system is linked. */
#include <stdio.h>

#include "commands.h"
#include "view.h"

const char view_key_help[] = "    (none: this build has no presenter)\n";

int gdr_cmd_view(int argc, char **argv)
{
    (void)argc, (void)argv;
    fprintf(stderr, "gdr view: this build has no presenter: the library was built without the present module "
                    "(GDR_EXCLUDE_MODULES); gdr render writes images headless\n");
    return 2;
}
