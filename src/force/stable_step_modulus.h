/* The per-tet modulus k of the state-aware step bound where no entry of Fhat is clamped, and
 * the force loop's cache of it (docs/time-stepping.md, "Cost").
 *
 * Why a cache: the bound's pass (stable_step.c) is bound by its arithmetic, not by the Fhat it
 * reads, and most of that arithmetic repeats the force loop's: the model's value and slopes at
 * Fhat, 1/f_i and ln J. So the force loop's lane kernels form k from the intermediates they
 * already have, and the force loop keeps per block of PIOLA_TET_BLOCK tets the maxima of
 * w_e k_e the pass needs, keyed by the update that formed them (material_lanes.h,
 * piola__step_cache_blocks); the pass reads them for every block the last update formed and
 * computes the rest (a clamped entry, the energy extension, a body without its weights) as
 * before. Kept per tet with the Fhat as key, as the Ogden and HGO caches are, the cache was a
 * memory stream of its own (4 doubles written and 8 read per tet) that took back most of what
 * it saved. Only blocks with no entry clamped are cached: there every extension except the
 * energy one adds exactly zero, so k is the same for CLAMP and LINEAR and needs neither the
 * LINEAR slopes' extra evaluations nor the threshold's rise. A clamped lane's k is NaN, which
 * marks its block not formed.
 *
 * The formulas live here once, for both the pass and the force loop. The force loop compiles
 * them with fused multiply-adds (force_lanes.c), so a cached k's last bits follow the kernel's
 * instruction set variant, as Fhat's own do; the pass computes without them. */
#ifndef PIOLA_FORCE_STABLE_STEP_MODULUS_H
#define PIOLA_FORCE_STABLE_STEP_MODULUS_H

#include <math.h>

#include "material/material_kernels.h"

/* num / den for a den of either sign, |den| normal (DV as in material_kernels.h): the fast
 * reciprocal takes positive arguments, so the sign moves to the numerator (an exact negation). */
MATERIAL_KERNEL double step_signed_div(double num, double den, kernel_division dv) {
  return dv == KERNEL_FAST_RECIPROCAL ? (den < 0.0 ? -num : num) * kernel_recip_fast(fabs(den)) : num / den;
}

/* Whether two entries agree to 1e-6, where a pair's divided difference (P_i - P_j) /
 * (f_i - f_j) gives way to the mean diagonal slope (step_pair_halves). */
MATERIAL_KERNEL int step_entries_close(double fi, double fj) {
  return fabs(fi - fj) <= 1e-6 * (fabs(fi) + fabs(fj));
}

/* a and b from the pair's divided differences: PLUS = (P_i + P_j) / (f_i + f_j) and
 * MINUS = (P_i - P_j) / (f_i - f_j), or where the two entries are CLOSE (agree to 1e-6) the
 * mean diagonal slope less K_ij instead of MINUS. */
MATERIAL_KERNEL void step_pair_halves(int close, double kii, double kjj, double kij, double minus,
                                      double plus, double *a, double *b) {
  const double difference = close ? 0.5 * (kii + kjj) - kij : minus;
  *a = 0.5 * (difference + plus), *b = 0.5 * (difference - plus);
}

/* The pair block's two eigenvalues as a +- b (stable_step.c's header), without the K_ij
 * coupling. Selects, no branches, so that the lane loop vectorizes. Its two divisions are
 * most of a pair's cost (a vector division takes several times a multiply-add's slot): the
 * force loop takes them as fast reciprocals (DV), the pass exactly. */
MATERIAL_KERNEL void step_pair_block(kernel_division dv, double c, double pi, double pj, double fi,
                                     double fj, double kii, double kjj, double kij, double *a, double *b) {
  const double df = fi - fj, sum = fi + fj;
  const int close = step_entries_close(fi, fj);
  const double den = sum >= 0.0 ? kernel_max(sum, c) : kernel_min(sum, -c);
  step_pair_halves(close, kii, kjj, kij, step_signed_div(pi - pj, close ? 1.0 : df, dv),
                   step_signed_div(pi + pj, den, dv), a, b);
}

/* Largest eigenvalue of the pair block plus the K_ij coupling. */
MATERIAL_KERNEL double step_pair_modulus(kernel_division dv, double c, double pi, double pj, double fi,
                                         double fj, double kii, double kjj, double kij) {
  double a, b;
  step_pair_block(dv, c, pi, pj, fi, fj, kii, kjj, kij, &a, &b);
  return a + fabs(b + kij);
}

/* k = max(max_i K_ii, max_{i<j} pair_ij) from the stress P and the 3x3 block K at Fhat f
 * (threshold c, which keeps the pairs' f_i + f_j away from 0). */
MATERIAL_KERNEL double step_modulus_of_slopes(kernel_division dv, double c, double p0, double p1,
                                              double p2, double f0, double f1, double f2, double k0,
                                              double k1, double k2, double k01, double k02, double k12) {
  double k = kernel_max(k0, kernel_max(k1, k2));
  k = kernel_max(k, step_pair_modulus(dv, c, p0, p1, f0, f1, k0, k1, k01));
  k = kernel_max(k, step_pair_modulus(dv, c, p0, p2, f0, f2, k0, k2, k02));
  return kernel_max(k, step_pair_modulus(dv, c, p1, p2, f1, f2, k1, k2, k12));
}

/* k of a lane with no entry clamped from the model's parts there (fc = f), muscle fibres'
 * bound included (HGO's directed fibre term is not: it has its own cache). The force loop's:
 * fast reciprocals. */
MATERIAL_KERNEL double step_unclamped_modulus(const piola_material *m, double c, const material_parts *pa,
                                              double f0, double f1, double f2) {
  return step_modulus_of_slopes(KERNEL_FAST_RECIPROCAL, c, pa->p[0], pa->p[1], pa->p[2], f0, f1, f2,
                                pa->k[0][0], pa->k[1][1], pa->k[2][2], pa->k[0][1], pa->k[0][2],
                                pa->k[1][2]) +
         m->fiber_modulus;
}

/* The spline's k with no entry clamped, without a division: max_i K_ii and, for each pair,
 * max(A''(f_i), A''(f_j)) + lambda g_i g_j, an upper bound of the pair's mode (the exact
 * pairs' six divisions took k in the force loop from 1.5% to 3.9% of an update's
 * instructions, BENCHMARKS.md). The
 * spline's stress is corotated's with the 1D curve A' for 2 mu (f - 1): P_i = A'(f_i) +
 * lambda (J - 1) g_i, g_i = J / f_i, K_ii = A''(f_i) + lambda g_i^2, and the pair ij's divided
 * differences are D -+ lambda (J - 1) f_k with D = (A'(f_i) - A'(f_j)) / (f_i - f_j) and
 * S = (A'(f_i) + A'(f_j)) / (f_i + f_j) in place of D: a = (D + S) / 2 and b + K_ij =
 * (D - S) / 2 + lambda g_i g_j, so the mode a + |b + K_ij| is D + lambda g_i g_j or
 * S - lambda g_i g_j. A'' is smallest at f = 1 and grows with |f - 1| on either side, so with
 * M = max(A''(f_i), A''(f_j)): D <= M (the mean value theorem), and S <= M (A'(f) <= (f - 1)
 * A''(f) above 1, A'(f) < 0 below). Hence mode <= M + lambda g_i g_j <= M + lambda (g_i^2 +
 * g_j^2) / 2, and since the exact k is at least (K_ii + K_jj) / 2 the bound exceeds it by at
 * most |A''(f_i) - A''(f_j)| / 2: nothing where the two entries share a segment of the curve
 * (at rest it is 2 mu + lambda), at most 1.5 times it anywhere. K holds the parts at f;
 * A''(f_i) = K_ii - lambda g_i^2. */
MATERIAL_KERNEL double step_spline_modulus(double lambda, double f0, double f1, double f2, double k0,
                                           double k1, double k2) {
  const double g0 = f1 * f2, g1 = f0 * f2, g2 = f0 * f1;
  const double c0 = k0 - lambda * g0 * g0, c1 = k1 - lambda * g1 * g1, c2 = k2 - lambda * g2 * g2;
  double k = kernel_max(k0, kernel_max(k1, k2));
  k = kernel_max(k, kernel_max(c0, c1) + lambda * g0 * g1);
  k = kernel_max(k, kernel_max(c0, c2) + lambda * g0 * g2);
  return kernel_max(k, kernel_max(c1, c2) + lambda * g1 * g2);
}

/* Mooney-Rivlin with every entry at or above the threshold, from i_k = 1 / f_k and
 * L = lambda ln J, without a division. Its stress is P_i = A'(f_i) + L i_i with
 * A'(f) = mu_1 f + mu_2 / f^3 - M / f (the Ogden terms (mu_1, 2) and (mu_2, -2), M = mu_1 + mu_2),
 * so K_ii = mu_1 - 3 mu_2 i_i^4 + (M + lambda - L) i_i^2 and K_ij = lambda i_i i_j. The pair ij's
 * divided differences of A' are D = mu_1 + M p - mu_2 p (i_i^2 + i_i i_j + i_j^2) and
 * S = mu_1 - M p + mu_2 p (i_i^2 - i_i i_j + i_j^2) with p = i_i i_j (f^-3's differences
 * factor exactly), and those of L i_k are -+ L p. So a = mu_1 - mu_2 p^2, b + K_ij =
 * p (M + lambda - L - mu_2 (i_i^2 + i_j^2)) and
 *   pair_ij = mu_1 - mu_2 p^2 + p |M + lambda - L - mu_2 (i_i^2 + i_j^2)|:
 * the exact pairs of the divided differences, without their divisions. */
MATERIAL_KERNEL double step_mooney_rivlin_modulus(const piola_material *m, double i0, double i1,
                                                  double i2, double l) {
  const double *o = m->model_constants;
  const double mu_1 = o[OGDEN_TERMS], mu_2 = o[OGDEN_TERMS + 2], soft = o[OGDEN_MU_SUM] + m->lambda - l;
  const double s0 = i0 * i0, s1 = i1 * i1, s2 = i2 * i2;
  const double k0 = mu_1 + (soft - 3.0 * mu_2 * s0) * s0;
  const double k1 = mu_1 + (soft - 3.0 * mu_2 * s1) * s1;
  const double k2 = mu_1 + (soft - 3.0 * mu_2 * s2) * s2;
  const double p01 = i0 * i1, p02 = i0 * i2, p12 = i1 * i2;
  double k = kernel_max(k0, kernel_max(k1, k2));
  k = kernel_max(k, mu_1 - mu_2 * p01 * p01 + p01 * fabs(soft - mu_2 * (s0 + s1)));
  k = kernel_max(k, mu_1 - mu_2 * p02 * p02 + p02 * fabs(soft - mu_2 * (s0 + s2)));
  return kernel_max(k, mu_1 - mu_2 * p12 * p12 + p12 * fabs(soft - mu_2 * (s1 + s2)));
}

/* The same at Fhat f, from the reciprocals and the one logarithm of J that
 * mooney_rivlin_stress_lanes_unclamped takes (J within its range). */
MATERIAL_KERNEL double step_mooney_rivlin_modulus_at(const piola_material *m, double f0, double f1,
                                                     double f2) {
  return step_mooney_rivlin_modulus(m, kernel_recip_fast(f0), kernel_recip_fast(f1), kernel_recip_fast(f2),
                                    m->lambda * kernel_log_div(f0 * f1 * f2, KERNEL_FAST_RECIPROCAL));
}

/* Neo-Hookean's matrix with every entry at or above the threshold, from i_k = 1 / f_k and
 * L = lambda ln J:
 *   K_ii = mu (1 + i_i^2) + (lambda - L) i_i^2,  pair_ij = mu + i_i i_j |mu + lambda - L|
 * (a + b = mu (1 + i_i i_j) - L i_i i_j, a - b = mu (1 - i_i i_j) + L i_i i_j,
 * K_ij = lambda i_i i_j). */
MATERIAL_KERNEL double step_neohookean_modulus(const piola_material *m, double i0, double i1, double i2,
                                               double l) {
  const double mu = m->mu, lambda = m->lambda;
  const double soft = lambda - l, cross = fabs(mu + lambda - l);
  const double k0 = mu * (1.0 + i0 * i0) + soft * i0 * i0;
  const double k1 = mu * (1.0 + i1 * i1) + soft * i1 * i1;
  const double k2 = mu * (1.0 + i2 * i2) + soft * i2 * i2;
  double k = kernel_max(k0, kernel_max(k1, k2));
  k = kernel_max(k, mu + i0 * kernel_max(i1, i2) * cross);
  return kernel_max(k, mu + i1 * i2 * cross);
}

/* The cache: per block of PIOLA_TET_BLOCK tets, the step bound's two partial maxima of
 * w_e k_e (w_e = 1 / (rho h_e^2), stable_step.c) and the update that formed them. LOW is the
 * largest over the block's tets whose k is at most STEP_CACHE_STIFF times the rest modulus,
 * HIGH over the others (0 where there is none): the direction-weighted models weigh only the
 * stiff ones (stable_step.c, weighted_range), the others take the larger of the two. */
enum {
  STEP_CACHE_KEY = 0,  /* the body's step_generation when the force loop formed the block;
                          0 (never a generation): not formed, a lane clamped, no weights */
  STEP_CACHE_LOW = 1,  /* 1/s^2 */
  STEP_CACHE_HIGH = 2, /* 1/s^2 */
  STEP_CACHE_SLOTS = 3
};

/* The direction weights apply to a tet whose modulus is above this many times its rest
 * modulus lambda + 2 mu: where the state, not the mesh, sets the step (scrambles, strong
 * stretch). Below it the bound is the unweighted one. */
#define STEP_CACHE_STIFF 4.0

/* The bodies whose force loop fills the cache: one material, one of these models, and an
 * extension other than the energy one (whose slopes are differences of the extended stress
 * everywhere, stable_step.c); HGO without fibres only (the fibre term has a cache of its own,
 * which its force loop forms after the matrix: rest_state.c). */
#define STEP_CACHE_MODEL(model)                                                              \
  ((model) == PIOLA_MODEL_NEOHOOKEAN || (model) == PIOLA_MODEL_MUSCLE ||                     \
   (model) == PIOLA_MODEL_COROTATED || (model) == PIOLA_MODEL_STVK ||                        \
   (model) == PIOLA_MODEL_ROTATED_LINEAR || (model) == PIOLA_MODEL_SPLINE ||                 \
   (model) == PIOLA_MODEL_STABLE_NEOHOOKEAN || (model) == PIOLA_MODEL_OGDEN ||               \
   (model) == PIOLA_MODEL_MOONEY_RIVLIN || (model) == PIOLA_MODEL_HGO)

/* A lane's k for the block's maxima: NaN where an entry is clamped (the block is then not
 * cached). */
MATERIAL_KERNEL void step_cache_store(double *k_out, int held, double k) { *k_out = held ? k : (double)NAN; }

/* The force loop's kernels. neohookean_stress_lanes_unclamped with k from its reciprocals and
 * logarithm (a few multiply-adds more), plus FIBER (Pa): the muscle's fibre bound. */
MATERIAL_KERNEL void neohookean_stress_modulus_plus(const piola_material *m, double fiber, double f0,
                                                    double f1, double f2, double *p0, double *p1,
                                                    double *p2, double *k_out) {
  const double mu = m->mu;
  const double i0 = kernel_recip_fast(f0), i1 = kernel_recip_fast(f1), i2 = kernel_recip_fast(f2);
  const double lq = m->lambda * kernel_log_div(f0 * f1 * f2, KERNEL_FAST_RECIPROCAL);
  *p0 = mu * (f0 - i0) + lq * i0;
  *p1 = mu * (f1 - i1) + lq * i1;
  *p2 = mu * (f2 - i2) + lq * i2;
  step_cache_store(k_out, 1, step_neohookean_modulus(m, i0, i1, i2, lq) + fiber);
}

/* Neo-Hookean and the muscle's matrix. */
MATERIAL_KERNEL void neohookean_stress_modulus_unclamped(const piola_material *m, double f0, double f1,
                                                         double f2, double *p0, double *p1, double *p2,
                                                         double *k_out) {
  neohookean_stress_modulus_plus(m, m->fiber_modulus, f0, f1, f2, p0, p1, p2, k_out);
}

/* HGO's matrix, neo-Hookean's, for a body without fibres: no fibre term (stable_step.c,
 * hgo_tet_fiber_modulus; HGO's m->fiber_modulus is its fibres' rest bound, which the
 * model's own modulus does not add). */
MATERIAL_KERNEL void hgo_matrix_stress_modulus_unclamped(const piola_material *m, double f0, double f1,
                                                         double f2, double *p0, double *p1, double *p2,
                                                         double *k_out) {
  neohookean_stress_modulus_plus(m, 0.0, f0, f1, f2, p0, p1, p2, k_out);
}

/* A lane the kernel above does not take (an entry clamped): no k, so no cached block. */
MATERIAL_KERNEL void step_cache_skip(double *k_out) { *k_out = (double)NAN; }

/* mooney_rivlin_stress_lanes_unclamped with k in closed form (step_mooney_rivlin_modulus_at):
 * the reciprocals and the logarithm are the stress's (the compiler forms them once). */
MATERIAL_KERNEL void mooney_rivlin_stress_modulus_unclamped(const piola_material *m, double f0, double f1,
                                                            double f2, double *p0, double *p1, double *p2,
                                                            double *k_out) {
  mooney_rivlin_stress_lanes_unclamped(m, f0, f1, f2, p0, p1, p2);
  step_cache_store(k_out, 1, step_mooney_rivlin_modulus_at(m, f0, f1, f2) + m->fiber_modulus);
}

/* k with no entry clamped, from the parts there, for the force loop. For three models the
 * pairs' divisions cancel (P_i = A'(f_i) + kappa q g_i, the pair ij's a +- b are the divided
 * differences of P_i -+ P_j):
 *   corotated (g_i = J / f_i, K_ii = 2 mu + lambda g_i^2): a = 2 mu (1 - s), b + K_ij =
 *     2 mu s + lambda g_i g_j with s = 1 / (f_i + f_j), so pair_ij = 2 mu + lambda g_i g_j, at
 *     most max(K_ii, K_jj): k = max_i K_ii;
 *   StVK (A' = mu f (f^2 - 1), kappa q g_i = Q f_i with Q = lambda / 2 (|f|^2 - 3), K_ij =
 *     lambda f_i f_j): a = mu (f_i^2 + f_j^2 - 1) + Q, b = mu f_i f_j, so
 *     pair_ij = mu (f_i^2 + f_j^2 - 1) + Q + (mu + lambda) f_i f_j, largest for the two
 *     largest entries;
 *   rotated linear (A' = 2 mu (f - 1), kappa q g_i = T = lambda (tr Fhat - 3), K_ij = lambda,
 *     K_ii = 2 mu + lambda): a = 2 mu + t s, b + K_ij = lambda - t s with t = T - 2 mu, so
 *     pair_ij = 2 mu + max(lambda, 2 t s - lambda), largest for the smallest f_i + f_j when
 *     t > 0 and at most K_ii when t <= 0: one division per tet instead of six.
 * The spline takes step_spline_modulus, a bound without division that the pass takes for its
 * unclamped lanes too; the others take the pair blocks as the pass does, with fast
 * reciprocals for their divisions. The pass's divided differences agree with
 * these closed forms up to its rounding (tests/test_stable_step.c, to 1e-12; on a million
 * random Fhat in [c, c + 5]^3 corotated and StVK to the bit, rotated linear to 4e-11, where
 * two entries lie within ~1e-5 of each other and the pass's (P_i - P_j) / (f_i - f_j) loses
 * digits that the closed form keeps). */
MATERIAL_KERNEL double step_model_unclamped_modulus(piola_material_model model, const piola_material *m,
                                                    double c, const material_parts *pa, double f0,
                                                    double f1, double f2) {
  const double mu = m->mu, lambda = m->lambda;
  const double diagonal = kernel_max(pa->k[0][0], kernel_max(pa->k[1][1], pa->k[2][2]));
  switch (model) {
    case PIOLA_MODEL_COROTATED: return diagonal + m->fiber_modulus;
    case PIOLA_MODEL_STVK: {
      /* the two largest entries: a b = the product of the pair without the smallest */
      const double least = kernel_min(f0, kernel_min(f1, f2));
      const double ab = least == f0 ? f1 * f2 : least == f1 ? f0 * f2 : f0 * f1;
      const double q = 0.5 * lambda * (f0 * f0 + f1 * f1 + f2 * f2 - 3.0) - mu;
      const double pair = mu * (f0 * f0 + f1 * f1 + f2 * f2 - least * least) + q + (mu + lambda) * ab;
      return kernel_max(diagonal, pair) + m->fiber_modulus;
    }
    case PIOLA_MODEL_ROTATED_LINEAR: {
      const double t = lambda * (f0 + f1 + f2 - 3.0) - 2.0 * mu;
      const double most = kernel_max(f0, kernel_max(f1, f2));
      const double pair = 2.0 * mu + kernel_max(lambda, 2.0 * t / (f0 + f1 + f2 - most) - lambda);
      return kernel_max(diagonal, pair) + m->fiber_modulus;
    }
    case PIOLA_MODEL_SPLINE:
      return step_spline_modulus(lambda, f0, f1, f2, pa->k[0][0], pa->k[1][1], pa->k[2][2]) + m->fiber_modulus;
    default: return step_unclamped_modulus(m, c, pa, f0, f1, f2);
  }
}

/* material_extended_stress of MODEL (no threshold rise) with k from the same parts where no
 * entry is clamped (step_model_unclamped_modulus), not the model again. */
MATERIAL_KERNEL void material_stress_modulus_lanes(piola_material_model model, const piola_material *m,
                                                   double f0, double f1, double f2, double *p0,
                                                   double *p1, double *p2, double *k_out) {
  const double c = MATERIAL_THRESHOLD(model, m, f0, f1, f2);
  const double fc0 = kernel_max(f0, c), fc1 = kernel_max(f1, c), fc2 = kernel_max(f2, c);
  material_parts parts;
  material_model_parts(model, m, KERNEL_FAST_RECIPROCAL, fc0, fc1, fc2, &parts);
  material_extend(m, KERNEL_FAST_RECIPROCAL, c, &parts, f0 - fc0, f1 - fc1, f2 - fc2, p0, p1, p2);
  const int held = (f0 >= c) & (f1 >= c) & (f2 >= c);
  step_cache_store(k_out, held, step_model_unclamped_modulus(model, m, c, &parts, f0, f1, f2));
}

/* One per model, so that the force loop's lane loops name a kernel with the model constant. */
#define STEP_STRESS_MODULUS_KERNEL(name, model)                                                        \
  MATERIAL_KERNEL void name##_stress_modulus_lanes(const piola_material *m, double f0, double f1,       \
                                                   double f2, double *p0, double *p1, double *p2,      \
                                                   double *k_out) {                                    \
    material_stress_modulus_lanes(model, m, f0, f1, f2, p0, p1, p2, k_out);                            \
  }
STEP_STRESS_MODULUS_KERNEL(corotated, PIOLA_MODEL_COROTATED)
STEP_STRESS_MODULUS_KERNEL(stvk, PIOLA_MODEL_STVK)
STEP_STRESS_MODULUS_KERNEL(spline, PIOLA_MODEL_SPLINE)
STEP_STRESS_MODULUS_KERNEL(rotated_linear, PIOLA_MODEL_ROTATED_LINEAR)
#undef STEP_STRESS_MODULUS_KERNEL

/* 1/x_0, 1/x_1, 1/x_2 from R = 1/(x_0 x_1 x_2): six multiplies instead of three reciprocals. */
MATERIAL_KERNEL void step_reciprocals_of_three(double x0, double x1, double x2, double r,
                                               double *i0, double *i1, double *i2) {
  *i0 = x1 * x2 * r, *i1 = x0 * x2 * r, *i2 = x0 * x1 * r;
}

/* The pair block's mode a + |b + K_ij| (step_pair_modulus) of an unclamped lane whose
 * reciprocals are given: SUM_INV = 1 / (f_i + f_j), DIFF_INV = 1 / (f_i - f_j), CLOSE where the
 * two entries agree to 1e-6 (the divided difference is then the mean diagonal slope). */
MATERIAL_KERNEL double step_pair_modulus_given(double pi, double pj, double kii, double kjj,
                                               double kij, int close, double sum_inv,
                                               double diff_inv) {
  double a, b;
  step_pair_halves(close, kii, kjj, kij, (pi - pj) * diff_inv, (pi + pj) * sum_inv, &a, &b);
  return a + fabs(b + kij);
}

/* The Ogden models' k (Mooney-Rivlin is two Ogden terms) from the slots their stress kernel
 * wrote for a lane (ogden_stress_cached_lanes, stride STRIDE): the Fhat, and Phat and the
 * diagonal slopes at the clamped point, whose powers f^(alpha_p - 1) are most of an update.
 * Their stress loop calls libm's pow and runs lane by lane; this one has no call, so it
 * vectorizes. Its nine quotients (1/f_i for K_ij, and each pair's 1/(f_i + f_j) and
 * 1/(f_i - f_j)) come from one reciprocal of their product: a reciprocal is about eleven
 * multiply-adds, and nine of them were most of what k added to an update on an AVX2 machine
 * (BENCHMARKS.md). A lane whose product leaves [1e-280, 1e280] (entries far apart in scale)
 * is left to the pass, as a clamped one is. */
MATERIAL_KERNEL void ogden_modulus_from_slots(const piola_material *m, const double *slots, long stride,
                                              double *k_out) {
  const double f0 = slots[OGDEN_CACHE_KEY * stride], f1 = slots[(OGDEN_CACHE_KEY + 1) * stride],
               f2 = slots[(OGDEN_CACHE_KEY + 2) * stride];
  const double c = material_threshold_at(m, f0, f1, f2);
  const int unclamped = (f0 >= c) & (f1 >= c) & (f2 >= c);
  /* clamped lanes store no k; their entries are raised to c so that every product is finite */
  const double e0 = kernel_max(f0, c), e1 = kernel_max(f1, c), e2 = kernel_max(f2, c);
  const double p0 = slots[OGDEN_CACHE_P * stride], p1 = slots[(OGDEN_CACHE_P + 1) * stride],
               p2 = slots[(OGDEN_CACHE_P + 2) * stride];
  const double k0 = slots[OGDEN_CACHE_K * stride], k1 = slots[(OGDEN_CACHE_K + 1) * stride],
               k2 = slots[(OGDEN_CACHE_K + 2) * stride];
  const double d01 = e0 - e1, d02 = e0 - e2, d12 = e1 - e2;
  const int close01 = step_entries_close(e0, e1), close02 = step_entries_close(e0, e2),
            close12 = step_entries_close(e1, e2);
  /* differences as magnitudes, their signs put back below; 1 where close (not used there) */
  const double a01 = close01 ? 1.0 : fabs(d01), a02 = close02 ? 1.0 : fabs(d02),
               a12 = close12 ? 1.0 : fabs(d12);
  const double s01 = e0 + e1, s02 = e0 + e2, s12 = e1 + e2;
  const double volume = e0 * e1 * e2, sums = s01 * s02 * s12, diffs = a01 * a02 * a12;
  const double product = volume * sums * diffs;
  const int representable = (product >= 1e-280) & (product <= 1e280);
  const double r = kernel_recip_fast(representable ? product : 1.0);
  double i0, i1, i2, si01, si02, si12, di01, di02, di12;
  step_reciprocals_of_three(e0, e1, e2, sums * diffs * r, &i0, &i1, &i2);
  step_reciprocals_of_three(s01, s02, s12, volume * diffs * r, &si01, &si02, &si12);
  step_reciprocals_of_three(a01, a02, a12, volume * sums * r, &di01, &di02, &di12);
  const double lambda = m->lambda;
  double k = kernel_max(k0, kernel_max(k1, k2));
  k = kernel_max(k, step_pair_modulus_given(p0, p1, k0, k1, lambda * i0 * i1, close01, si01,
                                            d01 < 0.0 ? -di01 : di01));
  k = kernel_max(k, step_pair_modulus_given(p0, p2, k0, k2, lambda * i0 * i2, close02, si02,
                                            d02 < 0.0 ? -di02 : di02));
  k = kernel_max(k, step_pair_modulus_given(p1, p2, k1, k2, lambda * i1 * i2, close12, si12,
                                            d12 < 0.0 ? -di12 : di12));
  step_cache_store(k_out, unclamped & representable, k + m->fiber_modulus);
}

/* Stable Neo-Hookean with no entry clamped (stable_neohookean_stress_lanes_unclamped) and its
 * k in closed form. With A = mu' I_C / (I_C + 1), g_i = J / f_i, v = lambda' (J - alpha) and
 * B = 2 mu' / (I_C + 1)^2: P_i = A f_i + v g_i, K_ii = A + lambda' g_i^2 + B f_i^2, and the
 * pair ij's divided differences are A -+ v f_k, so a = A, b = -v f_k and
 * pair_ij = A + lambda' g_i g_j + B f_i f_j, at most (K_ii + K_jj) / 2 (2 x y <= x^2 + y^2):
 * k = max_i K_ii, no division. */
MATERIAL_KERNEL void stable_neohookean_stress_modulus_unclamped(const piola_material *m, double f0,
                                                                double f1, double f2, double *p0,
                                                                double *p1, double *p2, double *k_out) {
  stable_neohookean_stress_lanes_unclamped(m, f0, f1, f2, p0, p1, p2);
  const double mu_s = m->model_constants[SNH_MU], lambda_s = m->model_constants[SNH_LAMBDA];
  const double ic = f0 * f0 + f1 * f1 + f2 * f2, r = kernel_recip_fast(ic + 1.0);
  const double a = mu_s * ic * r, b = 2.0 * mu_s * r * r;
  const double g0 = f1 * f2, g1 = f0 * f2, g2 = f0 * f1;
  const double k0 = a + lambda_s * g0 * g0 + b * f0 * f0;
  const double k1 = a + lambda_s * g1 * g1 + b * f1 * f1;
  const double k2 = a + lambda_s * g2 * g2 + b * f2 * f2;
  step_cache_store(k_out, 1, kernel_max(k0, kernel_max(k1, k2)) + m->fiber_modulus);
}

/* NAME_stress_lanes for a block with a lane clamped at the threshold in force: the stress with
 * no k formed (step_cache_skip's NaN), so the block is not cached. One per model that splits
 * its blocks (PIOLA_SPLIT_BY_BLOCK_WITH in material_lanes.h), for the lane loops to name. */
#define STEP_UNCACHED_STRESS_KERNEL(name)                                                           \
  MATERIAL_KERNEL void name##_stress_lanes_uncached(const piola_material *m, double f0, double f1,   \
                                                    double f2, double *p0, double *p1, double *p2,  \
                                                    double *k_out) {                                \
    name##_stress_lanes(m, f0, f1, f2, p0, p1, p2);                                                 \
    step_cache_skip(k_out);                                                                         \
  }
STEP_UNCACHED_STRESS_KERNEL(neohookean)
STEP_UNCACHED_STRESS_KERNEL(hgo)
STEP_UNCACHED_STRESS_KERNEL(stable_neohookean)
STEP_UNCACHED_STRESS_KERNEL(mooney_rivlin)
#undef STEP_UNCACHED_STRESS_KERNEL

#endif
