/* Issue 21's scramble done-when for Stable Neo-Hookean on the two sliver meshes,
 * gmsh/bar-186.msh (a 10:0.5:1 bar, slivers of mean ratio 0.02, dihedral angles down to 3.6
 * degrees) and gmsh/torus.msh (491 tets, dihedral angles down to 5.3 degrees): from one diagonal
 * of scramble it runs 2 s of simulated time with every step succeeding, a finite state and the
 * total energy never above the start's (real_mesh_scramble_run). Its J term stiffens without
 * limit under stretch, as corotated's does (test_scrambles_slivers.c runs those two); a program
 * of its own so that each stays under half a minute and ctest -j2 overlaps them with
 * test_scrambles_every_model, whose header lists what none of them runs, and why
 * (docs/time-stepping.md "What the test affords").
 *
 * With the step bound's direction weights (src/force/stable_step_anisotropy.h): on bar-186
 * 147,771 steps, most of them in the first 0.2 s, where the step is 1e-7 to 3e-6 s, before it
 * grows to ~1e-4 s (19 s of CPU, the longest scramble run of the tests); on the torus 17,865
 * steps (4.6 s).
 *
 * PIOLA_TEST_SCALE scales the 2 s (at least 0.02 s; the stiff start is much of the cost, so a
 * twentieth of the time still costs a third: 61,293 steps on bar-186); PIOLA_TEST_VERBOSE
 * prints steps and CPU time. */
#include "test_support.h"

#include "piola/threads.h"
#include "real_mesh_scenes.h"

#define DIAGONAL 2.0

static void stable_neohookean_runs_one_diagonal_on_slivers(void **state) {
  (void)state;
  static const piola_material_model models[] = {PIOLA_MODEL_STABLE_NEOHOOKEAN};
  /* the bar's stiff start costs about the same at any PIOLA_TEST_SCALE: the sanitizer pass
   * (scale below 0.5) runs the torus only, the Release pass both */
  if (test_scale() >= 0.5) real_mesh_scramble_models("gmsh/bar-186.msh", DIAGONAL, models, 1, DIAGONAL);
  real_mesh_scramble_models("gmsh/torus.msh", DIAGONAL, models, 1, DIAGONAL);
}

int main(void) {
  piola_set_thread_count(1); /* small bodies: results do not depend on the count */
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(stable_neohookean_runs_one_diagonal_on_slivers),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
