/* Numbers on the command line (cli_numbers.h). */
#include "cli/cli_numbers.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>

bool cli_parse_long(const char *s, long lo, long hi, long *out) {
  char *end;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (!*s || *end || errno || v < lo || v > hi) return false;
  *out = v;
  return true;
}

bool cli_parse_double(const char *s, double *out) {
  char *end;
  double v = strtod(s, &end);
  if (!*s || *end || !isfinite(v)) return false;
  *out = v;
  return true;
}

bool cli_parse_vec3(const char *s, piola_vec3 *out) {
  char *end;
  double v[3];
  const char *p = s;
  for (int k = 0; k < 3; ++k) {
    v[k] = strtod(p, &end);
    if (end == p || !isfinite(v[k])) return false;
    if (k < 2 && *end != ',') return false;
    p = end + (k < 2);
  }
  if (*end) return false;
  *out = (piola_vec3){v[0], v[1], v[2]};
  return true;
}
