/* Damping forces (paper section 6.2), the "robust variant".
 *
 * The velocity gradient Fdot = Ds_dot Dm^-1 is rotated into the frame of the last update's
 * diagonalization, Fdot_hat = U^T Fdot V; the damping stress there is the rotated-linear
 * analogue Phat = beta (Fdot_hat + Fdot_hat^T) + alpha tr(Fdot_hat) I, rotated back,
 * P = U Phat V^T, and turned into nodal forces exactly as the elastic stress is.
 *
 * Why this form: it never divides by Fhat, so it does not vanish (or blow up) on flat,
 * collapsed or inverted tets, which is what keeps those from oscillating. It is linear in v,
 * and with A = Fdot_hat(v), B = Fdot_hat(w): w . f(v) = -sum V0 [beta/2 (A + A^T):(B + B^T)
 * + alpha tr A tr B], symmetric in v and w and <= 0 for v = w (alpha, beta >= 0). So the
 * implicit step's matrix M - dt/2 D is symmetric positive definite and CG applies.
 * Angular momentum: the per-tet torque vanishes iff P F^T is symmetric, i.e. iff Phat Fhat
 * is symmetric; that holds at rest (Fhat = I) and for uniform scaling, not in general. So a
 * deformed element in rigid rotation feels a small spurious damping torque; the paper accepts
 * this (errors are small near the undeformed state), and so do we. */
#include <math.h>

#include "force/elastic_body_internal.h"
#include "force/svd_kernel.h"

#define B PIOLA_TET_BLOCK

PIOLA_WIDE_VECTORS static void damping_block(const piola_elastic_body *body, const double *vel, double beta,
                          double alpha, int32_t block) {
  const int32_t base = block * B;
  const int32_t *i0 = body->tet_vertices[0] + base, *i1 = body->tet_vertices[1] + base;
  const int32_t *i2 = body->tet_vertices[2] + base, *i3 = body->tet_vertices[3] + base;
  double *const *dmi = body->dm_inv;
  double *const *uu = body->u;
  double *const *vv = body->v;
  double g[9][B];
#pragma omp simd
  for (int l = 0; l < B; ++l) {
    const int32_t t = base + l;
    const double *p0 = vel + 3 * i0[l], *p1 = vel + 3 * i1[l], *p2 = vel + 3 * i2[l],
                 *p3 = vel + 3 * i3[l];
    double d[3][3] = {{p1[0] - p0[0], p2[0] - p0[0], p3[0] - p0[0]},
                      {p1[1] - p0[1], p2[1] - p0[1], p3[1] - p0[1]},
                      {p1[2] - p0[2], p2[2] - p0[2], p3[2] - p0[2]}};
    double fd[3][3], a[3][3], ph[3][3], p[3][3];
    /* Fdot = Ds_dot Dm^-1 */
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        fd[i][j] = d[i][0] * dmi[j][t] + d[i][1] * dmi[3 + j][t] + d[i][2] * dmi[6 + j][t];
    /* Fdot_hat = U^T Fdot V, via a = Fdot V first */
    double fv[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        fv[i][j] = fd[i][0] * vv[j][t] + fd[i][1] * vv[3 + j][t] + fd[i][2] * vv[6 + j][t];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        a[i][j] = uu[i][t] * fv[0][j] + uu[3 + i][t] * fv[1][j] + uu[6 + i][t] * fv[2][j];
    double tr = alpha * (a[0][0] + a[1][1] + a[2][2]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ph[i][j] = beta * (a[i][j] + a[j][i]) + (i == j ? tr : 0.0);
    /* P = U Phat V^T, via fv = U Phat */
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        fv[i][j] = uu[3 * i][t] * ph[0][j] + uu[3 * i + 1][t] * ph[1][j] + uu[3 * i + 2][t] * ph[2][j];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        p[i][j] = fv[i][0] * vv[3 * j][t] + fv[i][1] * vv[3 * j + 1][t] + fv[i][2] * vv[3 * j + 2][t];
    double w = -body->rest_volume[t];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        g[3 * i + j][l] = w * (p[i][0] * dmi[3 * j][t] + p[i][1] * dmi[3 * j + 1][t] +
                               p[i][2] * dmi[3 * j + 2][t]);
  }
  double *tf = body->tet_forces + 12 * (size_t)base;
  for (int l = 0; l < B; ++l) {
    double *o = tf + 12 * l;
    for (int i = 0; i < 3; ++i) {
      double a = g[3 * i][l], b = g[3 * i + 1][l], c = g[3 * i + 2][l];
      o[i] = -(a + b + c);
      o[3 + i] = a;
      o[6 + i] = b;
      o[9 + i] = c;
    }
  }
}

void piola_elastic_body_damping_forces(const piola_elastic_body *body, const double *v,
                                       double shear_viscosity, double bulk_viscosity,
                                       double *forces) {
  if (!body || !v || !forces) return;
  int32_t blocks = body->padded_tet_count / B;
  /* the per-tet buffer is scratch shared with the elastic update: concurrent calls on one
   * body are not allowed (documented in the header contract of the body) */
#pragma omp parallel for schedule(static) num_threads(piola__thread_count())
  for (int32_t b = 0; b < blocks; ++b)
    damping_block(body, v, shear_viscosity, bulk_viscosity, b);
  piola__elastic_body_gather_forces(body, forces);
}
