/* Coulomb friction against the obstacles (obstacle_friction.h). */
#include "sim/obstacle_friction.h"

#include <math.h>

void piola__nearest_obstacle_motion(piola_obstacle *const *obstacles, int32_t count, double t,
                                    piola_vec3 p, double *mu, piola_vec3 *velocity) {
  double best = INFINITY;
  *mu = 0;
  *velocity = (piola_vec3){0, 0, 0};
  for (int32_t o = 0; o < count; ++o) {
    piola_vec3 vel;
    double phi = fabs(piola_obstacle_signed_distance(obstacles[o], t, p, NULL, &vel));
    if (phi < best) best = phi, *mu = piola_obstacle_friction(obstacles[o]), *velocity = vel;
  }
}

int piola__coulomb_limit(double v[3], piola_vec3 vo, const double n[3], double mu, double dvn) {
  if (!(mu > 0)) return 0;
  double rel[3] = {v[0] - vo.x, v[1] - vo.y, v[2] - vo.z};
  double rn = rel[0] * n[0] + rel[1] * n[1] + rel[2] * n[2];
  double vt[3] = {rel[0] - rn * n[0], rel[1] - rn * n[1], rel[2] - rn * n[2]};
  double vtn = sqrt(vt[0] * vt[0] + vt[1] * vt[1] + vt[2] * vt[2]);
  if (!(vtn > 0)) return 0;
  double keep = fmax(0.0, 1.0 - mu * dvn / vtn);
  for (int k = 0; k < 3; ++k) v[k] -= (1.0 - keep) * vt[k];
  return keep > 0 ? 1 : 2;
}
