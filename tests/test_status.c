/* Status codes and the per-thread error message. */
#include "test_support.h"

#include "common/status_report.h"

static void failure_message_is_kept_until_cleared(void **state) {
  (void)state;
  piola_clear_error();
  assert_string_equal(piola_last_error(), "");
  piola_status s = PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "poisson_ratio must be < 0.5, got %g", 0.7);
  assert_int_equal(s, PIOLA_ERROR_INVALID_ARGUMENT);
  assert_string_equal(piola_last_error(), "poisson_ratio must be < 0.5, got 0.7");
  piola_clear_error();
  assert_string_equal(piola_last_error(), "");
}

static void every_status_has_a_name(void **state) {
  (void)state;
  for (int s = PIOLA_ERROR_UNSUPPORTED; s <= PIOLA_OK; ++s)
    assert_string_not_equal(piola_status_name((piola_status)s), "unknown status");
  assert_string_equal(piola_status_name((piola_status)42), "unknown status");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(failure_message_is_kept_until_cleared),
      cmocka_unit_test(every_status_has_a_name),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
