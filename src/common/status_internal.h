/* Internal helpers for reporting failures.
 *
 *   if (e <= 0) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
 *                                 "youngs_modulus must be > 0 Pa, got %g", e);
 *
 * piola__fail stores the formatted message for piola_last_error() and returns the
 * status unchanged, so a failure is reported and propagated in one expression. */
#ifndef PIOLA_COMMON_STATUS_INTERNAL_H
#define PIOLA_COMMON_STATUS_INTERNAL_H

#include "piola/status.h"

#if defined(__GNUC__) || defined(__clang__)
#define PIOLA_PRINTF_LIKE(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define PIOLA_PRINTF_LIKE(fmt, args)
#endif

piola_status piola__fail(piola_status status, const char *format, ...) PIOLA_PRINTF_LIKE(2, 3);

#define PIOLA_FAIL(status, ...) piola__fail((status), __VA_ARGS__)

/* Propagate a non-OK status from a call. */
#define PIOLA_TRY(call)                   \
  do {                                    \
    piola_status piola_try_status_ = (call); \
    if (piola_try_status_ != PIOLA_OK) return piola_try_status_; \
  } while (0)

#endif
