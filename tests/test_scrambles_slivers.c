/* Issue 21's scramble done-when on the two sliver meshes, gmsh/bar-186.msh (a 10:0.5:1 bar,
 * slivers of mean ratio 0.02, dihedral angles down to 3.6 degrees) and gmsh/torus.msh (491
 * tets, dihedral angles down to 5.3 degrees), for corotated and the spline, two of the models
 * that stiffen without limit under stretch: from one diagonal of scramble they run 2 s of
 * simulated time with every step succeeding, a finite state and the total energy never above
 * the start's (real_mesh_scramble_run). A program of its own so that ctest -j2 overlaps it with
 * test_scrambles_every_model, which runs the other cases (its header lists what none runs, and
 * why; docs/time-stepping.md "What the test affords"); test_scrambles_stable_neohookean.c runs
 * the third such model on the same meshes.
 *
 * These runs became affordable with the step bound's direction weights
 * (src/force/stable_step_anisotropy.h): corotated on bar-186 from one diagonal took 117,365
 * steps for 2 s without them, 65,664 with them (the spline 55,956); on the torus corotated took
 * 17,669 steps for its first 0.1 s without them, 12,154 for the whole 2 s with them (the spline
 * 9,633).
 *
 * PIOLA_TEST_SCALE scales the 2 s (at least 0.02 s); PIOLA_TEST_MODEL selects a model by name;
 * PIOLA_TEST_VERBOSE prints steps and CPU time. */
#include "test_support.h"

#include "piola/threads.h"
#include "real_mesh_scenes.h"

#define DIAGONAL 2.0

static void corotated_and_spline_run_one_diagonal_on_slivers(void **state) {
  (void)state;
  static const piola_material_model models[] = {PIOLA_MODEL_COROTATED, PIOLA_MODEL_SPLINE};
  /* the bar's stiff start costs about the same at any PIOLA_TEST_SCALE: the sanitizer pass
   * (scale below 0.5) runs the torus only, the Release pass both */
  if (test_scale() >= 0.5) real_mesh_scramble_models("gmsh/bar-186.msh", DIAGONAL, models, 2, DIAGONAL);
  real_mesh_scramble_models("gmsh/torus.msh", DIAGONAL, models, 2, DIAGONAL);
}

int main(void) {
  piola_set_thread_count(1); /* small bodies: results do not depend on the count */
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(corotated_and_spline_run_one_diagonal_on_slivers),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
