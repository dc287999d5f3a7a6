/* Disjoint sets of indices 0 .. n - 1 in a parent array (parent[i] == i at a root; start
 * with every index its own root): the impact zones of collision processing and the
 * fragments of fracture. */
#ifndef PIOLA_COMMON_UNION_FIND_H
#define PIOLA_COMMON_UNION_FIND_H

#include <stdint.h>

/* The root of i's set; halves the path on the way. */
static inline int32_t piola__union_find_root(int32_t *parent, int32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

/* Joins the sets of a and b; the smaller root becomes the root, so the sets and their roots
 * do not depend on the order of the joins. */
static inline void piola__union_find_join(int32_t *parent, int32_t a, int32_t b) {
  a = piola__union_find_root(parent, a), b = piola__union_find_root(parent, b);
  if (a < b)
    parent[b] = a;
  else if (b < a)
    parent[a] = b;
}

#endif
