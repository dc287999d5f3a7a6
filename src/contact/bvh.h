/* Bounding-volume hierarchy of axis-aligned boxes, the broad phase of collision processing.
 *
 * The tree is built top-down once per step from the boxes at the start of the step (median
 * split of the box centres along the longest axis, at most four primitives per leaf), and then
 * refit, without changing its shape, to the swept boxes of each detection pass. A build is
 * O(n log n) and a refit O(n); rebuilding every step keeps the tree tight however much the
 * surface deforms between steps. Nodes are stored in preorder: the left child of an inner
 * node directly follows it, so a refit is one backward sweep. Queries are read-only and run
 * from many threads at once. */
#ifndef PIOLA_CONTACT_BVH_H
#define PIOLA_CONTACT_BVH_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

typedef struct piola__box {
  double lo[3], hi[3];
} piola__box;

typedef struct piola__bvh_node {
  piola__box box;
  int32_t first; /* leaf: first entry in order; inner node: index of the right child */
  int32_t count; /* leaf: number of primitives (> 0); inner node: 0 */
} piola__bvh_node;

typedef struct piola__bvh {
  int32_t primitive_count;
  int32_t node_count;
  piola__bvh_node *nodes;
  int32_t *order;         /* primitive indices, grouped by leaf */
  piola__box *leaf_boxes; /* boxes[order[k]]: the primitive boxes in leaf order, so the tests
                             at the leaves read memory in sequence (set by build and refit) */
} piola__bvh;

/* A growable list of indices. */
typedef struct piola__index_list {
  int32_t *items;
  int64_t count;
  size_t capacity; /* items (common/grow.h) */
} piola__index_list;

/* Makes room for a tree over n primitives (2n nodes, n order and leaf entries; memory is
 * reused when it suffices) and empties it. Returns 0, or -1 when memory runs out. */
int piola__bvh_reserve(piola__bvh *bvh, int32_t n);

/* Builds (or rebuilds, reusing memory) the tree over n boxes. Returns 0, or -1 when memory
 * runs out. */
int piola__bvh_build(piola__bvh *bvh, const piola__box *boxes, int32_t n);

/* Recomputes every node box (and leaf_boxes) from the primitive boxes (same count and order
 * as the build). */
void piola__bvh_refit(piola__bvh *bvh, const piola__box *boxes);

/* Appends to out the primitives whose boxes (as of the last build or refit) overlap query.
 * Returns 0, or -1 out of memory. */
int piola__bvh_query(const piola__bvh *bvh, const piola__box *query, piola__index_list *out);

void piola__bvh_free(piola__bvh *bvh);

int piola__index_list_push(piola__index_list *list, int32_t value);

/* The box of the points within r of x in every coordinate. */
static inline piola__box piola__box_around(const double x[3], double r) {
  return (piola__box){{x[0] - r, x[1] - r, x[2] - r}, {x[0] + r, x[1] + r, x[2] + r}};
}

/* The box of triangle tri (three vertex indices) of positions x (3 per vertex). */
static inline piola__box piola__triangle_box(const double *x, const int32_t *tri) {
  piola__box b = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
  for (int c = 0; c < 3; ++c)
    for (int d = 0; d < 3; ++d) {
      const double v = x[3 * (size_t)tri[c] + d];
      b.lo[d] = fmin(b.lo[d], v), b.hi[d] = fmax(b.hi[d], v);
    }
  return b;
}

static inline int piola__boxes_overlap(const piola__box *a, const piola__box *b) {
  return a->lo[0] <= b->hi[0] && b->lo[0] <= a->hi[0] && a->lo[1] <= b->hi[1] &&
         b->lo[1] <= a->hi[1] && a->lo[2] <= b->hi[2] && b->lo[2] <= a->hi[2];
}

#endif
