/* Defaults of the world and solid definitions, written once. Kept apart from world.c so
 * that code that only builds definitions (the scene parser) does not pull in the solver. */
#include <string.h>

#include "math/mat3.h"
#include "piola/world.h"

piola_world_def piola_default_world_def(void) {
  piola_world_def def;
  memset(&def, 0, sizeof def);
  def.gravity[0] = piola_track_constant(0);
  def.gravity[1] = piola_track_constant(0);
  def.gravity[2] = piola_track_constant(-9.81);
  def.max_dt = 1e-3;
  def.cfl = 0.5;
  def.cg_tolerance = 1e-4;
  def.cg_max_iterations = 200;
  def.integrator = PIOLA_INTEGRATOR_NEWMARK;
  def.implicit_dt = 1.0 / 30.0;
  def.newton_tolerance = 1e-5;
  def.newton_max_iterations = 30;
  def.linear_tolerance = 1e-3;
  def.linear_max_iterations = 1000;
  def.preconditioner = PIOLA_PRECONDITIONER_BLOCK_JACOBI;
  def.linear_forcing = PIOLA_FORCING_EISENSTAT_WALKER;
  def.mpi_preconditioner = PIOLA_MPI_PRECONDITIONER_GAMG;
  return def;
}

static const char *const integrator_names[PIOLA_INTEGRATOR_COUNT] = {"newmark", "backward_euler",
                                                                     "quasistatic"};

const char *piola_integrator_type_name(piola_integrator_type type) {
  if ((int)type < 0 || type >= PIOLA_INTEGRATOR_COUNT) return "unknown";
  return integrator_names[type];
}

bool piola_integrator_type_from_name(const char *name, piola_integrator_type *type) {
  if (!name || !type) return false;
  for (int k = 0; k < PIOLA_INTEGRATOR_COUNT; ++k)
    if (strcmp(name, integrator_names[k]) == 0) {
      *type = (piola_integrator_type)k;
      return true;
    }
  return false;
}

piola_solid_def piola_default_solid_def(void) {
  piola_solid_def def;
  memset(&def, 0, sizeof def);
  def.material = piola_default_material_def();
  def.stiffness_scale = piola_track_constant(1);
  def.density = 1000;
  def.shear_viscosity = piola_track_constant(0);
  def.bulk_viscosity = piola_track_constant(0);
  def.initial_matrix = mat3_identity();
  def.scramble_seed = 1;
  def.self_collision.enabled = false;
  def.self_collision.thickness = 1e-3;
  def.self_collision.friction = 0.3;
  def.fiber_directions = NULL;
  def.activation = piola_track_constant(0);
  return def;
}

static const char *const preconditioner_names[PIOLA_PRECONDITIONER_COUNT] = {
    "block_jacobi", "incomplete_cholesky", "multigrid"};

const char *piola_preconditioner_type_name(piola_preconditioner_type type) {
  if ((int)type < 0 || type >= PIOLA_PRECONDITIONER_COUNT) return "unknown";
  return preconditioner_names[type];
}

bool piola_preconditioner_type_from_name(const char *name, piola_preconditioner_type *type) {
  if (!name || !type) return false;
  for (int k = 0; k < PIOLA_PRECONDITIONER_COUNT; ++k)
    if (strcmp(name, preconditioner_names[k]) == 0) {
      *type = (piola_preconditioner_type)k;
      return true;
    }
  return false;
}

static const char *const forcing_names[PIOLA_FORCING_COUNT] = {"eisenstat_walker", "fixed"};

const char *piola_linear_forcing_name(piola_linear_forcing forcing) {
  if ((int)forcing < 0 || forcing >= PIOLA_FORCING_COUNT) return "unknown";
  return forcing_names[forcing];
}

bool piola_linear_forcing_from_name(const char *name, piola_linear_forcing *forcing) {
  if (!name || !forcing) return false;
  for (int k = 0; k < PIOLA_FORCING_COUNT; ++k)
    if (strcmp(name, forcing_names[k]) == 0) {
      *forcing = (piola_linear_forcing)k;
      return true;
    }
  return false;
}

static const char *const mpi_preconditioner_names[PIOLA_MPI_PRECONDITIONER_COUNT] = {
    "gamg", "block_jacobi_icc"};

const char *piola_mpi_preconditioner_name(piola_mpi_preconditioner type) {
  if ((int)type < 0 || type >= PIOLA_MPI_PRECONDITIONER_COUNT) return "unknown";
  return mpi_preconditioner_names[type];
}

bool piola_mpi_preconditioner_from_name(const char *name, piola_mpi_preconditioner *type) {
  if (!name || !type) return false;
  for (int k = 0; k < PIOLA_MPI_PRECONDITIONER_COUNT; ++k)
    if (strcmp(name, mpi_preconditioner_names[k]) == 0) {
      *type = (piola_mpi_preconditioner)k;
      return true;
    }
  return false;
}
