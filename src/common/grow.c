/* Array growth (grow.h). */
#include "common/grow.h"

#include <stdint.h>
#include <stdlib.h>

int piola__grow(void **array, size_t *capacity, size_t need, size_t item) {
  if (need <= *capacity) return 0;
  size_t c = *capacity ? *capacity : 64;
  while (c < need) {
    if (c > SIZE_MAX / 2 / item) return -1;
    c *= 2;
  }
  void *p = realloc(*array, c * item);
  if (!p) return -1;
  *array = p;
  *capacity = c;
  return 0;
}
