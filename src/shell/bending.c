/* Dihedral-angle bending (Bridson, Marino and Fedkiw 2003), its damping, and the hinge
 * force loop.
 *
 * Each hinge has vertices x1, x2 (the corners opposite the shared edge) and x3 -> x4 (the
 * edge, e = x4 - x3), normals N1 = (x1 - x3) x (x1 - x4), N2 = (x2 - x4) x (x2 - x3) and the
 * signed angle theta = atan2((n1 x n2) . e/|e|, n1 . n2). BMF03's four force directions are
 * the gradient of theta:
 *   d theta/d x1 = -|e| N1 / |N1|^2,  d theta/d x2 = -|e| N2 / |N2|^2,
 *   d theta/d x3 = -((x1 - x4).e/|e| N1/|N1|^2 + (x2 - x4).e/|e| N2/|N2|^2),
 *   d theta/d x4 = +((x1 - x3).e/|e| N1/|N1|^2 + (x2 - x3).e/|e| N2/|N2|^2)
 * (BMF03's u1..u4 up to the overall sign, which follows from the sign of theta chosen
 * here; the test checks them against finite differences of theta). They sum to zero and
 * are invariant under rigid motion, so the forces carry no net force or torque.
 *
 * Energy: w D (Phi(theta) - Phi(theta0)) with Phi(theta) = -2 cos(theta/2) - theta
 * sin(theta0/2), so the force is -w D (sin(theta/2) - sin(theta0/2)) grad theta: BMF03's
 * magnitude with the geometric weight |e|^2/(|N1| + |N2|) taken at rest (as w = 2 |e0|^2 /
 * (A1 + A2), calibrated against the plate energy, docs/shells.md). Freezing the weight is what makes the force exactly conservative; with it
 * varying, the BMF03 force is not the gradient of anything. See docs/shells.md. */
#include <math.h>
#include <string.h>

#include "math/mat3.h"
#include "piola/threads.h"
#include "shell/shell_body_internal.h"

/* A hinge whose triangle height or edge is below this fraction of its size has no
 * well-defined angle: its gradient grows like 1/height. It gets zero bending force until it
 * opens again (the in-plane forces restore it). */
#define HINGE_DEGENERATE_RATIO 1e-8

double piola__hinge_angle(const double *p1, const double *p2, const double *p3, const double *p4,
                          double grad[12]) {
  vec3 x1 = vec3_load(p1), x2 = vec3_load(p2), x3 = vec3_load(p3), x4 = vec3_load(p4);
  vec3 e = vec3_sub(x4, x3);
  vec3 n1 = vec3_cross(vec3_sub(x1, x3), vec3_sub(x1, x4));
  vec3 n2 = vec3_cross(vec3_sub(x2, x4), vec3_sub(x2, x3));
  double ee = vec3_dot(e, e), nn1 = vec3_dot(n1, n1), nn2 = vec3_dot(n2, n2);
  double size2 = fmax(ee, fmax(vec3_norm2(vec3_sub(x1, x3)), vec3_norm2(vec3_sub(x2, x3))));
  double limit = HINGE_DEGENERATE_RATIO * HINGE_DEGENERATE_RATIO * size2 * size2;
  if (!(ee > HINGE_DEGENERATE_RATIO * HINGE_DEGENERATE_RATIO * size2) || !(nn1 > limit) ||
      !(nn2 > limit)) {
    if (grad) memset(grad, 0, 12 * sizeof(double));
    return 0.0;
  }
  double le = sqrt(ee), inv_le = 1.0 / le;
  double inv1 = 1.0 / sqrt(nn1), inv2 = 1.0 / sqrt(nn2);
  vec3 u1 = vec3_scale(n1, inv1), u2 = vec3_scale(n2, inv2);
  double s = vec3_dot(vec3_cross(u1, u2), e) * inv_le;
  double c = vec3_dot(u1, u2);
  double theta = atan2(s, c);
  if (grad) {
    vec3 a = vec3_scale(n1, 1.0 / nn1), b = vec3_scale(n2, 1.0 / nn2);
    vec3 g1 = vec3_scale(a, -le), g2 = vec3_scale(b, -le);
    double a3 = vec3_dot(vec3_sub(x1, x4), e) * inv_le, b3 = vec3_dot(vec3_sub(x2, x4), e) * inv_le;
    double a4 = vec3_dot(vec3_sub(x1, x3), e) * inv_le, b4 = vec3_dot(vec3_sub(x2, x3), e) * inv_le;
    vec3 g3 = vec3_neg(vec3_add(vec3_scale(a, a3), vec3_scale(b, b3)));
    vec3 g4 = vec3_add(vec3_scale(a, a4), vec3_scale(b, b4));
    vec3_store(grad, g1);
    vec3_store(grad + 3, g2);
    vec3_store(grad + 6, g3);
    vec3_store(grad + 9, g4);
  }
  return theta;
}

double piola__bending_potential(double theta, double theta0, double *derivative) {
  double s0 = sin(0.5 * theta0);
  if (derivative) *derivative = sin(0.5 * theta) - s0;
  return 2.0 * (cos(0.5 * theta0) - cos(0.5 * theta)) - (theta - theta0) * s0;
}
