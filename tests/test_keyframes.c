/* Keyframed scalars: piecewise-linear interpolation, clamping at the ends, validation. */
#include <math.h>
#include <string.h>

#include "test_support.h"

#include "piola/keyframes.h"

static void constant_track_is_constant(void **state) {
  (void)state;
  piola_track c = piola_track_constant(2.5);
  assert_int_equal(c.key_count, 0);
  assert_true(piola_track_eval(&c, -100.0) == 2.5);
  assert_true(piola_track_eval(&c, 0.0) == 2.5);
  assert_true(piola_track_eval(&c, 1e9) == 2.5);
}

static void keys_interpolate_linearly_and_clamp(void **state) {
  (void)state;
  const double times[] = {0.0, 1.0, 3.0, 3.5};
  const double values[] = {1.0, 3.0, -1.0, 0.0};
  piola_track track;
  assert_int_equal(piola_track_from_keys(times, values, 4, &track), PIOLA_OK);
  /* At the keys. */
  for (int i = 0; i < 4; ++i) assert_close(piola_track_eval(&track, times[i]), values[i], 1e-15);
  /* Between keys: by hand. */
  assert_close(piola_track_eval(&track, 0.5), 2.0, 1e-15);
  assert_close(piola_track_eval(&track, 0.25), 1.5, 1e-15);
  assert_close(piola_track_eval(&track, 2.0), 1.0, 1e-15);
  assert_close(piola_track_eval(&track, 2.5), 0.0, 1e-15);
  assert_close(piola_track_eval(&track, 3.25), -0.5, 1e-15);
  /* Before the first key: the first value; after the last: the last. */
  assert_close(piola_track_eval(&track, -7.0), 1.0, 0);
  assert_close(piola_track_eval(&track, 100.0), 0.0, 0);
  /* Continuity at every key. */
  for (int i = 0; i < 4; ++i) {
    double below = piola_track_eval(&track, times[i] - 1e-9);
    double above = piola_track_eval(&track, times[i] + 1e-9);
    assert_close(below, values[i], 1e-8);
    assert_close(above, values[i], 1e-8);
  }
}

static void single_key_is_constant(void **state) {
  (void)state;
  const double t = 2.0, value = -4.0;
  piola_track track;
  assert_int_equal(piola_track_from_keys(&t, &value, 1, &track), PIOLA_OK);
  assert_close(piola_track_eval(&track, 0.0), -4.0, 0);
  assert_close(piola_track_eval(&track, 2.0), -4.0, 0);
  assert_close(piola_track_eval(&track, 5.0), -4.0, 0);
}

static void bad_keys_are_rejected(void **state) {
  (void)state;
  piola_track track = piola_track_constant(7.0);
  const double equal_times[] = {0.0, 1.0, 1.0};
  const double decreasing[] = {0.0, 2.0, 1.0};
  const double values[] = {0.0, 1.0, 2.0};
  const double bad_values[] = {0.0, NAN, 2.0};
  const double inf_times[] = {0.0, INFINITY, 2.0};
  assert_int_equal(piola_track_from_keys(equal_times, values, 3, &track),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "keys[2]"));
  assert_int_equal(piola_track_from_keys(decreasing, values, 3, &track),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_track_from_keys(values, bad_values, 3, &track), PIOLA_ERROR_NOT_FINITE);
  assert_int_equal(piola_track_from_keys(inf_times, values, 3, &track), PIOLA_ERROR_NOT_FINITE);
  assert_int_equal(piola_track_from_keys(values, values, 0, &track), PIOLA_ERROR_INVALID_ARGUMENT);
  double many[PIOLA_MAX_KEYS + 1];
  for (int i = 0; i <= PIOLA_MAX_KEYS; ++i) many[i] = i;
  assert_int_equal(piola_track_from_keys(many, many, PIOLA_MAX_KEYS + 1, &track),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_track_from_keys(many, many, PIOLA_MAX_KEYS, &track), PIOLA_OK);
  assert_close(piola_track_eval(&track, 10.5), 10.5, 1e-14);
  /* A failed call leaves the output untouched. */
  piola_track kept = piola_track_constant(7.0);
  (void)piola_track_from_keys(decreasing, values, 3, &kept);
  assert_true(kept.key_count == 0 && kept.value == 7.0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(constant_track_is_constant),
      cmocka_unit_test(keys_interpolate_linearly_and_clamp),
      cmocka_unit_test(single_key_is_constant),
      cmocka_unit_test(bad_keys_are_rejected),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
