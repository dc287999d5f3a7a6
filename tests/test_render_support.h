/* Meshes and pixel counting shared by the renderer tests. */
#ifndef PIOLA_TEST_RENDER_SUPPORT_H
#define PIOLA_TEST_RENDER_SUPPORT_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "piola/render.h"

typedef struct test_sphere {
  int32_t vertex_count, triangle_count;
  double *positions;
  int32_t *triangles;
} test_sphere;

/* A latitude-longitude sphere: `slices` around the pole axis (z), `stacks` from pole to
 * pole, 2 * slices * (stacks - 1) triangles wound outward, vertices on the sphere. */
static inline test_sphere test_uv_sphere(int slices, int stacks, double radius, double cx,
                                         double cy, double cz) {
  int32_t nv = 2 + slices * (stacks - 1), nt = 2 * slices * (stacks - 1);
  double *x = malloc(3 * (size_t)nv * sizeof *x);
  int32_t *tri = malloc(3 * (size_t)nt * sizeof *tri);
  x[0] = cx, x[1] = cy, x[2] = cz + radius; /* north pole */
  x[3] = cx, x[4] = cy, x[5] = cz - radius; /* south pole */
  for (int i = 1; i < stacks; ++i) {
    double th = M_PI * i / stacks;
    for (int j = 0; j < slices; ++j) {
      double ph = 2 * M_PI * j / slices;
      double *p = x + 3 * (2 + (size_t)(i - 1) * (size_t)slices + (size_t)j);
      p[0] = cx + radius * sin(th) * cos(ph);
      p[1] = cy + radius * sin(th) * sin(ph);
      p[2] = cz + radius * cos(th);
    }
  }
#define RING(i, j) (2 + ((i)-1) * slices + ((j) % slices))
  int32_t k = 0;
  for (int j = 0; j < slices; ++j) {
    tri[3 * k] = 0, tri[3 * k + 1] = RING(1, j), tri[3 * k + 2] = RING(1, j + 1), ++k;
    tri[3 * k] = 1, tri[3 * k + 1] = RING(stacks - 1, j + 1), tri[3 * k + 2] = RING(stacks - 1, j),
            ++k;
  }
  for (int i = 1; i < stacks - 1; ++i)
    for (int j = 0; j < slices; ++j) {
      int32_t a = RING(i, j), b = RING(i, j + 1), c = RING(i + 1, j), d = RING(i + 1, j + 1);
      tri[3 * k] = a, tri[3 * k + 1] = c, tri[3 * k + 2] = d, ++k;
      tri[3 * k] = a, tri[3 * k + 1] = d, tri[3 * k + 2] = b, ++k;
    }
#undef RING
  return (test_sphere){nv, nt, x, tri};
}

static inline void test_sphere_free(test_sphere *s) {
  free(s->positions);
  free(s->triangles);
  memset(s, 0, sizeof *s);
}

/* Pixels where a and b differ. */
static inline long test_count_differing(const piola_image *a, const piola_image *b) {
  long n = 0;
  for (size_t i = 0; i < (size_t)a->width * (size_t)a->height; ++i)
    if (memcmp(a->rgb + 3 * i, b->rgb + 3 * i, 3) != 0) ++n;
  return n;
}

/* Pixels whose colour is strongly red (the inverted-element highlight, shaded). */
static inline long test_count_red(const piola_image *a) {
  long n = 0;
  for (size_t i = 0; i < (size_t)a->width * (size_t)a->height; ++i) {
    const uint8_t *p = a->rgb + 3 * i;
    if (p[0] > 60 && p[1] * 2 < p[0] && p[2] * 2 < p[0]) ++n;
  }
  return n;
}

#endif
