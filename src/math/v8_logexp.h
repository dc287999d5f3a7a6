/* Natural logarithm and exponential on 8 doubles at once (GCC/clang vector extensions),
 * branch-free, to a few ulp.
 *
 * Why not libm: the plastic return mapping takes 3 logarithms and 3 exponentials per
 * yielding tet, and libm's scalar calls (with their branches for special cases) cost more
 * than the rest of the update together and keep the tet loop from vectorizing. The inputs
 * there are tame (log: positive, normal, finite; exp: |x| < 700), so the special cases can
 * go and both functions become straight-line polynomial code over 8 lanes.
 *
 * log x. x = 2^e m with m in [sqrt(1/2), sqrt 2) (exponent and mantissa from the bits, the
 * mantissa moved down an octave when it is above sqrt 2). With f = m - 1 (exact) and
 * s = f / (2 + f), |s| <= 3 - 2 sqrt 2 = 0.1716 and log m = 2 atanh s = 2 s (1 + z/3 +
 * z^2/5 + ...), z = s^2 <= 0.0295: the series through z^10 leaves a relative error below
 * 0.0295^11 / 23 = 6e-19. Polynomials are evaluated by Estrin's scheme (short dependency
 * chains: the callers are latency-bound). log x = e ln2_hi + (e ln2_lo + log m), ln2_hi with 32
 * significant bits so e ln2_hi is exact.
 *
 * exp x. n = round(x / ln 2) (the 1.5 2^52 rounding trick), r = x - n ln2_hi - n ln2_lo,
 * |r| <= ln2 / 2 = 0.347, exp r by its Taylor series through r^13 (remainder below
 * 0.347^14 / 14! = 5e-18), times 2^n built in the exponent bits. x is clamped to
 * [-700, 700] first, so 2^n stays a normal number; NaN input gives an unspecified result.
 *
 * Measured against libm (tests/test_v8_logexp.c): relative error below 1e-15 for log over
 * [1e-300, 1e300] and near 1, and for exp over [-700, 700]. */
#ifndef PIOLA_MATH_V8_LOGEXP_H
#define PIOLA_MATH_V8_LOGEXP_H

#include <stdint.h>
#include <string.h>

/* Vectors are passed by value only between always-inlined functions (see svd_kernel.h). */
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

#if defined(__GNUC__) || defined(__clang__)
#define PIOLA_V8_INLINE static inline __attribute__((always_inline))
#else
#define PIOLA_V8_INLINE static inline
#endif

/* Functions holding 8-lane code ask GCC for full AVX-512 vectors where the build targets
 * them (as svd_kernel.h does for the force loop). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__AVX512F__)
#define PIOLA_F64X8_WIDE __attribute__((target("prefer-vector-width=512")))
#else
#define PIOLA_F64X8_WIDE
#endif

typedef double piola_f64x8 __attribute__((vector_size(64)));
typedef int64_t piola_i64x8 __attribute__((vector_size(64)));

/* mask ? a : b, mask lanes all ones or all zeros (a vector comparison's result) */
#define PIOLA_F64X8_SELECT(mask, a, b) \
  ((piola_f64x8)(((mask) & (piola_i64x8)(a)) | (~(mask) & (piola_i64x8)(b))))

PIOLA_V8_INLINE piola_f64x8 piola__f64x8_splat(double x) {
  piola_f64x8 r = {x, x, x, x, x, x, x, x};
  return r;
}
PIOLA_V8_INLINE piola_f64x8 piola__f64x8_load(const double *p) {
  piola_f64x8 r;
  memcpy(&r, p, sizeof r);
  return r;
}
PIOLA_V8_INLINE void piola__f64x8_store(double *p, piola_f64x8 x) { memcpy(p, &x, sizeof x); }

#define PIOLA_LN2_HI 0.6931471806019545      /* ln 2 to 32 significant bits */
#define PIOLA_LN2_LO (-4.2009150726810846e-11) /* ln 2 - PIOLA_LN2_HI */

/* log x for positive, normal, finite x. */
PIOLA_V8_INLINE piola_f64x8 piola__f64x8_log(piola_f64x8 x) {
  const piola_i64x8 bits = (piola_i64x8)x;
  piola_i64x8 e = ((bits >> 52) & 0x7ff) - 1023;
  piola_f64x8 m = (piola_f64x8)((bits & INT64_C(0x000fffffffffffff)) | INT64_C(0x3ff0000000000000));
  piola_i64x8 high = (piola_i64x8)(m > 1.4142135623730951);
  m = PIOLA_F64X8_SELECT(high, 0.5 * m, m);
  e -= high; /* high is -1 where true */
  piola_f64x8 ef = __builtin_convertvector(e, piola_f64x8);
  piola_f64x8 f = m - 1.0;
  piola_f64x8 s = f / (2.0 + f);
  piola_f64x8 z = s * s, z2 = z * z, z4 = z2 * z2, z8 = z4 * z4;
  /* p = sum_{i=0..9} z^i / (2 i + 3) by Estrin's scheme (depth 4 instead of Horner's 9:
   * the update is latency-bound) */
  piola_f64x8 q0 = (1.0 / 3.0) + z * (1.0 / 5.0), q1 = (1.0 / 7.0) + z * (1.0 / 9.0);
  piola_f64x8 q2 = (1.0 / 11.0) + z * (1.0 / 13.0), q3 = (1.0 / 15.0) + z * (1.0 / 17.0);
  piola_f64x8 q4 = (1.0 / 19.0) + z * (1.0 / 21.0);
  piola_f64x8 p = ((q0 + z2 * q1) + z4 * (q2 + z2 * q3)) + z8 * q4;
  /* log m = 2 s + 2 s z p: the leading term alone carries most of the value */
  piola_f64x8 two_s = 2.0 * s;
  return ef * PIOLA_LN2_HI + (ef * PIOLA_LN2_LO + (two_s + two_s * (z * p)));
}

/* exp x; x is clamped to [-700, 700]. */
PIOLA_V8_INLINE piola_f64x8 piola__f64x8_exp(piola_f64x8 x) {
  const piola_f64x8 lim = piola__f64x8_splat(700.0);
  x = PIOLA_F64X8_SELECT((piola_i64x8)(x > lim), lim, x);
  x = PIOLA_F64X8_SELECT((piola_i64x8)(x < -lim), -lim, x);
  const double shifter = 6755399441055744.0; /* 1.5 * 2^52: adding it rounds to an integer */
  piola_f64x8 t = x * 1.4426950408889634 + shifter;
  piola_f64x8 n = t - shifter;
  piola_i64x8 ni = (piola_i64x8)t - (piola_i64x8)piola__f64x8_splat(shifter);
  piola_f64x8 r = (x - n * PIOLA_LN2_HI) - n * PIOLA_LN2_LO;
  /* sum_{k=0..13} r^k / k! by Estrin's scheme (depth 5 instead of Horner's 13); the
   * terms after 1 + r are summed first, so the leading 1 is added last */
  piola_f64x8 r2 = r * r, r4 = r2 * r2;
  piola_f64x8 q1 = 0.5 + r * (1.0 / 6.0), q2 = (1.0 / 24.0) + r * (1.0 / 120.0);
  piola_f64x8 q3 = (1.0 / 720.0) + r * (1.0 / 5040.0), q4 = (1.0 / 40320.0) + r * (1.0 / 362880.0);
  piola_f64x8 q5 = (1.0 / 3628800.0) + r * (1.0 / 39916800.0);
  piola_f64x8 q6 = (1.0 / 479001600.0) + r * (1.0 / 6227020800.0);
  piola_f64x8 tail = (q1 + r2 * q2) + r4 * ((q3 + r2 * q4) + r4 * (q5 + r2 * q6));
  piola_f64x8 p = 1.0 + (r + r2 * tail);
  piola_f64x8 scale = (piola_f64x8)((ni + 1023) << 52);
  return p * scale;
}

#endif
