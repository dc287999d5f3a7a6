/* Issue 21's scramble done-when on the sliver meshes for the models that stiffen without limit
 * under stretch: on gmsh/bar-186.msh (a 10:0.5:1 bar, slivers of mean ratio 0.02, dihedral
 * angles down to 3.6 degrees) corotated and the spline, on gmsh/torus.msh (491 tets, dihedral
 * angles down to 5.3 degrees) corotated, the spline and Stable Neo-Hookean, each from one
 * diagonal of scramble, run 2 s of simulated time with every step succeeding, a finite state
 * and the total energy never above the start's (real_mesh_scramble_run). A program of its own so that
 * ctest -j2 overlaps it with test_scrambles_every_model, which runs the other cases
 * (its header lists what neither runs, and why; docs/time-stepping.md "What the test affords").
 *
 * These runs became affordable with the step bound's direction weights
 * (src/force/stable_step_anisotropy.h): corotated on bar-186 from one diagonal took 117,365
 * steps for 2 s without them, 66,467 with them (the spline 55,107). Stable Neo-Hookean from one
 * diagonal still took 97,963 steps for its first 0.2 s, so it stays out. On the torus the
 * weights brought corotated from one diagonal from 17,669 steps for its first 0.1 s to 5,308
 * (the spline 5,468, Stable Neo-Hookean 8,413; docs/time-stepping.md "What the test affords").
 *
 * PIOLA_TEST_SCALE scales the 2 s (at least 0.02 s); PIOLA_TEST_MODEL selects a model by name;
 * PIOLA_TEST_VERBOSE prints steps and CPU time. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "piola/mesh_io.h"
#include "piola/threads.h"
#include "real_mesh_scenes.h"

#define DIAGONAL 2.0

static void corotated_and_spline_run_one_diagonal_on_slivers(void **state) {
  (void)state;
  static const piola_material_model models[] = {PIOLA_MODEL_COROTATED, PIOLA_MODEL_SPLINE};
  const double seconds = fmax(0.02, 2.0 * fmin(test_scale(), 1.0));
  const char *only = getenv("PIOLA_TEST_MODEL");
  piola_tet_mesh mesh = real_mesh_scaled("gmsh/bar-186.msh", DIAGONAL);
  for (size_t k = 0; k < sizeof models / sizeof models[0]; ++k) {
    if (only && strcmp(only, piola_material_model_name(models[k]))) continue;
    real_mesh_scramble_run(&mesh, "gmsh/bar-186.msh", models[k], DIAGONAL, seconds, NULL);
  }
  piola_tet_mesh_free(&mesh);
}

static void stiffening_models_run_one_diagonal_on_torus(void **state) {
  (void)state;
  static const piola_material_model models[] = {PIOLA_MODEL_COROTATED, PIOLA_MODEL_SPLINE,
                                                PIOLA_MODEL_STABLE_NEOHOOKEAN};
  const double seconds = fmax(0.02, 2.0 * fmin(test_scale(), 1.0));
  const char *only = getenv("PIOLA_TEST_MODEL");
  piola_tet_mesh mesh = real_mesh_scaled("gmsh/torus.msh", DIAGONAL);
  for (size_t k = 0; k < sizeof models / sizeof models[0]; ++k) {
    if (only && strcmp(only, piola_material_model_name(models[k]))) continue;
    real_mesh_scramble_run(&mesh, "gmsh/torus.msh", models[k], DIAGONAL, seconds, NULL);
  }
  piola_tet_mesh_free(&mesh);
}

int main(void) {
  piola_set_thread_count(1); /* a small body: results do not depend on the count */
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(corotated_and_spline_run_one_diagonal_on_slivers),
      cmocka_unit_test(stiffening_models_run_one_diagonal_on_torus),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
