/* Numbers in messages: a refused value must read as refused. %g's six digits printed a
 * Poisson ratio one rounding above 0.5 as "got 0.5" and the cap 1000000 as 1e+06. Header-only,
 * so that every layer (the scene reader's messages too) prints numbers alike. */
#ifndef PIOLA_COMMON_NUMBER_TEXT_H
#define PIOLA_COMMON_NUMBER_TEXT_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "common/status_report.h"

/* v as an integer when it is one (below 1e15 in magnitude), else in the fewest significant
 * digits (6 to 17) that read back as v; written to buf, which is returned. */
static inline const char *piola__number_text(char buf[32], double v) {
  if (v == floor(v) && fabs(v) < 1e15) { /* integers as the docs write them */
    snprintf(buf, 32, "%.0f", v);
    return buf;
  }
  for (int digits = 6; digits <= 17; ++digits) {
    snprintf(buf, 32, "%.*g", digits, v);
    if (strtod(buf, NULL) == v) break;
  }
  return buf;
}

/* PIOLA_ERROR_INVALID_ARGUMENT with the message "RULE, got VALUE", the value printed as
 * piola__number_text prints it (rule: what the value must be, naming it). */
static inline piola_status piola__refuse_value(const char *rule, double value) {
  char got[32];
  return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s, got %s", rule,
                    piola__number_text(got, value));
}

#endif
