/* The energy check of the explicit step (src/sim/integrator.c, docs/time-stepping.md
 * "Energy check"), on an undamped 4x4x4 block released from a stretch of 1.2:
 *  - at the default cfl no step is redone (the check does not change a stable run) and the
 *    total energy stays within velocity Verlet's fluctuation;
 *  - past the stability limit (cfl 1.5) steps are redone and the energy peak is lower than
 *    without the check.
 * Shells the same way, on an undamped sheet released from an in-plane stretch. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "block_scenes.h"
#include "piola/world.h"
#include "sim/body.h"
#include "sim/world_internal.h"
#include "test_shell_fixtures.h"

static double total_energy(const piola_world *w) {
  piola_solid_stats es = piola_world_solid_stats(w, 0);
  return es.kinetic_energy + es.elastic_energy;
}

/* Largest total energy over `steps` steps of a block stretched by 1.2 along x, undamped,
 * and the redos of those steps. */
static double peak_energy(piola_material_model model, double cfl, double viscosity, int steps,
                          int *redos) {
  const piola_mat3 stretch = {{{1.2, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  /* the setting these checks were measured with (the default before issue 19 item 4): the
   * unstable runs reach the threshold, and CLAMP's energy (neo-Hookean's default now) is not
   * the potential of its stress there, so the check catches less of the blow-up */
  piola_world *w = deformed_block_world_inverting(model, PIOLA_INVERSION_LINEAR, 0.3, 4, stretch,
                                                  viscosity, cfl, 0);
  const double e0 = total_energy(w);
  double peak = e0;
  *redos = 0;
  for (int n = 0; n < steps; ++n) {
    piola_step_stats st;
    assert_int_equal(piola_world_step(w, 0, &st), PIOLA_OK);
    assert_int_equal(st.step_retries, 0);
    *redos += st.energy_redos;
    peak = fmax(peak, total_energy(w));
  }
  piola_world_destroy(w);
  return peak / e0;
}

/* At the default cfl the step is stable: no step is redone, so the check leaves the run
 * exactly as it was (damped and undamped, every isotropic model). */
static void stable_steps_are_not_redone(void **state) {
  (void)state;
  static const piola_material_model models[] = {
      PIOLA_MODEL_ROTATED_LINEAR, PIOLA_MODEL_COROTATED, PIOLA_MODEL_STVK, PIOLA_MODEL_NEOHOOKEAN,
      PIOLA_MODEL_SPLINE, PIOLA_MODEL_STABLE_NEOHOOKEAN};
  const int steps = (int)test_samples(600, 100);
  for (int k = 0; k < 6; ++k)
    for (int damped = 0; damped < 2; ++damped) {
      int redos = -1;
      const double peak = peak_energy(models[k], 0.5, damped ? 5.0 : 0.0, steps, &redos);
      if (redos != 0) fail_msg("%s, viscosity %d: %d redos", piola_material_model_name(models[k]), damped ? 5 : 0, redos);
      /* and the energy stays bounded (velocity Verlet's fluctuation, no growth) */
      assert_true(peak < 1.5);
    }
}

/* cfl 1.5 is past the stability limit of this block: without the check its energy grows
 * ~600 times in 600 steps; the check redoes the steps whose gain no stable step can produce
 * and holds the peak about three times lower (a slowly growing mode is not caught: see
 * docs/time-stepping.md). */
static void unstable_steps_are_redone(void **state) {
  (void)state;
  int redos_off = -1, redos_on = -1;
  piola__step_energy_check = 0;
  const double off = peak_energy(PIOLA_MODEL_NEOHOOKEAN, 1.5, 0, 600, &redos_off);
  piola__step_energy_check = 1;
  const double on = peak_energy(PIOLA_MODEL_NEOHOOKEAN, 1.5, 0, 600, &redos_on);
  if (getenv("PIOLA_TEST_VERBOSE"))
    print_message("cfl 1.5: peak energy %g E0 without the check, %g E0 with it (%d redos)\n", off, on, redos_on);
  assert_int_equal(redos_off, 0);
  assert_true(off > 100);
  assert_true(redos_on > 0);
  assert_true(on < 0.5 * off);
}

/* Largest total energy (kinetic, membrane, bending) over `steps` steps of an undamped
 * 1 x 1 m sheet (12 x 12 cells, 1 mm, E = 100 kPa) released from a stretch of `stretch`
 * along x and a slight sag (so bending works too), and the redos of those steps. */
static double shell_peak_energy(piola_material_model model, double cfl, double stretch, int steps,
                                int *redos) {
  piola_world *w = shell_sheet_world(model, cfl, 1e-4, NULL, 0);
  world_body *b = &w->bodies[0];
  for (int32_t i = 0; i < b->n; ++i) {
    double *x = b->x + 3 * i;
    x[2] += 0.02 * (x[0] * x[0] + x[1] * x[1]);
    x[0] *= stretch;
  }
  assert_int_equal(piola__body_update_forces(b, 0.0), PIOLA_OK);
  const piola_world_shell_stats s0 = piola_world_shell_get_stats(w, 0);
  const double e0 = s0.kinetic_energy + s0.membrane_energy + s0.bending_energy;
  double peak = e0;
  *redos = 0;
  for (int n = 0; n < steps; ++n) {
    piola_step_stats st;
    assert_int_equal(piola_world_step(w, 0, &st), PIOLA_OK);
    if (cfl <= 0.5 && st.step_retries != 0)
      fail_msg("%s: step %d retried %d times", piola_material_model_name(model), n,
               st.step_retries);
    *redos += st.energy_redos;
    const piola_world_shell_stats s = piola_world_shell_get_stats(w, 0);
    peak = fmax(peak, s.kinetic_energy + s.membrane_energy + s.bending_energy);
  }
  piola_world_destroy(w);
  return peak / e0;
}

/* A stable shell run is left as it was; one past the stability limit is redone and its energy
 * held lower. */
static void shells_are_checked_too(void **state) {
  (void)state;
  const int steps = (int)test_samples(600, 150);
  for (int mi = 0; mi < SHELL_MODEL_COUNT; ++mi) {
    int redos = -1;
    const double peak = shell_peak_energy(shell_all_models[mi], 0.5, 1.2, steps, &redos);
    if (redos != 0 || !(peak < 1.5))
      fail_msg("%s sheet at cfl 0.5: %d redos, peak %g E0",
               piola_material_model_name(shell_all_models[mi]), redos, peak);
  }
  int redos_off = -1, redos_on = -1;
  piola__step_energy_check = 0;
  const double off = shell_peak_energy(PIOLA_MODEL_STVK, 1.5, 1.2, steps, &redos_off);
  piola__step_energy_check = 1;
  const double on = shell_peak_energy(PIOLA_MODEL_STVK, 1.5, 1.2, steps, &redos_on);
  if (getenv("PIOLA_TEST_VERBOSE"))
    print_message(
        "sheet at cfl 1.5: peak energy %g E0 without the check, %g E0 with it (%d redos)\n", off,
        on, redos_on);
  assert_int_equal(redos_off, 0);
  assert_true(off > 100);
  assert_true(redos_on > 0);
  assert_true(on < 0.5 * off);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(stable_steps_are_not_redone),
      cmocka_unit_test(unstable_steps_are_redone),
      cmocka_unit_test(shells_are_checked_too),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
