/* Registered subcommands. Add a line here when adding a cli_<name>.c. */
#include "cli/commands.h"

#include <stddef.h>

const cli_command cli_commands[] = {
    {"run", cli_run},
    {NULL, NULL},
};
