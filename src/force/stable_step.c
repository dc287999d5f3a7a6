/* The state-aware explicit step bound (see stable_step.h and docs/time-stepping.md).
 *
 * Why the force loop forms most of it: the pass is bound by its arithmetic, not by the
 * stream (bench_stable_step's "warm" column: a second pass run at once after the first costs
 * the same CPU), and that arithmetic repeats the force loop's (the model's value and slopes
 * at Fhat, 1/f_i, ln J). So for every model but HGO (STEP_CACHE_MODEL) the force loop's lane
 * kernels form each tet's k (before the weight 1/(rho h_e^2) and the direction weights) where
 * no entry is clamped, and the force loop keeps per block the maxima of w_e k_e below and
 * above the stiff modulus under the update's generation (stable_step_modulus.h; corotated,
 * StVK, rotated linear and Stable Neo-Hookean in closed form, the spline's pairs by a bound
 * without division); the pass reads them for every block the last update formed, and the
 * weighted models' stiff blocks still take their weights here (a cached block's lanes are
 * known unclamped: STEP_EXTENSION_NONE). Blocks with a clamped entry, a stale key (formed by
 * an earlier update), the energy extension, mixed materials and HGO go through the lane
 * loops below: the model switch
 * hoisted out of an `omp simd` loop as in the force loop, per lane the model's value and
 * slope at the clamped point (material_model_parts), its extension (material_extend) and
 * three 2x2 blocks. The Ogden models' blocks with a clamped entry and HGO take their dearest
 * parts from caches of their own (their powers; the fibre term).
 *
 * The modulus. In the frame of the diagonalization dP/dF splits into the 3x3 block
 * K = dPhat/dFhat on the diagonal entries and one 2x2 block per pair (i, j) on (F_ij, F_ji),
 * [[a, b], [b, a]] with a + b = (P_i - P_j)/(f_i - f_j) and a - b = (P_i + P_j)/(f_i + f_j).
 * For a rank-one unit dF = a n^T (a plane wave) with d_i = dF_ii, x = dF_ij, y = dF_ji one has
 * d_i d_j = x y, so
 *     dF : C : dF = sum_i K_ii d_i^2 + sum_{i<j} [x y] (B_ij + K_ij [[0,1],[1,0]]) [x y]^T
 * and the weights d_i^2, x^2 + y^2 sum to |a|^2 |n|^2 = 1. Hence
 *     k = max(max_i K_ii, max_{i<j} a_ij + |b_ij + K_ij|)
 * bounds the squared plane-wave speed times density; at rest both terms are lambda + 2 mu.
 * Past the inversion threshold the slopes are those of the extension at the threshold (the
 * diagonal raised as the extension raises it); the denominator f_i + f_j is kept away from 0
 * by the threshold c (the rotational block is singular there for any invertible model).
 *
 * A kernel, compiled once per instruction set (common/isa.h): its lane loops are a few
 * percent of a step, and at baseline x86-64 four times that. Without fused multiply-adds
 * and with only max reductions, every variant computes the same bits here; a k cached by
 * the force loop carries that kernel's fused multiply-adds, so where the cache holds, the
 * bound's last bits follow the variant as Fhat's do (tests/test_kernel_isa.c). */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "force/stable_step.h"
#include "force/stable_step_anisotropy.h"
#include "force/stable_step_modulus.h"
#include "material/hgo_kernels.h"
#include "material/material_kernels.h"

#define STABLE_STEP_KERNEL static inline __attribute__((always_inline))

/* A positive double's bits, which order as it does. */
STABLE_STEP_KERNEL uint64_t magnitude_bits(double x) {
  uint64_t bits;
  memcpy(&bits, &x, sizeof bits);
  return bits;
}
STABLE_STEP_KERNEL double from_magnitude_bits(uint64_t bits) {
  double x;
  memcpy(&x, &bits, sizeof x);
  return x;
}

/* X rounded up to the weighted terms' grid (STEP_RATE_GRID_BITS mantissa bits; infinity past
 * its largest value); 0, negative, infinite and NaN X unchanged. */
STABLE_STEP_KERNEL double step_rate_grid_ceil(double x) {
  const uint64_t mask = ((uint64_t)1 << (52 - STEP_RATE_GRID_BITS)) - 1;
  const double up = from_magnitude_bits((magnitude_bits(x) + mask) & ~mask);
  return x > 0.0 && x < INFINITY ? up : x;
}

/* The same pair weighted by the direction weights wi, wj (stable_step_anisotropy.h). */
STABLE_STEP_KERNEL double weighted_pair_modulus(kernel_division dv, double c, double pi, double pj,
                                                double fi, double fj, double kii, double kjj, double kij,
                                                double wi, double wj) {
  double a, b;
  step_pair_block(dv, c, pi, pj, fi, fj, kii, kjj, kij, &a, &b);
  return step_weighted_pair(a, b + kij, wi, wj);
}

/* The models whose bound takes the direction weights: those that stiffen under stretch where
 * the sliver is wide (docs/time-stepping.md, "Slivers stretched along their thin direction").
 * Neo-Hookean, the muscle, Ogden, Mooney-Rivlin and HGO keep the unweighted bound. */
#define DIRECTION_WEIGHTED(model)                                                            \
  ((model) == PIOLA_MODEL_COROTATED || (model) == PIOLA_MODEL_STVK ||                        \
   (model) == PIOLA_MODEL_SPLINE || (model) == PIOLA_MODEL_STABLE_NEOHOOKEAN ||              \
   (model) == PIOLA_MODEL_ROTATED_LINEAR)

/* The extension a lane loop is compiled for (a compile-time constant there, like the model).
 * NONE: no entry is clamped, which the caller knows (a block the force loop cached): every
 * extension but the energy one adds exactly zero there, and the pairs' f_i + f_j >= 2 c > 0
 * and |f_i - f_j| are normal, so their divisions are fast reciprocals (multiply-adds only,
 * without fusing: the same bits in every variant). */
enum {
  STEP_EXTENSION_CLAMP = 0,
  STEP_EXTENSION_ENERGY = 1,
  STEP_EXTENSION_LINEAR = 2,
  STEP_EXTENSION_NONE = 3
};

/* Increment of the LINEAR extension over the unextended stress, E(parts, d) - p, entry by entry. */
STABLE_STEP_KERNEL void linear_increment(const piola_material *m, const material_parts *pa, double d0,
                                         double d1, double d2, double e[3]) {
  material_extend(m, KERNEL_FAST_RECIPROCAL, m->threshold, pa, d0, d1, d2, &e[0], &e[1], &e[2]);
  for (int i = 0; i < 3; ++i) e[i] -= pa->p[i];
}

/* The LINEAR extension's slopes along the unclamped entries. Its stress depends on an
 * unclamped entry f_u through the clamped point's p and K, which the extension multiplies by
 * the clamped offsets (an unclamped row is p_i + sum_l K_il q(d_l), a clamped one carries
 * its slopes times d_i): dP_i/df_u = K_iu + d(E_i - p_i)/df_u. The second term (third
 * derivatives of the energy times the offsets) is taken by a forward difference of the
 * extension's increment along each unclamped entry (three more evaluations of the clamped
 * point, in this mode only; upward, so the entry stays unclamped); it is exactly zero when no
 * entry is clamped, so the bound at rest is unchanged. Along a clamped entry l the slopes are
 * closed forms: max(K_il, 0) into another clamped row, K_il q'(d_l) into an unclamped one
 * (q' = (w / (w - d))^2, extension_saturation). The Jacobian has no potential where
 * entries are clamped, so the plane-wave form takes its symmetric part. */
STABLE_STEP_KERNEL void linear_extension_slopes(piola_material_model model, const piola_material *m,
                                                const material_parts *pa, double fc0, double fc1,
                                                double fc2, double d0, double d1, double d2,
                                                double *k0, double *k1, double *k2, double *k01,
                                                double *k02, double *k12) {
  const double fc[3] = {fc0, fc1, fc2}, d[3] = {d0, d1, d2}, w = 0.25 * m->threshold;
  double base[3], jac[3][3]; /* jac[i][u] = dP_i / df_u */
  linear_increment(m, pa, d0, d1, d2, base);
  for (int u = 0; u < 3; ++u) {
    const double h = 1e-6 * kernel_max(fc[u], 1.0);
    material_parts pu;
    material_model_parts(model, m, KERNEL_FAST_RECIPROCAL, fc0 + (u == 0 ? h : 0.0),
                         fc1 + (u == 1 ? h : 0.0), fc2 + (u == 2 ? h : 0.0), &pu);
    double e[3];
    linear_increment(m, &pu, d0, d1, d2, e);
    const double dl = d[u], ql = w * kernel_recip_fast(w - dl), qprime = ql * ql;
    for (int i = 0; i < 3; ++i) {
      const double unclamped_column = pa->k[i][u] + (e[i] - base[i]) / h;
      const double clamped_column = d[i] < 0.0 ? kernel_max(pa->k[i][u], 0.0) : pa->k[i][u] * qprime;
      jac[i][u] = dl < 0.0 ? clamped_column : unclamped_column;
    }
  }
  /* the diagonal of a clamped entry keeps the threshold bound above; an unclamped one's is
   * the slope just taken */
  *k0 = d0 < 0.0 ? *k0 : jac[0][0];
  *k1 = d1 < 0.0 ? *k1 : jac[1][1];
  *k2 = d2 < 0.0 ? *k2 : jac[2][2];
  const int any = (d0 < 0.0) | (d1 < 0.0) | (d2 < 0.0);
  *k01 = any ? 0.5 * (jac[0][1] + jac[1][0]) : *k01;
  *k02 = any ? 0.5 * (jac[0][2] + jac[2][0]) : *k02;
  *k12 = any ? 0.5 * (jac[1][2] + jac[2][1]) : *k12;
}

/* k of one tet of model MODEL with the stress extension of mode ENERGY (both compile-time
 * constants in the lane loops: STEP_EXTENSION_CLAMP, _ENERGY or _LINEAR); the model's parts at
 * the clamped point are GIVEN (the Ogden models' cache) or, when it is NULL, computed. With
 * direction weights WGT (NULL: none) the tet's term instead, its weight WEIGHT = 1 / (rho
 * h_e^2) times k, or where k is stiff times min(k, k_w) rounded up to the grid
 * (stable_step_anisotropy.h). */
STABLE_STEP_KERNEL double model_modulus_weighted(piola_material_model model, int energy,
                                                 const piola_material *m, double f0, double f1,
                                                 double f2, const material_parts *given,
                                                 const double *wgt, double weight) {
  const double c = MATERIAL_THRESHOLD(model, m, f0, f1, f2);
  const double fc0 = kernel_max(f0, c), fc1 = kernel_max(f1, c), fc2 = kernel_max(f2, c);
  const double d0 = f0 - fc0, d1 = f1 - fc1, d2 = f2 - fc2;
  material_parts pa;
  if (given) pa = *given;
  else material_model_parts(model, m, KERNEL_FAST_RECIPROCAL, fc0, fc1, fc2, &pa);
  double p0, p1, p2, k0, k1, k2;
  double k01 = pa.k[0][1], k02 = pa.k[0][2], k12 = pa.k[1][2];
  if (energy == STEP_EXTENSION_NONE) {
    p0 = pa.p[0], p1 = pa.p[1], p2 = pa.p[2];
    k0 = pa.k[0][0], k1 = pa.k[1][1], k2 = pa.k[2][2];
  } else if (energy == STEP_EXTENSION_ENERGY) {
    /* The energy extension (material_kernels.h) has no closed-form slopes worth writing out:
     * a clamped entry's diagonal is the extension's k, which grows with the other entries'
     * stretch (as its fourth power for the J models), and the unclamped entries' slopes and
     * the couplings carry derivatives of the clamped point's coefficients times the offsets.
     * So its 3x3 Jacobian is taken by differences of the extended stress: the larger
     * one-sided slope on the diagonal (the slope jumps at the threshold), central ones off
     * it. Six more stress evaluations, in this mode only. */
    material_energy_extended_stress(model, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2, &p0, &p1, &p2);
    const double h0 = 1e-6 * kernel_max(fabs(f0), 1.0), h1 = 1e-6 * kernel_max(fabs(f1), 1.0),
                 h2 = 1e-6 * kernel_max(fabs(f2), 1.0);
    double a0, a1, a2, b0, b1, b2, e0, e1, e2, g0, g1, g2, q0, q1, q2, r0, r1, r2;
    material_energy_extended_stress(model, m, KERNEL_FAST_RECIPROCAL, f0 + h0, f1, f2, &a0, &a1, &a2);
    material_energy_extended_stress(model, m, KERNEL_FAST_RECIPROCAL, f0 - h0, f1, f2, &b0, &b1, &b2);
    material_energy_extended_stress(model, m, KERNEL_FAST_RECIPROCAL, f0, f1 + h1, f2, &e0, &e1, &e2);
    material_energy_extended_stress(model, m, KERNEL_FAST_RECIPROCAL, f0, f1 - h1, f2, &g0, &g1, &g2);
    material_energy_extended_stress(model, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2 + h2, &q0, &q1, &q2);
    material_energy_extended_stress(model, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2 - h2, &r0, &r1, &r2);
    k0 = kernel_max((a0 - p0) / h0, (p0 - b0) / h0);
    k1 = kernel_max((e1 - p1) / h1, (p1 - g1) / h1);
    k2 = kernel_max((q2 - p2) / h2, (p2 - r2) / h2);
    /* symmetric (a gradient), averaged */
    k01 = 0.25 * ((a1 - b1) / h0 + (e0 - g0) / h1);
    k02 = 0.25 * ((a2 - b2) / h0 + (q0 - r0) / h2);
    k12 = 0.25 * ((e2 - g2) / h1 + (q1 - r1) / h2);
  } else {
    material_extend(m, KERNEL_FAST_RECIPROCAL, c, &pa, d0, d1, d2, &p0, &p1, &p2);
    /* a clamped entry's diagonal slope is at most the extension's threshold slope */
    const double floor_slope = m->mu;
    k0 = d0 < 0.0 ? kernel_max(pa.k[0][0], floor_slope + kernel_max(pa.p[0], 0.0) / c) : pa.k[0][0];
    k1 = d1 < 0.0 ? kernel_max(pa.k[1][1], floor_slope + kernel_max(pa.p[1], 0.0) / c) : pa.k[1][1];
    k2 = d2 < 0.0 ? kernel_max(pa.k[2][2], floor_slope + kernel_max(pa.p[2], 0.0) / c) : pa.k[2][2];
    if (energy == STEP_EXTENSION_LINEAR)
      linear_extension_slopes(model, m, &pa, fc0, fc1, fc2, d0, d1, d2, &k0, &k1, &k2, &k01, &k02, &k12);
    if (MATERIAL_THRESHOLD_RISES(model) && energy == STEP_EXTENSION_CLAMP) {
      /* the threshold's rise with J (material_threshold_at) adds g_i dc/dJ dJ/df_j to the
       * 3x3 block (g = dPhat/dc): its diagonal and its symmetric part off it */
      double g[3];
      clamp_threshold_sensitivity(m, c, &pa, d0, d1, d2, g);
      const double s = material_threshold_volume_slope(m, f0, f1, f2);
      const double j0 = f1 * f2, j1 = f0 * f2, j2 = f0 * f1;
      k0 += s * g[0] * j0, k1 += s * g[1] * j1, k2 += s * g[2] * j2;
      k01 += 0.5 * s * (g[0] * j1 + g[1] * j0);
      k02 += 0.5 * s * (g[0] * j2 + g[2] * j0);
      k12 += 0.5 * s * (g[1] * j2 + g[2] * j1);
    }
  }
  const kernel_division dv = energy == STEP_EXTENSION_NONE ? KERNEL_FAST_RECIPROCAL : KERNEL_EXACT_DIVIDE;
  /* the spline's plain lanes: the force loop's bound without divisions (step_spline_modulus);
   * NONE is named so that its loops, where d is zero but not known to be, drop the pairs */
  const int spline_plain = model == PIOLA_MODEL_SPLINE && energy != STEP_EXTENSION_ENERGY &&
                           (energy == STEP_EXTENSION_NONE || (d0 == 0.0 && d1 == 0.0 && d2 == 0.0));
  /* Mooney-Rivlin's likewise where the force loop takes its plain stress (its exact pairs in
   * closed form, step_mooney_rivlin_modulus_at) */
  const int mooney_rivlin_plain = model == PIOLA_MODEL_MOONEY_RIVLIN && energy != STEP_EXTENSION_ENERGY &&
                                  (energy == STEP_EXTENSION_NONE || mooney_rivlin_lane_unclamped(m, f0, f1, f2));
  double k = spline_plain          ? step_spline_modulus(m->lambda, f0, f1, f2, k0, k1, k2)
             : mooney_rivlin_plain ? step_mooney_rivlin_modulus_at(m, f0, f1, f2)
                                   : step_modulus_of_slopes(dv, c, p0, p1, p2, f0, f1, f2, k0, k1, k2, k01, k02, k12);
  if (wgt) {
    double kw = kernel_max(wgt[0] * k0, kernel_max(wgt[1] * k1, wgt[2] * k2));
    kw = kernel_max(kw, weighted_pair_modulus(dv, c, p0, p1, f0, f1, k0, k1, k01, wgt[0], wgt[1]));
    kw = kernel_max(kw, weighted_pair_modulus(dv, c, p0, p2, f0, f2, k0, k2, k02, wgt[0], wgt[2]));
    kw = kernel_max(kw, weighted_pair_modulus(dv, c, p1, p2, f1, f2, k1, k2, k12, wgt[1], wgt[2]));
    const int stiff = k > STEP_CACHE_STIFF * (m->lambda + 2.0 * m->mu);
    const double term = weight * ((stiff ? kernel_min(k, kw) : k) + m->fiber_modulus);
    return stiff ? step_rate_grid_ceil(term) : term;
  }
  /* muscle fibres: their tangent stiffness bound, as in the rest bound; HGO's exponential
   * fibres depend on their direction: hgo_tet_fiber_modulus, added by the callers */
  return k + (model == PIOLA_MODEL_HGO ? 0.0 : m->fiber_modulus);
}

STABLE_STEP_KERNEL double model_modulus_from(piola_material_model model, int energy,
                                             const piola_material *m, double f0, double f1,
                                             double f2, const material_parts *given) {
  return model_modulus_weighted(model, energy, m, f0, f1, f2, given, NULL, 1.0);
}

STABLE_STEP_KERNEL double model_modulus(piola_material_model model, int energy,
                                        const piola_material *m, double f0, double f1, double f2) {
  return model_modulus_weighted(model, energy, m, f0, f1, f2, NULL, NULL, 1.0);
}

/* The force loop's k cache (stable_step_modulus.h), or the Ogden and HGO caches of
 * material_kernels.h and hgo_kernels.h, where the pass may read it, else NULL. Not
 * in the replicated mode of a work split: there every process takes the bound over every tet
 * and must get the same bits, but only its own blocks' k come from its force loop (with fused
 * multiply-adds), the gathered ones would be computed here (without): the processes' steps
 * would part in their last bits and their collectives with them (mpi_frames.sh's
 * plastic_control hung on 2 processes). The local mode takes each process's own blocks only.
 * (The replicated mode's bodies also drop the caches when the split is set up, work_split.c,
 * so that their force loops do not form them.) */
static const double *readable_force_loop_cache(const piola_elastic_body *body, const double *cache) {
  return body->split && !body->split_local ? NULL : cache;
}
static const double *readable_step_cache(const piola_elastic_body *body) {
  return readable_force_loop_cache(body, body->step_cache);
}

/* Where the body has direction weights (stable_step_anisotropy.h): its Gram arrays once an
 * update has set V, else NULL. */
static const double *direction_gram(const piola_elastic_body *body) {
  return body->has_state ? body->step_gram : NULL;
}

/* The term of tet t of a DIRECTION_WEIGHTED model with its direction weights and its weight W
 * (GRAM not NULL; the callers choose outside their lane loops, so that these vectorize). */
STABLE_STEP_KERNEL double weighted_lane_rate(piola_material_model model, int energy,
                                             const piola_material *m,
                                             const piola_elastic_body *body, const double *gram,
                                             int32_t t, const double *f, double w) {
  double wgt[3];
  step_direction_weights(gram + t, body->tet_count, body->v[0] + t, body->padded_tet_count, wgt);
  return model_modulus_weighted(model, energy, m, f[0], f[1], f[2], NULL, wgt, w);
}

/* The fibre term of HGO tet t at Fhat f (hgo_directed_fiber_modulus): its families'
 * directions in the diagonal frame of the last update (V^T a, as the force loop forms them),
 * or the term that update cached when it evaluated this f (hgo_cache_holds). A body without
 * fibres has no fibre force, so no term; before any update only the direction-free bound of
 * hgo_kernels.h. */
static double hgo_tet_fiber_modulus(const piola_elastic_body *body, const piola_material *m,
                                    int32_t t, const double f[3]) {
  if (!body->fiber[0]) return 0.0;
  if (!body->has_state) return hgo_fiber_modulus_bound(&m->hgo, f[0], f[1], f[2]);
  const double *cache = readable_force_loop_cache(body, body->hgo_cache);
  if (cache && hgo_cache_holds(cache + t, body->padded_tet_count, f[0], f[1], f[2]))
    return cache[t + HGO_CACHE_MODULUS * body->padded_tet_count];
  const long stride = body->padded_tet_count;
  const double *v = body->v[0] + t;
  const double dir[3] = {body->fiber[0][t], body->fiber[1][t], body->fiber[2][t]};
  double fam[2][3], ahat[2][3];
  (void)hgo_families_from_fiber(m, dir, fam); /* checked when the body was built */
  for (int a = 0; a < 2; ++a)
    for (int k = 0; k < 3; ++k)
      ahat[a][k] = v[k * stride] * fam[a][0] + v[(3 + k) * stride] * fam[a][1] + v[(6 + k) * stride] * fam[a][2];
  return hgo_directed_fiber_modulus(&m->hgo, f[0], f[1], f[2], ahat);
}

/* Neo-Hookean (and the muscle's matrix) with every entry at or above the threshold: the
 * closed form of step_neohookean_modulus with one logarithm of J. The same numbers as
 * model_modulus up to rounding, at a fraction of the cost (three logarithms and the
 * extension's selects are what make it dear). */
STABLE_STEP_KERNEL double neohookean_matrix_modulus(const piola_material *m, double f0, double f1,
                                                    double f2) {
  const double i0 = kernel_recip_fast(f0), i1 = kernel_recip_fast(f1), i2 = kernel_recip_fast(f2);
  return step_neohookean_modulus(m, i0, i1, i2, m->lambda * kernel_log_div(f0 * f1 * f2, KERNEL_FAST_RECIPROCAL));
}

/* The same with the muscle's fibre bound (zero for neo-Hookean). */
STABLE_STEP_KERNEL double neohookean_plain_modulus(const piola_material *m, double f0, double f1,
                                                   double f2) {
  return neohookean_matrix_modulus(m, f0, f1, f2) + m->fiber_modulus;
}

/* One case of mode_modulus: MODEL's kernel inlined with its own constant, the direction
 * weights passed on only to the models that take them. */
#define MODE_MODULUS_CASE(model)                                      \
  case model:                                                         \
    return model_modulus_weighted(model, energy, m, f0, f1, f2, NULL, \
                                  DIRECTION_WEIGHTED(model) ? wgt : NULL, weight);

/* Per tet: the model and the extension mode chosen at run time; with WGT (a DIRECTION_WEIGHTED
 * model) the term of weight WEIGHT, as model_modulus_weighted. */
static double mode_modulus(int energy, const piola_material *m, double f0, double f1, double f2,
                           const double *wgt, double weight) {
  switch (m->model) {
    MODE_MODULUS_CASE(PIOLA_MODEL_COROTATED)
    MODE_MODULUS_CASE(PIOLA_MODEL_STVK)
    MODE_MODULUS_CASE(PIOLA_MODEL_NEOHOOKEAN)
    MODE_MODULUS_CASE(PIOLA_MODEL_MUSCLE)
    MODE_MODULUS_CASE(PIOLA_MODEL_HGO)
    MODE_MODULUS_CASE(PIOLA_MODEL_SPLINE)
    MODE_MODULUS_CASE(PIOLA_MODEL_STABLE_NEOHOOKEAN)
    MODE_MODULUS_CASE(PIOLA_MODEL_MOONEY_RIVLIN)
    MODE_MODULUS_CASE(PIOLA_MODEL_OGDEN)
    MODE_MODULUS_CASE(PIOLA_MODEL_ROTATED_LINEAR)
    default: abort(); /* every model has its case: a new one must get its modulus */
  }
}

#undef MODE_MODULUS_CASE

static double material_modulus(const piola_material *m, double f0, double f1, double f2,
                               const double *wgt, double weight) {
  switch (m->inversion_mode) {
    case PIOLA_INVERSION_ENERGY:
      return mode_modulus(STEP_EXTENSION_ENERGY, m, f0, f1, f2, wgt, weight);
    case PIOLA_INVERSION_LINEAR: /* with no entry clamped, the CLAMP numbers (linear_range) */
      return mode_modulus(
          lane_unclamped(m, f0, f1, f2) ? STEP_EXTENSION_CLAMP : STEP_EXTENSION_LINEAR, m, f0, f1,
          f2, wgt, weight);
    default:
      return mode_modulus(STEP_EXTENSION_CLAMP, m, f0, f1, f2, wgt, weight);
  }
}

double PIOLA_ISA_NAME(piola__elastic_body_tet_rest_altitude)(const piola_elastic_body *body, int32_t t) {
  /* grad N_c of corners 1..3 are the rows of Dm^-1, corner 0's is minus their sum */
  double g0[3] = {0, 0, 0}, worst = 0;
  for (int r = 0; r < 3; ++r) {
    double n2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double g = body->dm_inv[3 * r + k][t];
      g0[k] -= g;
      n2 += g * g;
    }
    worst = fmax(worst, n2);
  }
  worst = fmax(worst, g0[0] * g0[0] + g0[1] * g0[1] + g0[2] * g0[2]);
  return worst > 0 ? 1.0 / sqrt(worst) : INFINITY;
}

double PIOLA_ISA_NAME(piola__elastic_body_tet_modulus)(const piola_elastic_body *body, int32_t tet,
                                                      const double fhat[3]) {
  const piola_material *m = &body->materials[body->tet_material[tet]];
  const double k = material_modulus(m, fhat[0], fhat[1], fhat[2], NULL, 1.0);
  return m->model == PIOLA_MODEL_HGO ? k + hgo_tet_fiber_modulus(body, m, tet, fhat) : k;
}

double PIOLA_ISA_NAME(piola__elastic_body_tet_state_rate2)(const piola_elastic_body *body, int32_t tet) {
  const piola_material *m = &body->materials[body->tet_material[tet]];
  const double *f = body->fhat + 3 * tet, *gram = direction_gram(body);
  if (!gram || !DIRECTION_WEIGHTED(m->model))
    return body->step_weight[tet] * PIOLA_ISA_NAME(piola__elastic_body_tet_modulus)(body, tet, f);
  double wgt[3];
  step_direction_weights(gram + tet, body->tet_count, body->v[0] + tet, body->padded_tet_count, wgt);
  return material_modulus(m, f[0], f[1], f[2], wgt, body->step_weight[tet]);
}

/* 1 / (rho h_e^2) per tet and the Gram arrays of the direction weights, from the Dm^-1 the
 * body has when first asked: built once. That is the rest Dm^-1, except for a body a cut
 * rebuilt after plasticity changed it (the effective Dm^-1 then; checkpoints store these
 * weights for such solids, docs/file-formats.md). */
static const double *rate_weights(piola_elastic_body *body) {
  if (!body->step_weight) {
    double *w = malloc((size_t)(body->tet_count > 0 ? body->tet_count : 1) * sizeof *w);
    if (!w) return NULL;
    double *gram = malloc(6 * (size_t)(body->tet_count > 0 ? body->tet_count : 1) * sizeof *gram);
    if (!gram) {
      free(w);
      return NULL;
    }
    for (int32_t t = 0; t < body->tet_count; ++t) {
      const double h = PIOLA_ISA_NAME(piola__elastic_body_tet_rest_altitude)(body, t);
      w[t] = 1.0 / (body->density * h * h);
      double g[3][3], e[6];
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) g[r][k] = body->dm_inv[3 * r + k][t];
      step_gram_of(g, e);
      for (int k = 0; k < 6; ++k) gram[(size_t)k * (size_t)body->tet_count + (size_t)t] = e[k];
    }
    body->step_weight = w;
    body->step_gram = gram;
  }
  return body->step_weight;
}

const double *PIOLA_ISA_NAME(piola__elastic_body_step_weights)(piola_elastic_body *body) {
  return rate_weights(body);
}

/* Neo-Hookean by blocks of PIOLA_TET_BLOCK: the plain closed form when no lane of the block
 * is below the threshold (neohookean_lane_unclamped, as the force loop decides), else the
 * general one. */
static double neohookean_range(piola_material_model model, int energy, const piola_material *m,
                               const double *f, const double *w, int32_t begin, int32_t end) {
  double best = 0;
  int32_t t = begin;
  for (; t + PIOLA_TET_BLOCK <= end; t += PIOLA_TET_BLOCK) {
    int plain = 1;
#pragma omp simd reduction(&:plain)
    for (int l = 0; l < PIOLA_TET_BLOCK; ++l)
      plain &= neohookean_lane_unclamped(m, f[3 * (t + l)], f[3 * (t + l) + 1], f[3 * (t + l) + 2]);
    if (plain) {
#pragma omp simd reduction(max:best)
      for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
        const double *fl = f + 3 * (t + l);
        const double r = w[t + l] * neohookean_plain_modulus(m, fl[0], fl[1], fl[2]);
        best = r > best ? r : best;
      }
    } else {
#pragma omp simd reduction(max:best)
      for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
        const double *fl = f + 3 * (t + l);
        const double r = w[t + l] * model_modulus(model, energy, m, fl[0], fl[1], fl[2]);
        best = r > best ? r : best;
      }
    }
  }
  for (; t < end; ++t) {
    const double r = w[t] * model_modulus(model, energy, m, f[3 * t], f[3 * t + 1], f[3 * t + 2]);
    best = r > best ? r : best;
  }
  return best;
}

/* Ogden and Mooney-Rivlin (LINEAR or CLAMP: ENERGY is STEP_EXTENSION_LINEAR or _CLAMP) by
 * blocks of PIOLA_TET_BLOCK, for the blocks the step cache does not hold (the force loop
 * writes the per-tet slots of those only, piola__ogden_cache_unformed): the parts at the
 * clamped point from the force loop's cache when it holds every lane's Fhat (no pow here),
 * else computed; a LINEAR block with an entry past the
 * threshold takes the LINEAR slopes (linear_extension_slopes, which evaluate the clamped point
 * again), one with none the CLAMP numbers, as linear_range. */
static double ogden_range(const piola_elastic_body *body, int energy, const piola_material *m,
                          const double *f, const double *w, int32_t begin, int32_t end) {
  const double *cache = body->ogden_cache;
  const long stride = body->padded_tet_count;
  double best = 0;
  int32_t t = begin;
  for (; t + PIOLA_TET_BLOCK <= end; t += PIOLA_TET_BLOCK) {
    int held = 1, plain = 1;
#pragma omp simd reduction(&:held, plain)
    for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
      const double *fl = f + 3 * (t + l);
      held &= ogden_cache_holds(cache + t + l, stride, fl[0], fl[1], fl[2]);
      plain &= lane_unclamped(m, fl[0], fl[1], fl[2]);
    }
    const int ext = energy == STEP_EXTENSION_LINEAR && !plain ? STEP_EXTENSION_LINEAR : STEP_EXTENSION_CLAMP;
    if (held) {
      for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
        const double *fl = f + 3 * (t + l);
        material_parts pa;
        const double cl = material_threshold_at(m, fl[0], fl[1], fl[2]);
        ogden_cached_parts(m, cache + t + l, stride, kernel_max(fl[0], cl), kernel_max(fl[1], cl),
                           kernel_max(fl[2], cl), &pa);
        const double r = w[t + l] * model_modulus_from(PIOLA_MODEL_OGDEN, ext, m, fl[0], fl[1], fl[2], &pa);
        best = r > best ? r : best;
      }
    } else {
      for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
        const double *fl = f + 3 * (t + l);
        const double r = w[t + l] * model_modulus(PIOLA_MODEL_OGDEN, ext, m, fl[0], fl[1], fl[2]);
        best = r > best ? r : best;
      }
    }
  }
  for (; t < end; ++t) {
    const double *ft = f + 3 * t;
    const int ext = energy == STEP_EXTENSION_LINEAR && !lane_unclamped(m, ft[0], ft[1], ft[2])
                        ? STEP_EXTENSION_LINEAR : STEP_EXTENSION_CLAMP;
    const double r = w[t] * model_modulus(PIOLA_MODEL_OGDEN, ext, m, ft[0], ft[1], ft[2]);
    best = r > best ? r : best;
  }
  return best;
}

/* max(best, w_t k_t) over HGO tets [t, end), tet by tet: the matrix's general modulus (the
 * CLAMP numbers for a LINEAR tet with no entry clamped, as linear_range) plus the fibre term. */
static double hgo_tets_rate(const piola_elastic_body *body, int energy, const piola_material *m,
                            const double *f, const double *w, int32_t t, int32_t end, double best) {
  for (; t < end; ++t) {
    const double *ft = f + 3 * t;
    const double k = energy == STEP_EXTENSION_LINEAR && lane_unclamped(m, ft[0], ft[1], ft[2])
                         ? model_modulus(PIOLA_MODEL_HGO, STEP_EXTENSION_CLAMP, m, ft[0], ft[1], ft[2])
                         : model_modulus(PIOLA_MODEL_HGO, energy, m, ft[0], ft[1], ft[2]);
    const double r = w[t] * (k + hgo_tet_fiber_modulus(body, m, t, ft));
    best = r > best ? r : best;
  }
  return best;
}

/* HGO (LINEAR or CLAMP) by blocks of PIOLA_TET_BLOCK (issue 21: tet by tet it cost 143% of an
 * update). Its matrix is neo-Hookean's: where every lane of a block is at or above the
 * threshold in force there (hgo_lane_unclamped, as the force loop splits it; with no entry
 * clamped the threshold's rise adds nothing) it takes neo-Hookean's closed form, and its
 * fibre term is the one the force loop cached at each lane's Fhat (hgo_cache_holds; none
 * without fibres). Such a block is a lane loop over Fhat, the weight and one cached number;
 * the others go tet by tet. The energy extension keeps the tet-by-tet path, whose slopes are
 * differences (model_modulus), so that the lanes and the per-tet terms agree. */
static double hgo_range(const piola_elastic_body *body, int energy, const piola_material *m,
                        const double *f, const double *w, int32_t begin, int32_t end) {
  const int fibers = body->fiber[0] != NULL;
  const long stride = body->padded_tet_count;
  const double *cache = readable_force_loop_cache(body, body->hgo_cache);
  double best = 0;
  int32_t t = begin;
  if (energy != STEP_EXTENSION_ENERGY && (!fibers || cache))
    for (; t + PIOLA_TET_BLOCK <= end; t += PIOLA_TET_BLOCK) {
      int plain = 1;
#pragma omp simd reduction(&:plain)
      for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
        const double *fl = f + 3 * (t + l);
        plain &= hgo_lane_unclamped(m, fl[0], fl[1], fl[2]);
      }
      if (fibers) {
#pragma omp simd reduction(&:plain)
        for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
          const double *fl = f + 3 * (t + l);
          plain &= hgo_cache_holds(cache + t + l, stride, fl[0], fl[1], fl[2]);
        }
      }
      if (!plain) {
        best = hgo_tets_rate(body, energy, m, f, w, t, t + PIOLA_TET_BLOCK, best);
      } else if (fibers) {
        const double *fiber_term = cache + HGO_CACHE_MODULUS * stride + t;
#pragma omp simd reduction(max:best)
        for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
          const double *fl = f + 3 * (t + l);
          const double r = w[t + l] * (neohookean_matrix_modulus(m, fl[0], fl[1], fl[2]) + fiber_term[l]);
          best = r > best ? r : best;
        }
      } else {
#pragma omp simd reduction(max:best)
        for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
          const double *fl = f + 3 * (t + l);
          const double r = w[t + l] * neohookean_matrix_modulus(m, fl[0], fl[1], fl[2]);
          best = r > best ? r : best;
        }
      }
    }
  return hgo_tets_rate(body, energy, m, f, w, t, end, best);
}

/* max(best, w_t k_t) with the LINEAR extension, the direction weights where GRAM is not NULL
 * and they can matter (a stiff tet whose unweighted term is above BEST, as in weighted_range). */
STABLE_STEP_KERNEL double linear_tet_rate(piola_material_model model, const piola_elastic_body *body,
                                          const piola_material *m, const double *gram, const double *f,
                                          const double *w, int32_t t, double best) {
  const double *ft = f + 3 * t;
  const double k = model_modulus(model, STEP_EXTENSION_LINEAR, m, ft[0], ft[1], ft[2]);
  double r = w[t] * k;
  if (gram && DIRECTION_WEIGHTED(model) && step_rate_grid_ceil(r) > best &&
      k > STEP_CACHE_STIFF * (m->lambda + 2.0 * m->mu))
    r = weighted_lane_rate(model, STEP_EXTENSION_LINEAR, m, body, gram, t, ft, w[t]);
  return r > best ? r : best;
}

/* Whether no entry of the block of tets from t is below the threshold (the LINEAR extension
 * then gives the CLAMP numbers). */
STABLE_STEP_KERNEL int block_unclamped(const piola_material *m, const double *f, int32_t t) {
  int plain = 1;
#pragma omp simd reduction(&:plain)
  for (int l = 0; l < PIOLA_TET_BLOCK; ++l)
    plain &= lane_unclamped(m, f[3 * (t + l)], f[3 * (t + l) + 1], f[3 * (t + l) + 2]);
  return plain;
}

/* The force loop's slots of the block from t (stable_step_modulus.h) when that block was
 * formed by the update whose Fhat the body holds (its key is the body's generation), else
 * NULL. T starts a block: the callers' ranges do. */
STABLE_STEP_KERNEL const double *cached_block(const piola_elastic_body *body, const double *cache, int32_t t) {
  const double *slot = cache + (size_t)(t / PIOLA_TET_BLOCK) * STEP_CACHE_SLOTS;
  const double key = slot[STEP_CACHE_KEY];
  return t % PIOLA_TET_BLOCK == 0 && key != 0.0 && key == (double)body->step_generation ? slot : NULL;
}

/* max(best, w_u k_u) with the direction weights over the whole block from t, its lanes' extension
 * EXT a compile-time constant: a trip count the compiler knows, so the loop is one pass of
 * vector code (with a run-time count of 8 it ran the scalar remainder loop). */
STABLE_STEP_KERNEL double weighted_whole_block(piola_material_model model, int ext, const piola_material *m,
                                               const piola_elastic_body *body, const double *gram,
                                               const double *f, const double *w, int32_t t, double best) {
#pragma omp simd reduction(max:best)
  for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
    const double r =
        weighted_lane_rate(model, ext, m, body, gram, t + l, f + 3 * (t + l), w[t + l]);
    best = r > best ? r : best;
  }
  return best;
}

/* One block [t, e) of weighted_range: max(best, its terms with the direction weights). LINEAR
 * blocks with a clamped entry (or a short one) go tet by tet (linear_tet_rate); a block the
 * force loop cached (CACHED: no entry clamped) takes STEP_EXTENSION_NONE. */
STABLE_STEP_KERNEL double weighted_block(piola_material_model model, int energy, const piola_material *m,
                                         const piola_elastic_body *body, const double *gram,
                                         const double *f, const double *w, int32_t t, int32_t e,
                                         int cached, double best) {
  if (e - t == PIOLA_TET_BLOCK && cached && energy != STEP_EXTENSION_ENERGY)
    return weighted_whole_block(model, STEP_EXTENSION_NONE, m, body, gram, f, w, t, best);
  if (energy == STEP_EXTENSION_LINEAR && !(e - t == PIOLA_TET_BLOCK && block_unclamped(m, f, t))) {
    for (int32_t u = t; u < e; ++u) best = linear_tet_rate(model, body, m, gram, f, w, u, best);
    return best;
  }
  const int ext = energy == STEP_EXTENSION_LINEAR ? STEP_EXTENSION_CLAMP : energy;
  if (e - t == PIOLA_TET_BLOCK) return weighted_whole_block(model, ext, m, body, gram, f, w, t, best);
  for (int32_t u = t; u < e; ++u) {
    const double r = weighted_lane_rate(model, ext, m, body, gram, u, f + 3 * u, w[u]);
    best = r > best ? r : best;
  }
  return best;
}

/* What the whole-body pass found before its ranges (ordered_start): a term of the maximum
 * (0 for none), whether every cached block's terms are at most it, so that the ranges
 * skip those blocks, and whether besides every whole block was cached (the ranges then take
 * only the tets past the last whole block). */
typedef struct rate_start {
  double at_least;
  int cached_blocks_within;
  int every_block_cached;
} rate_start;
static const rate_start NO_START = {0.0, 0, 0};

/* weighted_range with the body's cache (stable_step_modulus.h) or none. Two instances, the
 * second with a constant NULL: with the cache's branch in it, the computed lane loop (a body
 * without the cache, the energy extension) took 3-4 times its time in the AVX-512 build. */
#define WEIGHTED_RANGE(model, energy, m, body, gram, f, w, t0, t1, start)                      \
  (readable_step_cache(body)                                                                   \
       ? weighted_range(model, energy, m, body, gram, readable_step_cache(body), f, w, t0, t1, \
                        start)                                                                 \
       : weighted_range(model, energy, m, body, gram, NULL, f, w, t0, t1, start))

/* Blocks a chunk of weighted_range holds: their stiff maxima stay on the stack. */
enum { WEIGHTED_CHUNK = 64 };

/* max over tets [t0, t1) of w_e k_e with the direction weights (GRAM not NULL), exact (a stiff
 * term is rounded up to the grid, step_rate_grid_ceil, on every path alike). The weighted term
 * is at most the unweighted one rounded up (min(k, k_w)) and differs from it only above
 * STEP_CACHE_STIFF. So the unweighted lane loop runs first, block by block, and splits the
 * unweighted maximum into the exact terms of the tets not above it (BEST) and, per block, an
 * upper bound of the stiff ones' (HIGH); a chunk's blocks whose HIGH is above the BEST so far
 * then take the weights (weighted_block) where it rounds up to more than BEST. Near rest no tet is
 * stiff and the bound costs the unweighted loop alone; in a stretched state only the blocks that
 * beat the running maximum pay. LINEAR blocks with no clamped entry take the CLAMP numbers
 * (linear_range). A block whose k the force loop cached (block_cached) reads the unweighted terms
 * from there. START is what the caller has already found (ordered_start; NO_START for nothing): the
 * running maximum starts at its term, so the result is max(START.at_least, every term), and
 * the cached blocks are skipped where it holds them. */
STABLE_STEP_KERNEL double weighted_range(piola_material_model model, int energy,
                                         const piola_material *m, const piola_elastic_body *body,
                                         const double *gram, const double *cache, const double *f,
                                         const double *w, int32_t t0, int32_t t1,
                                         rate_start start) {
  const double stiff = STEP_CACHE_STIFF * (m->lambda + 2.0 * m->mu);
  const int ext = energy == STEP_EXTENSION_LINEAR ? STEP_EXTENSION_CLAMP : energy;
  double best = start.at_least;
  for (int32_t c0 = t0; c0 < t1; c0 += WEIGHTED_CHUNK * PIOLA_TET_BLOCK) {
    const int32_t c1 = t1 - c0 < WEIGHTED_CHUNK * PIOLA_TET_BLOCK ? t1 : c0 + WEIGHTED_CHUNK * PIOLA_TET_BLOCK;
    double high[WEIGHTED_CHUNK], chunk_high = 0;
    int cached[WEIGHTED_CHUNK];
    for (int32_t t = c0; t < c1; t += PIOLA_TET_BLOCK) {
      const int32_t e = c1 - t < PIOLA_TET_BLOCK ? c1 : t + PIOLA_TET_BLOCK;
      double h = 0;
      const double *slot = cache && e - t == PIOLA_TET_BLOCK ? cached_block(body, cache, t) : NULL;
      if (slot && start.cached_blocks_within) {
        /* ordered_start has taken this block's terms: h stays 0 */
      } else if (slot) {
        best = slot[STEP_CACHE_LOW] > best ? slot[STEP_CACHE_LOW] : best;
        h = slot[STEP_CACHE_HIGH];
      } else if (energy == STEP_EXTENSION_LINEAR &&
                 !(e - t == PIOLA_TET_BLOCK && block_unclamped(m, f, t))) {
        for (int32_t u = t; u < e; ++u) {
          const double *fu = f + 3 * u;
          const double k = model_modulus(model, STEP_EXTENSION_LINEAR, m, fu[0], fu[1], fu[2]);
          const double r = w[u] * k;
          if (k > stiff) h = r > h ? r : h;
          else best = r > best ? r : best;
        }
      } else {
#pragma omp simd reduction(max:best) reduction(max:h)
        for (int32_t u = t; u < e; ++u) {
          const double k = model_modulus(model, ext, m, f[3 * u], f[3 * u + 1], f[3 * u + 2]);
          const double r = w[u] * k;
          const int above = k > stiff;
          best = !above && r > best ? r : best;
          h = above && r > h ? r : h;
        }
      }
      high[(t - c0) / PIOLA_TET_BLOCK] = h;
      cached[(t - c0) / PIOLA_TET_BLOCK] = slot != NULL;
      chunk_high = h > chunk_high ? h : chunk_high;
    }
    if (!(step_rate_grid_ceil(chunk_high) > best)) continue;
    for (int32_t t = c0; t < c1; t += PIOLA_TET_BLOCK)
      if (step_rate_grid_ceil(high[(t - c0) / PIOLA_TET_BLOCK]) > best) {
        const int32_t e = c1 - t < PIOLA_TET_BLOCK ? c1 : t + PIOLA_TET_BLOCK;
        best = weighted_block(model, energy, m, body, gram, f, w, t, e, cached[(t - c0) / PIOLA_TET_BLOCK], best);
      }
  }
  return best;
}

/* LINEAR by blocks of PIOLA_TET_BLOCK: a block with no entry below the threshold takes the
 * CLAMP instantiation, the same numbers there (the extension's terms vanish) without the
 * LINEAR slopes' three extra evaluations of the clamped point (linear_extension_slopes). */
STABLE_STEP_KERNEL double linear_range(piola_material_model model, const piola_elastic_body *body,
                                       const piola_material *m, const double *f, const double *w,
                                       int32_t begin, int32_t end, rate_start start) {
  const double *gram = direction_gram(body);
  if (DIRECTION_WEIGHTED(model) && gram)
    return WEIGHTED_RANGE(model, STEP_EXTENSION_LINEAR, m, body, gram, f, w, begin, end, start);
  double best = 0;
  int32_t t = begin;
  for (; t + PIOLA_TET_BLOCK <= end; t += PIOLA_TET_BLOCK) {
    if (block_unclamped(m, f, t)) {
#pragma omp simd reduction(max:best)
      for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
        const double *fl = f + 3 * (t + l);
        const double r = w[t + l] * model_modulus(model, STEP_EXTENSION_CLAMP, m, fl[0], fl[1], fl[2]);
        best = r > best ? r : best;
      }
    } else {
      for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
        const double *fl = f + 3 * (t + l);
        const double r = w[t + l] * model_modulus(model, STEP_EXTENSION_LINEAR, m, fl[0], fl[1], fl[2]);
        best = r > best ? r : best;
      }
    }
  }
  for (; t < end; ++t) {
    const double r = w[t] * model_modulus(model, STEP_EXTENSION_LINEAR, m, f[3 * t], f[3 * t + 1], f[3 * t + 2]);
    best = r > best ? r : best;
  }
  return best;
}

#define MODEL_LANE_LOOP(model)                                                                     \
  if (energy == STEP_EXTENSION_LINEAR)                                                             \
    return linear_range(model, body, m, f, w, begin, end, start);                                  \
  if (DIRECTION_WEIGHTED(model) && gram)                                                           \
    return WEIGHTED_RANGE(model, energy, m, body, gram, f, w, begin, end, start);                  \
  _Pragma("omp simd reduction(max:best)") for (int32_t t = begin; t < end; ++t) {                  \
    const double r = w[t] * model_modulus(model, energy, m, f[3 * t], f[3 * t + 1], f[3 * t + 2]); \
    best = r > best ? r : best;                                                                    \
  }                                                                                                \
  break;

/* max over tets [begin, end) of w_e k_e, one material, its extension ENERGY (STEP_EXTENSION_*)
 * a compile-time constant; START as in weighted_range (the other models ignore it: their
 * result is at least every term, and the caller takes the larger of the two) */
STABLE_STEP_KERNEL double uniform_range_rate2(const piola_elastic_body *body, int energy,
                                              const piola_material *m, const double *f,
                                              const double *w, int32_t begin, int32_t end,
                                              rate_start start) {
  const double *gram = direction_gram(body);
  double best = 0;
  switch (m->model) {
    case PIOLA_MODEL_COROTATED: MODEL_LANE_LOOP(PIOLA_MODEL_COROTATED)
    case PIOLA_MODEL_STVK: MODEL_LANE_LOOP(PIOLA_MODEL_STVK)
    case PIOLA_MODEL_NEOHOOKEAN:
      return neohookean_range(PIOLA_MODEL_NEOHOOKEAN, energy, m, f, w, begin, end);
    case PIOLA_MODEL_MUSCLE: return neohookean_range(PIOLA_MODEL_MUSCLE, energy, m, f, w, begin, end);
    case PIOLA_MODEL_HGO: return hgo_range(body, energy, m, f, w, begin, end);
    case PIOLA_MODEL_SPLINE: MODEL_LANE_LOOP(PIOLA_MODEL_SPLINE)
    case PIOLA_MODEL_STABLE_NEOHOOKEAN: MODEL_LANE_LOOP(PIOLA_MODEL_STABLE_NEOHOOKEAN)
    case PIOLA_MODEL_MOONEY_RIVLIN: MODEL_LANE_LOOP(PIOLA_MODEL_MOONEY_RIVLIN)
    case PIOLA_MODEL_OGDEN:
      if (energy != STEP_EXTENSION_ENERGY && readable_force_loop_cache(body, body->ogden_cache))
        return ogden_range(body, energy, m, f, w, begin, end);
      MODEL_LANE_LOOP(PIOLA_MODEL_OGDEN)
    case PIOLA_MODEL_ROTATED_LINEAR: MODEL_LANE_LOOP(PIOLA_MODEL_ROTATED_LINEAR)
    default: abort(); /* every model has its case (material_modulus) */
  }
  return best;
}

/* max over tets [begin, end) of w_e k_e, every k computed here; START as in uniform_range_rate2 */
static double computed_range_rate2(const piola_elastic_body *body, const double *w, int32_t begin,
                                   int32_t end, rate_start start) {
  const double *f = body->fhat;
  double best = 0;
  if (body->uniform_material >= 0) {
    const piola_material *m = &body->materials[body->uniform_material];
    switch (m->inversion_mode) {
      case PIOLA_INVERSION_ENERGY:
        return uniform_range_rate2(body, STEP_EXTENSION_ENERGY, m, f, w, begin, end, start);
      case PIOLA_INVERSION_LINEAR:
        return uniform_range_rate2(body, STEP_EXTENSION_LINEAR, m, f, w, begin, end, start);
      default:
        return uniform_range_rate2(body, STEP_EXTENSION_CLAMP, m, f, w, begin, end, start);
    }
  } else {
    for (int32_t t = begin; t < end; ++t) {
      const double r = PIOLA_ISA_NAME(piola__elastic_body_tet_state_rate2)(body, t);
      best = r > best ? r : best;
    }
  }
  return best;
}

/* max over tets [begin, end) of w_e k_e: k from the force loop's cache in the blocks where it
 * holds every tet's (block_cached), computed in the others. The direction-weighted models read
 * it inside weighted_range, which weighs only the blocks that can raise the maximum above
 * START.at_least (as there: the caller takes the larger of the two). */
static double range_rate2(const piola_elastic_body *body, const double *w, int32_t begin,
                          int32_t end, rate_start start) {
  const double *cache = readable_step_cache(body);
  if (!cache || (direction_gram(body) && DIRECTION_WEIGHTED(body->materials[body->uniform_material].model)))
    return computed_range_rate2(body, w, begin, end, start);
  double best = 0;
  int32_t t = begin;
  for (; t + PIOLA_TET_BLOCK <= end; t += PIOLA_TET_BLOCK) {
    const double *slot = cached_block(body, cache, t);
    const double r = slot ? (slot[STEP_CACHE_LOW] > slot[STEP_CACHE_HIGH] ? slot[STEP_CACHE_LOW]
                                                                          : slot[STEP_CACHE_HIGH])
                          : computed_range_rate2(body, w, t, t + PIOLA_TET_BLOCK, NO_START);
    best = r > best ? r : best;
  }
  if (t < end) {
    const double r = computed_range_rate2(body, w, t, end, NO_START);
    best = r > best ? r : best;
  }
  return best;
}

/* Whether the block from T0 may hold a tet whose rate is at least NEAR: not when the force
 * loop cached it (its unweighted terms below the stiff modulus are at most LOW) and its stiff
 * terms are below NEAR, as weighed by ordered_start (WEIGHED, 0 where it did not; NULL: none
 * kept) or else bounded by the stiff maximum. */
static int cached_block_may_hold(const piola_elastic_body *body, const double *cache,
                                 const double *weighed, int32_t t0, double near) {
  const int32_t b = t0 / PIOLA_TET_BLOCK;
  const double *slot = cache && b < body->tet_count / PIOLA_TET_BLOCK ? cached_block(body, cache, t0) : NULL;
  if (!slot) return 1;
  const double stiff =
      weighed && weighed[b] > 0 ? weighed[b] : step_rate_grid_ceil(slot[STEP_CACHE_HIGH]);
  return !(slot[STEP_CACHE_LOW] < near && stiff < near);
}

/* The first tet of [begin, end) (at most a block) whose rate is within 1e-12 of best, the
 * largest rate, or -1. A cached block is screened by its slots first (cached_block_may_hold,
 * with WEIGHED, ordered_start's weighed maxima, where the caller has them): the block's rate
 * weighs a direction-weighted model's stiff block, and searching the blocks before the worst
 * tet's that way weighed each of them again (in a stretched spline body, six times the rest of
 * the pass). The block's vector rate (the rate loop's) screens it first with a
 * margin 100 times wider, so the per-tet scalar modulus, several times dearer, runs on the
 * block that holds the tet only: searching every tet with it cost as much as the rate loop
 * itself, and in a split run made the process that searched longest the slowest one. */
static int32_t near_tet_in(const piola_elastic_body *body, const double *w, int32_t begin,
                           int32_t end, double best, const double *weighed) {
  const double near = best * (1 - 1e-10);
  if (!cached_block_may_hold(body, readable_step_cache(body), weighed, begin, near)) return -1;
  if (!(range_rate2(body, w, begin, end, NO_START) >= near)) return -1;
  for (int32_t t = begin; t < end; ++t)
    if (PIOLA_ISA_NAME(piola__elastic_body_tet_state_rate2)(body, t) >= best * (1 - 1e-12))
      return t;
  return -1;
}

/* Blocks per chunk of the rate pass whose maximum is kept for the worst tet's search. */
enum { SEARCH_CHUNK_BLOCKS = 32 };

/* The first tet near best (near_tet_in) in tets [begin, end), which start at a block, given
 * the largest rate `chunk_max` of each run of SEARCH_CHUNK_BLOCKS blocks from begin: only
 * the blocks of the chunks near best are screened. Searching block by block from the start
 * cost up to a second rate pass, paid by the process holding the worst tet alone (the
 * imbalance of docs/scaling.md). The same tet: a chunk holding a tet within 1e-12 of best
 * passes the 1e-10 screen. */
static int32_t near_tet_by_chunks(const piola_elastic_body *body, const double *w, int32_t begin,
                                  int32_t end, const double *chunk_max, double best) {
  const int32_t chunk = SEARCH_CHUNK_BLOCKS * PIOLA_TET_BLOCK;
  for (int32_t c = 0; begin + (int64_t)c * chunk < end; ++c) {
    if (!(chunk_max[c] >= best * (1 - 1e-10))) continue;
    const int32_t c1 = begin + (c + 1) * chunk < end ? begin + (c + 1) * chunk : end;
    for (int32_t t0 = begin + c * chunk; t0 < c1; t0 += PIOLA_TET_BLOCK) {
      const int32_t t = near_tet_in(body, w, t0, t0 + PIOLA_TET_BLOCK < c1 ? t0 + PIOLA_TET_BLOCK : c1, best, NULL);
      if (t >= 0) return t;
    }
  }
  return -1;
}

/* A split in the local mode: the largest rate over this process's blocks (runs of consecutive
 * blocks, in chunks whose maxima the search reads), then over the processes; the worst tet is
 * the first one near it over all processes, and its Fhat is sent to every process (the
 * warning quotes it). The maximum is exact, so every process gets the single process's bits. */
static double local_rate2(piola_elastic_body *body, const double *w, const piola_work_split *split,
                          int32_t *worst_tet) {
  const int32_t nt = body->tet_count, *list = body->split_blocks, count = body->split_block_count;
  /* chunks start a run or follow a full chunk: at most count / SEARCH_CHUNK_BLOCKS + runs */
  double *chunk_max = worst_tet ? malloc(sizeof(double) * (size_t)(count + 1)) : NULL;
  int32_t chunks = 0;
  double best = 0;
  for (int32_t k = 0; k < count;) {
    int32_t end = k + 1;
    while (end < count && list[end] == list[end - 1] + 1) ++end;
    const int32_t t0 = list[k] * PIOLA_TET_BLOCK;
    const int32_t t1 = (list[end - 1] + 1) * PIOLA_TET_BLOCK < nt ? (list[end - 1] + 1) * PIOLA_TET_BLOCK : nt;
    for (int32_t c0 = t0; c0 < t1; c0 += SEARCH_CHUNK_BLOCKS * PIOLA_TET_BLOCK) {
      const int32_t c1 = c0 + SEARCH_CHUNK_BLOCKS * PIOLA_TET_BLOCK < t1 ? c0 + SEARCH_CHUNK_BLOCKS * PIOLA_TET_BLOCK : t1;
      const double r = range_rate2(body, w, c0, c1, NO_START);
      if (chunk_max) chunk_max[chunks++] = r;
      best = r > best ? r : best;
    }
    k = end;
  }
  const double mine = best;
  split->reduce(split->context, &best, 1, PIOLA_WORK_SPLIT_MAX);
  if (!worst_tet || !(best > 0)) {
    free(chunk_max);
    return best;
  }
  double first = (double)nt;
  /* a process whose own largest rate is not near the largest of all holds no tet near it
   * (near_tet_in's margin): it skips the search. Without chunk_max (out of memory) every
   * block is screened. */
  if (mine >= best * (1 - 1e-10))
    for (int32_t k = 0, c = 0; k < count && first == nt;) {
      int32_t end = k + 1;
      while (end < count && list[end] == list[end - 1] + 1) ++end;
      const int32_t t0 = list[k] * PIOLA_TET_BLOCK;
      const int32_t t1 = (list[end - 1] + 1) * PIOLA_TET_BLOCK < nt ? (list[end - 1] + 1) * PIOLA_TET_BLOCK : nt;
      const int32_t run_chunks = (t1 - t0 + SEARCH_CHUNK_BLOCKS * PIOLA_TET_BLOCK - 1) / (SEARCH_CHUNK_BLOCKS * PIOLA_TET_BLOCK);
      int32_t t = -1;
      if (chunk_max) {
        t = near_tet_by_chunks(body, w, t0, t1, chunk_max + c, best);
      } else {
        for (int32_t b0 = t0; b0 < t1 && t < 0; b0 += PIOLA_TET_BLOCK)
          t = near_tet_in(body, w, b0, b0 + PIOLA_TET_BLOCK < t1 ? b0 + PIOLA_TET_BLOCK : t1, best, NULL);
      }
      if (t >= 0) first = t;
      c += run_chunks;
      k = end;
    }
  free(chunk_max);
  split->reduce(split->context, &first, 1, PIOLA_WORK_SPLIT_MIN);
  const int32_t t = (int32_t)first;
  if (t >= nt) return best;
  double f[3] = {-INFINITY, -INFINITY, -INFINITY};
  if (split->block_part[t / PIOLA_TET_BLOCK] == split->part)
    for (int c = 0; c < 3; ++c) f[c] = body->fhat[3 * t + c];
  split->reduce(split->context, f, 3, PIOLA_WORK_SPLIT_MAX);
  for (int c = 0; c < 3; ++c) body->fhat[3 * t + c] = f[c];
  *worst_tet = t;
  return best;
}

/* A cached block from t weighed (weighted_whole_block with no extension), the model a
 * constant in each instance. */
static double weighed_cached_block(const piola_elastic_body *body, const piola_material *m,
                                   const double *gram, const double *w, int32_t t, double best) {
  const double *f = body->fhat;
  switch (m->model) {
#define WEIGH_CASE(model) \
  case model:             \
    return weighted_whole_block(model, STEP_EXTENSION_NONE, m, body, gram, f, w, t, best);
    WEIGH_CASE(PIOLA_MODEL_COROTATED)
    WEIGH_CASE(PIOLA_MODEL_STVK)
    WEIGH_CASE(PIOLA_MODEL_SPLINE)
    WEIGH_CASE(PIOLA_MODEL_STABLE_NEOHOOKEAN)
    WEIGH_CASE(PIOLA_MODEL_ROTATED_LINEAR)
#undef WEIGH_CASE
    default:
      abort(); /* DIRECTION_WEIGHTED lists these five */
  }
}

/* The order's buckets: slices of a positive double's magnitude bits (the bits above SHIFT,
 * increasing with it; at SHIFT 50 the exponent and two mantissa bits, quarter octaves),
 * counted down from the slice of the largest stiff maximum, the last bucket holding
 * everything smaller. */
enum { ORDERED_BUCKETS = 1024 };
typedef struct ordered_slices {
  int64_t top_key;
  int shift;
} ordered_slices;
static int64_t order_key(double x, int shift) { return (int64_t)(magnitude_bits(x) >> shift); }

/* The finest slices (fewest bits dropped, from 32 to 50: the top slice's end stays finite)
 * that fit the span from LOW to TOP in the buckets (a wider span leaves its lowest blocks in
 * the last one, unordered): in a uniformly stretched body the blocks' stiff maxima lie close
 * together, and quarter octaves left thousands in one unordered bucket, weighed before the
 * maximum caught up with them. */
static ordered_slices ordered_slices_spanning(double low, double top) {
  int shift = 32;
  while (shift < 50 && order_key(top, shift) - order_key(low, shift) >= ORDERED_BUCKETS - 1) ++shift;
  return (ordered_slices){order_key(top, shift), shift};
}
static int ordered_bucket(const ordered_slices *s, double stiff_maximum) {
  const int64_t below = s->top_key - order_key(stiff_maximum, s->shift);
  return (int)(below < ORDERED_BUCKETS - 1 ? below : ORDERED_BUCKETS - 1);
}
/* Where BUCKET ends: every stiff maximum in it or after it lies below. */
static double ordered_bucket_end(const ordered_slices *s, int bucket) {
  const int64_t key = s->top_key - bucket + 1;
  return from_magnitude_bits(key > 0 ? (uint64_t)key << s->shift : 0);
}

/* The stiff maximum in the slots of block B. */
static double block_stiff_maximum(const double *cache, int32_t b) {
  return cache[(size_t)b * STEP_CACHE_SLOTS + STEP_CACHE_HIGH];
}

/* max(*shared, x) stored in *shared. */
static void raise_shared_maximum(_Atomic uint64_t *shared, double x) {
  const uint64_t bits = magnitude_bits(x);
  uint64_t seen = atomic_load_explicit(shared, memory_order_relaxed);
  while (bits > seen &&
         !atomic_compare_exchange_weak_explicit(shared, &seen, bits, memory_order_relaxed,
                                                memory_order_relaxed)) {
  }
}

/* Blocks a thread takes from the order at a time. */
enum { ORDERED_CHUNK = 4 };

/* max(best, the weighted terms of the COUNT cached blocks ORDER lists), ORDER sorted by
 * ordered_bucket in SLICES; WEIGHED (NULL: not kept) takes each weighed block's largest term
 * at its block's index, for the worst tet's search (near_tet_in). The threads take chunks of
 * the order from one counter and share their maxima through one word, with no barrier between
 * the slices (a barrier each cost more than weighing the blocks between them on two threads);
 * a thread stops at the first chunk whose slice ends, rounded up to the grid, at or below the
 * maximum it has seen. A block is skipped only when its stiff maximum rounded up to the grid
 * (step_rate_grid_ceil, which its weighted terms cannot exceed) is at most a maximum of terms
 * found, so what is returned is the largest term whatever the threads' timing: the same bits
 * on any thread count. */
static double weigh_in_order(const piola_elastic_body *body, const piola_material *m,
                             const double *gram, const double *cache, const double *w,
                             const int32_t *order, int32_t count, const ordered_slices *slices,
                             double best, double *weighed, int parallel) {
  _Atomic int32_t next = 0;
  _Atomic uint64_t shared = magnitude_bits(best);
#pragma omp parallel num_threads(piola_thread_count()) if (parallel)
  {
    double local = best;
    for (;;) {
      const int32_t i0 = atomic_fetch_add_explicit(&next, ORDERED_CHUNK, memory_order_relaxed);
      if (i0 >= count) break;
      const double seen = from_magnitude_bits(atomic_load_explicit(&shared, memory_order_relaxed));
      local = seen > local ? seen : local;
      /* every later block's stiff maximum lies below where this one's bucket ends */
      if (!(step_rate_grid_ceil(ordered_bucket_end(
                slices, ordered_bucket(slices, block_stiff_maximum(cache, order[i0])))) > local))
        break;
      const int32_t i1 = i0 + ORDERED_CHUNK < count ? i0 + ORDERED_CHUNK : count;
      for (int32_t i = i0; i < i1; ++i)
        if (step_rate_grid_ceil(block_stiff_maximum(cache, order[i])) > local) {
          const double own = weighed_cached_block(body, m, gram, w, order[i] * PIOLA_TET_BLOCK, 0.0);
          if (weighed) weighed[order[i]] = own;
          local = own > local ? own : local;
        }
      raise_shared_maximum(&shared, local);
    }
  }
  return from_magnitude_bits(atomic_load_explicit(&shared, memory_order_relaxed));
}

/* The stiff maximum of cached block B if the order holds it (rounded up to the grid above BEST,
 * not the top block, weighed already), else 0. */
static double ordered_candidate(const piola_elastic_body *body, const double *cache, int32_t b,
                                int32_t top_block, double best) {
  const double *slot = cached_block(body, cache, b * PIOLA_TET_BLOCK);
  return slot && b != top_block && step_rate_grid_ceil(slot[STEP_CACHE_HIGH]) > best
             ? slot[STEP_CACHE_HIGH]
             : 0.0;
}

/* The start of the ranges (rate_start) for a direction-weighted body whose force loop cached
 * its blocks: every cached block's terms taken here. Each range weighs the blocks
 * whose stiff maximum (an upper bound of their weighted terms) beats its running maximum, and
 * each range starts from nothing: in a stretched state (every block stiff) the ranges weighed
 * 16% of the blocks, while 0.4% had a stiff maximum above the final bound. Here the cached
 * blocks' exact maxima come first, then the block of the largest stiff maximum, then the
 * blocks whose stiff maximum is above what those found, in decreasing order of it (a counting
 * sort into slices of the span between: no comparison sort of every block each step), weighed
 * while they can still raise the maximum (weigh_in_order); a block whose stiff maximum is at
 * most the maximum so far holds no larger term. The ranges then take the uncached blocks
 * only. Without memory for the order: the cached blocks' exact maxima only, and the ranges
 * weigh as before. WEIGHED (NULL: not kept; else zeros, one per whole block) takes the largest
 * term of each block weighed here (weigh_in_order). */
static rate_start ordered_start(const piola_elastic_body *body, const piola_material *m,
                                const double *gram, const double *cache, const double *w,
                                double *weighed) {
  const int32_t blocks = body->tet_count / PIOLA_TET_BLOCK;
  double best = 0, top = 0;
  int32_t top_block = -1, uncached = 0;
  for (int32_t b = 0; b < blocks; ++b) {
    const double *slot = cached_block(body, cache, b * PIOLA_TET_BLOCK);
    if (!slot) {
      ++uncached;
      continue;
    }
    best = slot[STEP_CACHE_LOW] > best ? slot[STEP_CACHE_LOW] : best;
    if (slot[STEP_CACHE_HIGH] > top) {
      top = slot[STEP_CACHE_HIGH];
      top_block = b;
    }
  }
  const int every = uncached == 0;
  if (!(step_rate_grid_ceil(top) > best)) return (rate_start){best, 1, every};
  /* an infinite stiff maximum has no slice above it to end the first one: the ranges weigh
   * every block instead */
  if (!(top < INFINITY)) return (rate_start){best, 0, 0};
  /* the top block's terms bound the final maximum from below: the blocks at or under them
   * need no weighing, and the order's slices span only the blocks above */
  const double top_terms = weighed_cached_block(body, m, gram, w, top_block * PIOLA_TET_BLOCK, 0.0);
  if (weighed) weighed[top_block] = top_terms;
  best = top_terms > best ? top_terms : best;
  const ordered_slices slices = ordered_slices_spanning(best, top);
  /* the blocks above them gathered in one scan, without a branch per block (in a stretched
   * body about as many are above as not: a branch there mispredicted in the counting and
   * the placing scans over every block), then counted and placed by slice */
  int32_t *order = malloc(sizeof(int32_t) * 2 * (size_t)blocks);
  if (!order) return (rate_start){best, 0, 0};
  int32_t *above = order + blocks, count = 0;
  for (int32_t b = 0; b < blocks; ++b) {
    above[count] = b;
    count += ordered_candidate(body, cache, b, top_block, best) > 0;
  }
  int32_t first[ORDERED_BUCKETS + 1] = {0};
  for (int32_t i = 0; i < count; ++i)
    ++first[ordered_bucket(&slices, block_stiff_maximum(cache, above[i])) + 1];
  for (int k = 0; k < ORDERED_BUCKETS; ++k) first[k + 1] += first[k];
  int32_t next[ORDERED_BUCKETS];
  memcpy(next, first, sizeof next);
  for (int32_t i = 0; i < count; ++i)
    order[next[ordered_bucket(&slices, block_stiff_maximum(cache, above[i]))]++] = above[i];
  const double found = count > 0 ? weigh_in_order(body, m, gram, cache, w, order, count, &slices, best,
                                                  weighed, blocks >= PIOLA_PARALLEL_MIN_BLOCKS)
                                 : best;
  free(order);
  return (rate_start){found, 1, every};
}

/* The pass over a whole body takes RATE_RANGES ranges of whole blocks (the force loop's, whose
 * cached maxima it reads); range r starts at tet range_edge(nt, r) of nt. */
enum { RATE_RANGES = 16 };
static int32_t range_edge(int32_t nt, int r) {
  const int64_t blocks = ((int64_t)nt + PIOLA_TET_BLOCK - 1) / PIOLA_TET_BLOCK;
  const int64_t t = blocks * r / RATE_RANGES * PIOLA_TET_BLOCK;
  return (int32_t)(t < nt ? t : nt);
}

double PIOLA_ISA_NAME(piola__elastic_body_state_rate2)(piola_elastic_body *body, int32_t *worst_tet) {
  const double *w = rate_weights(body);
  const int32_t nt = body->tet_count;
  if (worst_tet) *worst_tet = -1;
  if (!w || nt <= 0) return 0;
  const piola_work_split *local = piola__local_split(body);
  if (local) return local_rate2(body, w, local, worst_tet);
  double part[RATE_RANGES];
  const double *cache = readable_step_cache(body), *gram = direction_gram(body);
  rate_start start = NO_START;
  /* the stiff blocks' weighed maxima, for the worst tet's search (NULL without memory: the
   * search weighs them again) */
  double *weighed = NULL;
  if (cache && gram && body->uniform_material >= 0 &&
      DIRECTION_WEIGHTED(body->materials[body->uniform_material].model)) {
    if (worst_tet) weighed = calloc((size_t)(nt / PIOLA_TET_BLOCK) + 1, sizeof(double));
    start = ordered_start(body, &body->materials[body->uniform_material], gram, cache, w, weighed);
  }
  const int parallel = nt >= PIOLA_PARALLEL_MIN_BLOCKS * PIOLA_TET_BLOCK;
  if (start.every_block_cached) {
    /* ordered_start took every whole block: the ranges hold nothing more but the tets past
     * the last (the last range's); the others keep its maximum for the search's screen */
    const int32_t whole = nt / PIOLA_TET_BLOCK * PIOLA_TET_BLOCK;
    for (int r = 0; r < RATE_RANGES; ++r) part[r] = start.at_least;
    if (whole < nt) part[RATE_RANGES - 1] = range_rate2(body, w, whole, nt, start);
  } else {
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) if (parallel)
    for (int r = 0; r < RATE_RANGES; ++r)
      part[r] = range_rate2(body, w, range_edge(nt, r), range_edge(nt, r + 1), start);
  }
  double best = start.at_least;
  for (int r = 0; r < RATE_RANGES; ++r) best = part[r] > best ? part[r] : best;
  /* the search screens the ranges by their maxima first (near_tet_by_chunks' reason) */
  if (worst_tet && best > 0)
    for (int r = 0; r < RATE_RANGES && *worst_tet < 0; ++r) {
      if (!(part[r] >= best * (1 - 1e-10))) continue;
      const int32_t r1 = range_edge(nt, r + 1);
      for (int32_t t0 = range_edge(nt, r); t0 < r1 && *worst_tet < 0; t0 += PIOLA_TET_BLOCK)
        *worst_tet = near_tet_in(body, w, t0, t0 + PIOLA_TET_BLOCK < nt ? t0 + PIOLA_TET_BLOCK : nt,
                                 best, weighed);
    }
  free(weighed);
  return best;
}
