/* The time-budget guard of `piola run` and `piola check` (run_budget.h). */
#include "cli/run_budget.h"

#include <math.h>
#include <stdio.h>

#include "piola/elastic_body.h"

/* The time it takes the fastest wave of the rest state to cross the smallest tet, over the
 * world's solids (s; INFINITY without solids): the rest CFL step at cfl = 1. */
static double rest_crossing_time(const piola_world *world) {
  double t = INFINITY;
  for (int32_t i = 0; i < piola_world_solid_count(world); ++i) {
    const piola_elastic_body *body = piola_world_solid_body(world, i);
    const double h = piola_elastic_body_min_rest_altitude(body);
    const double c = piola_elastic_body_max_wave_speed(body);
    if (h > 0 && c > 0) t = fmin(t, h / c);
  }
  return t;
}

/* Why the budget guard may have refused, where the first step is far below the rest state's:
 * a body that starts deformed (a scramble, a collapse) is stiff where it is stretched, and
 * the explicit step stays that short until it recovers, which the estimate cannot foresee;
 * the implicit integrator takes such starts in frame-sized steps. A hint, worded as one: a
 * tiny max_dt or stiffness_scale shortens the step too. */
static void deformed_start_hint(const char *command, const piola_world *world, double dt) {
  const double rest = rest_crossing_time(world);
  if (!isfinite(rest) || !(dt < 0.01 * rest)) return; /* no solid: no such hint */
  if (piola_world_integrator(world) != PIOLA_INTEGRATOR_NEWMARK) {
    /* the implicit step is the scene's own integrator.dt */
    fprintf(stderr,
            "%s: integrator.dt (%.3g s) is %.3g times shorter than the time the rest "
            "state's fastest wave takes to cross the smallest tet (%.3g s); \"%s\" needs no "
            "such step: leave integrator.dt out for one step per frame (docs/time-stepping.md, "
            "\"Implicit integrators\")\n",
            command, dt, rest / dt, rest,
            piola_integrator_type_name(piola_world_integrator(world)));
    return;
  }
  fprintf(stderr,
          "%s: the first step is %.3g times shorter than the time the rest state's "
          "fastest wave takes to cross the smallest tet (%.3g s). If a solid starts deformed "
          "(initial.scramble, initial.matrix), it is far stiffer where it is stretched, and "
          "the explicit step stays that short until it recovers: \"integrator\": {\"type\": "
          "\"backward_euler\"} takes frame-sized steps through it (docs/time-stepping.md, "
          "\"Implicit integrators\")\n",
          command, rest / dt, rest);
}

bool run_budget_ok(const char *command, const char *scene_path, const piola_world *world,
                   int frames, double fps, double max_steps, bool quiet) {
  double simulated = frames / fps, dt = piola_world_stable_dt(world);
  double steps = frames * ceil(1.0 / fps / dt - 1e-9);
  if (isfinite(steps) && steps <= max_steps) return true;
  if (quiet) return false; /* MPI processes other than 0 */
  fprintf(stderr,
          "%s: %s: %d frames at %g fps are %.3g s of simulated time, about %.3g steps of "
          "%.3g s: more than the limit of %.3g steps. Check fps and frames, or raise the limit "
          "with --max-steps N\n",
          command, scene_path, frames, fps, simulated, steps, dt, max_steps);
  deformed_start_hint(command, world, dt);
  return false;
}
