/* Decimal output of doubles that reads back to the same bits, as short as cheaply possible. */
#include <stdio.h>
#include <stdlib.h>

#include "io/mesh_writers.h"
#include "io/text_scanner.h"

int piola__format_double(char *out, double v) {
  /* 15 significant digits suffice for most values that came from mesh files (and print
   * them as they were); 17 always round-trip. The 15-digit form is checked by the scanner's
   * exact fast path when it applies, else by strtod. */
  int n = snprintf(out, 32, "%.15g", v);
  double back;
  int exact = 0;
  size_t used = piola__parse_double_checked(out, out + n, &back, &exact);
  if (used == (size_t)n && exact) {
    if (back == v) return n;
  } else if (strtod(out, NULL) == v) {
    return n;
  }
  return snprintf(out, 32, "%.17g", v);
}
