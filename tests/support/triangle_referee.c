/* The exact triangle referee of the contact tests (triangle_referee.h). */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>

#include "contact/triangle_intersection.h"
#include "piola/shell_body.h"
#include "piola/world.h"
#include "piola/world_shells.h"
#include "triangle_referee.h"

typedef struct tri_box {
  double lo[3], hi[3];
  int32_t set, tri;
} tri_box;

static int by_lo_x(const void *a, const void *b) {
  double u = ((const tri_box *)a)->lo[0], v = ((const tri_box *)b)->lo[0];
  return (u > v) - (u < v);
}

/* Whether triangles ta of xa and tb of xb intersect (0 or 1; the test fails on the exact
 * test's error); 0 for two triangles of one set that share a vertex. */
static int pair_intersects(const double *xa, const int32_t *ta, const double *xb, const int32_t *tb,
                           int same_set) {
  if (same_set) {
    int shared = 0;
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q) shared |= ta[p] == tb[q];
    if (shared) return 0;
  }
  const double *p[3] = {xa + 3 * ta[0], xa + 3 * ta[1], xa + 3 * ta[2]};
  const double *q[3] = {xb + 3 * tb[0], xb + 3 * tb[1], xb + 3 * tb[2]};
  int r = piola__triangles_intersect(p, q);
  assert_true(r >= 0);
  return r;
}

/* Intersecting triangle pairs over all sets (within and across), except pairs of one set
 * that share a vertex. Pairs whose closed boxes are disjoint cannot share a point. */
long referee_count_intersections(const judged *sets, int set_count) {
  int32_t n = 0;
  for (int s = 0; s < set_count; ++s) n += sets[s].count;
  tri_box *boxes = malloc(sizeof(tri_box) * (size_t)n);
  assert_non_null(boxes);
  int32_t k = 0;
  for (int s = 0; s < set_count; ++s)
    for (int32_t t = 0; t < sets[s].count; ++t, ++k) {
      tri_box *b = &boxes[k];
      b->set = s, b->tri = t;
      for (int d = 0; d < 3; ++d) b->lo[d] = INFINITY, b->hi[d] = -INFINITY;
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d) {
          double v = sets[s].x[3 * sets[s].tris[3 * t + c] + d];
          b->lo[d] = fmin(b->lo[d], v), b->hi[d] = fmax(b->hi[d], v);
        }
    }
  qsort(boxes, (size_t)n, sizeof(tri_box), by_lo_x);
  long hits = 0;
  for (int32_t i = 0; i < n; ++i)
    for (int32_t j = i + 1; j < n && boxes[j].lo[0] <= boxes[i].hi[0]; ++j) {
      const tri_box *a = &boxes[i], *b = &boxes[j];
      if (a->lo[1] > b->hi[1] || b->lo[1] > a->hi[1] || a->lo[2] > b->hi[2] || b->lo[2] > a->hi[2])
        continue;
      hits += pair_intersects(sets[a->set].x, sets[a->set].tris + 3 * a->tri, sets[b->set].x,
                              sets[b->set].tris + 3 * b->tri, a->set == b->set);
    }
  free(boxes);
  return hits;
}

long referee_count_intersections_every_pair(judged set) {
  long hits = 0;
  for (int32_t a = 0; a < set.count; ++a)
    for (int32_t b = a + 1; b < set.count; ++b)
      hits += pair_intersects(set.x, set.tris + 3 * a, set.x, set.tris + 3 * b, 1);
  return hits;
}


judged referee_shell_set(const piola_world *w, int32_t shell) {
  const piola_shell_body *b = piola_world_shell_body(w, shell);
  return (judged){piola_world_shell_positions(w, shell), piola_shell_body_triangles(b),
                  piola_shell_body_triangle_count(b)};
}
