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

#include "math/v8.h"

#define PIOLA_LN2_HI 0.6931471806019545      /* ln 2 to 32 significant bits */
#define PIOLA_LN2_LO (-4.2009150726810846e-11) /* ln 2 - PIOLA_LN2_HI */

/* log x for positive, normal, finite x. */
PIOLA_KERNEL_INLINE piola_v8d piola__v8_log(piola_v8d x) {
  const piola_v8l bits = (piola_v8l)x;
  piola_v8l e = ((bits >> 52) & 0x7ff) - 1023;
  piola_v8d m = (piola_v8d)((bits & INT64_C(0x000fffffffffffff)) | INT64_C(0x3ff0000000000000));
  piola_v8l high = (piola_v8l)(m > 1.4142135623730951);
  m = PIOLA_V8_SELECT(high, 0.5 * m, m);
  e -= high; /* high is -1 where true */
  piola_v8d ef = __builtin_convertvector(e, piola_v8d);
  piola_v8d f = m - 1.0;
  piola_v8d s = f / (2.0 + f);
  piola_v8d z = s * s, z2 = z * z, z4 = z2 * z2, z8 = z4 * z4;
  /* p = sum_{i=0..9} z^i / (2 i + 3) by Estrin's scheme (depth 4 instead of Horner's 9:
   * the update is latency-bound) */
  piola_v8d q0 = (1.0 / 3.0) + z * (1.0 / 5.0), q1 = (1.0 / 7.0) + z * (1.0 / 9.0);
  piola_v8d q2 = (1.0 / 11.0) + z * (1.0 / 13.0), q3 = (1.0 / 15.0) + z * (1.0 / 17.0);
  piola_v8d q4 = (1.0 / 19.0) + z * (1.0 / 21.0);
  piola_v8d p = ((q0 + z2 * q1) + z4 * (q2 + z2 * q3)) + z8 * q4;
  /* log m = 2 s + 2 s z p: the leading term alone carries most of the value */
  piola_v8d two_s = 2.0 * s;
  return ef * PIOLA_LN2_HI + (ef * PIOLA_LN2_LO + (two_s + two_s * (z * p)));
}

/* exp x; x is clamped to [-700, 700]. */
PIOLA_KERNEL_INLINE piola_v8d piola__v8_exp(piola_v8d x) {
  const piola_v8d lim = piola__v8_splat(700.0);
  x = PIOLA_V8_SELECT((piola_v8l)(x > lim), lim, x);
  x = PIOLA_V8_SELECT((piola_v8l)(x < -lim), -lim, x);
  const double shifter = 6755399441055744.0; /* 1.5 * 2^52: adding it rounds to an integer */
  piola_v8d t = x * 1.4426950408889634 + shifter;
  piola_v8d n = t - shifter;
  piola_v8l ni = (piola_v8l)t - (piola_v8l)piola__v8_splat(shifter);
  piola_v8d r = (x - n * PIOLA_LN2_HI) - n * PIOLA_LN2_LO;
  /* sum_{k=0..13} r^k / k! by Estrin's scheme (depth 5 instead of Horner's 13); the
   * terms after 1 + r are summed first, so the leading 1 is added last */
  piola_v8d r2 = r * r, r4 = r2 * r2;
  piola_v8d q1 = 0.5 + r * (1.0 / 6.0), q2 = (1.0 / 24.0) + r * (1.0 / 120.0);
  piola_v8d q3 = (1.0 / 720.0) + r * (1.0 / 5040.0), q4 = (1.0 / 40320.0) + r * (1.0 / 362880.0);
  piola_v8d q5 = (1.0 / 3628800.0) + r * (1.0 / 39916800.0);
  piola_v8d q6 = (1.0 / 479001600.0) + r * (1.0 / 6227020800.0);
  piola_v8d tail = (q1 + r2 * q2) + r4 * ((q3 + r2 * q4) + r4 * (q5 + r2 * q6));
  piola_v8d p = 1.0 + (r + r2 * tail);
  piola_v8d scale = (piola_v8d)((ni + 1023) << 52);
  return p * scale;
}

#endif
