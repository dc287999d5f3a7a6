/* Growth of a malloc'd array whose size is not known in advance (a file being read, a list
 * of contacts): one function for the whole library. */
#ifndef PIOLA_COMMON_GROW_H
#define PIOLA_COMMON_GROW_H

#include <stddef.h>

/* Makes room for `need` items of `item` bytes in *array, whose room is *capacity items: the
 * room doubles (from 64) until it holds need, so n pushes cost O(n). Returns 0, or -1 when
 * memory is short or the size would overflow (then *array and *capacity are unchanged). */
int piola__grow(void **array, size_t *capacity, size_t need, size_t item);

#endif
