/* Per-thread last-error message. A thread-local buffer keeps error reporting free of
 * allocation (it must work when allocation itself failed) and safe under OpenMP. */
#include "common/status_report.h"
#include "common/printable.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static _Thread_local char last_error_message[1024];

const char *piola_status_name(piola_status status) {
  switch (status) {
    case PIOLA_OK: return "ok";
    case PIOLA_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case PIOLA_ERROR_NOT_FINITE: return "not finite";
    case PIOLA_ERROR_DEGENERATE_ELEMENT: return "degenerate element";
    case PIOLA_ERROR_OUT_OF_MEMORY: return "out of memory";
    case PIOLA_ERROR_IO: return "input/output error";
    case PIOLA_ERROR_PARSE: return "parse error";
    case PIOLA_ERROR_UNSUPPORTED: return "unsupported";
    case PIOLA_ERROR_NOT_CONVERGED: return "not converged";
  }
  return "unknown status";
}

const char *piola_last_error(void) { return last_error_message; }

void piola_clear_error(void) { last_error_message[0] = '\0'; }

piola_status piola_fail(piola_status status, const char *format, ...) {
  /* Callers often wrap the last message ("%s: solids[0]: %s", ..., piola_last_error()):
   * format into a copy first, as the arguments may point into the buffer being written. */
  char message[sizeof last_error_message];
  va_list args;
  va_start(args, format);
  vsnprintf(message, sizeof message, format, args);
  va_end(args);
  /* messages quote file content: no control bytes reach the terminal */
  piola__printable(last_error_message, sizeof last_error_message, message);
  return status;
}
