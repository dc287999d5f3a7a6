/* The `piola` command-line program: dispatches to subcommands. Uses only the public API. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/allocator_policy.h"
#include "cli/commands.h"
#include "piola/kernels.h"

static void print_usage(FILE *out) {
  fprintf(out,
          "usage: piola <command> [options]\n"
          "\n"
          "commands:\n"
          "  run SCENE.json -o DIR        simulate a scene and write frames\n"
          "  check SCENE.json             validate and build a scene, estimate its run; writes nothing\n"
          "  render DIR                   PNG frames, a contact sheet and a movie of a run's frames\n"
          "  mesh info|convert|generate   inspect, convert or generate meshes\n"
          "  version                      print the version\n"
          "\n"
          "Run `piola <command> --help` for the options of a command.\n");
}

/* OpenMP threads wait passively (sleep) between parallel regions unless the user chose
 * otherwise. With the runtime's default, a thread that finishes its share spins for a while
 * before sleeping; on a machine busy with other work those spinning threads take the cores
 * the working ones need, and `--threads` at all cores ran 4.6-5.7x slower than one thread
 * (docs/cli.md). The runtime reads OMP_WAIT_POLICY once, when it is loaded, before main:
 * so the program sets it and starts itself again, once. */
static void wait_passively(char **argv) {
  if (getenv("OMP_WAIT_POLICY")) return;
  if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0) return;
  execv("/proc/self/exe", argv);
  /* no /proc: run on with the runtime's default */
}

int main(int argc, char **argv) {
  wait_passively(argv);
  piola_cli_keep_freed_memory();
  if (argc < 2) {
    print_usage(stderr);
    return 2;
  }
  const char *command = argv[1];
  for (const cli_command *c = cli_commands; c->name; ++c)
    if (strcmp(c->name, command) == 0) return c->run(argc - 1, argv + 1);
  if (strcmp(command, "--help") == 0 || strcmp(command, "-h") == 0 || strcmp(command, "help") == 0) {
    print_usage(stdout);
    return 0;
  }
  if (strcmp(command, "version") == 0 || strcmp(command, "--version") == 0) {
    printf("piola %s\nkernels: %s\n", PIOLA_VERSION_STRING, piola_kernel_isa());
    return 0;
  }
  fprintf(stderr, "piola: unknown command '%s'\n", command);
  print_usage(stderr);
  return 2;
}
