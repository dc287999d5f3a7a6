/* How piola code reports a failure, in every layer (core, scene, render, CLI):
 *
 *   if (e <= 0) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
 *                                 "youngs_modulus must be > 0 Pa, got %g", e);
 *
 * piola_fail (public, piola/status.h) stores the formatted message for piola_last_error() and
 * returns the status unchanged, so a failure is reported and propagated in one expression.
 * Macros only, over the public API, so the layers above the core may include it. */
#ifndef PIOLA_COMMON_STATUS_REPORT_H
#define PIOLA_COMMON_STATUS_REPORT_H

#include "piola/status.h"

#define PIOLA_FAIL(status, ...) piola_fail((status), __VA_ARGS__)

/* Propagate a non-OK status from a call. */
#define PIOLA_TRY(call)                   \
  do {                                    \
    piola_status piola_try_status_ = (call); \
    if (piola_try_status_ != PIOLA_OK) return piola_try_status_; \
  } while (0)

#endif
