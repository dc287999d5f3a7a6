/* A fast closed-form diagonalization of a triangle's 3x2 deformation gradient, with the
 * robust public piola_diagonalize3x2 as the fallback for nearly collapsed triangles.
 *
 * Why: the shell force loop diagonalizes every triangle every step; the public function is
 * written for any scale and any rank (Jacobi sweeps, power-of-two scaling, completion of
 * frames) and costs several hundred nanoseconds. For a triangle that is not nearly
 * collapsed, the 2x2 symmetric eigenproblem of C = F^T F has a closed form:
 *   V = [[c, -s], [s, c]] with (c, s) the half angle of tan(2 phi) = 2 c01 / (c00 - c11)
 *   (taken so that v0 is the major axis), u0 = F v0 / |F v0|, fhat0 = |F v0|, and, with
 *   n = f0 x f1 (the columns' cross product, = (F v0) x (F v1) since det V = 1),
 *   fhat1 = |n| / fhat0 and u1 = n / |n| x u0.
 * Taking fhat1 from the area |n| rather than from sqrt(lambda1) keeps it accurate when the
 * triangle is thin; building u1 from the normal keeps U orthonormal to rounding. When
 * |n| <= PIOLA_SVD3X2_FAST_RATIO * |F|^2 (a triangle collapsing to a line or a point) the
 * fallback decides the completed frame. The test compares both paths. */
#ifndef PIOLA_SHELL_SVD3X2_H
#define PIOLA_SHELL_SVD3X2_H

#include <math.h>

#include "piola/diagonalize.h"

#define PIOLA_SVD3X2_FAST_RATIO 1e-6

/* F = U diag(fhat) V^T, U 3x2 row-major (u[2 i + j]), V 2x2 row-major, fhat0 >= fhat1 >= 0.
 * Returns nonzero if F was not finite (then U, V = identity, fhat = 0). */
static inline int piola__svd3x2(double f[3][2], double u[6], double fhat[2],
                                double v[4]) {
  const double a0 = f[0][0], a1 = f[1][0], a2 = f[2][0];
  const double b0 = f[0][1], b1 = f[1][1], b2 = f[2][1];
  const double c00 = a0 * a0 + a1 * a1 + a2 * a2, c11 = b0 * b0 + b1 * b1 + b2 * b2;
  const double c01 = a0 * b0 + a1 * b1 + a2 * b2;
  const double n0 = a1 * b2 - a2 * b1, n1 = a2 * b0 - a0 * b2, n2 = a0 * b1 - a1 * b0;
  const double nn = n0 * n0 + n1 * n1 + n2 * n2, trace = c00 + c11;
  if (nn > PIOLA_SVD3X2_FAST_RATIO * PIOLA_SVD3X2_FAST_RATIO * trace * trace &&
      trace < 1e300) {
    const double d = c00 - c11, e = 2.0 * c01, r = sqrt(d * d + e * e);
    double c = 1.0, s = 0.0;
    if (r > 0) {
      if (d >= 0) {
        c = sqrt(0.5 * (1.0 + d / r));
        s = e / (2.0 * r * c);
      } else {
        s = sqrt(0.5 * (1.0 - d / r));
        s = e < 0 ? -s : s;
        c = e / (2.0 * r * s);
      }
    }
    /* b = F v0 */
    const double x0 = a0 * c + b0 * s, x1 = a1 * c + b1 * s, x2 = a2 * c + b2 * s;
    const double sigma0 = sqrt(x0 * x0 + x1 * x1 + x2 * x2);
    const double inv0 = 1.0 / sigma0, norm_n = sqrt(nn), inv_n = 1.0 / norm_n;
    const double u00 = x0 * inv0, u10 = x1 * inv0, u20 = x2 * inv0;
    const double m0 = n0 * inv_n, m1 = n1 * inv_n, m2 = n2 * inv_n;
    u[0] = u00, u[2] = u10, u[4] = u20;
    u[1] = m1 * u20 - m2 * u10;
    u[3] = m2 * u00 - m0 * u20;
    u[5] = m0 * u10 - m1 * u00;
    fhat[0] = sigma0;
    fhat[1] = norm_n * inv0;
    v[0] = c, v[1] = -s, v[2] = s, v[3] = c;
    return 0;
  }
  piola_mat3x2 fm, um;
  piola_mat2 vm;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) fm.m[i][j] = f[i][j];
  int failed = piola_diagonalize3x2(&fm, &um, fhat, &vm) != PIOLA_OK;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) u[2 * i + j] = um.m[i][j];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) v[2 * i + j] = vm.m[i][j];
  return failed;
}

#endif
