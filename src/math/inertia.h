/* The inertia tensor of point masses and the angular velocity it gives an angular momentum:
 * what a rigid velocity field (v_cm + w x r) that keeps a set of points' linear and angular
 * momentum is made of (the rigid impact zones of contact/impact_zones.c; the velocity a
 * failed backward Euler step leaves, sim/failed_step_velocity.c, which solves on the
 * principal axes instead: its angular momentum comes from another shape and can have a part
 * about a collapsed axis). */
#ifndef PIOLA_MATH_INERTIA_H
#define PIOLA_MATH_INERTIA_H

#include <math.h>

#include "math/mat3.h"

/* m (|r|^2 I - r r^T): a point of mass m (kg) at r (m) from the centre (kg m^2). */
static inline mat3 point_inertia(vec3 r, double m) {
  const double r2 = vec3_norm2(r);
  mat3 out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out.m[i][j] = m * ((i == j ? r2 : 0.0) - vec3_get(r, i) * vec3_get(r, j));
  return out;
}

/* Solves m w = b for the symmetric positive semi-definite inertia-like matrix m; when it is
 * (nearly) singular (points that are collinear) a small multiple of the trace is added so
 * that the rotation about the degenerate axis, which moves nothing, is taken as zero; all
 * points at one place (a zero trace) give w = 0. */
static inline vec3 solve_inertia(mat3 m, vec3 b) {
  const double tr = mat3_trace(m);
  if (!(tr > 0.0)) return (vec3){0, 0, 0};
  double det = mat3_det(m);
  if (!(fabs(det) > 1e-12 * tr * tr * tr)) {
    for (int k = 0; k < 3; ++k) m.m[k][k] += 1e-9 * tr;
    det = mat3_det(m);
    if (!(fabs(det) > 0.0)) return (vec3){0, 0, 0};
  }
  return mat3_mul_vec(mat3_inverse(m), b);
}

#endif
