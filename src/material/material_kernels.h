/* Constitutive models in diagonal form: the inline kernels (one source of truth).
 *
 * Why this header is shaped like this
 * -----------------------------------
 * The force loop evaluates Phat(Fhat) once per tetrahedron per step, for millions of
 * tetrahedra. It runs over blocks of tets in a `#pragma omp simd` loop, with the switch on
 * the model hoisted out of the loop:
 *
 *     switch (material.model) {
 *       case PIOLA_MODEL_NEOHOOKEAN:
 *         #pragma omp simd
 *         for (i = 0; i < n; ++i) neohookean_stress(&material, f0[i], f1[i], f2[i],
 *                                                   &p0[i], &p1[i], &p2[i]);
 *         break;
 *       ...
 *     }
 *
 * For that loop to vectorize, everything it calls must be inline (forced: clang otherwise
 * keeps the model switch as a call), take and return plain doubles (no loops over small
 * local arrays, which stay in memory), and have no data-dependent branches: the inversion
 * extension is written with compare-and-selects (`cond ? a : b` on values both computed,
 * kernel_max/kernel_min; C's fmax is avoided, see kernel_max) that compilers turn into
 * blends, and the logarithm of neo-Hookean is kernel_log, not a libm call. GCC and clang
 * vectorize all five per-model kernels in such a loop (bench/bench_material.c is one). The
 * model argument of material_model_parts() is a compile-time constant in each per-model
 * kernel (neohookean_stress() and friends), so after inlining its switch folds away; the
 * one place where the model is a run-time value is material_stress_kernel(), meant for
 * scalar callers and for the public API.
 *
 * Every model is written in one shape (see docs/materials.md):
 *     psi(f) = sum_i A(f_i) + kappa/2 (q(f) - q0)^2
 * a separable per-entry energy A plus a quadratic penalty on one invariant q (the trace, the
 * sum of squares, the determinant J or ln J). Stress P_i = A'(f_i) + kappa (q - q0) dq/df_i,
 * derivative K = diag(A'') + kappa (g g^T + (q - q0) H) with g, H the gradient and Hessian
 * of q. Writing the five models in this shape gives the derivative (needed by the C1
 * extension, which is a Taylor expansion) and the third derivative (needed for the exact
 * derivative of the extended stress) from a handful of one-line pieces instead of five
 * hand-derived tensors, and makes the models easy to check against each other.
 *
 * The inversion extension lives here too, because it is part of the hot stress evaluation:
 * entries below the threshold c are clamped to c (fc = max(f, c), d = f - fc <= 0) and the
 * stress is P(fc) + K'(fc) d, with the slope K' of the clamped rows made safe (positive
 * diagonal, at least steep enough that the stress is compressive at and past zero; no
 * negative coupling between clamped entries). The public functions in material.c call the
 * same functions, so the force loop and the API cannot drift apart. */
#ifndef PIOLA_MATERIAL_KERNELS_H
#define PIOLA_MATERIAL_KERNELS_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "piola/material.h"

/* Every kernel is forced inline: clang's inliner otherwise keeps the big model switch as a
 * call (before the constant model folds it away), and a call stops the simd loop. */
#if defined(__GNUC__) || defined(__clang__)
#define MATERIAL_KERNEL static inline __attribute__((always_inline))
#else
#define MATERIAL_KERNEL static inline
#endif

/* Slots of piola_material.spline_coefficients (filled by piola_material_init). */
enum {
  SPLINE_K0 = 0,     /* Pa: slope of the 1D stress curve at rest (2 mu) */
  SPLINE_DK = 1,     /* Pa: stiff slope minus rest slope (k1 - k0 >= 0) */
  SPLINE_WE = 2,     /* elongation transition width: elongation_stretch - 1 */
  SPLINE_WC = 3,     /* compression transition width: 1 - compression_stretch */
  SPLINE_INV_WE = 4, /* 1 / SPLINE_WE */
  SPLINE_INV_WC = 5  /* 1 / SPLINE_WC */
};

/* Slots of piola_material.model_constants for PIOLA_MODEL_STABLE_NEOHOOKEAN (filled by
 * material_derive_constants). */
enum {
  SNH_MU = 0,     /* Pa: mu' = 4/3 mu */
  SNH_LAMBDA = 1, /* Pa: lambda' = lambda + 5/6 mu (> 0 for every nu in (-1, 0.5)) */
  SNH_ALPHA = 2,  /* dimensionless: alpha = 1 + 3 mu' / (4 lambda') = 1 + mu / lambda' */
  SNH_REST = 3,   /* J/m^3: lambda'/2 (1 - alpha)^2, the J term's value at rest */
  ENERGY_SLOPE = 4, /* Pa: k0, the energy extension's diagonal slope at rest (every model) */
  ENERGY_GROWTH_2 = 5, /* Pa: a2, its growth with the clamped point's stretch (see energy_slope) */
  ENERGY_GROWTH_4 = 6, /* Pa: a4 */
  OGDEN_COUNT = 7,     /* Ogden and Mooney-Rivlin (as two Ogden terms): the number of terms */
  OGDEN_MU_SUM = 8,    /* Pa: sum_p mu_p, the coefficient of -ln J */
  OGDEN_TERMS = 9,     /* mu_p (Pa) at OGDEN_TERMS + 2 p, alpha_p at OGDEN_TERMS + 2 p + 1 */
  HGO_COS_ANGLE = 7,   /* HGO (no Ogden terms): cos and sin of hgo.fiber_angle_degrees */
  HGO_SIN_ANGLE = 8
};

/* Ogden and Mooney-Rivlin share one code path (Mooney-Rivlin is stored as the Ogden terms
 * (2 C10, 2), (-2 C01, -2)). */
#define MATERIAL_IS_OGDEN(model) ((model) == PIOLA_MODEL_OGDEN || (model) == PIOLA_MODEL_MOONEY_RIVLIN)

/* The muscle's and HGO's isotropic part (matrix and volume) is neo-Hookean: same code path. */
#define MATERIAL_IS_NEOHOOKEAN_MATRIX(model) \
  ((model) == PIOLA_MODEL_MUSCLE || (model) == PIOLA_MODEL_HGO)

/* f^a for f > 0 (clamped entries): libm's pow. Not vectorizable; the Ogden models have no
 * speed target. */
MATERIAL_KERNEL double kernel_pow(double f, double a) { return pow(f, a); }


/* max and min as selects. C's fmax/fmin must return the non-NaN operand, which x86 vector
 * max/min instructions do not do, so GCC refuses to vectorize them without
 * -ffinite-math-only; a compare-and-select maps onto those instructions directly. With a NaN
 * operand these return b; a NaN in Fhat still comes out as NaN in Phat (through f - fc). */
MATERIAL_KERNEL double kernel_max(double a, double b) { return a > b ? a : b; }
MATERIAL_KERNEL double kernel_min(double a, double b) { return a < b ? a : b; }

/* How a kernel divides. The public functions (material.c) divide exactly (correctly rounded
 * IEEE division). The force loop's lane kernels take KERNEL_FAST_RECIPROCAL: a divide is a
 * long-latency, low-throughput instruction on 512-bit vectors (~16 cycles per vdivpd, one
 * unit), and neo-Hookean with the inversion extension has 15 of them per lane (1/f_i, one in
 * each logarithm, p/c twice per entry, the saturation), which bound the stress loop.
 * kernel_recip_fast is multiplies and adds only (they pipeline, two units), within ~2 ulp of
 * 1/x. The argument is a compile-time constant in every caller, so the choice folds away. */
typedef enum kernel_division { KERNEL_EXACT_DIVIDE = 0, KERNEL_FAST_RECIPROCAL = 1 } kernel_division;

/* 1/x for a positive normal x whose reciprocal is normal (piola calls it on clamped entries
 * >= threshold, on 1 + m in [1.7, 2.5] in the logarithm and on the saturation's w - d >= w),
 * within ~2 ulp. First guess from the bits: subtracting x's bit pattern from a constant
 * negates the exponent and mirrors the mantissa, a piecewise-linear fit of 1/x whose
 * relative error e = 1 - x y is at most 0.0505 with this constant. Then two steps
 * y <- y (1 + e)(1 + e^2), each taking e to e^4: 0.0505 -> 6.5e-6 -> 1.8e-21, below the
 * rounding of the last operations. No fused multiply-add is assumed (C17 without
 * contraction); the rounding of x y in the last e costs at most ~1 ulp. */
MATERIAL_KERNEL double kernel_recip_fast(double x) {
  uint64_t bits;
  memcpy(&bits, &x, sizeof bits);
  bits = 0x7fde623822fc16e6ull - bits;
  double y;
  memcpy(&y, &bits, sizeof y);
  double e = 1.0 - x * y;
  y = y + y * e;
  y = y + y * (e * e);
  e = 1.0 - x * y;
  y = y + y * e;
  return y + y * (e * e);
}

MATERIAL_KERNEL double kernel_recip(double x, kernel_division dv) {
  return dv == KERNEL_FAST_RECIPROCAL ? kernel_recip_fast(x) : 1.0 / x;
}

MATERIAL_KERNEL double kernel_div(double a, double b, kernel_division dv) {
  return dv == KERNEL_FAST_RECIPROCAL ? a * kernel_recip_fast(b) : a / b;
}

/* Natural logarithm of x > 0 (normal or subnormal; piola calls it on clamped entries only,
 * which are >= threshold > 0), accurate to a few ulp, written so that GCC can vectorize it:
 * libm's log is a call the vectorizer cannot widen (glibc declares its vector variants only
 * under -ffast-math, which piola does not use). x = 2^e m with m in [sqrt(1/2), sqrt(2)),
 * ln m = 2 atanh(s) with s = (m - 1)/(m + 1), |s| < 0.172, from its odd series to s^23.
 * The exponent is turned into a double with the 2^52 trick (integer shifts and ors only,
 * no 64-bit integer-to-double conversion, which AVX2 lacks). */
MATERIAL_KERNEL double kernel_log_div(double x, kernel_division dv) {
  const int tiny = x < 2.2250738585072014e-308;         /* subnormal: scale into the normal range */
  const double xs = tiny ? x * 18014398509481984.0 : x; /* 2^54 */
  uint64_t bits;
  memcpy(&bits, &xs, sizeof bits);
  const uint64_t mbits = (bits & 0x000fffffffffffffull) | 0x3ff0000000000000ull;
  const uint64_t ebits = 0x4330000000000000ull | (bits >> 52); /* 2^52 + biased exponent */
  double m, e;
  memcpy(&m, &mbits, sizeof m);
  memcpy(&e, &ebits, sizeof e);
  e -= 4503599627370496.0 + 1023.0 + (tiny ? 54.0 : 0.0);
  const int big = m > 1.4142135623730951;
  m = big ? 0.5 * m : m;
  e = big ? e + 1.0 : e;
  const double s = kernel_div(m - 1.0, m + 1.0, dv), s2 = s * s;
  double poly = 1.0 / 23.0;
  poly = poly * s2 + 1.0 / 21.0;
  poly = poly * s2 + 1.0 / 19.0;
  poly = poly * s2 + 1.0 / 17.0;
  poly = poly * s2 + 1.0 / 15.0;
  poly = poly * s2 + 1.0 / 13.0;
  poly = poly * s2 + 1.0 / 11.0;
  poly = poly * s2 + 1.0 / 9.0;
  poly = poly * s2 + 1.0 / 7.0;
  poly = poly * s2 + 1.0 / 5.0;
  poly = poly * s2 + 1.0 / 3.0;
  const double ln2_hi = 6.93147180369123816490e-01, ln2_lo = 1.90821492927058770002e-10;
  /* 2 s (1 + s2 poly) = 2 s + 2 s s2 poly, the small part added last. */
  return e * ln2_hi + (2.0 * s + (2.0 * s * s2 * poly + e * ln2_lo));
}

MATERIAL_KERNEL double kernel_log(double x) { return kernel_log_div(x, KERNEL_EXACT_DIVIDE); }

/* Value and derivative of the model at a point with all entries >= threshold > 0. */
typedef struct material_parts {
  double p[3];    /* Pa: Phat */
  double k[3][3]; /* Pa: dPhat_i / dFhat_j */
} material_parts;

/* --------------------------------------------------------------- per-entry pieces */

/* A'(f) and A''(f) of the separable energy of each model. */
MATERIAL_KERNEL void entry_slope_curvature(piola_material_model model, const piola_material *m,
                                           kernel_division dv, double f, double *a1,
                                           double *a2) {
  const double mu = m->mu;
  switch (model) {
    case PIOLA_MODEL_STVK: /* A = mu/4 (f^2 - 1)^2 */
      *a1 = mu * f * (f * f - 1.0);
      *a2 = mu * (3.0 * f * f - 1.0);
      return;
    case PIOLA_MODEL_NEOHOOKEAN: /* muscle: its matrix and volume part is neo-Hookean */
    case PIOLA_MODEL_HGO: /* its matrix is neo-Hookean too */
    case PIOLA_MODEL_MUSCLE: { /* A = mu (f^2 - 1)/2 - mu ln f */
      const double inv = kernel_recip(f, dv);
      *a1 = mu * (f - inv);
      *a2 = mu * (1.0 + inv * inv);
      return;
    }
    case PIOLA_MODEL_SPLINE: { /* A' = the 1D stress curve (C1 Hermite spline) */
      const double *s = m->spline_coefficients;
      const double u = f - 1.0;
      const double t = kernel_max(u, 0.0), tc = kernel_min(t, s[SPLINE_WE]);
      const double c = kernel_max(-u, 0.0), cc = kernel_min(c, s[SPLINE_WC]);
      *a1 = s[SPLINE_K0] * u + s[SPLINE_DK] * (0.5 * tc * tc * s[SPLINE_INV_WE] + (t - tc)) -
            s[SPLINE_DK] * (0.5 * cc * cc * s[SPLINE_INV_WC] + (c - cc));
      *a2 = s[SPLINE_K0] + s[SPLINE_DK] * (tc * s[SPLINE_INV_WE] + cc * s[SPLINE_INV_WC]);
      return;
    }
    case PIOLA_MODEL_STABLE_NEOHOOKEAN: /* A = mu'/2 (f^2 - 1) */
      *a1 = m->model_constants[SNH_MU] * f;
      *a2 = m->model_constants[SNH_MU];
      return;
    case PIOLA_MODEL_MOONEY_RIVLIN: {
      /* the Ogden terms (mu_1, 2) and (mu_2, -2): their powers f^(alpha - 1) are f and 1/f^3,
       * in closed form (no pow), so that its lanes vectorize */
      const double *o = m->model_constants;
      const double inv = kernel_recip(f, dv), cube = inv * inv * inv, msum = o[OGDEN_MU_SUM];
      const double mu_1 = o[OGDEN_TERMS], mu_2 = o[OGDEN_TERMS + 2];
      *a1 = mu_1 * f + mu_2 * cube - msum * inv;
      *a2 = mu_1 - 3.0 * mu_2 * cube * inv + msum * inv * inv;
      return;
    }
    case PIOLA_MODEL_OGDEN: { /* A = sum_p mu_p / alpha_p (f^alpha_p - 1) - M ln f */
      const double *o = m->model_constants;
      const double inv = kernel_recip(f, dv), msum = o[OGDEN_MU_SUM];
      double s1 = 0.0, s2 = 0.0;
      for (int p = 0; p < (int)o[OGDEN_COUNT]; ++p) {
        const double mu_p = o[OGDEN_TERMS + 2 * p], alpha = o[OGDEN_TERMS + 2 * p + 1];
        const double fa = kernel_pow(f, alpha - 1.0); /* f^(alpha - 1) */
        s1 += mu_p * fa;
        s2 += mu_p * (alpha - 1.0) * fa * inv;
      }
      *a1 = s1 - msum * inv;
      *a2 = s2 + msum * inv * inv;
      return;
    }
    case PIOLA_MODEL_ROTATED_LINEAR:
    case PIOLA_MODEL_COROTATED:
    default: /* A = mu (f - 1)^2 */
      *a1 = 2.0 * mu * (f - 1.0);
      *a2 = 2.0 * mu;
      return;
  }
}

/* --------------------------------------------------------------- the invariant term */

/* kappa, q - q0, g = dq/df and H = d2q/df2 at f (all entries > 0). */
MATERIAL_KERNEL double invariant_terms(piola_material_model model, const piola_material *m,
                                       kernel_division dv, double f0, double f1, double f2, double g[3], double h[3][3],
                                       double *kappa) {
  h[0][0] = h[0][1] = h[0][2] = h[1][0] = h[1][1] = h[1][2] = h[2][0] = h[2][1] = h[2][2] = 0.0;
  switch (model) {
    case PIOLA_MODEL_ROTATED_LINEAR: /* q = tr Fhat, kappa = lambda */
      *kappa = m->lambda;
      g[0] = g[1] = g[2] = 1.0;
      return f0 + f1 + f2 - 3.0;
    case PIOLA_MODEL_STVK: /* q = |Fhat|^2, kappa = lambda/4: lambda/2 tr(E)^2 */
      *kappa = 0.25 * m->lambda;
      g[0] = 2.0 * f0, g[1] = 2.0 * f1, g[2] = 2.0 * f2;
      h[0][0] = h[1][1] = h[2][2] = 2.0;
      return f0 * f0 + f1 * f1 + f2 * f2 - 3.0;
    case PIOLA_MODEL_NEOHOOKEAN:
    case PIOLA_MODEL_HGO: /* its matrix is neo-Hookean too */
    case PIOLA_MODEL_MUSCLE:
    case PIOLA_MODEL_MOONEY_RIVLIN:
    case PIOLA_MODEL_OGDEN: { /* q = ln J, kappa = lambda */
      *kappa = m->lambda;
      const double i0 = kernel_recip(f0, dv), i1 = kernel_recip(f1, dv), i2 = kernel_recip(f2, dv);
      g[0] = i0, g[1] = i1, g[2] = i2;
      h[0][0] = -i0 * i0, h[1][1] = -i1 * i1, h[2][2] = -i2 * i2;
      /* Three logs, not log(J): J can underflow or overflow where each entry does not. */
      return kernel_log_div(f0, dv) + kernel_log_div(f1, dv) + kernel_log_div(f2, dv);
    }
    case PIOLA_MODEL_COROTATED:
    case PIOLA_MODEL_SPLINE:
    case PIOLA_MODEL_STABLE_NEOHOOKEAN:
    default: { /* q = J, kappa = lambda: the linear pressure lambda (J - 1) dJ/dFhat; Stable
                  Neo-Hookean: q0 = alpha, kappa = lambda' */
      const int snh = model == PIOLA_MODEL_STABLE_NEOHOOKEAN;
      *kappa = snh ? m->model_constants[SNH_LAMBDA] : m->lambda;
      g[0] = f1 * f2, g[1] = f0 * f2, g[2] = f0 * f1;
      h[0][1] = h[1][0] = f2;
      h[0][2] = h[2][0] = f1;
      h[1][2] = h[2][1] = f0;
      return f0 * f1 * f2 - (snh ? m->model_constants[SNH_ALPHA] : 1.0);
    }
  }
}

/* Phat and dPhat/dFhat of the unextended model at f (all entries > 0). */
MATERIAL_KERNEL void material_model_parts(piola_material_model model, const piola_material *m,
                                          kernel_division dv, double f0, double f1, double f2, material_parts *out) {
  double g[3], h[3][3], kappa;
  const double qm = invariant_terms(model, m, dv, f0, f1, f2, g, h, &kappa);
  /* Written out, not looped: clang does not always unroll a loop around the spline's entry
   * function, and a loop over small local arrays left in a simd loop blocks vectorization. */
  double a1[3], a2[3];
  entry_slope_curvature(model, m, dv, f0, &a1[0], &a2[0]);
  entry_slope_curvature(model, m, dv, f1, &a1[1], &a2[1]);
  entry_slope_curvature(model, m, dv, f2, &a1[2], &a2[2]);
  const double kq = kappa * qm;
  out->p[0] = a1[0] + kq * g[0];
  out->p[1] = a1[1] + kq * g[1];
  out->p[2] = a1[2] + kq * g[2];
  out->k[0][0] = a2[0] + kappa * g[0] * g[0] + kq * h[0][0];
  out->k[1][1] = a2[1] + kappa * g[1] * g[1] + kq * h[1][1];
  out->k[2][2] = a2[2] + kappa * g[2] * g[2] + kq * h[2][2];
  out->k[0][1] = out->k[1][0] = kappa * g[0] * g[1] + kq * h[0][1];
  out->k[0][2] = out->k[2][0] = kappa * g[0] * g[2] + kq * h[0][2];
  out->k[1][2] = out->k[2][1] = kappa * g[1] * g[2] + kq * h[1][2];
  if (model == PIOLA_MODEL_STABLE_NEOHOOKEAN) {
    /* The term -mu'/2 ln(I_C + 1), I_C = |f|^2: gradient -mu' f / u, Hessian
     * -mu' I / u + 2 mu' f f^T / u^2 with u = I_C + 1 >= 1. */
    const double mu_s = m->model_constants[SNH_MU];
    const double iu = kernel_recip(f0 * f0 + f1 * f1 + f2 * f2 + 1.0, dv);
    const double a = mu_s * iu, b = 2.0 * mu_s * iu * iu;
    out->p[0] -= a * f0;
    out->p[1] -= a * f1;
    out->p[2] -= a * f2;
    out->k[0][0] += b * f0 * f0 - a;
    out->k[1][1] += b * f1 * f1 - a;
    out->k[2][2] += b * f2 * f2 - a;
    out->k[0][1] = out->k[1][0] = out->k[0][1] + b * f0 * f1;
    out->k[0][2] = out->k[2][0] = out->k[0][2] + b * f0 * f2;
    out->k[1][2] = out->k[2][1] = out->k[1][2] + b * f1 * f2;
  }
}

/* --------------------------------------------------------------- the extension */

/* The threshold in force at Fhat f (CLAMP, docs/materials.md "Defaults that recover"):
 * threshold while J = f0 f1 f2 >= threshold_volume[1], threshold_compressed once
 * J <= threshold_volume[0], between them the smoothstep 3u^2 - 2u^3 of
 * u = (J_high - J) / (J_high - J_low) (C1 in J, so the stress stays continuous and its
 * derivative finite). Exactly threshold when the rise is off (threshold_compressed ==
 * threshold). */
MATERIAL_KERNEL double material_threshold_ramp(const piola_material *m, double j) {
  const double lo = m->threshold_volume[0], hi = m->threshold_volume[1];
  return kernel_min(kernel_max((hi - j) / (hi - lo), 0.0), 1.0);
}
MATERIAL_KERNEL double material_threshold_at(const piola_material *m, double f0, double f1,
                                             double f2) {
  const double u = material_threshold_ramp(m, f0 * f1 * f2);
  return m->threshold + (m->threshold_compressed - m->threshold) * (u * u * (3.0 - 2.0 * u));
}
/* The largest threshold material_threshold_at can return: an Fhat with every entry at or
 * above it has no entry clamped, whatever its J. */
MATERIAL_KERNEL double material_threshold_largest(const piola_material *m) {
  return kernel_max(m->threshold, m->threshold_compressed);
}
/* dc/dJ of material_threshold_at (zero outside the rise). */
MATERIAL_KERNEL double material_threshold_volume_slope(const piola_material *m, double f0,
                                                       double f1, double f2) {
  const double u = material_threshold_ramp(m, f0 * f1 * f2);
  const double lo = m->threshold_volume[0], hi = m->threshold_volume[1];
  return -(m->threshold_compressed - m->threshold) * 6.0 * u * (1.0 - u) / (hi - lo);
}
/* The models whose default threshold can rise with J: the Ogden models and HGO (whose
 * kernels are instantiated with PIOLA_MODEL_HGO for that; its matrix is neo-Hookean). */
#define MATERIAL_THRESHOLD_RISES(model) (MATERIAL_IS_OGDEN(model) || (model) == PIOLA_MODEL_HGO)
/* The threshold a kernel of MODEL uses at f: only those models have the rise (a
 * compile-time choice in the per-model kernels). */
#define MATERIAL_THRESHOLD(model, m, f0, f1, f2) \
  (MATERIAL_THRESHOLD_RISES(model) ? material_threshold_at((m), (f0), (f1), (f2)) : (m)->threshold)

/* Diagonal slope at the threshold for a clamped entry i whose value at the clamped point is p
 * and whose Taylor slope is kii. LINEAR: the Taylor slope, raised where needed so that the
 * stress is at most -mu c at f_i = 0 (restoring) and at least mu (never softening past the
 * threshold). CLAMP: zero (constant stress), unless the clamped stress is not already
 * compressive enough, in which case the ramp that reaches -mu c at zero. */
MATERIAL_KERNEL double extension_diagonal_slope(const piola_material *m, kernel_division dv,
                                                double c, double p, double kii) {
  const double floor_slope = m->mu;
  /* Both variants are computed and blended by a 0/1 factor: a select on a loop-invariant
   * integer between doubles is one of the statements GCC's vectorizer rejects. */
  const double linear = (double)(m->inversion_mode != PIOLA_INVERSION_CLAMP);
  const double taylor = kernel_max(kii, floor_slope + kernel_div(kernel_max(p, 0.0), c, dv));
  const double ramp = kernel_max(0.0, kernel_div(p, c, dv) + floor_slope);
  return linear * taylor + (1.0 - linear) * ramp;
}

/* LINEAR: the slope far past the threshold, which the diagonal slope relaxes to (see
 * extension_saturation): the threshold slope capped at the rest stiffness 2 mu + lambda (never
 * below the restoring floor mu + max(p, 0)/c, nor below mu). Equal to the threshold slope for
 * models whose slope there is already moderate; neo-Hookean's is ~14x its rest stiffness, and
 * continued linearly that steep slope makes tangled meshes stable (docs/materials.md). CLAMP:
 * the ramp itself. */
MATERIAL_KERNEL double extension_far_slope(const piola_material *m, kernel_division dv, double c,
                                           double p, double kii) {
  const double floor_slope = m->mu;
  const double linear = (double)(m->inversion_mode != PIOLA_INVERSION_CLAMP);
  const double cap = kernel_max(2.0 * m->mu + m->lambda, floor_slope);
  const double far = kernel_max(kernel_min(kii, cap), floor_slope + kernel_div(kernel_max(p, 0.0), c, dv));
  const double ramp = kernel_max(0.0, kernel_div(p, c, dv) + floor_slope);
  return linear * far + (1.0 - linear) * ramp;
}

/* The saturating offset q(d) = d / (1 - d / w), w = c / 4, for d = f - fc <= 0: q(0) = 0,
 * q'(0) = 1 (so the extension keeps the Taylor value and slope at the threshold: C1), and
 * -w < q <= 0 (so what is multiplied by q stays bounded however deep the inversion). */
MATERIAL_KERNEL double extension_saturation(kernel_division dv, double c, double d) {
  const double w = 0.25 * c;
  return kernel_div(d * w, w - d, dv);
}

/* One entry of the extended stress: entry i with value p and slopes kii, kij, kik at the
 * clamped point, offsets di, dj, dk = f - fc <= 0 (zero at or above the threshold) and their
 * saturated values qi, qj, qk. Written on scalars with selects, not loops over arrays with
 * branches: GCC vectorizes the force loop only in this form.
 *   clamped row:   p + s_far di + (s - s_far) qi + max(kij, 0) dj + max(kik, 0) dk
 *   unclamped row: p + kij qj + kik qk
 * The diagonal slope starts at s (Taylor) at the threshold and relaxes to s_far; couplings
 * into unclamped rows saturate: their Taylor extrapolation overshoots (corotated's lateral
 * stress turns compressive past f_k < c/2 and grows with the lateral stretch, a feedback
 * that expands a body without bound). Clamped rows never take a negative coupling to other
 * clamped entries (it could pull an inverted entry further). CLAMP: p + ramp di. */
MATERIAL_KERNEL double extended_entry(const piola_material *m, kernel_division dv, double c, double p, double kii, double kij,
                                      double kik, double di, double dj, double dk, double qi,
                                      double qj, double qk) {
  const double s = extension_diagonal_slope(m, dv, c, p, kii);
  const double s_far = extension_far_slope(m, dv, c, p, kii);
  const double clamped_row = kernel_max(kij, 0.0) * dj + kernel_max(kik, 0.0) * dk;
  const double free_row = kij * qj + kik * qk;
  const double coupling = di < 0.0 ? clamped_row : free_row;
  const double linear = (double)(m->inversion_mode != PIOLA_INVERSION_CLAMP);
  return p + s_far * di + linear * ((s - s_far) * qi + coupling);
}

/* Extended stress from the parts at the clamped point and the offsets d = f - fc. */
MATERIAL_KERNEL void material_extend(const piola_material *m, kernel_division dv, double c,
                                     const material_parts *pa, double d0,
                                     double d1, double d2, double *p0, double *p1, double *p2) {
  const double q0 = extension_saturation(dv, c, d0), q1 = extension_saturation(dv, c, d1),
               q2 = extension_saturation(dv, c, d2);
  *p0 = extended_entry(m, dv, c, pa->p[0], pa->k[0][0], pa->k[0][1], pa->k[0][2], d0, d1, d2, q0, q1, q2);
  *p1 = extended_entry(m, dv, c, pa->p[1], pa->k[1][1], pa->k[1][0], pa->k[1][2], d1, d0, d2, q1, q0, q2);
  *p2 = extended_entry(m, dv, c, pa->p[2], pa->k[2][2], pa->k[2][0], pa->k[2][1], d2, d0, d1, q2, q0, q1);
}

/* CLAMP: g_i = dPhat_i/dc at fixed Fhat, the stress's change with the threshold itself (its
 * rise with J, material_threshold_at), from the parts at the clamped point and the offsets
 * d = f - fc. A clamped entry k moves with c (dfc_k/dc = 1, dd_k/dc = -1): p_i changes by
 * sum over clamped k of K_ik, and a clamped row's ramp term r_i d_i, r_i = max(0, p_i/c + mu),
 * by dr_i/dc d_i - r_i. */
MATERIAL_KERNEL void clamp_threshold_sensitivity(const piola_material *m, double c,
                                                 const material_parts *pa, double d0, double d1,
                                                 double d2, double g[3]) {
  const double d[3] = {d0, d1, d2};
  for (int i = 0; i < 3; ++i) {
    double dp = 0.0;
    for (int k = 0; k < 3; ++k) dp += d[k] < 0.0 ? pa->k[i][k] : 0.0;
    const double ramp = pa->p[i] / c + m->mu;
    const double r = kernel_max(ramp, 0.0), dr = ramp > 0.0 ? dp / c - pa->p[i] / (c * c) : 0.0;
    g[i] = dp + (d[i] < 0.0 ? dr * d[i] - r : 0.0);
  }
}

/* Integral from 0 to d of the saturating offset: -w d - w^2 ln(1 - d / w) (d <= 0, so the
 * logarithm's argument is >= 1). */
MATERIAL_KERNEL double extension_saturation_integral(double c, double d) {
  const double w = 0.25 * c;
  return -w * d - w * w * kernel_log(1.0 - d / w);
}

/* The hot entry point for one model known at compile time. */
MATERIAL_KERNEL void material_extended_stress(piola_material_model model, const piola_material *m,
                                              kernel_division dv, double f0, double f1, double f2, double *p0,
                                              double *p1, double *p2) {
  const double c = MATERIAL_THRESHOLD(model, m, f0, f1, f2);
  const double fc0 = kernel_max(f0, c), fc1 = kernel_max(f1, c), fc2 = kernel_max(f2, c);
  material_parts parts;
  material_model_parts(model, m, dv, fc0, fc1, fc2, &parts);
  material_extend(m, dv, c, &parts, f0 - fc0, f1 - fc1, f2 - fc2, p0, p1, p2);
}

/* --------------------------------------------------------------- the energy extension
 *
 * PIOLA_INVERSION_ENERGY (after Stomakhin, Howes, Schroeder, Teran 2012): the energy, not the
 * stress, is extended past the threshold, and the stress is its exact gradient. With
 * p = Phat(fc), K = dPhat/dFhat(fc) and T = d3 psi / df0 df1 df2 (fc) of the model at the
 * clamped point and d = f - fc <= 0 (zero for unclamped entries):
 *
 *     psi_E(f) = psi(fc) + p.d + k(fc)/2 |d|^2 + sum_{i<j} K_ij d_i d_j + T d0 d1 d2
 *     Phat_i   = p_i + k d_i + sum_{j != i} K_ij d_j + T d_j d_l + phi'(fc_i) |d|^2 / 2
 *
 * (j, l the other two; k(fc) = k0 + sum_j phi(fc_j), see energy_growth)
 * the same formula for clamped and unclamped entries (for an unclamped i, d_i = 0 and the
 * derivatives of the coefficients with f_i multiply d_i, so they drop out). This is the
 * Taylor expansion of the energy around the clamped point with its diagonal curvature
 * replaced by k: Stomakhin et al.'s psi(fc) + grad psi . d + k/2 |d|^2, plus the mixed terms
 * that keep the energy C1 where the clamped set changes (the edges and corners of the box
 * f >= c, which their smooth threshold surface does not have). k must grow with the clamped
 * point's stretch (the volume term's tension p_i there grows like lambda c s^4 for the J
 * models: with a constant k the energy would be unbounded below), but may depend on an entry
 * only through a function flat at the threshold (energy_growth). The energy is C1
 * everywhere; the stress is continuous and its derivative jumps at the threshold. */

/* Mixed third derivative d3 psi / df0 df1 df2 of the model at f (all entries > 0): zero for
 * the separable-plus-(trace, |f|^2 or ln J) models, kappa (4 J - q0) for the J penalty,
 * plus the Stable Neo-Hookean log term's -8 mu' f0 f1 f2 / (|f|^2 + 1)^3. */
MATERIAL_KERNEL double material_mixed_third(piola_material_model model, const piola_material *m,
                                            kernel_division dv, double f0, double f1, double f2) {
  switch (model) {
    case PIOLA_MODEL_COROTATED:
    case PIOLA_MODEL_SPLINE:
      return m->lambda * (4.0 * f0 * f1 * f2 - 1.0);
    case PIOLA_MODEL_STABLE_NEOHOOKEAN: {
      const double j = f0 * f1 * f2, iu = kernel_recip(f0 * f0 + f1 * f1 + f2 * f2 + 1.0, dv);
      return m->model_constants[SNH_LAMBDA] * (4.0 * j - m->model_constants[SNH_ALPHA]) -
             8.0 * m->model_constants[SNH_MU] * j * iu * iu * iu;
    }
    default:
      return 0.0;
  }
}

/* The model constants that follow from mu and lambda. Called by piola_material_init and
 * again wherever lambda is replaced (the shells' plane-stress material).
 * Stable Neo-Hookean (Smith, de Goes, Kim 2018, section 3.4): its own Lame parameters are
 * chosen so that its rest tangent is linear elasticity's 2 mu I + lambda 1 1^T with the
 * user's E and nu, like every other model.
 * The energy extension's slope k (PIOLA_INVERSION_ENERGY, every model): the rest stiffness
 * 2 mu + lambda plus what the model's couplings at the point collapse (c, c, c) could take
 * away from it (2 max(-K_01, 0) + max(T, 0) c) and the tension of an entry at the threshold at (c, c, c)
 * and with the other two stretched to 2 (max(p_0, 0) / c each), so that a collapsed, flat or
 * inverted entry is pushed back up to that lateral stretch (docs/materials.md). */
MATERIAL_KERNEL void material_derive_constants(piola_material *m) {
  if (m->model == PIOLA_MODEL_STABLE_NEOHOOKEAN) {
    const double mu_s = 4.0 / 3.0 * m->mu, lambda_s = m->lambda + 5.0 / 6.0 * m->mu;
    const double alpha = 1.0 + m->mu / lambda_s;
    m->model_constants[SNH_MU] = mu_s;
    m->model_constants[SNH_LAMBDA] = lambda_s;
    m->model_constants[SNH_ALPHA] = alpha;
    m->model_constants[SNH_REST] = 0.5 * lambda_s * (1.0 - alpha) * (1.0 - alpha);
  }
  const piola_material_model model = MATERIAL_IS_NEOHOOKEAN_MATRIX(m->model) ? PIOLA_MODEL_NEOHOOKEAN
                                     : m->model == PIOLA_MODEL_MOONEY_RIVLIN ? PIOLA_MODEL_OGDEN
                                                                             : m->model;
  const double c = m->threshold;
  material_parts pa;
  material_model_parts(model, m, KERNEL_EXACT_DIVIDE, c, c, c, &pa);
  const double t = material_mixed_third(model, m, KERNEL_EXACT_DIVIDE, c, c, c);
  material_parts stretched; /* one entry at c, the others stretched to 2 */
  material_model_parts(model, m, KERNEL_EXACT_DIVIDE, c, 2.0, 2.0, &stretched);
  m->model_constants[ENERGY_SLOPE] = 2.0 * m->mu + m->lambda + 2.0 * kernel_max(-pa.k[0][1], 0.0) +
                                     kernel_max(t, 0.0) * c + kernel_max(pa.p[0], 0.0) / c +
                                     kernel_max(stretched.p[0], 0.0) / c;
  /* The volume terms make p_i(c, s, s) grow like lambda s^2 (trace, |f|^2, ln J) or
   * lambda c s^4 (J): the growth terms keep k above 2 p_i / c (restoring, and psi_E bounded
   * below: its minimum along d_i, psi(fc) - p_i^2 / 2k, stays above psi(fc) / 2). */
  const int quartic = model == PIOLA_MODEL_COROTATED || model == PIOLA_MODEL_SPLINE ||
                      model == PIOLA_MODEL_STABLE_NEOHOOKEAN;
  const double volume = model == PIOLA_MODEL_STABLE_NEOHOOKEAN ? m->model_constants[SNH_LAMBDA] : m->lambda;
  m->model_constants[ENERGY_GROWTH_2] = 2.0 * (2.0 * m->mu + fabs(volume)) / c;
  m->model_constants[ENERGY_GROWTH_4] = quartic ? 2.0 * fabs(volume) / c : 0.0;
}

/* phi(x) = a2 u^2 + a4 u^4, u = max(x - 1, 0), and its first two derivatives: the growth of
 * the slope k(fc) = k0 + phi(fc0) + phi(fc1) + phi(fc2) with a clamped point's stretch beyond
 * 1 (k0 covers the stretches up to 2). phi is flat at the threshold (phi = phi' = 0 there),
 * so k does not move with an entry at the threshold: that is what keeps the energy C1 where
 * an entry crosses it while another is clamped (k's slope there multiplies |d|^2 / 2 in the
 * crossing entry's stress). */
MATERIAL_KERNEL double energy_growth(const piola_material *m, double x, double *slope,
                                     double *curvature) {
  const double u = kernel_max(x - 1.0, 0.0), u2 = u * u;
  const double stretched = (double)(x > 1.0);
  const double a2 = m->model_constants[ENERGY_GROWTH_2], a4 = m->model_constants[ENERGY_GROWTH_4];
  *slope = 2.0 * a2 * u + 4.0 * a4 * u2 * u;
  *curvature = stretched * (2.0 * a2 + 12.0 * a4 * u2);
  return a2 * u2 + a4 * u2 * u2;
}

/* The gradient of psi_E from the parts at the clamped point fc and the offsets d = f - fc:
 * Phat_i = p_i + k d_i + sum_{j != i} K_ij d_j + T d_j d_l + phi'(fc_i) |d|^2 / 2. */
MATERIAL_KERNEL void material_energy_extend(const piola_material *m, const material_parts *pa,
                                            double t, double fc0, double fc1, double fc2,
                                            double d0, double d1, double d2, double *p0,
                                            double *p1, double *p2, double *slope_k) {
  double g0, g1, g2, h;
  const double k = m->model_constants[ENERGY_SLOPE] + energy_growth(m, fc0, &g0, &h) +
                   energy_growth(m, fc1, &g1, &h) + energy_growth(m, fc2, &g2, &h);
  const double half_d2 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2);
  *p0 = pa->p[0] + k * d0 + pa->k[0][1] * d1 + pa->k[0][2] * d2 + t * d1 * d2 + g0 * half_d2;
  *p1 = pa->p[1] + k * d1 + pa->k[1][0] * d0 + pa->k[1][2] * d2 + t * d0 * d2 + g1 * half_d2;
  *p2 = pa->p[2] + k * d2 + pa->k[2][0] * d0 + pa->k[2][1] * d1 + t * d0 * d1 + g2 * half_d2;
  *slope_k = k;
}

/* The hot entry point of the energy extension for one model known at compile time. */
MATERIAL_KERNEL void material_energy_extended_stress(piola_material_model model,
                                                     const piola_material *m, kernel_division dv,
                                                     double f0, double f1, double f2, double *p0,
                                                     double *p1, double *p2) {
  const double c = m->threshold;
  const double fc0 = kernel_max(f0, c), fc1 = kernel_max(f1, c), fc2 = kernel_max(f2, c);
  material_parts parts;
  material_model_parts(model, m, dv, fc0, fc1, fc2, &parts);
  const double t = material_mixed_third(model, m, dv, fc0, fc1, fc2);
  double k;
  material_energy_extend(m, &parts, t, fc0, fc1, fc2, f0 - fc0, f1 - fc1, f2 - fc2, p0, p1, p2, &k);
}

/* A(f): the separable energy of each model (see entry_slope_curvature). */
MATERIAL_KERNEL double entry_energy(piola_material_model model, const piola_material *m, double f) {
  const double mu = m->mu;
  switch (model) {
    case PIOLA_MODEL_STVK:
      return 0.25 * mu * (f * f - 1.0) * (f * f - 1.0);
    case PIOLA_MODEL_NEOHOOKEAN:
    case PIOLA_MODEL_HGO: /* its matrix is neo-Hookean too */
    case PIOLA_MODEL_MUSCLE:
      return mu * (0.5 * (f * f - 1.0) - kernel_log(f));
    case PIOLA_MODEL_SPLINE: {
      /* Integral from 1 to f of the 1D stress curve. Each side (t = stretch or compression
       * beyond rest, w = its transition width) contributes tc^3 / (6 w) over the transition,
       * where the slope rises linearly, then the straight stiff part. */
      const double *s = m->spline_coefficients;
      const double u = f - 1.0;
      const double t = kernel_max(u, 0.0), tc = kernel_min(t, s[SPLINE_WE]);
      const double c = kernel_max(-u, 0.0), cc = kernel_min(c, s[SPLINE_WC]);
      const double te = t - tc, ce = c - cc;
      const double tension =
          tc * tc * tc * s[SPLINE_INV_WE] / 6.0 + te * (0.5 * s[SPLINE_WE] + 0.5 * te);
      const double compression =
          cc * cc * cc * s[SPLINE_INV_WC] / 6.0 + ce * (0.5 * s[SPLINE_WC] + 0.5 * ce);
      return 0.5 * s[SPLINE_K0] * u * u + s[SPLINE_DK] * (tension + compression);
    }
    case PIOLA_MODEL_STABLE_NEOHOOKEAN:
      return 0.5 * m->model_constants[SNH_MU] * (f * f - 1.0);
    case PIOLA_MODEL_MOONEY_RIVLIN: { /* the Ogden terms with alpha = 2 and -2 */
      const double *o = m->model_constants, inv = 1.0 / f;
      return 0.5 * o[OGDEN_TERMS] * (f * f - 1.0) - 0.5 * o[OGDEN_TERMS + 2] * (inv * inv - 1.0) -
             o[OGDEN_MU_SUM] * kernel_log(f);
    }
    case PIOLA_MODEL_OGDEN: {
      const double *o = m->model_constants;
      double a = -o[OGDEN_MU_SUM] * kernel_log(f);
      for (int p = 0; p < (int)o[OGDEN_COUNT]; ++p) {
        const double alpha = o[OGDEN_TERMS + 2 * p + 1];
        a += o[OGDEN_TERMS + 2 * p] / alpha * (kernel_pow(f, alpha) - 1.0);
      }
      return a;
    }
    case PIOLA_MODEL_ROTATED_LINEAR:
    case PIOLA_MODEL_COROTATED:
    default:
      return mu * (f - 1.0) * (f - 1.0);
  }
}

/* Energy density of the unextended model at f (all entries > 0). */
MATERIAL_KERNEL double material_model_energy(piola_material_model model, const piola_material *m,
                                             double f0, double f1, double f2) {
  double g[3], h[3][3], kappa;
  const double qm = invariant_terms(model, m, KERNEL_EXACT_DIVIDE, f0, f1, f2, g, h, &kappa);
  const double separable =
      entry_energy(model, m, f0) + entry_energy(model, m, f1) + entry_energy(model, m, f2);
  if (model == PIOLA_MODEL_STABLE_NEOHOOKEAN) /* minus the rest values: zero at rest */
    return separable + (0.5 * kappa * qm * qm - m->model_constants[SNH_REST]) -
           0.5 * m->model_constants[SNH_MU] * kernel_log(0.25 * (f0 * f0 + f1 * f1 + f2 * f2 + 1.0));
  return separable + 0.5 * kappa * qm * qm;
}

/* Extended stress and energy density in one pass (the force loop wants both; the clamped
 * point's parts are shared). Energy past the threshold: psi(fc) + p.d + sum over clamped i of
 * (1/2 s_far d_i^2 + (s - s_far) Q(d_i)), Q the integral of the saturating offset, plus the
 * clamped-clamped couplings max(K_ij, 0) d_i d_j: the same slopes as the stress, so that d psi / d f_i = Phat_i
 * for every clamped entry (docs/materials.md). Unclamped entries have d = 0 and drop out of
 * every product, which keeps this branch-free. */
MATERIAL_KERNEL void material_extended_stress_energy(piola_material_model model,
                                                     const piola_material *m, double f0, double f1,
                                                     double f2, double *p0, double *p1, double *p2,
                                                     double *psi) {
  const double c = MATERIAL_THRESHOLD(model, m, f0, f1, f2);
  const double fc0 = kernel_max(f0, c), fc1 = kernel_max(f1, c), fc2 = kernel_max(f2, c);
  const double d0 = f0 - fc0, d1 = f1 - fc1, d2 = f2 - fc2;
  material_parts pa;
  material_model_parts(model, m, KERNEL_EXACT_DIVIDE, fc0, fc1, fc2, &pa);
  material_extend(m, KERNEL_EXACT_DIVIDE, c, &pa, d0, d1, d2, p0, p1, p2);
  const double linear = (double)(m->inversion_mode != PIOLA_INVERSION_CLAMP);
  const double s0 = extension_diagonal_slope(m, KERNEL_EXACT_DIVIDE, c, pa.p[0], pa.k[0][0]);
  const double s1 = extension_diagonal_slope(m, KERNEL_EXACT_DIVIDE, c, pa.p[1], pa.k[1][1]);
  const double s2 = extension_diagonal_slope(m, KERNEL_EXACT_DIVIDE, c, pa.p[2], pa.k[2][2]);
  const double r0 = extension_far_slope(m, KERNEL_EXACT_DIVIDE, c, pa.p[0], pa.k[0][0]);
  const double r1 = extension_far_slope(m, KERNEL_EXACT_DIVIDE, c, pa.p[1], pa.k[1][1]);
  const double r2 = extension_far_slope(m, KERNEL_EXACT_DIVIDE, c, pa.p[2], pa.k[2][2]);
  const double first = pa.p[0] * d0 + pa.p[1] * d1 + pa.p[2] * d2;
  const double second =
      0.5 * (r0 * d0 * d0 + r1 * d1 * d1 + r2 * d2 * d2) +
      linear * ((s0 - r0) * extension_saturation_integral(c, d0) +
                (s1 - r1) * extension_saturation_integral(c, d1) +
                (s2 - r2) * extension_saturation_integral(c, d2)) +
      linear * (kernel_max(pa.k[0][1], 0.0) * d0 * d1 + kernel_max(pa.k[0][2], 0.0) * d0 * d2 +
                kernel_max(pa.k[1][2], 0.0) * d1 * d2);
  *psi = material_model_energy(model, m, fc0, fc1, fc2) + first + second;
}

/* psi_E and its gradient in one pass (PIOLA_INVERSION_ENERGY). */
MATERIAL_KERNEL void material_energy_extended_stress_energy(piola_material_model model,
                                                            const piola_material *m, double f0,
                                                            double f1, double f2, double *p0,
                                                            double *p1, double *p2, double *psi) {
  const double c = m->threshold;
  const double fc0 = kernel_max(f0, c), fc1 = kernel_max(f1, c), fc2 = kernel_max(f2, c);
  const double d0 = f0 - fc0, d1 = f1 - fc1, d2 = f2 - fc2;
  material_parts pa;
  material_model_parts(model, m, KERNEL_EXACT_DIVIDE, fc0, fc1, fc2, &pa);
  const double t = material_mixed_third(model, m, KERNEL_EXACT_DIVIDE, fc0, fc1, fc2);
  double k;
  material_energy_extend(m, &pa, t, fc0, fc1, fc2, d0, d1, d2, p0, p1, p2, &k);
  *psi = material_model_energy(model, m, fc0, fc1, fc2) +
         (pa.p[0] * d0 + pa.p[1] * d1 + pa.p[2] * d2 +
          0.5 * k * (d0 * d0 + d1 * d1 + d2 * d2) +
          (pa.k[0][1] * d0 * d1 + pa.k[0][2] * d0 * d2 + pa.k[1][2] * d1 * d2) + t * d0 * d1 * d2);
}

/* Per-model kernels: the model is a constant, so each compiles to straight-line code. */
MATERIAL_KERNEL void rotated_linear_stress(const piola_material *m, double f0, double f1, double f2,
                                           double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_ROTATED_LINEAR, m, KERNEL_EXACT_DIVIDE, f0, f1, f2, p0, p1, p2);
}
MATERIAL_KERNEL void corotated_stress(const piola_material *m, double f0, double f1, double f2,
                                      double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_COROTATED, m, KERNEL_EXACT_DIVIDE, f0, f1, f2, p0, p1, p2);
}
MATERIAL_KERNEL void stvk_stress(const piola_material *m, double f0, double f1, double f2,
                                 double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_STVK, m, KERNEL_EXACT_DIVIDE, f0, f1, f2, p0, p1, p2);
}
MATERIAL_KERNEL void neohookean_stress(const piola_material *m, double f0, double f1, double f2,
                                       double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_NEOHOOKEAN, m, KERNEL_EXACT_DIVIDE, f0, f1, f2, p0, p1, p2);
}
/* HGO's matrix: neo-Hookean's formulas, with HGO's threshold rise (MATERIAL_THRESHOLD). */
MATERIAL_KERNEL void hgo_stress(const piola_material *m, double f0, double f1, double f2,
                                double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_HGO, m, KERNEL_EXACT_DIVIDE, f0, f1, f2, p0, p1, p2);
}
MATERIAL_KERNEL void spline_stress(const piola_material *m, double f0, double f1, double f2,
                                   double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_SPLINE, m, KERNEL_EXACT_DIVIDE, f0, f1, f2, p0, p1, p2);
}
MATERIAL_KERNEL void ogden_stress(const piola_material *m, double f0, double f1, double f2,
                                  double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_OGDEN, m, KERNEL_EXACT_DIVIDE, f0, f1, f2, p0, p1, p2);
}
MATERIAL_KERNEL void stable_neohookean_stress(const piola_material *m, double f0, double f1,
                                              double f2, double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_STABLE_NEOHOOKEAN, m, KERNEL_EXACT_DIVIDE, f0, f1, f2, p0,
                           p1, p2);
}

/* The same kernels with the fast reciprocal, for the force loop's lanes (material_lanes.h):
 * not bit-identical to the public piola_material_stress (within a few ulp). */
MATERIAL_KERNEL void rotated_linear_stress_lanes(const piola_material *m, double f0, double f1, double f2,
                                      double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_ROTATED_LINEAR, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2, p0, p1, p2);
}
MATERIAL_KERNEL void corotated_stress_lanes(const piola_material *m, double f0, double f1, double f2,
                                      double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_COROTATED, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2, p0, p1, p2);
}
MATERIAL_KERNEL void stvk_stress_lanes(const piola_material *m, double f0, double f1, double f2,
                                      double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_STVK, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2, p0, p1, p2);
}
MATERIAL_KERNEL void neohookean_stress_lanes(const piola_material *m, double f0, double f1, double f2,
                                      double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_NEOHOOKEAN, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2, p0, p1, p2);
}
/* Neo-Hookean for lanes whose entries all lie at or above the threshold (the force loop takes
 * it for a block only when every lane qualifies, see material_lanes.h): there the extension
 * adds exactly zero (d = q = 0), so this is the plain formula p_i = mu (f_i - 1/f_i) +
 * lambda ln J / f_i, without the extension's saturations, slopes and selects. One logarithm
 * of J = f0 f1 f2 instead of three: the caller guarantees J within [1e-300, 1e300]. Differs
 * from neohookean_stress_lanes by a few ulp of lambda (ln J rounds once, not thrice). */
MATERIAL_KERNEL void neohookean_stress_lanes_unclamped(const piola_material *m, double f0,
                                                       double f1, double f2, double *p0,
                                                       double *p1, double *p2) {
  const double mu = m->mu;
  const double i0 = kernel_recip_fast(f0), i1 = kernel_recip_fast(f1), i2 = kernel_recip_fast(f2);
  const double lq = m->lambda * kernel_log_div(f0 * f1 * f2, KERNEL_FAST_RECIPROCAL);
  *p0 = mu * (f0 - i0) + lq * i0;
  *p1 = mu * (f1 - i1) + lq * i1;
  *p2 = mu * (f2 - i2) + lq * i2;
}

/* 1 when neohookean_stress_lanes_unclamped applies to this lane: every entry >= threshold
 * (false for NaN) and J in the range its single logarithm takes. */
MATERIAL_KERNEL int neohookean_lane_unclamped(const piola_material *m, double f0, double f1,
                                              double f2) {
  const double c = m->threshold, j = f0 * f1 * f2;
  return (f0 >= c) & (f1 >= c) & (f2 >= c) & (j >= 1e-300) & (j <= 1e300);
}
/* HGO's matrix for the force loop's lanes, and when neohookean_stress_lanes_unclamped
 * applies to a lane of it: every entry at or above the threshold in force there. */
MATERIAL_KERNEL void hgo_stress_lanes(const piola_material *m, double f0, double f1, double f2,
                                      double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_HGO, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2, p0, p1, p2);
}
MATERIAL_KERNEL int hgo_lane_unclamped(const piola_material *m, double f0, double f1, double f2) {
  const double c = material_threshold_at(m, f0, f1, f2), j = f0 * f1 * f2;
  return (f0 >= c) & (f1 >= c) & (f2 >= c) & (j >= 1e-300) & (j <= 1e300);
}
MATERIAL_KERNEL void spline_stress_lanes(const piola_material *m, double f0, double f1, double f2,
                                      double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_SPLINE, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2, p0, p1, p2);
}
MATERIAL_KERNEL void ogden_stress_lanes(const piola_material *m, double f0, double f1, double f2,
                                        double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_OGDEN, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2, p0, p1, p2);
}
/* Mooney-Rivlin for lanes whose entries all lie at or above the threshold in force
 * (mooney_rivlin_lane_unclamped; the force loop takes it for a block only when every lane
 * qualifies): there the extension adds exactly zero, so this is the plain formula
 * P_i = mu_1 f_i + mu_2 / f_i^3 - M / f_i + lambda ln J / f_i (the Ogden terms (mu_1, 2) and
 * (mu_2, -2), M = mu_1 + mu_2) with one logarithm of J instead of three. Differs from
 * mooney_rivlin_stress_lanes by a few ulp of lambda. */
MATERIAL_KERNEL void mooney_rivlin_stress_lanes_unclamped(const piola_material *m, double f0, double f1,
                                                          double f2, double *p0, double *p1, double *p2) {
  const double *o = m->model_constants;
  const double mu_1 = o[OGDEN_TERMS], mu_2 = o[OGDEN_TERMS + 2], msum = o[OGDEN_MU_SUM];
  const double i0 = kernel_recip_fast(f0), i1 = kernel_recip_fast(f1), i2 = kernel_recip_fast(f2);
  const double lq = m->lambda * kernel_log_div(f0 * f1 * f2, KERNEL_FAST_RECIPROCAL);
  *p0 = mu_1 * f0 + (mu_2 * i0 * i0 - msum + lq) * i0;
  *p1 = mu_1 * f1 + (mu_2 * i1 * i1 - msum + lq) * i1;
  *p2 = mu_1 * f2 + (mu_2 * i2 * i2 - msum + lq) * i2;
}
/* 1 when mooney_rivlin_stress_lanes_unclamped applies to this lane: every entry at or above
 * the threshold in force (which rises as J falls) and J in the range its logarithm takes. */
MATERIAL_KERNEL int mooney_rivlin_lane_unclamped(const piola_material *m, double f0, double f1,
                                                 double f2) {
  return hgo_lane_unclamped(m, f0, f1, f2); /* the same rising threshold and range of J */
}

/* Mooney-Rivlin with its own model constant: its two powers in closed form (f and 1/f^3,
 * material_model_parts), so its lane loop vectorizes where the Ogden one calls pow per entry
 * and term. The public functions take it as two Ogden terms: the same numbers within a few
 * ulp. */
MATERIAL_KERNEL void mooney_rivlin_stress_lanes(const piola_material *m, double f0, double f1,
                                                double f2, double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_MOONEY_RIVLIN, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2, p0, p1, p2);
}
/* The Ogden models' step-bound cache (LINEAR and CLAMP). Their powers f^(alpha_p - 1) are
 * most of an update, and the state-aware step bound (force/stable_step.c) needs the same
 * ones: the force loop keeps, per tet, the Fhat it evaluated and the model's Phat and
 * diagonal slopes at the clamped point, and the bound takes them from there instead of
 * calling pow again. Where the force loop forms k itself (a block with no entry clamped,
 * force/stable_step_modulus.h) it takes them from a block's slots on its stack and writes
 * the body's only for the other blocks. The couplings are lambda / (fc_i fc_j) (the ln J term; the separable
 * part has none): three reciprocals, formed again. Structure of arrays, slot s of a tet at
 * s * stride from its first. */
enum {
  OGDEN_CACHE_KEY = 0,   /* Fhat of the update that wrote the slots */
  OGDEN_CACHE_P = 3,     /* Pa: Phat at the clamped point */
  OGDEN_CACHE_K = 6,     /* Pa: dPhat_i/dFhat_i there */
  OGDEN_CACHE_SLOTS = 9
};

/* ogden_stress_lanes, and the tet's cache slots written (cache points at its first slot). */
MATERIAL_KERNEL void ogden_stress_cached_lanes(const piola_material *m, double f0, double f1,
                                               double f2, double *p0, double *p1, double *p2,
                                               double *cache, long stride) {
  const double c = material_threshold_at(m, f0, f1, f2);
  const double fc0 = kernel_max(f0, c), fc1 = kernel_max(f1, c), fc2 = kernel_max(f2, c);
  material_parts parts;
  material_model_parts(PIOLA_MODEL_OGDEN, m, KERNEL_FAST_RECIPROCAL, fc0, fc1, fc2, &parts);
  material_extend(m, KERNEL_FAST_RECIPROCAL, c, &parts, f0 - fc0, f1 - fc1, f2 - fc2, p0, p1, p2);
  cache[(OGDEN_CACHE_KEY + 0) * stride] = f0;
  cache[(OGDEN_CACHE_KEY + 1) * stride] = f1;
  cache[(OGDEN_CACHE_KEY + 2) * stride] = f2;
  cache[(OGDEN_CACHE_P + 0) * stride] = parts.p[0];
  cache[(OGDEN_CACHE_P + 1) * stride] = parts.p[1];
  cache[(OGDEN_CACHE_P + 2) * stride] = parts.p[2];
  cache[(OGDEN_CACHE_K + 0) * stride] = parts.k[0][0];
  cache[(OGDEN_CACHE_K + 1) * stride] = parts.k[1][1];
  cache[(OGDEN_CACHE_K + 2) * stride] = parts.k[2][2];
}

/* 1 when the cache holds the parts of Fhat f: written by the update that stored f (a state
 * moved in from another process, or never computed here, has another key; the zero key of a
 * never-written slot never matches). */
MATERIAL_KERNEL int ogden_cache_holds(const double *cache, long stride, double f0, double f1,
                                      double f2) {
  return (cache[OGDEN_CACHE_KEY * stride] == f0) & (cache[(OGDEN_CACHE_KEY + 1) * stride] == f1) &
         (cache[(OGDEN_CACHE_KEY + 2) * stride] == f2) & ((f0 != 0.0) | (f1 != 0.0) | (f2 != 0.0));
}

/* The parts at the clamped point fc from the cache: what material_model_parts(OGDEN) gives
 * there, without its powers. */
MATERIAL_KERNEL void ogden_cached_parts(const piola_material *m, const double *cache, long stride,
                                        double fc0, double fc1, double fc2, material_parts *out) {
  const double i0 = kernel_recip_fast(fc0), i1 = kernel_recip_fast(fc1), i2 = kernel_recip_fast(fc2);
  out->p[0] = cache[OGDEN_CACHE_P * stride];
  out->p[1] = cache[(OGDEN_CACHE_P + 1) * stride];
  out->p[2] = cache[(OGDEN_CACHE_P + 2) * stride];
  out->k[0][0] = cache[OGDEN_CACHE_K * stride];
  out->k[1][1] = cache[(OGDEN_CACHE_K + 1) * stride];
  out->k[2][2] = cache[(OGDEN_CACHE_K + 2) * stride];
  out->k[0][1] = out->k[1][0] = m->lambda * i0 * i1;
  out->k[0][2] = out->k[2][0] = m->lambda * i0 * i2;
  out->k[1][2] = out->k[2][1] = m->lambda * i1 * i2;
}

MATERIAL_KERNEL void stable_neohookean_stress_lanes(const piola_material *m, double f0, double f1,
                                                    double f2, double *p0, double *p1, double *p2) {
  material_extended_stress(PIOLA_MODEL_STABLE_NEOHOOKEAN, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2, p0,
                           p1, p2);
}

/* Stable Neo-Hookean for lanes whose entries all lie at or above the threshold (the caller
 * checks a whole block with any_lane_clamped): the plain formula
 * p_i = mu' (1 - 1/(I_C + 1)) f_i + lambda' (J - alpha) J / f_i, no logarithm and one
 * reciprocal. Within a few ulp of stable_neohookean_stress_lanes. */
MATERIAL_KERNEL void stable_neohookean_stress_lanes_unclamped(const piola_material *m, double f0,
                                                              double f1, double f2, double *p0,
                                                              double *p1, double *p2) {
  const double mu_s = m->model_constants[SNH_MU], lambda_s = m->model_constants[SNH_LAMBDA];
  const double ic = f0 * f0 + f1 * f1 + f2 * f2;
  const double a = mu_s * ic * kernel_recip_fast(ic + 1.0);
  const double v = lambda_s * (f0 * f1 * f2 - m->model_constants[SNH_ALPHA]);
  *p0 = a * f0 + v * (f1 * f2);
  *p1 = a * f1 + v * (f0 * f2);
  *p2 = a * f2 + v * (f0 * f1);
}

/* 1 when this lane has no entry below the threshold (false for NaN). */
MATERIAL_KERNEL int lane_unclamped(const piola_material *m, double f0, double f1, double f2) {
  const double c = m->threshold;
  return (f0 >= c) & (f1 >= c) & (f2 >= c);
}

/* PIOLA_INVERSION_ENERGY kernels, one per model: NAME_stress_energy_mode (exact division, for
 * the public functions) and NAME_stress_energy_mode_lanes (the force loop's). */
#define MATERIAL_ENERGY_MODE_KERNELS(name, model)                                               \
  MATERIAL_KERNEL void name##_stress_energy_mode(const piola_material *m, double f0, double f1, \
                                                 double f2, double *p0, double *p1,             \
                                                 double *p2) {                                  \
    material_energy_extended_stress(model, m, KERNEL_EXACT_DIVIDE, f0, f1, f2, p0, p1, p2);     \
  }                                                                                             \
  MATERIAL_KERNEL void name##_stress_energy_mode_lanes(const piola_material *m, double f0,      \
                                                       double f1, double f2, double *p0,        \
                                                       double *p1, double *p2) {                \
    material_energy_extended_stress(model, m, KERNEL_FAST_RECIPROCAL, f0, f1, f2, p0, p1, p2);  \
  }
MATERIAL_ENERGY_MODE_KERNELS(rotated_linear, PIOLA_MODEL_ROTATED_LINEAR)
MATERIAL_ENERGY_MODE_KERNELS(corotated, PIOLA_MODEL_COROTATED)
MATERIAL_ENERGY_MODE_KERNELS(stvk, PIOLA_MODEL_STVK)
MATERIAL_ENERGY_MODE_KERNELS(neohookean, PIOLA_MODEL_NEOHOOKEAN)
MATERIAL_ENERGY_MODE_KERNELS(spline, PIOLA_MODEL_SPLINE)
MATERIAL_ENERGY_MODE_KERNELS(stable_neohookean, PIOLA_MODEL_STABLE_NEOHOOKEAN)
MATERIAL_ENERGY_MODE_KERNELS(ogden, PIOLA_MODEL_OGDEN)
#undef MATERIAL_ENERGY_MODE_KERNELS

/* Run-time dispatch, for scalar callers. In a loop, switch on m->model outside the loop and
 * call the per-model kernel inside. */
MATERIAL_KERNEL void material_stress_kernel(const piola_material *m, double f0, double f1,
                                            double f2, double *p0, double *p1, double *p2) {
  if (m->inversion_mode == PIOLA_INVERSION_ENERGY) {
    switch (m->model) {
      case PIOLA_MODEL_COROTATED:
        corotated_stress_energy_mode(m, f0, f1, f2, p0, p1, p2);
        return;
      case PIOLA_MODEL_STVK:
        stvk_stress_energy_mode(m, f0, f1, f2, p0, p1, p2);
        return;
      case PIOLA_MODEL_NEOHOOKEAN:
      case PIOLA_MODEL_HGO: /* its matrix is neo-Hookean too */
      case PIOLA_MODEL_MUSCLE:
        neohookean_stress_energy_mode(m, f0, f1, f2, p0, p1, p2);
        return;
      case PIOLA_MODEL_SPLINE:
        spline_stress_energy_mode(m, f0, f1, f2, p0, p1, p2);
        return;
      case PIOLA_MODEL_STABLE_NEOHOOKEAN:
        stable_neohookean_stress_energy_mode(m, f0, f1, f2, p0, p1, p2);
        return;
      case PIOLA_MODEL_MOONEY_RIVLIN:
      case PIOLA_MODEL_OGDEN:
        ogden_stress_energy_mode(m, f0, f1, f2, p0, p1, p2);
        return;
      case PIOLA_MODEL_ROTATED_LINEAR:
      default:
        rotated_linear_stress_energy_mode(m, f0, f1, f2, p0, p1, p2);
        return;
    }
  }
  switch (m->model) {
    case PIOLA_MODEL_COROTATED:
      corotated_stress(m, f0, f1, f2, p0, p1, p2);
      return;
    case PIOLA_MODEL_STVK:
      stvk_stress(m, f0, f1, f2, p0, p1, p2);
      return;
    case PIOLA_MODEL_NEOHOOKEAN:
    case PIOLA_MODEL_MUSCLE:
      neohookean_stress(m, f0, f1, f2, p0, p1, p2);
      return;
    case PIOLA_MODEL_HGO: /* its matrix is neo-Hookean, with its threshold's rise */
      hgo_stress(m, f0, f1, f2, p0, p1, p2);
      return;
    case PIOLA_MODEL_SPLINE:
      spline_stress(m, f0, f1, f2, p0, p1, p2);
      return;
    case PIOLA_MODEL_STABLE_NEOHOOKEAN:
      stable_neohookean_stress(m, f0, f1, f2, p0, p1, p2);
      return;
    case PIOLA_MODEL_MOONEY_RIVLIN:
    case PIOLA_MODEL_OGDEN:
      ogden_stress(m, f0, f1, f2, p0, p1, p2);
      return;
    case PIOLA_MODEL_ROTATED_LINEAR:
    default:
      rotated_linear_stress(m, f0, f1, f2, p0, p1, p2);
      return;
  }
}

MATERIAL_KERNEL void rotated_linear_stress_energy(const piola_material *m, double f0, double f1,
                                                  double f2, double *p0, double *p1, double *p2,
                                                  double *psi) {
  material_extended_stress_energy(PIOLA_MODEL_ROTATED_LINEAR, m, f0, f1, f2, p0, p1, p2, psi);
}
MATERIAL_KERNEL void corotated_stress_energy(const piola_material *m, double f0, double f1,
                                             double f2, double *p0, double *p1, double *p2,
                                             double *psi) {
  material_extended_stress_energy(PIOLA_MODEL_COROTATED, m, f0, f1, f2, p0, p1, p2, psi);
}
MATERIAL_KERNEL void stvk_stress_energy(const piola_material *m, double f0, double f1, double f2,
                                        double *p0, double *p1, double *p2, double *psi) {
  material_extended_stress_energy(PIOLA_MODEL_STVK, m, f0, f1, f2, p0, p1, p2, psi);
}
MATERIAL_KERNEL void neohookean_stress_energy(const piola_material *m, double f0, double f1,
                                              double f2, double *p0, double *p1, double *p2,
                                              double *psi) {
  material_extended_stress_energy(PIOLA_MODEL_NEOHOOKEAN, m, f0, f1, f2, p0, p1, p2, psi);
}
MATERIAL_KERNEL void hgo_stress_energy(const piola_material *m, double f0, double f1, double f2,
                                       double *p0, double *p1, double *p2, double *psi) {
  material_extended_stress_energy(PIOLA_MODEL_HGO, m, f0, f1, f2, p0, p1, p2, psi);
}
MATERIAL_KERNEL void spline_stress_energy(const piola_material *m, double f0, double f1, double f2,
                                          double *p0, double *p1, double *p2, double *psi) {
  material_extended_stress_energy(PIOLA_MODEL_SPLINE, m, f0, f1, f2, p0, p1, p2, psi);
}
MATERIAL_KERNEL void ogden_stress_energy(const piola_material *m, double f0, double f1, double f2,
                                         double *p0, double *p1, double *p2, double *psi) {
  material_extended_stress_energy(PIOLA_MODEL_OGDEN, m, f0, f1, f2, p0, p1, p2, psi);
}
MATERIAL_KERNEL void stable_neohookean_stress_energy(const piola_material *m, double f0,
                                                     double f1, double f2, double *p0, double *p1,
                                                     double *p2, double *psi) {
  material_extended_stress_energy(PIOLA_MODEL_STABLE_NEOHOOKEAN, m, f0, f1, f2, p0, p1, p2, psi);
}

/* Run-time dispatch of the stress-and-energy kernels (same use as material_stress_kernel). */
MATERIAL_KERNEL void material_stress_energy_kernel(const piola_material *m, double f0, double f1,
                                                   double f2, double *p0, double *p1, double *p2,
                                                   double *psi) {
  if (m->inversion_mode == PIOLA_INVERSION_ENERGY) {
    /* Off the hot path: the model is a run-time value here. */
    const piola_material_model model =
        MATERIAL_IS_NEOHOOKEAN_MATRIX(m->model) ? PIOLA_MODEL_NEOHOOKEAN : m->model;
    switch (model) {
      case PIOLA_MODEL_COROTATED:
        material_energy_extended_stress_energy(PIOLA_MODEL_COROTATED, m, f0, f1, f2, p0, p1, p2, psi);
        return;
      case PIOLA_MODEL_STVK:
        material_energy_extended_stress_energy(PIOLA_MODEL_STVK, m, f0, f1, f2, p0, p1, p2, psi);
        return;
      case PIOLA_MODEL_NEOHOOKEAN:
        material_energy_extended_stress_energy(PIOLA_MODEL_NEOHOOKEAN, m, f0, f1, f2, p0, p1, p2, psi);
        return;
      case PIOLA_MODEL_SPLINE:
        material_energy_extended_stress_energy(PIOLA_MODEL_SPLINE, m, f0, f1, f2, p0, p1, p2, psi);
        return;
      case PIOLA_MODEL_STABLE_NEOHOOKEAN:
        material_energy_extended_stress_energy(PIOLA_MODEL_STABLE_NEOHOOKEAN, m, f0, f1, f2, p0, p1,
                                               p2, psi);
        return;
      case PIOLA_MODEL_MOONEY_RIVLIN:
      case PIOLA_MODEL_OGDEN:
        material_energy_extended_stress_energy(PIOLA_MODEL_OGDEN, m, f0, f1, f2, p0, p1, p2, psi);
        return;
      default:
        material_energy_extended_stress_energy(PIOLA_MODEL_ROTATED_LINEAR, m, f0, f1, f2, p0, p1, p2,
                                               psi);
        return;
    }
  }
  switch (m->model) {
    case PIOLA_MODEL_COROTATED:
      corotated_stress_energy(m, f0, f1, f2, p0, p1, p2, psi);
      return;
    case PIOLA_MODEL_STVK:
      stvk_stress_energy(m, f0, f1, f2, p0, p1, p2, psi);
      return;
    case PIOLA_MODEL_NEOHOOKEAN:
    case PIOLA_MODEL_MUSCLE:
      neohookean_stress_energy(m, f0, f1, f2, p0, p1, p2, psi);
      return;
    case PIOLA_MODEL_HGO: /* its matrix is neo-Hookean, with its threshold's rise */
      hgo_stress_energy(m, f0, f1, f2, p0, p1, p2, psi);
      return;
    case PIOLA_MODEL_SPLINE:
      spline_stress_energy(m, f0, f1, f2, p0, p1, p2, psi);
      return;
    case PIOLA_MODEL_STABLE_NEOHOOKEAN:
      stable_neohookean_stress_energy(m, f0, f1, f2, p0, p1, p2, psi);
      return;
    case PIOLA_MODEL_MOONEY_RIVLIN:
    case PIOLA_MODEL_OGDEN:
      ogden_stress_energy(m, f0, f1, f2, p0, p1, p2, psi);
      return;
    case PIOLA_MODEL_ROTATED_LINEAR:
    default:
      rotated_linear_stress_energy(m, f0, f1, f2, p0, p1, p2, psi);
      return;
  }
}

#endif
