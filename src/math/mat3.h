/* Inline 3x3, 3x2 and 2x2 matrix and 3-vector arithmetic in double precision.
 *
 * Values are passed and returned by value: the structs are small, and with everything
 * inline the compiler keeps them in registers. Row-major: m[row][col]. Names read as
 * math: mat3_mul(a, b) = a b, mat3_mul_transpose_b(a, b) = a b^T. */
#ifndef PIOLA_MATH_MAT3_H
#define PIOLA_MATH_MAT3_H

#include <math.h>
#include <string.h>

#include "piola/math_types.h"

typedef piola_vec3 vec3;
typedef piola_mat3 mat3;
typedef piola_mat3x2 mat3x2;
typedef piola_mat2 mat2;

/* ------------------------------------------------------------------ vec3 */
static inline vec3 vec3_make(double x, double y, double z) { return (vec3){x, y, z}; }
static inline vec3 vec3_add(vec3 a, vec3 b) { return (vec3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static inline vec3 vec3_sub(vec3 a, vec3 b) { return (vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline vec3 vec3_scale(vec3 a, double s) { return (vec3){a.x * s, a.y * s, a.z * s}; }
static inline vec3 vec3_neg(vec3 a) { return (vec3){-a.x, -a.y, -a.z}; }
static inline double vec3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 vec3_cross(vec3 a, vec3 b) {
  return (vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static inline double vec3_norm2(vec3 a) { return vec3_dot(a, a); }
static inline double vec3_norm(vec3 a) { return sqrt(vec3_dot(a, a)); }
static inline vec3 vec3_load(const double *p) { return (vec3){p[0], p[1], p[2]}; }
static inline void vec3_store(double *p, vec3 a) { p[0] = a.x; p[1] = a.y; p[2] = a.z; }
static inline double vec3_get(vec3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }

/* ------------------------------------------------------------------ mat3 */
static inline mat3 mat3_zero(void) { return (mat3){{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}}; }
static inline mat3 mat3_identity(void) { return (mat3){{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}; }
static inline mat3 mat3_diag(double a, double b, double c) {
  return (mat3){{{a, 0, 0}, {0, b, 0}, {0, 0, c}}};
}
/* The matrix whose columns are a, b, c. */
static inline mat3 mat3_from_columns(vec3 a, vec3 b, vec3 c) {
  return (mat3){{{a.x, b.x, c.x}, {a.y, b.y, c.y}, {a.z, b.z, c.z}}};
}
static inline vec3 mat3_column(mat3 a, int j) { return (vec3){a.m[0][j], a.m[1][j], a.m[2][j]}; }
static inline void mat3_set_column(mat3 *a, int j, vec3 c) {
  a->m[0][j] = c.x; a->m[1][j] = c.y; a->m[2][j] = c.z;
}

static inline mat3 mat3_add(mat3 a, mat3 b) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][j] + b.m[i][j];
  return r;
}
static inline mat3 mat3_sub(mat3 a, mat3 b) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][j] - b.m[i][j];
  return r;
}
static inline mat3 mat3_scale(mat3 a, double s) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][j] * s;
  return r;
}
static inline mat3 mat3_transpose(mat3 a) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[j][i];
  return r;
}
/* a b */
static inline mat3 mat3_mul(mat3 a, mat3 b) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
  return r;
}
/* a b^T */
static inline mat3 mat3_mul_transpose_b(mat3 a, mat3 b) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = a.m[i][0] * b.m[j][0] + a.m[i][1] * b.m[j][1] + a.m[i][2] * b.m[j][2];
  return r;
}
/* a^T b */
static inline mat3 mat3_mul_transpose_a(mat3 a, mat3 b) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = a.m[0][i] * b.m[0][j] + a.m[1][i] * b.m[1][j] + a.m[2][i] * b.m[2][j];
  return r;
}
/* a diag(d) b^T: how U Fhat V^T and U Phat V^T are formed. */
static inline mat3 mat3_mul_diag_transpose(mat3 a, vec3 d, mat3 b) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = a.m[i][0] * d.x * b.m[j][0] + a.m[i][1] * d.y * b.m[j][1] +
                  a.m[i][2] * d.z * b.m[j][2];
  return r;
}
static inline vec3 mat3_mul_vec(mat3 a, vec3 v) {
  return (vec3){a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z,
                a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
                a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
}
/* a^T v */
static inline vec3 mat3_transpose_mul_vec(mat3 a, vec3 v) {
  return (vec3){a.m[0][0] * v.x + a.m[1][0] * v.y + a.m[2][0] * v.z,
                a.m[0][1] * v.x + a.m[1][1] * v.y + a.m[2][1] * v.z,
                a.m[0][2] * v.x + a.m[1][2] * v.y + a.m[2][2] * v.z};
}
static inline double mat3_det(mat3 a) {
  return a.m[0][0] * (a.m[1][1] * a.m[2][2] - a.m[1][2] * a.m[2][1]) -
         a.m[0][1] * (a.m[1][0] * a.m[2][2] - a.m[1][2] * a.m[2][0]) +
         a.m[0][2] * (a.m[1][0] * a.m[2][1] - a.m[1][1] * a.m[2][0]);
}
static inline double mat3_trace(mat3 a) { return a.m[0][0] + a.m[1][1] + a.m[2][2]; }
/* Cofactor matrix: cof(A) = det(A) A^-T, defined also for singular A. */
static inline mat3 mat3_cofactor(mat3 a) {
  mat3 c;
  c.m[0][0] = a.m[1][1] * a.m[2][2] - a.m[1][2] * a.m[2][1];
  c.m[0][1] = a.m[1][2] * a.m[2][0] - a.m[1][0] * a.m[2][2];
  c.m[0][2] = a.m[1][0] * a.m[2][1] - a.m[1][1] * a.m[2][0];
  c.m[1][0] = a.m[0][2] * a.m[2][1] - a.m[0][1] * a.m[2][2];
  c.m[1][1] = a.m[0][0] * a.m[2][2] - a.m[0][2] * a.m[2][0];
  c.m[1][2] = a.m[0][1] * a.m[2][0] - a.m[0][0] * a.m[2][1];
  c.m[2][0] = a.m[0][1] * a.m[1][2] - a.m[0][2] * a.m[1][1];
  c.m[2][1] = a.m[0][2] * a.m[1][0] - a.m[0][0] * a.m[1][2];
  c.m[2][2] = a.m[0][0] * a.m[1][1] - a.m[0][1] * a.m[1][0];
  return c;
}
/* Inverse; the caller guarantees det(a) is safely away from zero. */
static inline mat3 mat3_inverse(mat3 a) {
  return mat3_scale(mat3_transpose(mat3_cofactor(a)), 1.0 / mat3_det(a));
}
/* Frobenius norm and inner product. */
static inline double mat3_ddot(mat3 a, mat3 b) {
  double s = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s += a.m[i][j] * b.m[i][j];
  return s;
}
static inline double mat3_norm(mat3 a) { return sqrt(mat3_ddot(a, a)); }
static inline double mat3_max_abs(mat3 a) {
  double s = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s = fmax(s, fabs(a.m[i][j]));
  return s;
}
static inline int mat3_is_finite(mat3 a) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!isfinite(a.m[i][j])) return 0;
  return 1;
}
/* Load from / store to 9 consecutive row-major doubles. */
static inline mat3 mat3_load(const double *p) {
  return (mat3){{{p[0], p[1], p[2]}, {p[3], p[4], p[5]}, {p[6], p[7], p[8]}}};
}
static inline void mat3_store(double *p, mat3 a) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) p[3 * i + j] = a.m[i][j];
}

/* ------------------------------------------------------------------ mat3x2 and mat2 */
static inline vec3 mat3x2_column(mat3x2 a, int j) { return (vec3){a.m[0][j], a.m[1][j], a.m[2][j]}; }
static inline mat3x2 mat3x2_from_columns(vec3 a, vec3 b) {
  return (mat3x2){{{a.x, b.x}, {a.y, b.y}, {a.z, b.z}}};
}
static inline double mat3x2_norm(mat3x2 a) {
  double s = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) s += a.m[i][j] * a.m[i][j];
  return sqrt(s);
}
/* a b for a 3x2 and b 2x2 */
static inline mat3x2 mat3x2_mul_mat2(mat3x2 a, mat2 b) {
  mat3x2 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j];
  return r;
}
/* a diag(d) b^T for a 3x2, d 2-vector, b 2x2 */
static inline mat3x2 mat3x2_mul_diag_transpose(mat3x2 a, const double d[2], mat2 b) {
  mat3x2 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) r.m[i][j] = a.m[i][0] * d[0] * b.m[j][0] + a.m[i][1] * d[1] * b.m[j][1];
  return r;
}
static inline mat2 mat2_identity(void) { return (mat2){{{1, 0}, {0, 1}}}; }
static inline double mat2_det(mat2 a) { return a.m[0][0] * a.m[1][1] - a.m[0][1] * a.m[1][0]; }
static inline mat2 mat2_transpose(mat2 a) { return (mat2){{{a.m[0][0], a.m[1][0]}, {a.m[0][1], a.m[1][1]}}}; }
static inline mat2 mat2_mul(mat2 a, mat2 b) {
  mat2 r;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j];
  return r;
}
static inline mat2 mat2_inverse(mat2 a) {
  double inv = 1.0 / mat2_det(a);
  return (mat2){{{a.m[1][1] * inv, -a.m[0][1] * inv}, {-a.m[1][0] * inv, a.m[0][0] * inv}}};
}

/* ------------------------------------------------------- row-major arrays */
/* inv = a^-1 for a 3x3 block a[9] (row-major) of a system matrix; a singular or non-finite
 * block (a massless node in quasistatics) gets the inverse of its diagonal only, 0 where that
 * is not positive, so a preconditioner built from it stays finite. */
static inline void piola__invert3_or_diagonal(const double *a, double *inv) {
  double c00 = a[4] * a[8] - a[5] * a[7], c01 = a[5] * a[6] - a[3] * a[8], c02 = a[3] * a[7] - a[4] * a[6];
  double det = a[0] * c00 + a[1] * c01 + a[2] * c02;
  if (!(fabs(det) > 0) || !isfinite(det)) {
    /* a singular block (a massless node in quasistatics): its diagonal only */
    memset(inv, 0, 9 * sizeof(double));
    for (int i = 0; i < 3; ++i) inv[4 * i] = a[4 * i] > 0 ? 1.0 / a[4 * i] : 0.0;
    return;
  }
  double r = 1.0 / det;
  inv[0] = c00 * r;
  inv[3] = c01 * r;
  inv[6] = c02 * r;
  inv[1] = (a[2] * a[7] - a[1] * a[8]) * r;
  inv[4] = (a[0] * a[8] - a[2] * a[6]) * r;
  inv[7] = (a[1] * a[6] - a[0] * a[7]) * r;
  inv[2] = (a[1] * a[5] - a[2] * a[4]) * r;
  inv[5] = (a[2] * a[3] - a[0] * a[5]) * r;
  inv[8] = (a[0] * a[4] - a[1] * a[3]) * r;
}

#endif
