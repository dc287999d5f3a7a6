/* Membrane (in-plane) constitutive models for shells: the 2-entry diagonal form.
 *
 * Why it looks like this
 * ----------------------
 * A shell triangle has a 3x2 deformation gradient F = U Fhat V^T with a 2-entry Fhat. The
 * solids' models (material_kernels.h) are functions of a 3-entry Fhat; rather than write a
 * second set of five models, each membrane model is the matching solid model evaluated with
 * the through-thickness stretch held at 1 and with Lame's first parameter replaced by its
 * plane-stress value:
 *
 *     psi_m(f0, f1) = psi_model(f0, f1, 1; mu, lambda*),   lambda* = 2 mu lambda / (lambda + 2 mu)
 *     Phat_m,i      = Phat_model,i(f0, f1, 1; mu, lambda*),  i = 0, 1
 *
 * - It is a function of the two singular values only, so it is isotropic in the plane and
 *   its stress is exactly d psi_m / d f_i: forces are the gradient of an energy.
 * - Near rest it is linear plane-stress elasticity with the material's Young's modulus and
 *   Poisson's ratio: psi = mu |eps|^2 + (lambda* / 2) tr(eps)^2, which is what a thin sheet in
 *   plane stress has after the thickness strain is eliminated. (Holding the thickness
 *   stretch at 1 with the 3D lambda would be plane strain: too stiff in area change, and
 *   unbounded as nu -> 1/2; lambda* stays below 2 mu.)
 * - Far from rest each model keeps its character (St. Venant-Kirchhoff softens in
 *   compression, neo-Hookean resists area collapse with a log barrier, the spline stiffens).
 * - The inversion extension is the solids' one, entry by entry: a triangle collapsed to a
 *   line (f1 = 0), to a point (f0 = f1 = 0), or "inverted" with respect to a reference normal
 *   (f1 < 0, decided by the shell code) gets finite stresses that push it back.
 * The third entry never reaches the threshold (it is 1), so it never clamps; only the first
 * two outputs are used. See docs/shells.md. */
#ifndef PIOLA_MEMBRANE_KERNELS_H
#define PIOLA_MEMBRANE_KERNELS_H

#include "material/material_kernels.h"

/* The plane-stress material: a copy of m with lambda replaced by 2 mu lambda / (lambda + 2 mu)
 * (and the model constants derived from it, e.g. Stable Neo-Hookean's lambda'). */
MATERIAL_KERNEL piola_material membrane_material_from(const piola_material *m) {
  piola_material r = *m;
  const double denominator = m->lambda + 2.0 * m->mu;
  r.lambda = denominator > 0.0 ? 2.0 * m->mu * m->lambda / denominator : 0.0;
  material_derive_constants(&r); /* the constants that follow from lambda */
  return r;
}

/* Membrane stress for a material already converted by membrane_material_from. */
MATERIAL_KERNEL void membrane_stress_kernel(const piola_material *membrane, double f0, double f1,
                                            double *p0, double *p1) {
  double p2;
  material_stress_kernel(membrane, f0, f1, 1.0, p0, p1, &p2);
}

/* Membrane stress and energy density (J/m^3) for a converted material. */
MATERIAL_KERNEL void membrane_stress_energy_kernel(const piola_material *membrane, double f0,
                                                   double f1, double *p0, double *p1,
                                                   double *psi) {
  double p2;
  material_stress_energy_kernel(membrane, f0, f1, 1.0, p0, p1, &p2, psi);
}

#endif
