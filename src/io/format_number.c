/* Decimal output of doubles that reads back to the same bits, as short as cheaply possible. */
#include <stdio.h>
#include <stdlib.h>

#include "io/mesh_writers.h"

int piola__format_double(char *out, double v) {
  /* 15 significant digits suffice for most values from mesh files; else 17 always do. */
  int n = snprintf(out, 32, "%.15g", v);
  if (strtod(out, NULL) == v) return n;
  n = snprintf(out, 32, "%.16g", v);
  if (strtod(out, NULL) == v) return n;
  return snprintf(out, 32, "%.17g", v);
}
