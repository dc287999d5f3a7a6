/* piola: status codes and error messages.
 *
 * Every fallible public function returns a piola_status. PIOLA_OK is zero, errors are
 * negative. When a function fails it also leaves a human-readable message (naming the
 * file, line, element index or parameter at fault) in a per-thread buffer that
 * piola_last_error() returns until the next failure on the same thread. */
#ifndef PIOLA_STATUS_H
#define PIOLA_STATUS_H

#include "piola/export.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum piola_status {
  PIOLA_OK = 0,
  PIOLA_ERROR_INVALID_ARGUMENT = -1,    /* a parameter is out of its documented range */
  PIOLA_ERROR_NOT_FINITE = -2,          /* NaN or Inf in an input or in the state */
  PIOLA_ERROR_DEGENERATE_ELEMENT = -3,  /* a rest element has (near) zero volume or area */
  PIOLA_ERROR_OUT_OF_MEMORY = -4,
  PIOLA_ERROR_IO = -5,                  /* a file could not be opened, read or written */
  PIOLA_ERROR_PARSE = -6,               /* a file or scene is malformed */
  PIOLA_ERROR_UNSUPPORTED = -7,         /* well-formed input that piola does not handle */
  PIOLA_ERROR_NOT_CONVERGED = -8,       /* an iterative solve (the implicit integrators'
                                           Newton) did not reach its tolerance */
} piola_status;

/* Short constant name of a status, e.g. "invalid argument". Never NULL. */
PIOLA_API const char *piola_status_name(piola_status status);

/* The message of the last failure on the calling thread ("" if none). */
PIOLA_API const char *piola_last_error(void);

/* Clears the calling thread's last error message. */
PIOLA_API void piola_clear_error(void);

#if defined(__GNUC__) || defined(__clang__)
#define PIOLA_PRINTF_LIKE(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define PIOLA_PRINTF_LIKE(fmt, args)
#endif

/* Sets the calling thread's last error message (printf-style format) and returns status
 * unchanged: how the layers built on the core (scene files, the renderer) and code that
 * calls back into piola report a failure the way piola's own functions do. */
PIOLA_API piola_status piola_fail(piola_status status, const char *format, ...)
    PIOLA_PRINTF_LIKE(2, 3);

#ifdef __cplusplus
}
#endif

#endif
