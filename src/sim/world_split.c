/* What a world split among processes supports (piola/work_split.h): the split divides the
 * solids' force loop and damping products, and with a Newton solver (solve_newton) the
 * implicit integrators' linear solves; everything else runs the same
 * on every process, self-collision of the solids' surfaces included (it reads node state
 * only, which every process holds bit for bit, and its detection does not depend on the
 * thread count: every process makes the same corrections). */
#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "piola/work_split.h"
#include "sim/body.h"
#include "sim/world_internal.h"

const char *piola_world_split_unsupported(const piola_world *world) {
  if (world && world->def.integrator != PIOLA_INTEGRATOR_NEWMARK)
    return "the implicit integrators (integrator.type backward_euler or quasistatic) run on "
           "several processes only in a build with PETSc (petsc-dev), which this one lacks";
  return piola_world_split_unsupported_solving(world);
}

const char *piola_world_split_unsupported_solving(const piola_world *world) {
  if (!world) return "no world";
  for (int32_t i = 0; i < world->body_count; ++i) {
    const world_body *b = &world->bodies[i];
    if (b->kind == PIOLA_BODY_SHELL) return "shells run on one process only";
  }
  return NULL;
}

piola_status piola_world_split_collect(piola_world *world) {
  if (!world) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "split collect: world is NULL");
  for (int32_t i = 0; i < world->body_count; ++i) {
    world_body *b = &world->bodies[i];
    if (b->kind != PIOLA_BODY_SOLID || !piola__local_split(b->solid)) continue;
    piola__elastic_body_split_collect(b->solid);
    b->elastic_stale = 1; /* process 0's statistics now see every tet */
  }
  return PIOLA_OK;
}

void piola_world_set_work_split_replanner(piola_world *world, const piola_work_split_planner *planner) {
  if (!world) return;
  world->split_replanner = planner ? *planner : (piola_work_split_planner){NULL, NULL};
}

void piola_world_defer_work_split_replans(piola_world *world, int defer) {
  if (world) world->split_replans_deferred = defer != 0;
}

int piola_world_solid_split_pending(const piola_world *world, int32_t solid) {
  const world_body *b = world ? piola__world_body_of(world, PIOLA_BODY_SOLID, solid) : NULL;
  return b && b->split_pending;
}

piola_status piola_world_solid_replan_work_split(piola_world *world, int32_t solid) {
  world_body *b = world ? piola__world_body_of(world, PIOLA_BODY_SOLID, solid) : NULL;
  if (!b) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "work split: no solid %d", (int)solid);
  /* the replanner frees the solid's old split: no body may refer to it then */
  PIOLA_TRY(piola__elastic_body_set_work_split(b->solid, NULL, 0));
  b->split_pending = 0;
  return piola__body_resplit(world, b);
}

void piola_world_set_work_split_planner(piola_world *world, const piola_work_split_planner *planner) {
  if (!world) return;
  world->split_planner = planner ? *planner : (piola_work_split_planner){NULL, NULL};
}
