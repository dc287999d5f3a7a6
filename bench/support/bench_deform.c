/* The force benchmarks' deformed state (bench_deform.h). */
#include "support/bench_deform.h"

#include <math.h>
#include <stdlib.h>

#include "support/bench_support.h"

/* Deformed positions: rest + noise (1% of the mean edge), then ~1% of tets get corner 0
 * mirrored through the plane of corners 1..3. */
double *bench_deformed_positions(const piola_elastic_body *body) {
  int32_t nv = piola_elastic_body_vertex_count(body), nt = piola_elastic_body_tet_count(body);
  const double *rest = piola_elastic_body_rest_positions(body);
  const int32_t *tets = piola_elastic_body_tets(body);
  double edge = 0;
  for (int32_t t = 0; t < nt; ++t) {
    const double *a = rest + 3 * tets[4 * t], *b = rest + 3 * tets[4 * t + 1];
    edge += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
  }
  edge /= nt;
  double *x = malloc(sizeof(double) * 3 * (size_t)nv);
  for (int32_t i = 0; i < 3 * nv; ++i) x[i] = rest[i] + 0.01 * edge * bench_uniform(-1, 1);
  for (int32_t t = 0; t < nt; ++t) {
    if (bench_uniform(0, 1) > 0.01) continue;
    const int32_t *c = tets + 4 * t;
    double *p = x + 3 * c[0], *a = x + 3 * c[1], *b = x + 3 * c[2], *d = x + 3 * c[3];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    double nrm[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    double nn = nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2];
    if (nn == 0) continue;
    double dist = ((p[0] - a[0]) * nrm[0] + (p[1] - a[1]) * nrm[1] + (p[2] - a[2]) * nrm[2]) / nn;
    for (int i = 0; i < 3; ++i) p[i] -= 2 * dist * nrm[i];
  }
  return x;
}

