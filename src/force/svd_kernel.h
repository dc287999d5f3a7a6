/* A branch-free 3x3 SVD with the invertible sign convention, on 8 matrices at once (one
 * per SIMD lane, written on explicit GCC/clang vectors).
 *
 * Why a second diagonalization besides the public piola_diagonalize3: that one is written
 * for robustness at any scale and to 1e-12, with branches; the force loop runs a
 * diagonalization for every tet every step and needs it fast and branch-free. The approach
 * is that of McAdams et al. 2011 ("Computing the singular value decomposition of 3x3
 * matrices with minimal branching and elementary floating point operations"), adapted to
 * double precision and written from the method's description:
 *   1. normalize F by its largest entry (the kernel is then scale invariant), and flush
 *      entries below 1e-100 of it to zero (no denormals downstream);
 *   2. symmetric eigenproblem of S = F^T F by cyclic Jacobi with a fixed number of sweeps
 *      (4; 3 leave a worst random case at 1e-5). Unlike McAdams' approximate Givens angles
 *      (which need more sweeps in double), each rotation uses the exact Jacobi angle, but
 *      computed cheaply: only the angle matters, so the square roots in it are rough and
 *      the rotation is kept an exact rotation times a scale, which leaves the eigenvectors
 *      alone; V is normalized once at the end;
 *   3. B = F V, columns sorted by decreasing norm (a swap negates one column so det V = +1);
 *   4. U by Gram-Schmidt on B's columns, which is QR without the rotations: u0 = b0/|b0|,
 *      u1 = b1 minus its u0 part (twice), normalized, u2 = u0 x u1 so det U = +1;
 *      Fhat = (|b0|, |b1'|, u2 . b2), the last carrying the sign of det F: an inverted
 *      element gets one negative entry, the one of smallest magnitude. A zero b0 (F = 0)
 *      gives U = I; a b1 that is zero or below 1e-14 of itself after the projection
 *      (rank <= 1) gets a completed u1.
 * No sqrt and one divide per matrix (the normalization): reciprocal square roots start from
 * the hardware estimate where the build targets AVX-512 (vrsqrt14pd, 2^-14) and otherwise
 * from a bit-level guess plus two Newton steps, then as many Newton steps as each use needs
 * (none for the rotation's normalization, whose error the scale m absorbs exactly).
 *
 * Fused multiply-adds. The files that inline the kernel ask GCC for fp-contract=fast
 * (GCC's -std=c17 otherwise turns contraction off, and the kernel is mostly a*b + c): about
 * a third fewer floating-point instructions. Results stay deterministic (contraction is
 * decided at compile time) and identical for any thread count.
 *
 * Measured accuracy (tests/test_elastic_body.c, docs/forces.md): worst relative
 * reconstruction |U Fhat V^T - F| / |F| 2e-15 (7e-15 for rank-2 matrices) and orthogonality
 * |U^T U - I|, |V^T V - I| 2.5e-15 over random, rank-2, rank-1, zero, near-identity, tiny
 * and huge matrices, on both the AVX-512 and the fallback path. */
#ifndef PIOLA_FORCE_SVD_KERNEL_H
#define PIOLA_FORCE_SVD_KERNEL_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "common/isa.h"
#include "math/v8.h"

#ifndef PIOLA_SVD_JACOBI_SWEEPS
#define PIOLA_SVD_JACOBI_SWEEPS 4
#endif

/* Relative to the normalized matrix (largest entry 1), values below this are zero: it keeps
 * every intermediate far from denormal numbers, which cost ~100 cycles each in hardware,
 * while changing F by less than 1e-100 of its size. */
#define PIOLA_SVD_FLUSH 1e-100

/* Fixed-count inner loops must be unrolled before the lane loop is vectorized (GCC does not
 * vectorize a loop around two consecutive inner loops). */
#if defined(__GNUC__) && !defined(__clang__)
#define PIOLA_UNROLL _Pragma("GCC unroll 16")
#else
#define PIOLA_UNROLL
#endif

/* ---- The kernel on 8 lanes at once, in GCC/clang vector extensions ----
 *
 * One piola_v8d holds one matrix entry of 8 tets (one AVX-512 register; other targets split
 * it into narrower registers). Writing the kernel on explicit vectors, instead of per-lane
 * code in an `omp simd` loop, lets it use the hardware reciprocal square root estimate
 * (vrsqrt14pd, relative error below 2^-14) where the build targets AVX-512: one instruction
 * instead of the bit-level guess and two Newton steps, which shortens the dependency chain
 * of every Jacobi rotation (the kernel is latency-bound: each rotation waits for the last).
 * Elsewhere the estimate is the bit-level guess refined by two Newton steps (error 5e-6),
 * so both paths meet the same bound. Selections are bit masks (C has no vector ?:). */
PIOLA_KERNEL_INLINE piola_v8d piola__v8_rsqrt_newton(piola_v8d x, piola_v8d y) {
  return y * (1.5 - 0.5 * x * y * y);
}
/* Reciprocal square root estimate of normal positive x, relative error below 6.2e-5. */
PIOLA_KERNEL_INLINE piola_v8d piola__v8_rsqrt_estimate(piola_v8d x) {
#if defined(__AVX512F__)
  return (piola_v8d)_mm512_rsqrt14_pd((__m512d)x);
#else
  /* unsigned shift: x > 0, and AVX2 has no 64-bit arithmetic shift */
  piola_v8u i = UINT64_C(0x5fe6eb50c7b537a9) - ((piola_v8u)x >> 1);
  piola_v8d y = (piola_v8d)i;
  y = piola__v8_rsqrt_newton(x, y);
  return piola__v8_rsqrt_newton(x, y);
#endif
}
/* Estimate and one Newton step: relative error below 6e-9. */
PIOLA_KERNEL_INLINE piola_v8d piola__v8_rsqrt_refined(piola_v8d x) {
  return piola__v8_rsqrt_newton(x, piola__v8_rsqrt_estimate(x));
}
/* To about 1 ulp (estimate, then two Newton steps: 6.2e-5 -> 6e-9 -> 5e-17). */
PIOLA_KERNEL_INLINE piola_v8d piola__v8_rsqrt(piola_v8d x) {
  piola_v8d y = piola__v8_rsqrt_estimate(x);
  y = piola__v8_rsqrt_newton(x, y);
  return piola__v8_rsqrt_newton(x, y);
}

/* One Jacobi rotation in the (p, q) plane of the symmetric S (k the third index), on 8
 * lanes, with the exact Jacobi angle tan(2 theta) = e / d, d = s_pp - s_qq, e = 2 s_pq,
 * taken with |2 theta| <= pi/2: tan(theta) = sgn(d) e / (|d| + r), r = sqrt(d^2 + e^2).
 * Only the angle decides the eigenvectors, so the square roots are cheap: r from
 * rsqrt_r (an error in r only tilts the angle, which a later sweep corrects), and the
 * normalization k of (c, s) from the bare estimate, so that c^2 + s^2 = 1 + delta with
 * |delta| < 1.3e-4. The transform is then G = m R, R an exact rotation, m = sqrt(1 + delta)
 * from its series to third order (error 5 delta^4 / 128 < 1e-17), and the third axis is
 * scaled by the same m: S <- G^T S G = m^2 R^T S R keeps its eigenvectors, V <- V G stays
 * a scaled rotation and is normalized once at the end. No branch, no divide, no mask:
 * d = e = 0 (a diagonal or zero S) gives c = 1, s = 0 through the 1e-300 floor.
 * Written for a short chain from one rotation's S to the next (the chain, not the
 * instruction count, bounds the kernel): the new S entries are k^2 (m k for the k row)
 * times what the unscaled (c0, s0) give, and those products are formed while the estimate
 * k is computed; m comes from delta = k^2 rho0^2 - 1 (rho0^2 = c0^2 + s0^2) by an Estrin
 * form of its series, and skk is scaled by m^2 = k^2 rho0^2 with no series at all. */
#define PIOLA_V8_JACOBI(rsqrt_r, spp, sqq, skk, spq, spk, sqk, v0p, v0q, v0k, v1p, v1q, v1k,  \
                        v2p, v2q, v2k)                                                      \
  do {                                                                                      \
    piola_v8d d_ = spp - sqq, e_ = 2.0 * spq;                                               \
    /* + 1e-300: d = e = 0 gives r, c ~ 1e-150 and so c = 1, s = 0 after normalization */   \
    piola_v8d r2_ = d_ * d_ + (e_ * e_ + 1e-300);                                           \
    piola_v8d c0_ = piola__v8_abs(d_) + r2_ * rsqrt_r(r2_);                                 \
    piola_v8l dsign_ = (piola_v8l)d_ & INT64_MIN; /* s = d >= 0 ? e : -e */                 \
    piola_v8d s0_ = (piola_v8d)((piola_v8l)e_ ^ dsign_);                                    \
    piola_v8d rho2_ = c0_ * c0_ + s0_ * s0_;                                                \
    /* the new S entries as k^2 (or m k) times what c0, s0 give, formed while the estimate \
     * k is computed: the chain from one rotation's S to the next is shorter */            \
    piola_v8d cc0_ = c0_ * c0_, ss0_ = s0_ * s0_, cs0_ = c0_ * s0_;                         \
    piola_v8d spp0_ = cc0_ * spp + cs0_ * e_ + ss0_ * sqq;                                  \
    piola_v8d sqq0_ = ss0_ * spp - cs0_ * e_ + cc0_ * sqq;                                  \
    piola_v8d spq0_ = (cc0_ - ss0_) * spq - cs0_ * d_;                                      \
    piola_v8d spk0_ = c0_ * spk + s0_ * sqk, sqk0_ = c0_ * sqk - s0_ * spk;                 \
    piola_v8d k_ = piola__v8_rsqrt_estimate(rho2_);                                         \
    piola_v8d k2_ = k_ * k_;                                                                \
    piola_v8d m2_ = k2_ * rho2_; /* c^2 + s^2 of the scaled (c, s) = 1 + delta */           \
    piola_v8d delta_ = k2_ * rho2_ - 1.0;                                                   \
    piola_v8d delta2_ = delta_ * delta_;                                                    \
    piola_v8d mser_ = 0.5 * delta_ + delta2_ * (-0.125 + delta_ * 0.0625); /* m - 1 */     \
    piola_v8d m_ = 1.0 + mser_, mk_ = k_ + k_ * mser_;                                      \
    piola_v8d c_ = c0_ * k_, s_ = s0_ * k_;                                                 \
    spp = k2_ * spp0_;                                                                      \
    sqq = k2_ * sqq0_;                                                                      \
    spq = k2_ * spq0_;                                                                      \
    spk = mk_ * spk0_;                                                                      \
    sqk = mk_ * sqk0_;                                                                      \
    skk = m2_ * skk;                                                                        \
    piola_v8d t_;                                                                           \
    t_ = v0p; v0p = c_ * t_ + s_ * v0q; v0q = c_ * v0q - s_ * t_; v0k *= m_;                \
    t_ = v1p; v1p = c_ * t_ + s_ * v1q; v1q = c_ * v1q - s_ * t_; v1k *= m_;                \
    t_ = v2p; v2p = c_ * t_ + s_ * v2q; v2q = c_ * v2q - s_ * t_; v2k *= m_;                \
  } while (0)

#define PIOLA_V8_SORT(ni, nj, b0i, b1i, b2i, b0j, b1j, b2j, v0i, v1i, v2i, v0j, v1j, v2j) \
  do {                                                                                  \
    piola_v8l swap_ = (piola_v8l)(ni < nj);                                             \
    piola_v8d t_;                                                                       \
    t_ = ni; ni = PIOLA_V8_SELECT(swap_, nj, ni); nj = PIOLA_V8_SELECT(swap_, t_, nj);  \
    t_ = b0i; b0i = PIOLA_V8_SELECT(swap_, b0j, b0i); b0j = PIOLA_V8_SELECT(swap_, -t_, b0j); \
    t_ = b1i; b1i = PIOLA_V8_SELECT(swap_, b1j, b1i); b1j = PIOLA_V8_SELECT(swap_, -t_, b1j); \
    t_ = b2i; b2i = PIOLA_V8_SELECT(swap_, b2j, b2i); b2j = PIOLA_V8_SELECT(swap_, -t_, b2j); \
    t_ = v0i; v0i = PIOLA_V8_SELECT(swap_, v0j, v0i); v0j = PIOLA_V8_SELECT(swap_, -t_, v0j); \
    t_ = v1i; v1i = PIOLA_V8_SELECT(swap_, v1j, v1i); v1j = PIOLA_V8_SELECT(swap_, -t_, v1j); \
    t_ = v2i; v2i = PIOLA_V8_SELECT(swap_, v2j, v2i); v2j = PIOLA_V8_SELECT(swap_, -t_, v2j); \
  } while (0)

/* The state of 8 diagonalizations between their steps: the normalized F (a), its scale, the
 * symmetric S = F^T F being diagonalized and the accumulated V. The kernel is split into a
 * beginning, Jacobi rotations and an end so that two independent blocks can be interleaved
 * rotation by rotation (piola__svd3_kernel_v8x2): each rotation waits for the previous one
 * (the angle needs the updated S), so one block's rotations leave most of the core idle
 * for their latency, and a second, independent chain fills it. Every lane's arithmetic is
 * the same in both forms, so the results are identical bit for bit. */
typedef struct piola_svd8 {
  piola_v8d a00, a01, a02, a10, a11, a12, a20, a21, a22, scale;
  piola_v8d s00, s11, s22, s01, s02, s12;
  piola_v8d v00, v01, v02, v10, v11, v12, v20, v21, v22;
} piola_svd8;

/* Loads entry k of F for lanes 0..7 from f[k * in_stride + 0..7], normalizes it, forms S. */
PIOLA_KERNEL_INLINE void piola__svd8_begin(piola_svd8 *st, const double *f, long in_stride) {
  const piola_v8d zero = piola__v8_splat(0.0), one = piola__v8_splat(1.0);
  piola_v8d a00 = piola__v8_load(f), a01 = piola__v8_load(f + in_stride),
            a02 = piola__v8_load(f + 2 * in_stride), a10 = piola__v8_load(f + 3 * in_stride),
            a11 = piola__v8_load(f + 4 * in_stride), a12 = piola__v8_load(f + 5 * in_stride),
            a20 = piola__v8_load(f + 6 * in_stride), a21 = piola__v8_load(f + 7 * in_stride),
            a22 = piola__v8_load(f + 8 * in_stride);
  piola_v8d scale = piola__v8_abs(a00), t;
#define PIOLA_V8_MAX_ABS(a) t = piola__v8_abs(a); scale = PIOLA_V8_SELECT((piola_v8l)(t > scale), t, scale)
  PIOLA_V8_MAX_ABS(a01); PIOLA_V8_MAX_ABS(a02); PIOLA_V8_MAX_ABS(a10); PIOLA_V8_MAX_ABS(a11);
  PIOLA_V8_MAX_ABS(a12); PIOLA_V8_MAX_ABS(a20); PIOLA_V8_MAX_ABS(a21); PIOLA_V8_MAX_ABS(a22);
#undef PIOLA_V8_MAX_ABS
  piola_v8l nonzero = (piola_v8l)(scale > 1e-290);
  piola_v8d inv_scale = PIOLA_V8_SELECT(nonzero, one / PIOLA_V8_SELECT(nonzero, scale, one), zero);
#define PIOLA_V8_NORMALIZE(a) \
  a = a * inv_scale; a = PIOLA_V8_SELECT((piola_v8l)(piola__v8_abs(a) < PIOLA_SVD_FLUSH), zero, a)
  PIOLA_V8_NORMALIZE(a00); PIOLA_V8_NORMALIZE(a01); PIOLA_V8_NORMALIZE(a02);
  PIOLA_V8_NORMALIZE(a10); PIOLA_V8_NORMALIZE(a11); PIOLA_V8_NORMALIZE(a12);
  PIOLA_V8_NORMALIZE(a20); PIOLA_V8_NORMALIZE(a21); PIOLA_V8_NORMALIZE(a22);
#undef PIOLA_V8_NORMALIZE

  piola_v8d s00 = a00 * a00 + a10 * a10 + a20 * a20;
  piola_v8d s11 = a01 * a01 + a11 * a11 + a21 * a21;
  piola_v8d s22 = a02 * a02 + a12 * a12 + a22 * a22;
  piola_v8d s01 = a00 * a01 + a10 * a11 + a20 * a21;
  piola_v8d s02 = a00 * a02 + a10 * a12 + a20 * a22;
  piola_v8d s12 = a01 * a02 + a11 * a12 + a21 * a22;
  piola_v8d v00 = one, v01 = zero, v02 = zero, v10 = zero, v11 = one, v12 = zero, v20 = zero,
            v21 = zero, v22 = one;
  st->a00 = a00; st->a01 = a01; st->a02 = a02; st->a10 = a10; st->a11 = a11; st->a12 = a12;
  st->a20 = a20; st->a21 = a21; st->a22 = a22; st->scale = scale;
  st->s00 = s00; st->s11 = s11; st->s22 = s22; st->s01 = s01; st->s02 = s02; st->s12 = s12;
  st->v00 = v00; st->v01 = v01; st->v02 = v02; st->v10 = v10; st->v11 = v11; st->v12 = v12;
  st->v20 = v20; st->v21 = v21; st->v22 = v22;
}

/* The three rotations of a cyclic sweep, as (p, q, k) = (0, 1, 2), (0, 2, 1), (1, 2, 0). */
#define PIOLA_V8_ROTATION_01(st, rsqrt_r)                                                      \
  PIOLA_V8_JACOBI(rsqrt_r, (st).s00, (st).s11, (st).s22, (st).s01, (st).s02, (st).s12, (st).v00, \
                  (st).v01, (st).v02, (st).v10, (st).v11, (st).v12, (st).v20, (st).v21, (st).v22)
#define PIOLA_V8_ROTATION_02(st, rsqrt_r)                                                      \
  PIOLA_V8_JACOBI(rsqrt_r, (st).s00, (st).s22, (st).s11, (st).s02, (st).s01, (st).s12, (st).v00, \
                  (st).v02, (st).v01, (st).v10, (st).v12, (st).v11, (st).v20, (st).v22, (st).v21)
#define PIOLA_V8_ROTATION_12(st, rsqrt_r)                                                      \
  PIOLA_V8_JACOBI(rsqrt_r, (st).s11, (st).s22, (st).s00, (st).s12, (st).s01, (st).s02, (st).v01, \
                  (st).v02, (st).v00, (st).v11, (st).v12, (st).v10, (st).v21, (st).v22, (st).v20)

/* r = sqrt(d^2 + e^2) only tilts the angle: the first sweeps take it from the bare estimate
 * (angle off by ~1e-4 of itself, which later sweeps correct), the next to last refines it
 * once (6e-9), the last to an ulp (worst random-matrix reconstruction 1e-14 -> 2e-15). */
#define PIOLA_V8_SWEEP_RSQRT(sweep)                                                    \
  ((sweep) == PIOLA_SVD_JACOBI_SWEEPS - 1 ? 2 : (sweep) == PIOLA_SVD_JACOBI_SWEEPS - 2 ? 1 : 0)

/* V normalized, B = F V with its columns sorted, U by Gram-Schmidt, Fhat; stores U, V (entry
 * k at k * out_stride) and Fhat (entry i at i * fhat_stride). */
PIOLA_KERNEL_INLINE void piola__svd8_finish(const piola_svd8 *st, double *u, double *v,
                                            long out_stride, double *fhat, long fhat_stride) {
  const piola_v8d zero = piola__v8_splat(0.0), one = piola__v8_splat(1.0);
  const piola_v8d a00 = st->a00, a01 = st->a01, a02 = st->a02, a10 = st->a10, a11 = st->a11,
                  a12 = st->a12, a20 = st->a20, a21 = st->a21, a22 = st->a22, scale = st->scale;
  piola_v8d v00 = st->v00, v01 = st->v01, v02 = st->v02, v10 = st->v10, v11 = st->v11,
            v12 = st->v12, v20 = st->v20, v21 = st->v21, v22 = st->v22;
  piola_v8d kv = piola__v8_rsqrt(v00 * v00 + v10 * v10 + v20 * v20);
  v00 *= kv; v01 *= kv; v02 *= kv;
  v10 *= kv; v11 *= kv; v12 *= kv;
  v20 *= kv; v21 *= kv; v22 *= kv;

  piola_v8d b00 = a00 * v00 + a01 * v10 + a02 * v20;
  piola_v8d b01 = a00 * v01 + a01 * v11 + a02 * v21;
  piola_v8d b02 = a00 * v02 + a01 * v12 + a02 * v22;
  piola_v8d b10 = a10 * v00 + a11 * v10 + a12 * v20;
  piola_v8d b11 = a10 * v01 + a11 * v11 + a12 * v21;
  piola_v8d b12 = a10 * v02 + a11 * v12 + a12 * v22;
  piola_v8d b20 = a20 * v00 + a21 * v10 + a22 * v20;
  piola_v8d b21 = a20 * v01 + a21 * v11 + a22 * v21;
  piola_v8d b22 = a20 * v02 + a21 * v12 + a22 * v22;
  piola_v8d n0 = b00 * b00 + b10 * b10 + b20 * b20;
  piola_v8d n1 = b01 * b01 + b11 * b11 + b21 * b21;
  piola_v8d n2 = b02 * b02 + b12 * b12 + b22 * b22;
  PIOLA_V8_SORT(n0, n1, b00, b10, b20, b01, b11, b21, v00, v10, v20, v01, v11, v21);
  PIOLA_V8_SORT(n0, n2, b00, b10, b20, b02, b12, b22, v00, v10, v20, v02, v12, v22);
  PIOLA_V8_SORT(n1, n2, b01, b11, b21, b02, b12, b22, v01, v11, v21, v02, v12, v22);

  piola_v8l col0_ok = (piola_v8l)(n0 > PIOLA_SVD_FLUSH * PIOLA_SVD_FLUSH);
  piola_v8d k0 = piola__v8_rsqrt(PIOLA_V8_SELECT(col0_ok, n0, one));
  piola_v8d u00 = PIOLA_V8_SELECT(col0_ok, b00 * k0, one);
  piola_v8d u10 = PIOLA_V8_SELECT(col0_ok, b10 * k0, zero);
  piola_v8d u20 = PIOLA_V8_SELECT(col0_ok, b20 * k0, zero);
  piola_v8d r00 = PIOLA_V8_SELECT(col0_ok, n0 * k0, zero);
  piola_v8d dot01 = u00 * b01 + u10 * b11 + u20 * b21;
  piola_v8d w0 = b01 - dot01 * u00, w1 = b11 - dot01 * u10, w2 = b21 - dot01 * u20;
  piola_v8d dot01b = u00 * w0 + u10 * w1 + u20 * w2;
  w0 -= dot01b * u00;
  w1 -= dot01b * u10;
  w2 -= dot01b * u20;
  w0 = PIOLA_V8_SELECT((piola_v8l)(piola__v8_abs(w0) < PIOLA_SVD_FLUSH), zero, w0);
  w1 = PIOLA_V8_SELECT((piola_v8l)(piola__v8_abs(w1) < PIOLA_SVD_FLUSH), zero, w1);
  w2 = PIOLA_V8_SELECT((piola_v8l)(piola__v8_abs(w2) < PIOLA_SVD_FLUSH), zero, w2);
  piola_v8d m1 = w0 * w0 + w1 * w1 + w2 * w2;
  /* b1 counts as zero also when what is left of it is below 1e-14 of its length: with
   * fused multiply-adds, projecting out a u0 that is unit only to an ulp leaves a residue
   * parallel to u0 (b1 times ~1e-16 per pass), which must not become u1 */
  piola_v8l col1_ok = (piola_v8l)(m1 > PIOLA_SVD_FLUSH * PIOLA_SVD_FLUSH) & (piola_v8l)(m1 > 1e-28 * n1);
  piola_v8d k1 = piola__v8_rsqrt(PIOLA_V8_SELECT(col1_ok, m1, one));
  piola_v8d ax0 = piola__v8_abs(u00), ax1 = piola__v8_abs(u10), ax2 = piola__v8_abs(u20);
  piola_v8l pick0 = (piola_v8l)(ax0 <= ax1) & (piola_v8l)(ax0 <= ax2);
  piola_v8l pick1 = ~pick0 & (piola_v8l)(ax1 <= ax2);
  piola_v8l pick2 = ~pick0 & ~pick1;
  piola_v8d e0 = PIOLA_V8_SELECT(pick0, one, zero), e1 = PIOLA_V8_SELECT(pick1, one, zero),
            e2 = PIOLA_V8_SELECT(pick2, one, zero);
  piola_v8d c0 = u10 * e2 - u20 * e1, c1 = u20 * e0 - u00 * e2, c2 = u00 * e1 - u10 * e0;
  piola_v8d kc = piola__v8_rsqrt(c0 * c0 + c1 * c1 + c2 * c2);
  piola_v8d u01 = PIOLA_V8_SELECT(col1_ok, w0 * k1, c0 * kc);
  piola_v8d u11 = PIOLA_V8_SELECT(col1_ok, w1 * k1, c1 * kc);
  piola_v8d u21 = PIOLA_V8_SELECT(col1_ok, w2 * k1, c2 * kc);
  piola_v8d r11 = PIOLA_V8_SELECT(col1_ok, m1 * k1, zero);
  piola_v8d u02 = u10 * u21 - u20 * u11, u12 = u20 * u01 - u00 * u21, u22 = u00 * u11 - u10 * u01;
  piola_v8d r22 = u02 * b02 + u12 * b12 + u22 * b22;

  piola__v8_store(fhat, r00 * scale);
  piola__v8_store(fhat + fhat_stride, r11 * scale);
  piola__v8_store(fhat + 2 * fhat_stride, r22 * scale);
  piola__v8_store(u, u00); piola__v8_store(u + out_stride, u01);
  piola__v8_store(u + 2 * out_stride, u02); piola__v8_store(u + 3 * out_stride, u10);
  piola__v8_store(u + 4 * out_stride, u11); piola__v8_store(u + 5 * out_stride, u12);
  piola__v8_store(u + 6 * out_stride, u20); piola__v8_store(u + 7 * out_stride, u21);
  piola__v8_store(u + 8 * out_stride, u22);
  piola__v8_store(v, v00); piola__v8_store(v + out_stride, v01);
  piola__v8_store(v + 2 * out_stride, v02); piola__v8_store(v + 3 * out_stride, v10);
  piola__v8_store(v + 4 * out_stride, v11); piola__v8_store(v + 5 * out_stride, v12);
  piola__v8_store(v + 6 * out_stride, v20); piola__v8_store(v + 7 * out_stride, v21);
  piola__v8_store(v + 8 * out_stride, v22);
}

/* piola__svd3_kernel on 8 matrices: entry k of F for lanes 0..7 is f[k * in_stride + 0..7],
 * and likewise for U, V (out_stride) and Fhat (fhat_stride). Same steps, same conventions. */
PIOLA_KERNEL_INLINE void piola__svd3_kernel_v8(const double *f, long in_stride, double *u,
                                               double *v, long out_stride, double *fhat,
                                               long fhat_stride) {
  piola_svd8 st;
  piola__svd8_begin(&st, f, in_stride);
  PIOLA_UNROLL
  for (int sweep = 0; sweep < PIOLA_SVD_JACOBI_SWEEPS; ++sweep) {
    switch (PIOLA_V8_SWEEP_RSQRT(sweep)) {
      case 0:
        PIOLA_V8_ROTATION_01(st, piola__v8_rsqrt_estimate);
        PIOLA_V8_ROTATION_02(st, piola__v8_rsqrt_estimate);
        PIOLA_V8_ROTATION_12(st, piola__v8_rsqrt_estimate);
        break;
      case 1:
        PIOLA_V8_ROTATION_01(st, piola__v8_rsqrt_refined);
        PIOLA_V8_ROTATION_02(st, piola__v8_rsqrt_refined);
        PIOLA_V8_ROTATION_12(st, piola__v8_rsqrt_refined);
        break;
      default:
        PIOLA_V8_ROTATION_01(st, piola__v8_rsqrt);
        PIOLA_V8_ROTATION_02(st, piola__v8_rsqrt);
        PIOLA_V8_ROTATION_12(st, piola__v8_rsqrt);
        break;
    }
  }
  piola__svd8_finish(&st, u, v, out_stride, fhat, fhat_stride);
}

/* Two independent blocks of 8 (F at fa and fb, same in_stride; outputs at ua, va, fhata and
 * ub, vb, fhatb), their rotations interleaved: the same results as two calls of
 * piola__svd3_kernel_v8, in less time (see piola_svd8). */
PIOLA_KERNEL_INLINE void piola__svd3_kernel_v8x2(const double *fa, const double *fb, long in_stride,
                                                 double *ua, double *va, double *ub, double *vb,
                                                 long out_stride, double *fhata, double *fhatb,
                                                 long fhat_stride) {
  piola_svd8 sa, sb;
  piola__svd8_begin(&sa, fa, in_stride);
  piola__svd8_begin(&sb, fb, in_stride);
  PIOLA_UNROLL
  for (int sweep = 0; sweep < PIOLA_SVD_JACOBI_SWEEPS; ++sweep) {
    switch (PIOLA_V8_SWEEP_RSQRT(sweep)) {
      case 0:
        PIOLA_V8_ROTATION_01(sa, piola__v8_rsqrt_estimate); PIOLA_V8_ROTATION_01(sb, piola__v8_rsqrt_estimate);
        PIOLA_V8_ROTATION_02(sa, piola__v8_rsqrt_estimate); PIOLA_V8_ROTATION_02(sb, piola__v8_rsqrt_estimate);
        PIOLA_V8_ROTATION_12(sa, piola__v8_rsqrt_estimate); PIOLA_V8_ROTATION_12(sb, piola__v8_rsqrt_estimate);
        break;
      case 1:
        PIOLA_V8_ROTATION_01(sa, piola__v8_rsqrt_refined); PIOLA_V8_ROTATION_01(sb, piola__v8_rsqrt_refined);
        PIOLA_V8_ROTATION_02(sa, piola__v8_rsqrt_refined); PIOLA_V8_ROTATION_02(sb, piola__v8_rsqrt_refined);
        PIOLA_V8_ROTATION_12(sa, piola__v8_rsqrt_refined); PIOLA_V8_ROTATION_12(sb, piola__v8_rsqrt_refined);
        break;
      default:
        PIOLA_V8_ROTATION_01(sa, piola__v8_rsqrt); PIOLA_V8_ROTATION_01(sb, piola__v8_rsqrt);
        PIOLA_V8_ROTATION_02(sa, piola__v8_rsqrt); PIOLA_V8_ROTATION_02(sb, piola__v8_rsqrt);
        PIOLA_V8_ROTATION_12(sa, piola__v8_rsqrt); PIOLA_V8_ROTATION_12(sb, piola__v8_rsqrt);
        break;
    }
  }
  piola__svd8_finish(&sa, ua, va, out_stride, fhata, fhat_stride);
  piola__svd8_finish(&sb, ub, vb, out_stride, fhatb, fhat_stride);
}

/* For benchmarks and tests: n matrices, row-major AoS (9 each), through the kernel in
 * vectorized blocks; the plain name runs the variant piola__isa_variant() chose
 * (kernel_dispatch.c), the suffixed ones (common/isa.h) a given one. */
PIOLA_ISA_DECLARE(void, piola__svd3_kernel_batch,
                  (int32_t n, const double *f, double *u, double *fhat, double *v));
void piola__svd3_kernel_batch(int32_t n, const double *f, double *u, double *fhat, double *v);

#endif
