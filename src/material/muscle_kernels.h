/* The fibre part of the muscle model (PIOLA_MODEL_MUSCLE) as inline kernels: one source of
 * truth for the public functions (muscle.c) and the force loop's lane kernel
 * (force/fiber_lanes.c).
 *
 * Why the model is shaped like this
 * ---------------------------------
 * Paper section 6.1 rotates the material fibre direction a into the diagonal frame,
 * ahat = V^T a, and writes the anisotropic stress as Fhat times a symmetric matrix, so that
 * Shat = Fhat^-1 Phat is symmetric and angular momentum is preserved. A fibre energy that
 * depends on F only through the fibre stretch lambda = |F a| = |Fhat ahat| does exactly that:
 *     P_f = (T(lambda) / lambda) F a a^T,   Phat_f = Fhat [(T / lambda) ahat ahat^T],
 * with T = d psi_f / d lambda the fibre tension (Pa, nominal: force per rest area across the
 * fibre). The stretch is defined for every F, flat and inverted ones included, so nothing
 * needs extending past the inversion threshold, provided T / lambda stays bounded as lambda
 * goes to 0. It does: the fibre is tension-only (T >= 0; the passive part is zero below
 * stretch 1, the active force-length bump is zero below optimal_stretch (1 - active_width)),
 * so T is exactly zero near lambda = 0.
 *
 * Tension-only also means the fibre never fights the inversion extension of the isotropic
 * part: for an entry f_k <= 0 the fibre's diagonal stress (T / lambda) f_k ahat_k^2 is <= 0,
 * the same sign as the restoring isotropic stress. An inverted element is pushed back at
 * least as hard as without fibres (tests/test_muscle.c checks it).
 *
 * The curves are piecewise polynomials so that the energy is closed form (the tests check
 * stress = energy gradient by finite differences) and every piece is branch-free selects
 * that vectorize in the force loop's lanes. */
#ifndef PIOLA_MATERIAL_MUSCLE_KERNELS_H
#define PIOLA_MATERIAL_MUSCLE_KERNELS_H

#include <math.h>

#include "material/material_kernels.h"
#include "piola/material.h"

/* Largest |dL/ds| of the force-length bump L(s) = (1 - s^2)^2, at s = 1/sqrt(3). */
#define MUSCLE_BUMP_MAX_SLOPE 1.5396007178390020

/* B(s) = integral of L from 0 to s (s in [-1, 1]). */
MATERIAL_KERNEL double muscle_bump_integral(double s) {
  const double s2 = s * s;
  return s * (1.0 - s2 * (2.0 / 3.0 - 0.2 * s2));
}

/* Fibre tension T (Pa) and energy density psi (J/m^3, zero at stretch 1) at stretch lambda,
 * with activation already clamped to [0, 1]. */
MATERIAL_KERNEL void muscle_fiber_tension_energy(const piola_muscle_def *m, double lambda,
                                                 double activation, double *tension,
                                                 double *energy) {
  /* passive: quadratic toe on (1, toe), then linear with slope k */
  const double k = m->passive_stiffness, wt = m->passive_toe_stretch - 1.0;
  const double u = kernel_max(lambda - 1.0, 0.0), uc = kernel_min(u, wt), ue = u - uc;
  const double tp = k * (0.5 * uc * uc / wt + ue);
  const double ep = k * (uc * uc * uc / (6.0 * wt) + ue * (0.5 * wt + 0.5 * ue));
  /* active: activation * sigma_max * L(s), s = (lambda / lambda_opt - 1) / w */
  const double sigma = activation * m->max_active_stress;
  const double lo = m->optimal_stretch, w = m->active_width;
  const double s = kernel_min(kernel_max((lambda / lo - 1.0) / w, -1.0), 1.0);
  const double s1 = kernel_min(kernel_max((1.0 / lo - 1.0) / w, -1.0), 1.0);
  const double one_minus = 1.0 - s * s;
  const double ta = sigma * one_minus * one_minus;
  const double ea = sigma * lo * w * (muscle_bump_integral(s) - muscle_bump_integral(s1));
  *tension = tp + ta;
  *energy = ep + ea;
}

/* dT / dlambda (Pa) at stretch lambda, activation clamped to [0, 1]: the slope of
 * muscle_fiber_tension_energy's tension, piece by piece (the implicit integrator's fibre
 * stiffness). */
MATERIAL_KERNEL double muscle_fiber_tension_slope(const piola_muscle_def *m, double lambda,
                                                  double activation) {
  const double k = m->passive_stiffness, wt = m->passive_toe_stretch - 1.0;
  const double u = kernel_max(lambda - 1.0, 0.0);
  const double passive = u > 0.0 ? k * kernel_min(u / wt, 1.0) : 0.0;
  const double sigma = activation * m->max_active_stress;
  const double lo = m->optimal_stretch, w = m->active_width;
  const double s = (lambda / lo - 1.0) / w;
  const double active = s > -1.0 && s < 1.0 ? -4.0 * sigma * s * (1.0 - s * s) / (lo * w) : 0.0;
  return passive + active;
}

/* Fibre stretch lambda = |Fhat ahat| and the factor T / lambda (Pa) for a unit ahat. */
MATERIAL_KERNEL double muscle_fiber_factor(const piola_muscle_def *m, double f0, double f1,
                                           double f2, double a0, double a1, double a2,
                                           double activation, double *energy) {
  const double x0 = f0 * a0, x1 = f1 * a1, x2 = f2 * a2;
  const double lambda = sqrt(x0 * x0 + x1 * x1 + x2 * x2);
  double t, e;
  muscle_fiber_tension_energy(m, lambda, activation, &t, &e);
  *energy = e;
  /* T is exactly 0 for lambda < optimal_stretch (1 - active_width) > 0 (tension-only
   * fibre), so the select only guards 0 / 0. */
  return lambda > 0.0 ? t / (lambda > 0.0 ? lambda : 1.0) : 0.0;
}

/* Activation clamped to [0, 1] (NaN gives 0). */
MATERIAL_KERNEL double muscle_clamp_activation(double activation) {
  return activation > 0.0 ? (activation < 1.0 ? activation : 1.0) : 0.0;
}

#endif
