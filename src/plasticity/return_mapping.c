/* Radial return onto the yield surface and the limit projection (see return_mapping.h). */
#include "plasticity/return_mapping.h"

#include <math.h>

int piola__plastic_return_map(const plastic_params *p, const double fhat[3], double alpha,
                              double delta[3], double *dlambda) {
  double e[3], mean = 0;
  for (int i = 0; i < 3; ++i) {
    e[i] = log(fhat[i] > PIOLA_PLASTIC_FLAT_FLOOR ? fhat[i] : PIOLA_PLASTIC_FLAT_FLOOR);
    mean += e[i];
  }
  mean = p->volume_preserving ? mean / 3.0 : 0.0;
  double d[3] = {e[0] - mean, e[1] - mean, e[2] - mean};
  double norm = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  double gamma = p->yield + p->hardening * alpha;
  delta[0] = delta[1] = delta[2] = 0.0;
  *dlambda = 0.0;
  if (!(norm > gamma)) return 0;
  double dl = (norm - gamma) / (1.0 + p->hardening);
  double s = dl / norm;
  for (int i = 0; i < 3; ++i) delta[i] = s * d[i];
  *dlambda = dl;
  return 1;
}

static double clamp(double v, double lo, double hi) { return v < lo ? lo : (v > hi ? hi : v); }

int piola__plastic_clamp_log_stretches(double l[3], double limit, int keep_sum) {
  int inside = 1;
  for (int i = 0; i < 3; ++i) inside &= fabs(l[i]) <= limit;
  if (inside) return 0;
  if (!keep_sum) {
    for (int i = 0; i < 3; ++i) l[i] = clamp(l[i], -limit, limit);
    return 1;
  }
  /* sum_i clamp(l_i - mu) decreases in mu from 3 limit to -3 limit: bisect for the target */
  double target = clamp(l[0] + l[1] + l[2], -3.0 * limit, 3.0 * limit);
  double lo = fmin(fmin(l[0], l[1]), l[2]) - limit, hi = fmax(fmax(l[0], l[1]), l[2]) + limit;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * (1.0 + fabs(lo) + fabs(hi)); ++it) {
    double mu = 0.5 * (lo + hi), s = 0;
    for (int i = 0; i < 3; ++i) s += clamp(l[i] - mu, -limit, limit);
    if (s > target) lo = mu;
    else hi = mu;
  }
  double mu = 0.5 * (lo + hi);
  for (int i = 0; i < 3; ++i) l[i] = clamp(l[i] - mu, -limit, limit);
  return 1;
}
