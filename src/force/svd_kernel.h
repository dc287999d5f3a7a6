/* A branch-free 3x3 SVD with the invertible sign convention, written to be vectorized
 * across SIMD lanes (one matrix per lane) by the compiler.
 *
 * Why a second diagonalization besides the public piola_diagonalize3: that one is written
 * for robustness at any scale and to 1e-12, with branches; the force loop runs it for every
 * tet every step and needs it fast. This kernel follows the approach of McAdams et al. 2011
 * ("Computing the singular value decomposition of 3x3 matrices with minimal branching and
 * elementary floating point operations"), in double precision and written from the method's
 * description:
 *   1. normalize F by its largest entry (the kernel is then scale invariant);
 *   2. symmetric eigenproblem of S = F^T F by cyclic Jacobi with a fixed number of sweeps,
 *      each rotation from the approximate Givens half-angle (ch, sh) = (2 (s_pp - s_qq), s_pq),
 *      clamped to pi/8 when the off-diagonal dominates; V accumulates the rotations;
 *   3. B = F V, columns sorted by decreasing norm (a swap negates one column so det V = +1);
 *   4. QR of B by three Givens rotations: U = Q, Fhat = diag(R). R_00, R_11 >= 0 and R_22
 *      carries the sign of det F, so an inverted element gets one negative entry, the one of
 *      smallest magnitude.
 * Reciprocal square roots come from a bit-level first guess refined by Newton steps (no
 * divides, no sqrt). Near-zero rotations (an entry of S or a column of B below 1e-150 of
 * the normalized scale) are replaced by the identity, so F = 0 gives U = V = I and a
 * collapsed element gets a completed, proper U. The measured accuracy is in docs/forces.md
 * (reconstruction |U Fhat V^T - F| / |F| and orthogonality ~1e-15 with the sweep count
 * below). Every function is static inline so that it can sit inside an `omp simd` loop. */
#ifndef PIOLA_FORCE_SVD_KERNEL_H
#define PIOLA_FORCE_SVD_KERNEL_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#define PIOLA_SVD_JACOBI_SWEEPS 4

/* The kernels must be inlined into the caller's `omp simd` loop, or that loop cannot be
 * vectorized. */
#if defined(__GNUC__) || defined(__clang__)
#define PIOLA_KERNEL_INLINE static inline __attribute__((always_inline))
#else
#define PIOLA_KERNEL_INLINE static inline
#endif
/* Fixed-count inner loops must be unrolled before the lane loop is vectorized (GCC does not
 * vectorize a loop around two consecutive inner loops). */
#if defined(__GNUC__) && !defined(__clang__)
#define PIOLA_UNROLL _Pragma("GCC unroll 16")
#else
#define PIOLA_UNROLL
#endif

/* 1 / sqrt(x) for normal positive x, to about 1 ulp: bit-level guess (3.4% error), then
 * four Newton steps (each roughly cubes... squares the relative error: 1e-3, 1e-6, 1e-12,
 * 1e-16). */
PIOLA_KERNEL_INLINE double piola__rsqrt(double x) {
  int64_t i;
  memcpy(&i, &x, sizeof i);
  i = INT64_C(0x5fe6eb50c7b537a9) - (i >> 1);
  double y;
  memcpy(&y, &i, sizeof y);
  double h = 0.5 * x;
  y = y * (1.5 - h * y * y);
  y = y * (1.5 - h * y * y);
  y = y * (1.5 - h * y * y);
  y = y * (1.5 - h * y * y);
  return y;
}

/* The kernel is written on named scalars, not small arrays: inside an `omp simd` loop GCC
 * turns per-lane arrays into scattered "simd arrays" and gives up vectorizing. */

/* One Jacobi rotation in the (p, q) plane of the symmetric S (k the third index):
 * S <- G^T S G, V <- V G with G = [c -s; s c] in that plane, the exact Jacobi angle
 * tan(2 theta) = 2 s_pq / (s_pp - s_qq) taken with 2 theta in [-pi/2, pi/2] so that
 * cos(theta) >= 1/sqrt(2) and the half-angle formulas are stable. A negligible s_pq gives
 * the identity. */
#define PIOLA_SVD_JACOBI(spp, sqq, spq, spk, sqk, v0p, v0q, v1p, v1q, v2p, v2q)        \
  do {                                                                                  \
    double d_ = spp - sqq, e_ = 2.0 * spq;                                              \
    int negligible_ = e_ * e_ <= 1e-300;                                                \
    double w_ = piola__rsqrt(negligible_ ? 1.0 : d_ * d_ + e_ * e_);                   \
    double cos2_ = fabs(d_) * w_;                                                       \
    double sin2_ = (d_ >= 0 ? e_ : -e_) * w_;                                           \
    double h_ = 0.5 + 0.5 * cos2_;                                                      \
    double wc_ = piola__rsqrt(h_);                                                      \
    double c_ = negligible_ ? 1.0 : h_ * wc_;                                           \
    double s_ = negligible_ ? 0.0 : 0.5 * sin2_ * wc_;                                  \
    double cc_ = c_ * c_, ss_ = s_ * s_, cs_ = c_ * s_;                                 \
    double spp_ = spp, sqq_ = sqq, spq_ = spq, spk_ = spk, sqk_ = sqk;                 \
    spp = cc_ * spp_ + 2.0 * cs_ * spq_ + ss_ * sqq_;                                   \
    sqq = ss_ * spp_ - 2.0 * cs_ * spq_ + cc_ * sqq_;                                   \
    spq = (cc_ - ss_) * spq_ - cs_ * (spp_ - sqq_);                                     \
    spk = c_ * spk_ + s_ * sqk_;                                                        \
    sqk = -s_ * spk_ + c_ * sqk_;                                                       \
    double t_;                                                                          \
    t_ = v0p; v0p = c_ * t_ + s_ * v0q; v0q = -s_ * t_ + c_ * v0q;                      \
    t_ = v1p; v1p = c_ * t_ + s_ * v1q; v1q = -s_ * t_ + c_ * v1q;                      \
    t_ = v2p; v2p = c_ * t_ + s_ * v2q; v2q = -s_ * t_ + c_ * v2q;                      \
  } while (0)

/* Swaps columns i and j of B and V when column j of B is longer, negating one of them so
 * det V stays +1. */
#define PIOLA_SVD_SORT(ni, nj, b0i, b1i, b2i, b0j, b1j, b2j, v0i, v1i, v2i, v0j, v1j, v2j) \
  do {                                                                                  \
    int swap_ = ni < nj;                                                                \
    double t_;                                                                          \
    t_ = ni; ni = swap_ ? nj : ni; nj = swap_ ? t_ : nj;                                \
    t_ = b0i; b0i = swap_ ? b0j : b0i; b0j = swap_ ? -t_ : b0j;                         \
    t_ = b1i; b1i = swap_ ? b1j : b1i; b1j = swap_ ? -t_ : b1j;                         \
    t_ = b2i; b2i = swap_ ? b2j : b2i; b2j = swap_ ? -t_ : b2j;                         \
    t_ = v0i; v0i = swap_ ? v0j : v0i; v0j = swap_ ? -t_ : v0j;                         \
    t_ = v1i; v1i = swap_ ? v1j : v1i; v1j = swap_ ? -t_ : v1j;                         \
    t_ = v2i; v2i = swap_ ? v2j : v2i; v2j = swap_ ? -t_ : v2j;                         \
  } while (0)

/* Givens rotation of rows p and q of B zeroing b_qp and leaving b_pp = |(b_pp, b_qp)| >= 0;
 * U accumulates its transpose so U B is invariant. Both entries negligible: identity. */
#define PIOLA_SVD_GIVENS(bp0, bp1, bp2, bq0, bq1, bq2, a, b, u0p, u0q, u1p, u1q, u2p, u2q) \
  do {                                                                                  \
    double a_ = a, b_ = b;                                                              \
    double r2_ = a_ * a_ + b_ * b_;                                                     \
    int ok_ = r2_ > 1e-300;                                                             \
    double w_ = piola__rsqrt(ok_ ? r2_ : 1.0);                                          \
    double c_ = ok_ ? a_ * w_ : 1.0, s_ = ok_ ? b_ * w_ : 0.0, t_;                      \
    t_ = bp0; bp0 = c_ * t_ + s_ * bq0; bq0 = -s_ * t_ + c_ * bq0;                      \
    t_ = bp1; bp1 = c_ * t_ + s_ * bq1; bq1 = -s_ * t_ + c_ * bq1;                      \
    t_ = bp2; bp2 = c_ * t_ + s_ * bq2; bq2 = -s_ * t_ + c_ * bq2;                      \
    t_ = u0p; u0p = c_ * t_ + s_ * u0q; u0q = -s_ * t_ + c_ * u0q;                      \
    t_ = u1p; u1p = c_ * t_ + s_ * u1q; u1q = -s_ * t_ + c_ * u1q;                      \
    t_ = u2p; u2p = c_ * t_ + s_ * u2q; u2q = -s_ * t_ + c_ * u2q;                      \
  } while (0)

/* F = U diag(fhat) V^T with U, V proper rotations, |fhat_0| >= |fhat_1| >= |fhat_2|,
 * fhat_0, fhat_1 >= 0, sign(fhat_2) = sign(det F). Entry k (row-major, k = 3 row + col) of
 * F is f[k * in_stride]; of U and V, u[k * out_stride] and v[k * out_stride]; fhat entry i
 * is fhat[i * out_stride]. Strides let the caller read and write SoA lanes directly. */
PIOLA_KERNEL_INLINE void piola__svd3_kernel(const double *f, long in_stride, double *u,
                                            double *fhat, double *v, long out_stride) {
  double a00 = f[0 * in_stride], a01 = f[1 * in_stride], a02 = f[2 * in_stride];
  double a10 = f[3 * in_stride], a11 = f[4 * in_stride], a12 = f[5 * in_stride];
  double a20 = f[6 * in_stride], a21 = f[7 * in_stride], a22 = f[8 * in_stride];
  /* ternary max, not fmax: GCC vectorizes the former but not the latter's NaN rules */
  double scale = fabs(a00);
  scale = fabs(a01) > scale ? fabs(a01) : scale;
  scale = fabs(a02) > scale ? fabs(a02) : scale;
  scale = fabs(a10) > scale ? fabs(a10) : scale;
  scale = fabs(a11) > scale ? fabs(a11) : scale;
  scale = fabs(a12) > scale ? fabs(a12) : scale;
  scale = fabs(a20) > scale ? fabs(a20) : scale;
  scale = fabs(a21) > scale ? fabs(a21) : scale;
  scale = fabs(a22) > scale ? fabs(a22) : scale;
  /* the one divide per matrix; a zero (or denormal) F is treated as F = 0 */
  int nonzero = scale > 1e-290;
  double inv_scale = nonzero ? 1.0 / (nonzero ? scale : 1.0) : 0.0;
  a00 *= inv_scale; a01 *= inv_scale; a02 *= inv_scale;
  a10 *= inv_scale; a11 *= inv_scale; a12 *= inv_scale;
  a20 *= inv_scale; a21 *= inv_scale; a22 *= inv_scale;

  /* S = A^T A */
  double s00 = a00 * a00 + a10 * a10 + a20 * a20;
  double s11 = a01 * a01 + a11 * a11 + a21 * a21;
  double s22 = a02 * a02 + a12 * a12 + a22 * a22;
  double s01 = a00 * a01 + a10 * a11 + a20 * a21;
  double s02 = a00 * a02 + a10 * a12 + a20 * a22;
  double s12 = a01 * a02 + a11 * a12 + a21 * a22;
  double v00 = 1, v01 = 0, v02 = 0, v10 = 0, v11 = 1, v12 = 0, v20 = 0, v21 = 0, v22 = 1;
  PIOLA_UNROLL
  for (int sweep = 0; sweep < PIOLA_SVD_JACOBI_SWEEPS; ++sweep) {
    PIOLA_SVD_JACOBI(s00, s11, s01, s02, s12, v00, v01, v10, v11, v20, v21);
    PIOLA_SVD_JACOBI(s00, s22, s02, s01, s12, v00, v02, v10, v12, v20, v22);
    PIOLA_SVD_JACOBI(s11, s22, s12, s01, s02, v01, v02, v11, v12, v21, v22);
  }

  /* B = A V, columns sorted by decreasing norm */
  double b00 = a00 * v00 + a01 * v10 + a02 * v20;
  double b01 = a00 * v01 + a01 * v11 + a02 * v21;
  double b02 = a00 * v02 + a01 * v12 + a02 * v22;
  double b10 = a10 * v00 + a11 * v10 + a12 * v20;
  double b11 = a10 * v01 + a11 * v11 + a12 * v21;
  double b12 = a10 * v02 + a11 * v12 + a12 * v22;
  double b20 = a20 * v00 + a21 * v10 + a22 * v20;
  double b21 = a20 * v01 + a21 * v11 + a22 * v21;
  double b22 = a20 * v02 + a21 * v12 + a22 * v22;
  double n0 = b00 * b00 + b10 * b10 + b20 * b20;
  double n1 = b01 * b01 + b11 * b11 + b21 * b21;
  double n2 = b02 * b02 + b12 * b12 + b22 * b22;
  PIOLA_SVD_SORT(n0, n1, b00, b10, b20, b01, b11, b21, v00, v10, v20, v01, v11, v21);
  PIOLA_SVD_SORT(n0, n2, b00, b10, b20, b02, b12, b22, v00, v10, v20, v02, v12, v22);
  PIOLA_SVD_SORT(n1, n2, b01, b11, b21, b02, b12, b22, v01, v11, v21, v02, v12, v22);

  /* QR: B = U R */
  double u00 = 1, u01 = 0, u02 = 0, u10 = 0, u11 = 1, u12 = 0, u20 = 0, u21 = 0, u22 = 1;
  PIOLA_SVD_GIVENS(b00, b01, b02, b10, b11, b12, b00, b10, u00, u01, u10, u11, u20, u21);
  PIOLA_SVD_GIVENS(b00, b01, b02, b20, b21, b22, b00, b20, u00, u02, u10, u12, u20, u22);
  PIOLA_SVD_GIVENS(b10, b11, b12, b20, b21, b22, b11, b21, u01, u02, u11, u12, u21, u22);

  fhat[0] = b00 * scale;
  fhat[out_stride] = b11 * scale;
  fhat[2 * out_stride] = b22 * scale;
  u[0] = u00; u[out_stride] = u01; u[2 * out_stride] = u02;
  u[3 * out_stride] = u10; u[4 * out_stride] = u11; u[5 * out_stride] = u12;
  u[6 * out_stride] = u20; u[7 * out_stride] = u21; u[8 * out_stride] = u22;
  v[0] = v00; v[out_stride] = v01; v[2 * out_stride] = v02;
  v[3 * out_stride] = v10; v[4 * out_stride] = v11; v[5 * out_stride] = v12;
  v[6 * out_stride] = v20; v[7 * out_stride] = v21; v[8 * out_stride] = v22;
}

/* For benchmarks and tests: n matrices, row-major AoS (9 each), through the kernel in
 * vectorized blocks. */
void piola__svd3_kernel_batch(int32_t n, const double *f, double *u, double *fhat, double *v);

#endif
