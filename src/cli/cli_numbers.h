/* Numbers on the command line: the whole argument must be the number (no trailing text),
 * finite, and for integers within [lo, hi]. Each returns false, leaving *out alone,
 * otherwise; the caller names the option in its message. */
#ifndef PIOLA_CLI_NUMBERS_H
#define PIOLA_CLI_NUMBERS_H

#include <stdbool.h>

#include "piola/math_types.h"

bool cli_parse_long(const char *s, long lo, long hi, long *out);
bool cli_parse_double(const char *s, double *out);
/* "x,y,z" */
bool cli_parse_vec3(const char *s, piola_vec3 *out);

#endif
