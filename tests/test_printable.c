/* Error messages are printable (common/printable.c): control bytes, C1 controls and bytes
 * that are not valid UTF-8 become \xNN; valid UTF-8 text stays as it is. */
#include <string.h>

#include "test_support.h"

#include "common/printable.h"
#include "common/status_report.h"

static void escapes(const char *in, const char *expected) {
  char out[256];
  piola__printable(out, sizeof out, in);
  assert_string_equal(out, expected);
}

static void control_bytes_are_escaped(void **state) {
  (void)state;
  escapes("plain text: 1.5e-3, [x] {y}", "plain text: 1.5e-3, [x] {y}");
  escapes("\x1b[2J\x1b]0;title\x07", "\\x1b[2J\\x1b]0;title\\x07");
  escapes("a\nb\rc\td\x7f", "a\\x0ab\\x0dc\\x09d\\x7f");
}

static void utf8_is_kept_and_broken_utf8_escaped(void **state) {
  (void)state;
  escapes("caf\xc3\xa9 \xe2\x88\x87 \xf0\x9f\x98\x80", "caf\xc3\xa9 \xe2\x88\x87 \xf0\x9f\x98\x80");
  escapes(
      "\xc2\x9b"
      "31m",
      "\\xc2\\x9b31m"); /* C1 CSI as UTF-8 */
  escapes(
      "\x9b"
      "31m",
      "\\x9b31m");                            /* raw C1 byte */
  escapes("\xc0\xaf", "\\xc0\\xaf");          /* overlong '/' */
  escapes("\xed\xa0\x80", "\\xed\\xa0\\x80"); /* a surrogate */
  escapes("\xe2\x88", "\\xe2\\x88");          /* cut short */
  escapes("\xff\xfe", "\\xff\\xfe");
}

static void truncation_never_splits_an_escape(void **state) {
  (void)state;
  char out[8];
  piola__printable(out, sizeof out, "ab\x1b\x1b");
  assert_string_equal(out, "ab\\x1b"); /* the second escape does not fit whole */
  piola__printable(out, sizeof out, "abcde\xc3\xa9");
  assert_string_equal(out, "abcde\xc3\xa9"); /* 7 bytes fit */
  piola__printable(out, sizeof out, "abcdef\xc3\xa9");
  assert_string_equal(out, "abcdef"); /* a UTF-8 sequence is not split */
}

static void failure_messages_are_printable(void **state) {
  (void)state;
  PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s:3: expected a number, got '%s'", "m.node", "\x1b[31mx");
  assert_string_equal(piola_last_error(), "m.node:3: expected a number, got '\\x1b[31mx'");
  piola_clear_error();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(control_bytes_are_escaped),
      cmocka_unit_test(utf8_is_kept_and_broken_utf8_escaped),
      cmocka_unit_test(truncation_never_splits_an_escape),
      cmocka_unit_test(failure_messages_are_printable),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
