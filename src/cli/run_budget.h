/* The time-budget guard shared by `piola run` and `piola check` (docs/cli.md, `--max-steps`):
 * a scene whose frames would take more than max_steps steps of the first stable step is
 * refused before anything is written, as a mistyped fps (1e-300) or frame count would
 * otherwise run for ever. The estimate uses the step at t = 0; steps shrink under stiffening
 * and contact, and every frame ends a step (so a step longer than a frame, an implicit
 * integrator's integrator.dt, still takes one per frame): frames times ceil(frame time /
 * step), as `piola check` estimates, is a lower bound. */
#ifndef PIOLA_CLI_RUN_BUDGET_H
#define PIOLA_CLI_RUN_BUDGET_H

#include <stdbool.h>

#include "piola/world.h"

/* true when the run fits max_steps; else false, and (unless quiet: MPI processes other than
 * 0) a message on stderr prefixed with command, with a hint where the first step is far
 * below the rest state's. */
bool run_budget_ok(const char *command, const char *scene_path, const piola_world *world,
                   int frames, double fps, double max_steps, bool quiet);

#endif
