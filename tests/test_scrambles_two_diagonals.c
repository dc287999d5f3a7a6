/* Issue 21's scramble done-when from two diagonals for the three models that stiffen without
 * limit under stretch (corotated, the spline and Stable Neo-Hookean with their J terms), which
 * test_scrambles_every_model.c runs from two diagonals on gmsh/msh_tetra.msh only: here they run
 * 2 s of simulated time from two diagonals on gmsh/torus.msh (491 tets, dihedral angles down to
 * 5.3 degrees) and from 0.5, 1 and 2 diagonals on medit/cylinder.mesh (1,348 tets, well shaped),
 * so that every model runs every scramble on three real meshes, one with slivers. Every step
 * succeeds, the state stays finite and the total energy never rises above the start's
 * (real_mesh_scramble_run). A program of its own so that ctest -j2 overlaps it with the other
 * scramble tests. Measured 2026-12-03 (one thread, quiet machine, CPU time): the torus from two
 * diagonals, corotated 235,613 steps (47 s), the spline 75,636 (14 s), Stable Neo-Hookean 396,972
 * (75 s); the cylinder from two diagonals, corotated 44,110 (14 s), Stable Neo-Hookean 81,448
 * (26 s). Not run: bar-186 from two diagonals (corotated gains energy there, the CLAMP
 * extension's work without a potential: docs/time-stepping.md "What the test affords").
 *
 * PIOLA_TEST_SCALE scales the 2 s (at least 0.02 s); below 0.5 (the sanitizer pass) only the
 * spline runs, and only on the cylinder from 0.5 and 1 diagonal, since the stiff start from two
 * diagonals costs about the same at any scale (the torus's first 0.1 s: 47,387 steps; the
 * cylinder's: 22,835 steps, 89 s of wall with the sanitizers' build). PIOLA_TEST_MODEL
 * selects a model by name; PIOLA_TEST_VERBOSE prints steps and CPU time. */
#include "test_support.h"

#include "piola/threads.h"
#include "real_mesh_scenes.h"

#define DIAGONAL 2.0

static const piola_material_model stiffening[] = {PIOLA_MODEL_COROTATED, PIOLA_MODEL_SPLINE,
                                                  PIOLA_MODEL_STABLE_NEOHOOKEAN};

/* all three at the Release scale, the spline alone under the sanitizers */
static int models_to_run(const piola_material_model **models) {
  static const piola_material_model spline_only[] = {PIOLA_MODEL_SPLINE};
  if (test_scale() >= 0.5) {
    *models = stiffening;
    return 3;
  }
  *models = spline_only;
  return 1;
}

static void stiffening_models_run_two_diagonals_on_the_sliver_torus(void **state) {
  (void)state;
  if (test_scale() < 0.5) skip(); /* its stiff start: see the header */
  const piola_material_model *models;
  const int count = models_to_run(&models);
  real_mesh_scramble_models("gmsh/torus.msh", DIAGONAL, models, count, 2 * DIAGONAL);
}

static void stiffening_models_run_every_scramble_on_the_cylinder(void **state) {
  (void)state;
  const piola_material_model *models;
  const int count = models_to_run(&models);
  const double radii[] = {0.5 * DIAGONAL, DIAGONAL, 2 * DIAGONAL};
  const int radius_count = test_scale() >= 0.5 ? 3 : 2; /* the header says why */
  for (int r = 0; r < radius_count; ++r)
    real_mesh_scramble_models("medit/cylinder.mesh", DIAGONAL, models, count, radii[r]);
}

int main(void) {
  piola_set_thread_count(1); /* small bodies: results do not depend on the count */
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(stiffening_models_run_two_diagonals_on_the_sliver_torus),
      cmocka_unit_test(stiffening_models_run_every_scramble_on_the_cylinder),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
