/* The invertible diagonalization F = U Fhat V^T (paper section 5), for 3x3 and 3x2 F.
 *
 * Why one-sided Jacobi and not the eigenvectors of F^T F. The paper forms F^T F, takes its
 * eigenvectors as V and recovers U from F V. Squaring F halves the usable precision: with
 * singular values 1, 1e-8 and 0 the two small eigenvalues of F^T F are 1e-16 and 0, both at
 * rounding level, so the split of V between them is arbitrary, F V has non-orthogonal small
 * columns and dropping the coupling loses 1e-8 |F| of F. Instead we rotate the columns of F
 * itself (Hestenes' one-sided Jacobi): B = F V with V a product of plane rotations, repeated
 * until every pair of columns of B is orthogonal to working precision. Then the column norms
 * of B are the singular values and the columns point along U. Every step is an orthogonal
 * transformation of F, so B V^T = F to rounding at any conditioning, and nothing is squared
 * except inside dot products of a prescaled F.
 *
 * Scaling: F is first multiplied by a power of two (exact) so its largest entry lies in
 * [0.5, 1); dot products then neither overflow nor lose the large entries, and the result is
 * scaled back at the end. Columns whose norm is below 2^-150 of that are too small for the
 * squares in a rotation to be trusted; they are left uncoupled (their whole size is below
 * 1e-45 |F|, so leaving them is invisible at the promised 1e-12).
 *
 * Building U: u1 is b1 normalized (b1 is the longest column and, after scaling, never tiny),
 * u2 is the part of b2 orthogonal to u1, normalized (one Gram-Schmidt pass after Jacobi; a
 * second pass when b2 is tiny or nearly parallel to u1, so u2 stays orthogonal even when b2 is
 * mostly noise), or, when b2 has no usable direction, any unit vector orthogonal to u1 (the
 * completion of a collapsed element). For 3x3, u3 = u1 x u2,
 * which makes det U = +1 by construction; fhat3 = u3 . b3 then carries the sign of det F by
 * itself: det F = det B = |b1| |b2| (u1 x u2) . b3. That is the paper's "negate the smallest
 * entry and its column of U" without a separate reflection test.
 *
 * Rotations and the two fix-ups below keep det V = det U = +1 at every step: a swap of two
 * columns (for sorting) is always paired with negating one of them in both U and V, which
 * leaves u_k fhat_k v_k^T, and hence F, unchanged. */
#include "piola/diagonalize.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "common/status_report.h"
#include "math/mat3.h"

enum { MAX_SWEEPS = 20 };

/* Two columns count as orthogonal when |b_i . b_j| <= TOL |b_i| |b_j|, TOL = 4 DBL_EPSILON
 * (squared here). A few ulps: the dot product itself carries about that much rounding, so
 * asking for less would only spin. */
static const double ORTHOGONALITY_TOL2 = 16.0 * DBL_EPSILON * DBL_EPSILON;

/* Squared column norms below this (relative to a largest entry in [0.5, 1)) are not rotated,
 * so no square in the rotation underflows: 2^-300, i.e. column norms below 2^-150 = 7e-46. */
static const double NEGLIGIBLE_NORM2 = 0x1p-300;

/* A direction is taken from a vector only if its largest entry is at least this (2^-1020):
 * smaller vectors are subnormal-ish and 1 / max would overflow. */
static const double SMALLEST_DIRECTION = 0x1p-1020;

/* 2^k for -1022 <= k <= 1023, built from its bits (exact, and cheaper than ldexp). */
static inline double pow2(int k) {
  uint64_t bits = (uint64_t)(k + 1023) << 52;
  double d;
  memcpy(&d, &bits, sizeof d);
  return d;
}

/* Multiplying by a power of two 2^k, |k| <= 2044, as two exact factors: a single 2^k need not be
 * a normal double (an F made of subnormals needs 2^1073). */
typedef struct pow2_scale {
  double first, second;
} pow2_scale;

static inline pow2_scale pow2_scale_make(int k) {
  int half = k / 2;
  return (pow2_scale){pow2(half), pow2(k - half)};
}

static inline double pow2_scale_apply(pow2_scale s, double x) { return x * s.first * s.second; }

static inline double max_of(double a, double b) { return a > b ? a : b; }

/* An entry of Fhat scaled back to F's units. An entry that is nonzero but underflows (only
 * for F near the bottom of the double range) becomes the smallest subnormal of its sign, so
 * the sign of det F is never lost; + 0.0 turns -0 into +0. */
static inline double unscale_entry(pow2_scale up, double d) {
  double x = pow2_scale_apply(up, d) + 0.0;
  return (x == 0 && d != 0) ? copysign(DBL_TRUE_MIN, d) : x;
}

static inline double dot3(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Rotates the column pair (x, y) <- (c x - s y, s x + c y) over n entries. */
static inline void rotate_pair(double *x, double *y, int n, double c, double s) {
  for (int k = 0; k < n; ++k) {
    double xk = x[k], yk = y[k];
    x[k] = c * xk - s * yk;
    y[k] = s * xk + c * yk;
  }
}

/* One Jacobi step on columns i and j of B (3 rows) and of V (nv rows): the plane rotation that
 * makes b_i and b_j orthogonal. Returns 1 if it rotated, 0 if the pair was already orthogonal
 * (or negligible). */
static inline int orthogonalize_columns(double (*b)[3], double (*v)[3], int nv, int i, int j) {
  double alpha = dot3(b[i], b[i]), beta = dot3(b[j], b[j]), gamma = dot3(b[i], b[j]);
  if (alpha < NEGLIGIBLE_NORM2 || beta < NEGLIGIBLE_NORM2) return 0;
  if (gamma * gamma <= ORTHOGONALITY_TOL2 * alpha * beta) return 0;
  /* The rotation (c x - s y, s x + c y) with tan(2 theta) = q / p, p = beta - alpha,
   * q = 2 gamma, |theta| <= pi/4 (the small angle keeps the columns in place as they converge):
   * with r = sqrt(p^2 + q^2) and w = r + |p|, c = w / sqrt(2 r w) and s = sign(p) q / sqrt(2 r w).
   * One sqrt on the critical path fewer than the textbook tan(theta) form. No underflow: alpha,
   * beta >= 2^-300 and gamma^2 > TOL^2 alpha beta keep q^2 above 1e-215. */
  double p = beta - alpha, q = 2.0 * gamma;
  double r = sqrt(p * p + q * q), w = r + fabs(p);
  double k = 1.0 / sqrt(2.0 * r * w);
  double c = w * k, s = copysign(1.0, p) * q * k;
  rotate_pair(b[i], b[j], 3, c, s);
  rotate_pair(v[i], v[j], nv, c, s);
  return 1;
}

static inline void swap_columns(double *x, double *y, int n) {
  for (int k = 0; k < n; ++k) {
    double t = x[k];
    x[k] = y[k];
    y[k] = t;
  }
}

static inline void negate_column(double *x, int n) {
  for (int k = 0; k < n; ++k) x[k] = -x[k];
}

/* Unit vector orthogonal to the unit vector u: the axis least aligned with u, minus its part
 * along u. Used to complete U when F has no direction to offer. */
static inline void any_orthogonal_unit(const double *u, double *out) {
  int k = 0;
  if (fabs(u[1]) < fabs(u[k])) k = 1;
  if (fabs(u[2]) < fabs(u[k])) k = 2;
  double e[3] = {0, 0, 0};
  e[k] = 1.0;
  double d = u[k];
  for (int r = 0; r < 3; ++r) e[r] -= d * u[r];
  double inv = 1.0 / sqrt(dot3(e, e)); /* |e|^2 = 1 - u_k^2 >= 2/3 */
  for (int r = 0; r < 3; ++r) out[r] = e[r] * inv;
}

/* The unit vector along the part of b orthogonal to the unit vector u, or a completion when
 * that part is too small to have a direction. */
static inline void orthogonal_direction(const double *u, const double *b, double *out) {
  double w[3], d = dot3(u, b);
  for (int r = 0; r < 3; ++r) w[r] = b[r] - d * u[r];
  /* The common case: b is not tiny and mostly orthogonal to u already (as after Jacobi), so one
   * Gram-Schmidt pass is accurate to a few ulps and the squares cannot underflow. */
  double wn2 = dot3(w, w), bn2 = dot3(b, b);
  if (bn2 >= 0x1p-600 && wn2 >= 0.25 * bn2) {
    double inv = 1.0 / sqrt(wn2);
    for (int r = 0; r < 3; ++r) out[r] = w[r] * inv;
    return;
  }
  double m = max_of(fabs(w[0]), max_of(fabs(w[1]), fabs(w[2])));
  if (!(m >= SMALLEST_DIRECTION)) {
    any_orthogonal_unit(u, out);
    return;
  }
  /* Scale to a largest entry of 1, then orthogonalize once more: if b was nearly parallel to u
   * the first pass left mostly rounding, which the second pass removes. */
  double inv_m = 1.0 / m;
  for (int r = 0; r < 3; ++r) w[r] *= inv_m;
  d = dot3(u, w);
  for (int r = 0; r < 3; ++r) w[r] -= d * u[r];
  double n2 = dot3(w, w);
  if (!(n2 >= 0.25)) { /* w was rounding noise aligned with u: no trustworthy direction */
    any_orthogonal_unit(u, out);
    return;
  }
  double inv = 1.0 / sqrt(n2);
  for (int r = 0; r < 3; ++r) out[r] = w[r] * inv;
}

static void set_identity_outputs3(piola_mat3 *u, piola_vec3 *fhat, piola_mat3 *v) {
  *u = mat3_identity();
  *v = mat3_identity();
  *fhat = (piola_vec3){0, 0, 0};
}

static void set_identity_outputs3x2(piola_mat3x2 *u, double fhat[2], piola_mat2 *v) {
  *u = (piola_mat3x2){{{1, 0}, {0, 1}, {0, 0}}};
  *v = mat2_identity();
  fhat[0] = fhat[1] = 0;
}

/* Exponent e with max_abs = f 2^e, f in [0.5, 1), for finite max_abs > 0: read from the bits
 * (what frexp does, without the call). Subnormals are first lifted by 2^64. */
static inline int scale_exponent(double max_abs) {
  int lift = 0;
  if (max_abs < DBL_MIN) {
    max_abs *= 0x1p64;
    lift = 64;
  }
  uint64_t bits;
  memcpy(&bits, &max_abs, sizeof bits);
  return (int)((bits >> 52) & 0x7ff) - 1022 - lift;
}

/* ------------------------------------------------------------------------------------ 3x3 */

piola_status piola_diagonalize3(const piola_mat3 *f, piola_mat3 *u, piola_vec3 *fhat,
                                piola_mat3 *v) {
  double max_abs = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double x = f->m[i][j];
      if (!isfinite(x)) {
        set_identity_outputs3(u, fhat, v);
        return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                          "diagonalize3: deformation gradient entry F[%d][%d] = %g is not finite",
                          i, j, x);
      }
      max_abs = max_of(max_abs, fabs(x));
    }
  if (max_abs == 0) { /* the element is a point: the paper's U = I */
    set_identity_outputs3(u, fhat, v);
    return PIOLA_OK;
  }
  int e = scale_exponent(max_abs);
  pow2_scale down = pow2_scale_make(-e);

  /* b[j] is column j of the scaled F (then of B = F V), vc[j] column j of V. */
  double b[3][3], vc[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) b[j][i] = pow2_scale_apply(down, f->m[i][j]);

  for (int sweep = 0; sweep < MAX_SWEEPS; ++sweep) {
    int rotated = orthogonalize_columns(b, vc, 3, 0, 1);
    rotated += orthogonalize_columns(b, vc, 3, 0, 2);
    rotated += orthogonalize_columns(b, vc, 3, 1, 2);
    if (!rotated) break;
  }

  /* Longest column first. Each swap negates one of the two columns so det V stays +1. */
  double n2[3] = {dot3(b[0], b[0]), dot3(b[1], b[1]), dot3(b[2], b[2])};
  static const int pairs[3][2] = {{0, 1}, {1, 2}, {0, 1}};
  for (int p = 0; p < 3; ++p) {
    int i = pairs[p][0], j = pairs[p][1];
    if (n2[j] > n2[i]) {
      double t = n2[i];
      n2[i] = n2[j];
      n2[j] = t;
      swap_columns(b[i], b[j], 3);
      swap_columns(vc[i], vc[j], 3);
      negate_column(b[j], 3);
      negate_column(vc[j], 3);
    }
  }

  double uc[3][3], d[3];
  double inv1 = 1.0 / sqrt(n2[0]); /* n2[0] >= (0.5)^2 / 3: the largest entry survives */
  for (int r = 0; r < 3; ++r) uc[0][r] = b[0][r] * inv1;
  d[0] = dot3(uc[0], b[0]);
  orthogonal_direction(uc[0], b[1], uc[1]);
  d[1] = dot3(uc[1], b[1]);
  if (d[1] < 0) { /* only for a completed u2; u3 follows it below */
    negate_column(uc[1], 3);
    d[1] = -d[1];
  }
  uc[2][0] = uc[0][1] * uc[1][2] - uc[0][2] * uc[1][1];
  uc[2][1] = uc[0][2] * uc[1][0] - uc[0][0] * uc[1][2];
  uc[2][2] = uc[0][0] * uc[1][1] - uc[0][1] * uc[1][0];
  d[2] = dot3(uc[2], b[2]); /* signed: its sign is the sign of det F */

  /* Columns left uncoupled (negligible) or equal up to rounding can leave |d| slightly out of
   * order: sort again, by magnitude, with the same det-preserving swaps. */
  for (int p = 0; p < 3; ++p) {
    int i = pairs[p][0], j = pairs[p][1];
    if (fabs(d[j]) > fabs(d[i])) {
      double t = d[i];
      d[i] = d[j];
      d[j] = t;
      swap_columns(uc[i], uc[j], 3);
      swap_columns(vc[i], vc[j], 3);
      negate_column(uc[j], 3);
      negate_column(vc[j], 3);
    }
  }
  /* Only the smallest entry may be negative: move any other minus sign onto it by negating two
   * entries together with their columns of U (det U unchanged, u_k d_k unchanged). */
  for (int i = 0; i < 2; ++i)
    if (d[i] < 0) {
      d[i] = -d[i];
      d[2] = -d[2];
      negate_column(uc[i], 3);
      negate_column(uc[2], 3);
    }

  pow2_scale up = pow2_scale_make(e);
  double out[3];
  for (int k = 0; k < 3; ++k) out[k] = unscale_entry(up, d[k]);
  if (!isfinite(out[0])) {
    set_identity_outputs3(u, fhat, v);
    return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                      "diagonalize3: the largest singular value of F (%g * 2^%d) exceeds the "
                      "double range",
                      d[0], e);
  }
  *fhat = (piola_vec3){out[0], out[1], out[2]};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      u->m[i][j] = uc[j][i];
      v->m[i][j] = vc[j][i];
    }
  return PIOLA_OK;
}

/* ------------------------------------------------------------------------------------ 3x2 */

piola_status piola_diagonalize3x2(const piola_mat3x2 *f, piola_mat3x2 *u, double fhat[2],
                                  piola_mat2 *v) {
  double max_abs = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) {
      double x = f->m[i][j];
      if (!isfinite(x)) {
        set_identity_outputs3x2(u, fhat, v);
        return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                          "diagonalize3x2: deformation gradient entry F[%d][%d] = %g is not "
                          "finite",
                          i, j, x);
      }
      max_abs = max_of(max_abs, fabs(x));
    }
  if (max_abs == 0) { /* a triangle collapsed to a point */
    set_identity_outputs3x2(u, fhat, v);
    return PIOLA_OK;
  }
  int e = scale_exponent(max_abs);
  pow2_scale down = pow2_scale_make(-e);

  /* V is 2x2; its columns are stored in the first two entries of vc[j]. */
  double b[2][3], vc[2][3] = {{1, 0, 0}, {0, 1, 0}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) b[j][i] = pow2_scale_apply(down, f->m[i][j]);

  for (int sweep = 0; sweep < MAX_SWEEPS; ++sweep)
    if (!orthogonalize_columns(b, vc, 2, 0, 1)) break;

  double n2[2] = {dot3(b[0], b[0]), dot3(b[1], b[1])};
  if (n2[1] > n2[0]) {
    double t = n2[0];
    n2[0] = n2[1];
    n2[1] = t;
    swap_columns(b[0], b[1], 3);
    swap_columns(vc[0], vc[1], 2);
    negate_column(b[1], 3);
    negate_column(vc[1], 2);
  }

  double uc[2][3], d[2];
  double inv1 = 1.0 / sqrt(n2[0]);
  for (int r = 0; r < 3; ++r) uc[0][r] = b[0][r] * inv1;
  d[0] = dot3(uc[0], b[0]);
  orthogonal_direction(uc[0], b[1], uc[1]);
  d[1] = dot3(uc[1], b[1]);
  if (d[1] < 0) { /* U is 3x2: no determinant to keep, so u2 simply takes the sign */
    negate_column(uc[1], 3);
    d[1] = -d[1];
  }
  if (d[1] > d[0]) {
    double t = d[0];
    d[0] = d[1];
    d[1] = t;
    swap_columns(uc[0], uc[1], 3);
    swap_columns(vc[0], vc[1], 2);
    /* Negating both u2 and v2 keeps d[1] >= 0 and det V = +1. */
    negate_column(uc[1], 3);
    negate_column(vc[1], 2);
  }

  pow2_scale up = pow2_scale_make(e);
  double out0 = unscale_entry(up, d[0]), out1 = unscale_entry(up, d[1]);
  if (!isfinite(out0)) {
    set_identity_outputs3x2(u, fhat, v);
    return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                      "diagonalize3x2: the largest singular value of F (%g * 2^%d) exceeds the "
                      "double range",
                      d[0], e);
  }
  fhat[0] = out0;
  fhat[1] = out1;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) u->m[i][j] = uc[j][i];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) v->m[i][j] = vc[j][i];
  return PIOLA_OK;
}
