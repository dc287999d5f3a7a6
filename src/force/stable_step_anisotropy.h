/* The direction weights of the state-aware step bound (stable_step.c; docs/time-stepping.md,
 * "Step size", "Slivers stretched along their thin direction").
 *
 * The plane-wave bound k_e / (rho h_e^2) pairs the stiffest wave of the tet's state with its
 * steepest shape-function gradient, 1 / h_e. The two need not meet: a scrambled sliver is
 * stretched most along its thin rest direction (F = Ds Dm^-1, and Dm^-1 is large there), while
 * the stiffness that stretch brings (corotated's volume term, lambda (f_1 f_2)^2 on the third
 * entry) acts on the directions where the tet is wide. In the frame of the diagonalization,
 * dF-hat = U^T dF V has column j along the rest direction V e_j, and the gradients' weight
 * there is A-hat = V^T (sum_c g_c g_c^T) V. Its Gershgorin majorant diag(D), D_j = sum_k
 * |A-hat_jk| (A-hat <= diag(D) for a symmetric matrix), scales column j of every wave by
 * sqrt(D_j); normalized by the largest D_j, the weights w_j are in (0, 1], one of them 1. The
 * plane-wave form of stable_step.c with the weights:
 *     k_w = max(max_i w_i K_ii, max_{i<j} lambda_max([[a w_j, c s], [c s, a w_i]])),
 * s = sqrt(w_i w_j), c = b_ij + K_ij: the same modes, each scaled by the gradient its columns
 * meet. With all weights 1 it is k_e; at rest (isotropic tangent) it is lambda + 2 mu whatever
 * the weights, so the rest bound is unchanged. The bound takes min(k_w, k_e) for tets whose k_e
 * is above 4 (lambda + 2 mu) (STEP_CACHE_STIFF), their term rounded up to a grid
 * (STEP_RATE_GRID_BITS below), k_e for the others.
 *
 * Everything here is plain arithmetic with selects (no fused multiply-adds: stable_step.c's
 * bits do not depend on the instruction set). */
#ifndef PIOLA_FORCE_STABLE_STEP_ANISOTROPY_H
#define PIOLA_FORCE_STABLE_STEP_ANISOTROPY_H

#include <math.h>
#include <stdint.h>

#include "material/material_kernels.h"

/* Per-tet rest Gram matrix of the shape-function gradients, sum_c g_c g_c^T (m^-2), as six
 * arrays of tet_count (xx, xy, xz, yy, yz, zz), from the rows of Dm^-1 (g_0 = -g_1 - g_2 - g_3). */
static inline void step_gram_of(double g[3][3], double out[6]) {
  const double g0[3] = {-(g[0][0] + g[1][0] + g[2][0]), -(g[0][1] + g[1][1] + g[2][1]),
                        -(g[0][2] + g[1][2] + g[2][2])};
  static const int row[6] = {0, 0, 0, 1, 1, 2}, col[6] = {0, 1, 2, 1, 2, 2};
  for (int e = 0; e < 6; ++e)
    out[e] = g0[row[e]] * g0[col[e]] + g[0][row[e]] * g[0][col[e]] + g[1][row[e]] * g[1][col[e]] +
             g[2][row[e]] * g[2][col[e]];
}

/* The weights w (see above) of tet t from its Gram entries gram[e * n + t] and its V (row-major
 * V_rk at v[(3 r + k) * stride]). */
static inline __attribute__((always_inline)) void step_direction_weights(const double *gram, int32_t n,
                                                                        const double *v, long stride,
                                                                        double w[3]) {
  const double a[3][3] = {{gram[0], gram[n], gram[2 * (long)n]},
                          {gram[n], gram[3 * (long)n], gram[4 * (long)n]},
                          {gram[2 * (long)n], gram[4 * (long)n], gram[5 * (long)n]}};
  double vm[3][3], av[3][3], ah[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) vm[r][k] = v[(3 * r + k) * stride];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) av[r][k] = a[r][0] * vm[0][k] + a[r][1] * vm[1][k] + a[r][2] * vm[2][k];
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) ah[j][k] = vm[0][j] * av[0][k] + vm[1][j] * av[1][k] + vm[2][j] * av[2][k];
  const double d0 = fabs(ah[0][0]) + fabs(ah[0][1]) + fabs(ah[0][2]);
  const double d1 = fabs(ah[1][0]) + fabs(ah[1][1]) + fabs(ah[1][2]);
  const double d2 = fabs(ah[2][0]) + fabs(ah[2][1]) + fabs(ah[2][2]);
  const double top = kernel_max(d0, kernel_max(d1, d2));
  const int ok = top > 0.0 && top < INFINITY;
  const double den = ok ? top : 1.0; /* divided, not multiplied by 1 / top: the largest is 1 exactly */
  w[0] = ok ? d0 / den : 1.0;
  w[1] = ok ? d1 / den : 1.0;
  w[2] = ok ? d2 / den : 1.0;
}

/* The weighted terms' grid: a stiff tet's weighted term, w_e min(k_e, k_w), is rounded up to
 * the next double with STEP_RATE_GRID_BITS mantissa bits (at most 2^-5 above it, so its step
 * at most 1.6% shorter). The weighing then skips every block whose stiff maximum rounds up to
 * at most the maximum found, not only those whose stiff maximum is at most it: a uniformly
 * stretched body's stiff maxima lie within a few percent of each other, and the exact maximum
 * weighed hundreds of blocks where the rounded one weighs tens (docs/time-stepping.md, "The
 * weighted terms' grid"). A function of the term alone, so every path (the ordered weighing,
 * the ranges, a split's processes, the per-tet search) takes the same bits. The rounding is
 * step_rate_grid_ceil in stable_step.c. */
#define STEP_RATE_GRID_BITS 5

/* Largest eigenvalue of [[a wj, c s], [c s, a wi]], s = sqrt(wi wj): one pair's weighted mode. */
static inline __attribute__((always_inline)) double step_weighted_pair(double a, double c, double wi,
                                                                      double wj) {
  const double half = 0.5 * a * (wi - wj);
  return 0.5 * a * (wi + wj) + sqrt(half * half + c * c * wi * wj);
}

#endif
