/* A branch-free 3x3 SVD with the invertible sign convention, written to be vectorized
 * across SIMD lanes (one matrix per lane) by the compiler.
 *
 * Why a second diagonalization besides the public piola_diagonalize3: that one is written
 * for robustness at any scale and to 1e-12, with branches; the force loop runs a
 * diagonalization for every tet every step and needs it fast and branch-free. The approach
 * is that of McAdams et al. 2011 ("Computing the singular value decomposition of 3x3
 * matrices with minimal branching and elementary floating point operations"), adapted to
 * double precision and written from the method's description:
 *   1. normalize F by its largest entry (the kernel is then scale invariant), and flush
 *      entries below 1e-100 of it to zero (no denormals anywhere downstream);
 *   2. symmetric eigenproblem of S = F^T F by cyclic Jacobi with a fixed number of sweeps
 *      (4). Unlike McAdams' approximate Givens angles (which need more sweeps in double),
 *      each rotation uses the exact Jacobi angle, but computed cheaply: only the angle
 *      matters, so the square roots in it are rough (Newton-refined bit-level guesses) and
 *      the rotation is kept an exact rotation times a scale, which leaves the eigenvectors
 *      alone; V is normalized once at the end;
 *   3. B = F V, columns sorted by decreasing norm (a swap negates one column so det V = +1);
 *   4. U by Gram-Schmidt on B's columns, which is QR without the rotations: u0 = b0/|b0|,
 *      u1 = b1 minus its u0 part (twice), normalized, u2 = u0 x u1 so det U = +1;
 *      Fhat = (|b0|, |b1'|, u2 . b2), the last carrying the sign of det F: an inverted
 *      element gets one negative entry, the one of smallest magnitude. A zero b0 (F = 0)
 *      gives U = I; a zero b1 (rank <= 1) gets a completed u1.
 * Reciprocal square roots come from a bit-level first guess refined by Newton steps (no
 * sqrt, one divide per matrix for the normalization).
 * Measured accuracy (tests/test_elastic_body.c, docs/forces.md): worst relative
 * reconstruction |U Fhat V^T - F| / |F| and orthogonality |U^T U - I|, |V^T V - I| about
 * 2e-15 over random, rank-2, rank-1, zero, near-identity, tiny and huge matrices. Every
 * function is inline and written on named scalars so that it can sit inside an `omp simd`
 * loop. */
#ifndef PIOLA_FORCE_SVD_KERNEL_H
#define PIOLA_FORCE_SVD_KERNEL_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#define PIOLA_SVD_JACOBI_SWEEPS 4

/* Relative to the normalized matrix (largest entry 1), values below this are zero: it keeps
 * every intermediate far from denormal numbers, which cost ~100 cycles each in hardware,
 * while changing F by less than 1e-100 of its size. */
#define PIOLA_SVD_FLUSH 1e-100

/* The kernels must be inlined into the caller's `omp simd` loop, or that loop cannot be
 * vectorized. */
#if defined(__GNUC__) || defined(__clang__)
#define PIOLA_KERNEL_INLINE static inline __attribute__((always_inline))
#else
#define PIOLA_KERNEL_INLINE static inline
#endif
/* Functions holding a lane loop ask for full AVX-512 vectors where the build targets them
 * (GCC otherwise prefers 256-bit vectors on these CPUs; the kernel is ~30% faster at 512). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__AVX512F__)
#define PIOLA_WIDE_VECTORS __attribute__((target("prefer-vector-width=512")))
#else
#define PIOLA_WIDE_VECTORS
#endif
/* Fixed-count inner loops must be unrolled before the lane loop is vectorized (GCC does not
 * vectorize a loop around two consecutive inner loops). */
#if defined(__GNUC__) && !defined(__clang__)
#define PIOLA_UNROLL _Pragma("GCC unroll 16")
#else
#define PIOLA_UNROLL
#endif

/* Reciprocal square root of a normal positive x: a bit-level first guess (relative error
 * below 3.5%) refined by Newton steps, each of which roughly squares the error
 * (e -> 1.5 e^2): 1 step 2e-3, 2 steps 5e-6, 3 steps 4e-11, 4 steps ~1 ulp. */
PIOLA_KERNEL_INLINE double piola__rsqrt_guess(double x) {
  int64_t i;
  memcpy(&i, &x, sizeof i);
  i = INT64_C(0x5fe6eb50c7b537a9) - (i >> 1);
  double y;
  memcpy(&y, &i, sizeof y);
  return y;
}
PIOLA_KERNEL_INLINE double piola__rsqrt_newton(double x, double y) {
  return y * (1.5 - 0.5 * x * y * y);
}
/* To about 1 ulp. */
PIOLA_KERNEL_INLINE double piola__rsqrt(double x) {
  double y = piola__rsqrt_guess(x);
  y = piola__rsqrt_newton(x, y);
  y = piola__rsqrt_newton(x, y);
  y = piola__rsqrt_newton(x, y);
  return piola__rsqrt_newton(x, y);
}
/* To about 4e-11: for r in the Jacobi angle, where an error slows convergence. */
PIOLA_KERNEL_INLINE double piola__rsqrt_angle(double x) {
  double y = piola__rsqrt_guess(x);
  y = piola__rsqrt_newton(x, y);
  y = piola__rsqrt_newton(x, y);
  return piola__rsqrt_newton(x, y);
}
/* To about 5e-6: enough where only a ratio or a rough scale is needed. */
PIOLA_KERNEL_INLINE double piola__rsqrt_rough(double x) {
  double y = piola__rsqrt_guess(x);
  y = piola__rsqrt_newton(x, y);
  return piola__rsqrt_newton(x, y);
}

/* The kernel is written on named scalars, not small arrays: inside an `omp simd` loop GCC
 * turns per-lane arrays into scattered "simd arrays" and gives up vectorizing. */

/* One Jacobi rotation in the (p, q) plane of the symmetric S (k the third index) with the
 * exact Jacobi angle, tan(2 theta) = e / d with d = s_pp - s_qq, e = 2 s_pq, taken with
 * |2 theta| <= pi/2: tan(theta) = sgn(d) e / (|d| + r), r = sqrt(d^2 + e^2).
 * Cheap but exact where it matters: only the angle decides the eigenvectors, so r and the
 * normalization of (c, s) use a rough reciprocal square root (error ~5e-6). The transform
 * is then G = m R with R an exact rotation and m = |(c, s)| = 1 +- 1e-5; the third axis is
 * scaled by the same m (from a 2nd-order series, exact to ~1e-16) so that G stays a scaled
 * rotation: S <- G^T S G = m^2 R^T S R keeps its eigenvectors, V <- V G stays a scaled
 * rotation and is normalized once at the end. An error in r only perturbs the angle a
 * little, which the next sweep corrects. A negligible s_pq gives the identity. */
#define PIOLA_SVD_JACOBI(spp, sqq, skk, spq, spk, sqk, v0p, v0q, v0k, v1p, v1q, v1k, v2p, \
                         v2q, v2k)                                                          \
  do {                                                                                      \
    double d_ = spp - sqq, e_ = 2.0 * spq;                                                  \
    d_ = fabs(d_) < PIOLA_SVD_FLUSH ? 0.0 : d_;                                             \
    e_ = fabs(e_) < PIOLA_SVD_FLUSH ? 0.0 : e_;                                             \
    double r2_ = d_ * d_ + e_ * e_;                                                         \
    int negligible_ = e_ == 0.0;                                                            \
    double r_ = r2_ * piola__rsqrt_angle(negligible_ ? 1.0 : r2_);                          \
    double c_ = fabs(d_) + r_, s_ = d_ >= 0 ? e_ : -e_;                                     \
    double k_ = piola__rsqrt_rough(negligible_ ? 1.0 : c_ * c_ + s_ * s_);                  \
    c_ = negligible_ ? 1.0 : c_ * k_;                                                       \
    s_ = negligible_ ? 0.0 : s_ * k_;                                                       \
    double delta_ = c_ * c_ + s_ * s_ - 1.0;                                                \
    double m_ = 1.0 + delta_ * (0.5 - 0.125 * delta_);                                      \
    double cc_ = c_ * c_, ss_ = s_ * s_, cs_ = c_ * s_;                                     \
    double spp_ = spp, sqq_ = sqq, spq_ = spq, spk_ = spk, sqk_ = sqk;                     \
    spp = cc_ * spp_ + 2.0 * cs_ * spq_ + ss_ * sqq_;                                       \
    sqq = ss_ * spp_ - 2.0 * cs_ * spq_ + cc_ * sqq_;                                       \
    spq = (cc_ - ss_) * spq_ - cs_ * (spp_ - sqq_);                                         \
    spk = m_ * (c_ * spk_ + s_ * sqk_);                                                     \
    sqk = m_ * (-s_ * spk_ + c_ * sqk_);                                                    \
    skk = m_ * m_ * skk;                                                                    \
    double t_;                                                                              \
    t_ = v0p; v0p = c_ * t_ + s_ * v0q; v0q = -s_ * t_ + c_ * v0q; v0k *= m_;               \
    t_ = v1p; v1p = c_ * t_ + s_ * v1q; v1q = -s_ * t_ + c_ * v1q; v1k *= m_;               \
    t_ = v2p; v2p = c_ * t_ + s_ * v2q; v2q = -s_ * t_ + c_ * v2q; v2k *= m_;               \
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

/* F = U diag(fhat) V^T with U, V proper rotations, |fhat_0| >= |fhat_1| >= |fhat_2|,
 * fhat_0, fhat_1 >= 0, sign(fhat_2) = sign(det F). Entry k (row-major, k = 3 row + col) of
 * F is f[k * in_stride]; of U and V, u[k * out_stride] and v[k * out_stride]; fhat entry i
 * is fhat[i * fhat_stride]. Strides let the caller read and write SoA lanes directly. */
PIOLA_KERNEL_INLINE void piola__svd3_kernel(const double *f, long in_stride, double *u,
                                            double *v, long out_stride, double *fhat,
                                            long fhat_stride) {
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
#define PIOLA_SVD_NORMALIZE(a) a = fabs(a * inv_scale) < PIOLA_SVD_FLUSH ? 0.0 : a * inv_scale
  PIOLA_SVD_NORMALIZE(a00); PIOLA_SVD_NORMALIZE(a01); PIOLA_SVD_NORMALIZE(a02);
  PIOLA_SVD_NORMALIZE(a10); PIOLA_SVD_NORMALIZE(a11); PIOLA_SVD_NORMALIZE(a12);
  PIOLA_SVD_NORMALIZE(a20); PIOLA_SVD_NORMALIZE(a21); PIOLA_SVD_NORMALIZE(a22);
#undef PIOLA_SVD_NORMALIZE

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
    PIOLA_SVD_JACOBI(s00, s11, s22, s01, s02, s12, v00, v01, v02, v10, v11, v12, v20, v21, v22);
    PIOLA_SVD_JACOBI(s00, s22, s11, s02, s01, s12, v00, v02, v01, v10, v12, v11, v20, v22, v21);
    PIOLA_SVD_JACOBI(s11, s22, s00, s12, s01, s02, v01, v02, v00, v11, v12, v10, v21, v22, v20);
  }

  /* V is a rotation times the product of the rough scales: normalize it once */
  double kv = piola__rsqrt(v00 * v00 + v10 * v10 + v20 * v20);
  v00 *= kv; v01 *= kv; v02 *= kv;
  v10 *= kv; v11 *= kv; v12 *= kv;
  v20 *= kv; v21 *= kv; v22 *= kv;

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

  /* U by Gram-Schmidt on the (nearly orthogonal) columns of B, which is QR without the
   * rotations: u0 = b0 / |b0|, u1 = the part of b1 orthogonal to u0, normalized,
   * u2 = u0 x u1 (so det U = +1), and R's diagonal is |b0|, |b1 - (u0.b1) u0|, u2.b2, the
   * last carrying the sign of det F. A negligible b0 (F = 0) gives u0 = e0; a negligible
   * b1 (F of rank <= 1) gives u1 = any unit vector orthogonal to u0. */
  int col0_ok = n0 > PIOLA_SVD_FLUSH * PIOLA_SVD_FLUSH;
  double k0 = piola__rsqrt(col0_ok ? n0 : 1.0);
  double u00 = col0_ok ? b00 * k0 : 1.0, u10 = col0_ok ? b10 * k0 : 0.0, u20 = col0_ok ? b20 * k0 : 0.0;
  double r00 = col0_ok ? n0 * k0 : 0.0;
  double dot01 = u00 * b01 + u10 * b11 + u20 * b21;
  double w0 = b01 - dot01 * u00, w1 = b11 - dot01 * u10, w2 = b21 - dot01 * u20;
  /* a second pass ("twice is enough") keeps u1 orthogonal to u0 when b1 is mostly noise */
  double dot01b = u00 * w0 + u10 * w1 + u20 * w2;
  w0 -= dot01b * u00;
  w1 -= dot01b * u10;
  w2 -= dot01b * u20;
  w0 = fabs(w0) < PIOLA_SVD_FLUSH ? 0.0 : w0;
  w1 = fabs(w1) < PIOLA_SVD_FLUSH ? 0.0 : w1;
  w2 = fabs(w2) < PIOLA_SVD_FLUSH ? 0.0 : w2;
  double m1 = w0 * w0 + w1 * w1 + w2 * w2;
  int col1_ok = m1 > PIOLA_SVD_FLUSH * PIOLA_SVD_FLUSH;
  double k1 = piola__rsqrt(col1_ok ? m1 : 1.0);
  /* completion: u0 x e_j with e_j the axis along which u0 is smallest */
  double ax0 = fabs(u00), ax1 = fabs(u10), ax2 = fabs(u20);
  int pick0 = ax0 <= ax1 && ax0 <= ax2, pick1 = !pick0 && ax1 <= ax2, pick2 = !pick0 && !pick1;
  double e0 = pick0 ? 1.0 : 0.0, e1 = pick1 ? 1.0 : 0.0, e2 = pick2 ? 1.0 : 0.0;
  double c0 = u10 * e2 - u20 * e1, c1 = u20 * e0 - u00 * e2, c2 = u00 * e1 - u10 * e0;
  double kc = piola__rsqrt(c0 * c0 + c1 * c1 + c2 * c2);
  double u01 = col1_ok ? w0 * k1 : c0 * kc, u11 = col1_ok ? w1 * k1 : c1 * kc,
         u21 = col1_ok ? w2 * k1 : c2 * kc;
  double r11 = col1_ok ? m1 * k1 : 0.0;
  double u02 = u10 * u21 - u20 * u11, u12 = u20 * u01 - u00 * u21, u22 = u00 * u11 - u10 * u01;
  double r22 = u02 * b02 + u12 * b12 + u22 * b22;
  b00 = r00;
  b11 = r11;
  b22 = r22;

  fhat[0] = b00 * scale;
  fhat[fhat_stride] = b11 * scale;
  fhat[2 * fhat_stride] = b22 * scale;
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
