/* Power iteration for the stability limit (stability_rate.h). */
#include "support/stability_rate.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

piola_status largest_stability_rate2(piola_elastic_body *body, const double *x, double *u,
                                     int iterations, double *rate2) {
  const int32_t n = 3 * piola_elastic_body_vertex_count(body);
  const double *mass = piola_elastic_body_masses(body);
  double *y = malloc(sizeof *y * (size_t)n);
  double *fp = malloc(sizeof *fp * (size_t)n), *fm = malloc(sizeof *fm * (size_t)n);
  double *r = malloc(sizeof *r * (size_t)n); /* M^-1/2, 0 on vertices in no tet */
  for (int32_t j = 0; j < n; ++j) r[j] = mass[j / 3] > 0 ? 1 / sqrt(mass[j / 3]) : 0;
  double lambda = 0, scale = 0;
  for (int32_t j = 0; j < n; ++j) scale = fmax(scale, fabs(x[j]));
  const double h = 1e-7 * scale;
  piola_status status = PIOLA_OK, s;
  for (int it = 0; it < iterations; ++it) {
    double norm = 0;
    for (int32_t j = 0; j < n; ++j) norm += u[j] * u[j];
    norm = sqrt(norm);
    for (int32_t j = 0; j < n; ++j) u[j] /= norm;
    /* y = M^-1/2 K M^-1/2 u, K = -df/dx */
    for (int32_t j = 0; j < n; ++j) y[j] = x[j] + h * u[j] * r[j];
    if ((s = piola_elastic_body_update(body, y, 1.0, fp, NULL)) != PIOLA_OK && status == PIOLA_OK) status = s;
    for (int32_t j = 0; j < n; ++j) y[j] = x[j] - h * u[j] * r[j];
    if ((s = piola_elastic_body_update(body, y, 1.0, fm, NULL)) != PIOLA_OK && status == PIOLA_OK) status = s;
    double rq = 0;
    for (int32_t j = 0; j < n; ++j) {
      y[j] = -(fp[j] - fm[j]) / (2 * h) * r[j];
      rq += u[j] * y[j];
    }
    lambda = rq;
    memcpy(u, y, sizeof *u * (size_t)n);
  }
  /* the state the caller left */
  if ((s = piola_elastic_body_update(body, x, 1.0, fp, NULL)) != PIOLA_OK && status == PIOLA_OK) status = s;
  free(y), free(fp), free(fm), free(r);
  *rate2 = lambda;
  return status;
}
