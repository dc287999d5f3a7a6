/* The fibre part of the Holzapfel-Gasser-Ogden model (PIOLA_MODEL_HGO) as inline kernels:
 * one source of truth for the public functions (hgo.c), the force loop's lane kernel
 * (force/fiber_lanes.c) and the step bound (force/stable_step.c).
 *
 * Why the model is shaped like this
 * ---------------------------------
 * Each family a contributes psi_f(E) = k1 / (2 k2) (exp(k2 <E>^2) - 1) with
 * E = kappa (I1 - 3) + (1 - 3 kappa) (I4 - 1), I1 = |F|^2, I4 = |F a|^2. Both invariants are
 * defined for every F (flat and inverted ones included), so, as for the muscle's fibres,
 * nothing needs extending past the inversion threshold: the matrix is neo-Hookean with its
 * extension, the fibres are evaluated as they are. Their stress
 *     P_f = 2 psi'(E) (kappa F + (1 - 3 kappa) F a a^T) = F [2 psi'(E) (kappa I + (1 - 3 kappa) a a^T)]
 * is F times a symmetric matrix (angular momentum preserved), and in the diagonal frame its
 * diagonal entry k is 2 psi' f_k (kappa + (1 - 3 kappa) ahat_k^2): the sign of f_k, since
 * psi' >= 0. So for an entry f_k <= 0 the fibres push the same way as the matrix's restoring
 * stress: they never hold an element inverted.
 *
 * The Macaulay bracket <E> = max(E, 0) is HGO 2000's "fibres bear no compression" (for kappa = 0
 * it is their I4 > 1 switch); psi' = k1 E exp(k2 E^2) is 0 at E = 0, so the stress is C1.
 * Past the fibre stretch limit (hgo.fiber_stretch_limit, materials.md) the exponential is not
 * followed further: with the generalized fibre stretch s = sqrt(1 + E) (for kappa = 0 the
 * fibre's stretch |F a|; in general the norm |F H^(1/2)|, H = kappa I + (1 - 3 kappa) a a^T,
 * since 1 + E = kappa I1 + (1 - 3 kappa) I4), the energy is continued by its second-order
 * Taylor expansion in s at the limit s_l: psi = psi_l + a (s - s_l) + b/2 (s - s_l)^2, a linear
 * spring in s. So energy, stress (its gradient) and dP/dF are continuous (C2 in s) and the
 * stiffness stays bounded however far a scramble stretches the tet: dF : C : dF <=
 * (1 - 2 kappa) b per family for a unit rank-one dF (hgo_fiber_modulus_bound). In E the
 * continuation reads psi'(E) = psi_s / (2 s), psi''(E) = (b s_l - a) / (4 s^3) > 0, so the
 * formulas of the stress and dP/dF below are unchanged. The limit is lowered, if needed, to
 * where k2 E^2 = HGO_EXP_CAP (by piola__hgo_init, in the material's hgo) (exp would overflow at 709; at 12 the fibre stress is already
 * ~1.6e5 k1 E, far past collagen's rupture). */
#ifndef PIOLA_MATERIAL_HGO_KERNELS_H
#define PIOLA_MATERIAL_HGO_KERNELS_H

#include <math.h>

#include "material/material_kernels.h"
#include "piola/material.h"

#define HGO_EXP_CAP 12.0

/* The fibre strain E where the continuation starts, from the limit in force (piola__hgo_init
 * lowers the scene's to where k2 E^2 = HGO_EXP_CAP). */
MATERIAL_KERNEL double hgo_limit_strain(const piola_hgo_def *h) {
  const double l = h->fiber_stretch_limit;
  return l * l - 1.0;
}

/* psi_f(E) (J/m^3), its slope psi' (Pa) and curvature psi'' (Pa) for one family. */
MATERIAL_KERNEL void hgo_fiber_curve(const piola_hgo_def *h, double e, double *psi, double *slope,
                                     double *curvature) {
  const double k1 = h->k1, k2 = h->k2;
  const double ep = kernel_max(e, 0.0), el = hgo_limit_strain(h);
  const double x = kernel_min(ep, el);
  const double ex = exp(k2 * x * x);
  const double p0 = 0.5 * k1 / k2 * (ex - 1.0), s0 = k1 * x * ex,
               c0 = e > 0.0 ? k1 * (1.0 + 2.0 * k2 * x * x) * ex : 0.0;
  /* past the limit: the quadratic in s = sqrt(1 + E) with a = dpsi/ds, b = d2psi/ds2 at s_l */
  const double sl = h->fiber_stretch_limit, s = sqrt(1.0 + ep), y = s - sl;
  const double a = 2.0 * sl * s0, b = 2.0 * s0 + 4.0 * sl * sl * c0;
  const int past = ep > el;
  *psi = past ? p0 + y * (a + 0.5 * b * y) : p0;
  *slope = past ? (a + b * y) / (2.0 * s) : s0;
  *curvature = past ? (b * sl - a) / (4.0 * s * s * s) : c0;
}

/* d2psi/ds2 of one family at E (the generalized fibre stretch s = sqrt(1 + E)): 2 psi' +
 * 4 s^2 psi''; nondecreasing in E, constant past the limit. */
MATERIAL_KERNEL double hgo_stretch_stiffness(const piola_hgo_def *h, double e) {
  const double el = hgo_limit_strain(h), x = kernel_min(kernel_max(e, 0.0), el);
  double psi, slope, curvature;
  hgo_fiber_curve(h, kernel_max(x, 1e-300), &psi, &slope, &curvature);
  return 2.0 * slope + 4.0 * (1.0 + x) * curvature;
}

/* E of one unit family a at a 3x3 f (row-major), with w = f a. */
MATERIAL_KERNEL double hgo_invariant(const piola_hgo_def *h, const double f[9], const double a[3],
                                     double w[3]) {
  double i1 = 0.0;
  for (int k = 0; k < 9; ++k) i1 += f[k] * f[k];
  for (int i = 0; i < 3; ++i) w[i] = f[3 * i] * a[0] + f[3 * i + 1] * a[1] + f[3 * i + 2] * a[2];
  const double i4 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
  return h->kappa * (i1 - 3.0) + (1.0 - 3.0 * h->kappa) * (i4 - 1.0);
}

/* One family's part of dP_f/dF at a 3x3 f (row-major) in factored form: with G = kappa f +
 * (1 - 3 kappa) (f n) n^T (into g), c4 = 4 psi'' and s2 = 2 psi' at the family's E,
 *   dP_ij/dF_kl = c4 G_ij G_kl + delta_ik s2 (kappa delta_jl + (1 - 3 kappa) n_j n_l).
 * The public dP_f/dF forms its 81 numbers from it; the implicit assembly contracts it with the
 * shape gradients without forming them (force/stiffness_matrix.c). */
MATERIAL_KERNEL void hgo_family_derivative(const piola_hgo_def *h, const double f[9],
                                           const double n[3], double g[9], double *c4, double *s2) {
  double w[3], psi, slope, curvature;
  hgo_fiber_curve(h, hgo_invariant(h, f, n, w), &psi, &slope, &curvature);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      g[3 * i + j] = h->kappa * f[3 * i + j] + (1.0 - 3.0 * h->kappa) * w[i] * n[j];
  *c4 = 4.0 * curvature, *s2 = 2.0 * slope;
}

/* One family's share of the fibres' plane-wave stiffness bound (Pa) at a state whose largest
 * |f_i| is BIG, with I4 = |Fhat ahat|^2, slope psi' and curvature psi'' at its E: per family,
 *   dF : C_a : dF = 4 psi''(E_a) (G_a : dF)^2 + 2 psi'(E_a) (kappa |dF|^2 + (1 - 3 kappa) |dF a|^2)
 * with G_a = kappa Fhat + (1 - 3 kappa) (Fhat ahat) ahat^T. For a unit rank-one dF,
 * |G_a : dF| <= |G_a|_2 <= kappa max|f_i| + (1 - 3 kappa) |Fhat ahat| (kappa <= 1/3), and the
 * last factor is at most 1 - 2 kappa. psi'' jumps from 0 to k1 at E = 0: the caller passes the
 * larger side (k1 for E <= 0). Exact along the largest stretch, 8 k1 (1 - 2 kappa)^2 at rest. */
MATERIAL_KERNEL double hgo_family_wave_modulus(const piola_hgo_def *h, double big, double i4,
                                               double slope, double curvature) {
  const double g = h->kappa * big + (1.0 - 3.0 * h->kappa) * sqrt(i4);
  return 4.0 * curvature * g * g + 2.0 * slope * (1.0 - 2.0 * h->kappa);
}

/* The diagonal-frame fibre stress of both families: with Fhat = diag(f) and unit ahat_a,
 * Phat_f = Fhat S, S = sum_a 2 psi'_a (kappa I + (1 - 3 kappa) ahat_a ahat_a^T). Writes
 * g = sum_a 2 psi'_a kappa (the isotropic coefficient), r_a = 2 psi'_a (1 - 3 kappa),
 * *modulus = both families' hgo_family_wave_modulus (the step bound's fibre term, from the
 * same exponentials: the force loop caches it, fiber_lanes.c) and returns the energy. (The
 * force loop uses these; P_f = g F + sum_a r_a (F a)(a)^T.) */
MATERIAL_KERNEL double hgo_fiber_terms_modulus(const piola_hgo_def *h, double f0, double f1,
                                               double f2, double ahat[2][3], double *g,
                                               double r[2], double *modulus) {
  const double i1 = f0 * f0 + f1 * f1 + f2 * f2;
  const double big = kernel_max(fabs(f0), kernel_max(fabs(f1), fabs(f2)));
  double energy = 0.0, iso = 0.0, wave = 0.0;
  for (int a = 0; a < 2; ++a) {
    const double x0 = f0 * ahat[a][0], x1 = f1 * ahat[a][1], x2 = f2 * ahat[a][2];
    const double i4 = x0 * x0 + x1 * x1 + x2 * x2;
    const double e = h->kappa * (i1 - 3.0) + (1.0 - 3.0 * h->kappa) * (i4 - 1.0);
    double psi, slope, curvature;
    hgo_fiber_curve(h, e, &psi, &slope, &curvature);
    energy += psi;
    iso += 2.0 * slope * h->kappa;
    r[a] = 2.0 * slope * (1.0 - 3.0 * h->kappa);
    wave += hgo_family_wave_modulus(h, big, i4, slope, e > 0.0 ? curvature : h->k1);
  }
  *g = iso;
  *modulus = wave;
  return energy;
}

/* hgo_fiber_terms_modulus without the modulus (the public functions and the energy). */
MATERIAL_KERNEL double hgo_fiber_terms_diagonal(const piola_hgo_def *h, double f0, double f1,
                                                double f2, double ahat[2][3], double *g,
                                                double r[2]) {
  double modulus;
  return hgo_fiber_terms_modulus(h, f0, f1, f2, ahat, g, r, &modulus);
}

/* HGO's fibre stiffness for a plane wave at Fhat f with the two families' unit directions
 * ahat in the diagonal frame (docs/time-stepping.md, "The modulus"): the sum of
 * hgo_family_wave_modulus over the families. */
MATERIAL_KERNEL double hgo_directed_fiber_modulus(const piola_hgo_def *h, double f0, double f1,
                                                  double f2, double ahat[2][3]) {
  double g, r[2], modulus;
  (void)hgo_fiber_terms_modulus(h, f0, f1, f2, ahat, &g, r, &modulus);
  return modulus;
}

/* The step bound's cache of an HGO body with fibres (one material): the force loop keeps,
 * per tet, the Fhat it evaluated and the fibre term hgo_fiber_terms_modulus gave there, so
 * that the bound reads one number instead of the tet's V, its fibre and two exponentials.
 * Structure of arrays, slot s of a tet at s * stride from its first. */
enum {
  HGO_CACHE_KEY = 0,     /* Fhat of the update that wrote the slots */
  HGO_CACHE_MODULUS = 3, /* Pa: the fibres' plane-wave term there */
  HGO_CACHE_SLOTS = 4
};

/* 1 when the cache holds the fibre term of Fhat f (as ogden_cache_holds: a zero key never
 * matches). */
MATERIAL_KERNEL int hgo_cache_holds(const double *cache, long stride, double f0, double f1,
                                    double f2) {
  return (cache[HGO_CACHE_KEY * stride] == f0) & (cache[(HGO_CACHE_KEY + 1) * stride] == f1) &
         (cache[(HGO_CACHE_KEY + 2) * stride] == f2) & ((f0 != 0.0) | (f1 != 0.0) | (f2 != 0.0));
}

/* The two unit family directions from a unit fibre direction m and the unit axis of an HGO
 * material: false when m is parallel to the axis (to 1e-12) and the angle is not 0. */
MATERIAL_KERNEL int hgo_families_from_fiber(const piola_material *material, const double m[3],
                                            double families[2][3]) {
  const piola_hgo_def *h = &material->hgo;
  const double d = h->axis[0] * m[0] + h->axis[1] * m[1] + h->axis[2] * m[2];
  double n[3] = {h->axis[0] - d * m[0], h->axis[1] - d * m[1], h->axis[2] - d * m[2]};
  const double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const double c = material->model_constants[HGO_COS_ANGLE], s = material->model_constants[HGO_SIN_ANGLE];
  const int ok = len > 1e-12 || s == 0.0;
  for (int i = 0; i < 3; ++i) n[i] = len > 1e-12 ? n[i] / len : 0.0;
  for (int i = 0; i < 3; ++i) {
    families[0][i] = c * m[i] + s * n[i];
    families[1][i] = c * m[i] - s * n[i];
  }
  return ok;
}

/* A bound on the fibres' tangent stiffness for a plane wave (Pa) at a state with diagonal
 * entries f, whatever the families' directions: per family, for a unit rank-one dF,
 * dF : C_a : dF = 4 psi''(E_a) (G_a : dF)^2 + 2 psi'(E_a) (kappa |dF|^2 + (1 - 3 kappa) |dF a|^2)
 * with G_a = F H_a, |G_a|_2 <= |F H_a^(1/2)|_F |H_a^(1/2)|_2 = s_a sqrt(1 - 2 kappa), so it is at
 * most (1 - 2 kappa) (4 s_a^2 psi'' + 2 psi') = (1 - 2 kappa) psi_ss(s_a), which grows with E_a,
 * and E_a <= kappa (I1 - 3) + (1 - 3 kappa) (max f_i^2 - 1). 8 k1 (1 - 2 kappa) at rest;
 * bounded past the stretch limit. */
MATERIAL_KERNEL double hgo_fiber_modulus_bound(const piola_hgo_def *h, double f0, double f1,
                                               double f2) {
  const double big = kernel_max(f0 * f0, kernel_max(f1 * f1, f2 * f2));
  const double e = h->kappa * (f0 * f0 + f1 * f1 + f2 * f2 - 3.0) + (1.0 - 3.0 * h->kappa) * (big - 1.0);
  return 2.0 * (1.0 - 2.0 * h->kappa) * hgo_stretch_stiffness(h, e);
}

#endif
