/* Self-intersection of a triangle surface (surface_intersection.h). */
#include "contact/surface_intersection.h"

#include <math.h>
#include <stdlib.h>

#include "contact/bvh.h"
#include "contact/triangle_intersection.h"

static int share_vertex(const int32_t *a, const int32_t *b) {
  for (int p = 0; p < 3; ++p)
    for (int q = 0; q < 3; ++q)
      if (a[p] == b[q]) return 1;
  return 0;
}

/* The first pair (a < b, in order of a) of the COUNT triangles that share no vertex and
 * intersect or touch, taken only across groups when GROUP is given: 1 with the pair in
 * PAIR, 0 for none, -1 out of memory. */
static int first_intersection(const double *x, const int32_t *tris, const int32_t *group,
                              int32_t count, int32_t pair[2]) {
  if (count < 2) return 0;
  piola__box *boxes = calloc((size_t)count, sizeof(piola__box));
  piola__bvh bvh = {0};
  piola__index_list near = {0};
  int found = -1;
  if (!boxes) goto done;
  for (int32_t t = 0; t < count; ++t) boxes[t] = piola__triangle_box(x, tris + 3 * (size_t)t);
  if (piola__bvh_build(&bvh, boxes, count) != 0) goto done;
  found = 0;
  for (int32_t a = 0; a < count && found == 0; ++a) {
    near.count = 0;
    if (piola__bvh_query(&bvh, &boxes[a], &near) != 0) {
      found = -1;
      break;
    }
    const int32_t *ta = tris + 3 * (size_t)a;
    const double *p[3] = {x + 3 * (size_t)ta[0], x + 3 * (size_t)ta[1], x + 3 * (size_t)ta[2]};
    /* the query lists candidates in the tree's order: the pair reported is the first b */
    int32_t first_b = -1;
    for (int64_t k = 0; k < near.count; ++k) {
      const int32_t b = near.items[k];
      const int32_t *tb = tris + 3 * (size_t)b;
      if (b <= a || (first_b >= 0 && b > first_b) || (group && group[a] == group[b]) ||
          share_vertex(ta, tb))
        continue; /* each pair once; neighbours touch */
      const double *q[3] = {x + 3 * (size_t)tb[0], x + 3 * (size_t)tb[1], x + 3 * (size_t)tb[2]};
      if (piola__triangles_intersect(p, q) != 0) first_b = b;
    }
    if (first_b >= 0) found = 1, pair[0] = a, pair[1] = first_b;
  }
done:
  free(boxes);
  free(near.items);
  piola__bvh_free(&bvh);
  return found;
}

int piola__surface_intersects(const double *x, const int32_t *tris, int32_t count) {
  int32_t pair[2];
  return first_intersection(x, tris, NULL, count, pair);
}

int piola__surfaces_cross(const double *x, const int32_t *tris, const int32_t *group, int32_t count,
                          int32_t pair[2]) {
  return first_intersection(x, tris, group, count, pair);
}
