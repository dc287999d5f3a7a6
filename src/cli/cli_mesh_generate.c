/* `piola mesh generate`: replaced by the mesher's implementation when it lands. */
#include <stdio.h>

#include "cli/commands.h"

int cli_mesh_generate(int argc, char **argv) {
  (void)argc;
  (void)argv;
  fprintf(stderr, "piola mesh generate: the mesher is not part of this build yet\n");
  return 2;
}
