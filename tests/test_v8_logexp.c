/* The 8-lane log and exp (src/math/v8_logexp.h) against libm: relative error over the whole
 * range they are used on (and far beyond), near 1 where log is small, exact identities,
 * and the clamp of exp. */
#include <float.h>
#include <math.h>

#include "math/v8_logexp.h"
#include "test_support.h"

static double rel_err(double got, double want) {
  if (got == want) return 0.0;
  return fabs(got - want) / fmax(fabs(want), DBL_MIN);
}

/* log of 8 lanes of xs against libm; returns the worst relative error */
static double log_error(const double xs[8]) {
  double out[8];
  piola__v8_store(out, piola__v8_log(piola__v8_load(xs)));
  double worst = 0;
  for (int l = 0; l < 8; ++l) {
    double want = log(xs[l]);
    /* near 1 log is tiny: judge by the absolute error relative to an ulp of x as well */
    double err = fabs(want) < 1e-3 ? fabs(out[l] - want) / fmax(fabs(want), 1e-300) : rel_err(out[l], want);
    if (err > worst) worst = err;
  }
  return worst;
}

static double exp_error(const double xs[8]) {
  double out[8];
  piola__v8_store(out, piola__v8_exp(piola__v8_load(xs)));
  double worst = 0;
  for (int l = 0; l < 8; ++l) worst = fmax(worst, rel_err(out[l], exp(xs[l])));
  return worst;
}

static void log_matches_libm_over_the_range(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(11);
  long n = test_samples(200000, 2000);
  double worst = 0;
  for (long i = 0; i < n; ++i) {
    double xs[8];
    for (int l = 0; l < 8; ++l) {
      switch ((i + l) % 4) {
        case 0: xs[l] = exp(test_rng_uniform(&rng, -690, 690)); break;      /* whole range */
        case 1: xs[l] = test_rng_uniform(&rng, 0.01, 100); break;           /* plastic range */
        case 2: xs[l] = 1.0 + test_rng_uniform(&rng, -1e-3, 1e-3); break;   /* near 1 */
        default: xs[l] = 1.0 + ldexp(test_rng_uniform(&rng, -1, 1), -40); break; /* very near 1 */
      }
    }
    worst = fmax(worst, log_error(xs));
  }
  print_message("log: worst relative error %.3g over %ld x 8 samples\n", worst, n);
  assert_true(worst < 1e-15);
}

static void log_of_octave_boundaries_and_powers_of_two(void **state) {
  (void)state;
  double xs[8] = {1.0, 2.0, 0.5, 1.4142135623730951, 1.4142135623730949, 0.7071067811865476, 1024.0, 0x1p-1000};
  assert_true(log_error(xs) < 1e-15);
  double out[8];
  piola__v8_store(out, piola__v8_log(piola__v8_load(xs)));
  assert_true(out[0] == 0.0); /* log 1 is exactly 0 */
  double tiny[8] = {DBL_MIN, 0x1p-1021, 3e-308, DBL_MAX, 1e308, nextafter(1.0, 2.0), nextafter(1.0, 0.0), 7.0};
  assert_true(log_error(tiny) < 1e-15);
}

static void exp_matches_libm_over_the_range(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(12);
  long n = test_samples(200000, 2000);
  double worst = 0;
  for (long i = 0; i < n; ++i) {
    double xs[8];
    for (int l = 0; l < 8; ++l) {
      switch ((i + l) % 3) {
        case 0: xs[l] = test_rng_uniform(&rng, -700, 700); break;
        case 1: xs[l] = test_rng_uniform(&rng, -5, 5); break;
        default: xs[l] = test_rng_uniform(&rng, -1e-6, 1e-6); break;
      }
    }
    worst = fmax(worst, exp_error(xs));
  }
  print_message("exp: worst relative error %.3g over %ld x 8 samples\n", worst, n);
  assert_true(worst < 1e-15);
}

static void exp_identities_and_clamp(void **state) {
  (void)state;
  double xs[8] = {0.0, -0.0, 1.0, -1.0, 0.34657359027997264, -0.34657359027997264, 1e3, -1e3};
  double out[8];
  piola__v8_store(out, piola__v8_exp(piola__v8_load(xs)));
  assert_true(out[0] == 1.0 && out[1] == 1.0); /* exp 0 is exactly 1: unyielded lanes stay put */
  for (int l = 2; l < 6; ++l) assert_true(rel_err(out[l], exp(xs[l])) < 1e-15);
  assert_true(rel_err(out[6], exp(700.0)) < 1e-15);
  assert_true(rel_err(out[7], exp(-700.0)) < 1e-15);
  /* exp(log x) round trip over the plastic range */
  test_rng rng = test_rng_seeded(13);
  for (int i = 0; i < 1000; ++i) {
    double in[8], back[8];
    for (int l = 0; l < 8; ++l) in[l] = test_rng_uniform(&rng, 1e-3, 1e3);
    piola__v8_store(back, piola__v8_exp(piola__v8_log(piola__v8_load(in))));
    for (int l = 0; l < 8; ++l) assert_true(rel_err(back[l], in[l]) < 1e-13);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(log_matches_libm_over_the_range),
      cmocka_unit_test(log_of_octave_boundaries_and_powers_of_two),
      cmocka_unit_test(exp_matches_libm_over_the_range),
      cmocka_unit_test(exp_identities_and_clamp),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
