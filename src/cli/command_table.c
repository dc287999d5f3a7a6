/* Registered subcommands. Add a line here when adding a cli_<name>.c. */
#include "cli/commands.h"

#include <stddef.h>

int cli_mesh(int argc, char **argv);
int cli_render(int argc, char **argv);

const cli_command cli_commands[] = {
    {"run", cli_run},
    {"mesh", cli_mesh},
    {"render", cli_render},
    {"check", cli_check},
    {NULL, NULL},
};
