/* The table of `piola` subcommands. Each lives in its own cli_<name>.c file and returns the
 * process exit code: 0 success, 1 runtime failure, 2 bad usage or bad input. */
#ifndef PIOLA_CLI_COMMANDS_H
#define PIOLA_CLI_COMMANDS_H

#define PIOLA_VERSION_STRING "0.1.0"

typedef struct cli_command {
  const char *name;
  int (*run)(int argc, char **argv); /* argv[0] is the command name */
} cli_command;

extern const cli_command cli_commands[];

/* `piola run SCENE.json -o DIR ...` (src/cli/cli_run.c). */
int cli_run(int argc, char **argv);

/* `piola check SCENE.json ...`: validate, build and estimate a scene (src/cli/cli_check.c). */
int cli_check(int argc, char **argv);

/* `piola mesh generate ...` (argv[0] is "generate"), called by the `mesh` command. */
int cli_mesh_generate(int argc, char **argv);

/* Whether path names a surface file (.obj, .off, .stl) rather than a tet mesh (cli_mesh.c). */
int cli_is_surface_path(const char *path);

#endif
