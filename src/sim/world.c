/* The world: creation, obstacles, the time. The bodies live in a table (body_table.c) and
 * each kind in a file of its own (world_solids.c, world_shells.c); the time stepping lives
 * in integrator.c. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/number_text.h"
#include "common/status_report.h"
#include "sim/solid_contacts.h"
#include "sim/world_internal.h"

int piola__track_ok(const piola_track *t, double lo) {
  if (t->key_count < 0 || t->key_count > PIOLA_MAX_KEYS) return 0;
  if (t->key_count == 0) return isfinite(t->value) && t->value >= lo;
  for (int32_t k = 0; k < t->key_count; ++k)
    if (!isfinite(t->values[k]) || t->values[k] < lo) return 0;
  return 1;
}

piola_status piola__check_viscosities(const char *kind, int32_t id, const piola_track *shear,
                                      const piola_track *bulk) {
  const piola_track *tracks[2] = {shear, bulk};
  static const char *const names[2] = {"shear_viscosity", "bulk_viscosity"};
  for (int k = 0; k < 2; ++k)
    if (!piola__track_ok(tracks[k], 0))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "%s %d: %s must be finite and >= 0 Pa s at every key", kind, (int)id,
                        names[k]);
  return PIOLA_OK;
}

piola_status piola_world_create(const piola_world_def *def, piola_world **out) {
  if (!def || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "world: NULL argument");
  *out = NULL;
  for (int k = 0; k < 3; ++k)
    if (!piola__track_ok(&def->gravity[k], -INFINITY))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "gravity[%d] must be finite m/s^2", k);
  /* the ranges of the scene's keys (scene-format.md, "Integrator"), so that a world built
   * through the library or Python refuses what a scene file would */
  if (!(def->max_dt > 0 && def->max_dt <= 1))
    return piola__refuse_value("max_dt must be in (0, 1] s", def->max_dt);
  if (!(def->cfl > 0 && def->cfl <= 2))
    return piola__refuse_value("cfl must be in (0, 2]", def->cfl);
  if (!(def->cg_tolerance > 0 && def->cg_tolerance < 1))
    return piola__refuse_value("cg_tolerance must be in (0, 1)", def->cg_tolerance);
  if (def->cg_max_iterations < 1 || def->cg_max_iterations > 1000000)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "cg_max_iterations must be in [1, 1000000], got %d",
                      (int)def->cg_max_iterations);
  if (!(def->collision_interval >= 0 && def->collision_interval <= 1))
    return piola__refuse_value("collision_interval must be in [0, 1] s", def->collision_interval);
  if ((int)def->integrator < 0 || def->integrator >= PIOLA_INTEGRATOR_COUNT)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "integrator: unknown type %d", (int)def->integrator);
  if (!(def->implicit_dt > 0) || !isfinite(def->implicit_dt))
    return piola__refuse_value("integrator dt must be > 0 s", def->implicit_dt);
  if (!(def->newton_tolerance > 0 && def->newton_tolerance < 1))
    return piola__refuse_value("newton_tolerance must be in (0, 1)", def->newton_tolerance);
  if (def->newton_max_iterations < 1 || def->newton_max_iterations > 1000000)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "newton_max_iterations must be in [1, 1000000], got %d",
                      (int)def->newton_max_iterations);
  if (!(def->linear_tolerance > 0 && def->linear_tolerance < 1))
    return piola__refuse_value("linear_tolerance must be in (0, 1)", def->linear_tolerance);
  if (def->linear_max_iterations < 1 || def->linear_max_iterations > 1000000)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "linear_max_iterations must be in [1, 1000000], got %d",
                      (int)def->linear_max_iterations);
  if ((int)def->preconditioner < 0 || def->preconditioner >= PIOLA_PRECONDITIONER_COUNT)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "unknown preconditioner %d",
                      (int)def->preconditioner);
  if ((int)def->linear_forcing < 0 || def->linear_forcing >= PIOLA_FORCING_COUNT)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "unknown linear forcing %d",
                      (int)def->linear_forcing);
  if ((int)def->mpi_preconditioner < 0 || def->mpi_preconditioner >= PIOLA_MPI_PRECONDITIONER_COUNT)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "unknown MPI preconditioner %d",
                      (int)def->mpi_preconditioner);
  piola_world *w = calloc(1, sizeof *w);
  if (!w) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "world: out of memory");
  w->def = *def;
  w->collision_deadline = NAN;
  w->deeper_steps_left = -1;
  if (def->integrator == PIOLA_INTEGRATOR_NEWMARK && def->cfl > 1)
    piola__world_warn(w, PIOLA_WARNING_UNSTABLE_CFL,
                      "integrator.cfl %g is above 1, past the stability limit of well-shaped "
                      "meshes (0.94-1.35 measured, time-stepping.md \"How far cfl can go\"): an "
                      "undamped body's energy can grow by a little every step, below what the "
                      "energy check catches (an undamped neo-Hookean block's grew 3e9 times in 5 s at cfl 2); 0.5, the "
                      "default, is about half the limit and 0.37 (0.29 near nu = 0.5) is stable "
                      "on any mesh",
                      def->cfl);
  *out = w;
  return PIOLA_OK;
}

void piola_world_destroy(piola_world *world) {
  if (!world) return;
  piola__world_free_bodies(world);
  for (int32_t i = 0; i < world->obstacle_count; ++i) piola_obstacle_destroy(world->obstacles[i]);
  piola__world_contact_free(world);
  piola__solid_contacts_free(world);
  piola__world_warnings_free(world);
  free(world->obstacles);
  free(world);
}

piola_status piola_world_add_obstacle(piola_world *world, const piola_obstacle_def *def,
                                      int32_t *index) {
  if (!world || !def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "add_obstacle: NULL argument");
  if (world->obstacle_count == world->obstacle_capacity) {
    int32_t cap = world->obstacle_capacity ? 2 * world->obstacle_capacity : 4;
    piola_obstacle **grown = realloc(world->obstacles, (size_t)cap * sizeof *grown);
    if (!grown) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "add_obstacle: out of memory");
    world->obstacles = grown;
    world->obstacle_capacity = cap;
  }
  piola_obstacle *o = NULL;
  PIOLA_TRY(piola_obstacle_create(def, &o));
  world->obstacles[world->obstacle_count] = o;
  if (index) *index = world->obstacle_count;
  world->obstacle_count++;
  return PIOLA_OK;
}

double piola_world_time(const piola_world *world) { return world ? world->time : NAN; }
piola_integrator_type piola_world_integrator(const piola_world *world) {
  return world ? world->def.integrator : PIOLA_INTEGRATOR_COUNT;
}
int32_t piola_world_obstacle_count(const piola_world *world) {
  return world ? world->obstacle_count : 0;
}
