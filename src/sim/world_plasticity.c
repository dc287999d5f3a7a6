/* Plastic solids in the world: creation, the once-per-step plastic update and the CFL factor.
 *
 * Where the update sits. Positions change only in steps 2 and 3 of a step, and F, its
 * diagonalization and the elastic force are computed once, after step 3 (integrator.c).
 * The return mapping reads that diagonalization, so it runs after the step, once every
 * solid has stepped without error (a failed step restores the state and leaves Fp alone).
 * The new Fp enters the force at the next step's force evaluation: f^n+1, already used by
 * this step's trapezoidal velocity and by the next step's first solve, is not recomputed
 * (that would double the force cost). The lag is one step.
 *
 * Step size. The effective Dm^-1 Fp^-1 is up to sigma_max(Fp^-1) stiffer than Dm^-1, so the
 * CFL altitude is divided by the bound the plastic update reports (at most e^limit). */
#include <math.h>

#include "common/status_report.h"
#include "sim/world_internal.h"

piola_status piola__solid_plastic_create(world_body *s, const piola_solid_def *def) {
  s->plastic = NULL;
  s->plastic_stats = (piola_plastic_stats){0, 0, 1.0};
  if (!def->plasticity) return PIOLA_OK;
  piola_status st = piola_plastic_state_create(s->solid, def->plasticity, &s->plastic);
  if (st != PIOLA_OK) return PIOLA_FAIL(st, "solid '%s': %s", s->name, piola_last_error());
  return PIOLA_OK;
}

void piola__solid_plastic_update(world_body *s, double dt) {
  if (!s->plastic) return;
  /* cannot fail: the state exists and dt > 0 is checked by the step */
  (void)piola_plastic_state_update(s->plastic, dt, &s->plastic_stats);
}

double piola__solid_plastic_stiffening(const world_body *s) {
  if (!s->plastic) return 1.0;
  double k = s->plastic_stats.max_fp_stretch;
  return k > 1.0 && isfinite(k) ? k : 1.0;
}

const piola_plastic_state *piola_world_solid_plastic_state(const piola_world *world, int32_t solid) {
  const world_body *b = piola__world_body_of(world, PIOLA_BODY_SOLID, solid);
  return b ? b->plastic : NULL;
}

piola_plastic_stats piola_world_solid_plastic_stats(const piola_world *world, int32_t solid) {
  piola_plastic_stats none = {0, 0, 1.0};
  const world_body *b = piola__world_body_of(world, PIOLA_BODY_SOLID, solid);
  return b ? b->plastic_stats : none;
}
